//! The quiet force's spectrum (issue 27): table 4.4's vehicle and track, perfect wheels,
//! 70 km/h, the endless track (the converged window, 20 m a side), the left wheel's contact force over
//! whole sleeper-passing periods after 0.2 s, for several grids (nodes per span n).
//! At steady state the force is periodic with the sleeper passing period `a / V`, so
//! its spectrum is the harmonics `k V / a`; the n-th harmonic is the node-passing line
//! `n V / a`. Prints, per n: the peak to peak, the sleeper-passing line (k = 1) and the
//! node-passing line (k = n) as amplitudes (kN) of their harmonic, projected over whole
//! periods. `cargo run --release --example ripple_study [linear] [N]...` (default
//! 4 8 16 32; `linear`: the rail between nodes by the thesis' (3.23), as before
//! issue 27).
use wheelflat::numerics::harmonic_amplitude as amplitude;
use wheelflat::sim::{Scenario, Simulation, TrackWindow};
use wheelflat::track::RailBetweenNodes;

fn main() {
    let linear = std::env::args().nth(1).as_deref() == Some("linear");
    let ns: Vec<usize> = std::env::args()
        .skip(1 + usize::from(linear))
        .map(|a| a.parse().expect("n"))
        .collect();
    let ns = if ns.is_empty() {
        vec![4, 8, 16, 32]
    } else {
        ns
    };
    println!(
        "| n | dt (us) | peak to peak (kN) | sleeper passing V/a (kN) | node passing nV/a (kN, Hz) | mean (kN) |"
    );
    println!("|---|---|---|---|---|---|");
    for n in ns {
        let mut s = Scenario::table_4_4();
        s.set_nodes_per_span(n);
        if linear {
            s.set_between_nodes(RailBetweenNodes::Linear);
        }
        s.window = Some(TrackWindow::CONVERGED);
        s.start_position = 10.0 * 0.685;
        let mut sim = Simulation::new(&s).unwrap();
        let dt = sim.dt();
        let a = 0.685;
        let f1 = s.speed / a;
        sim.run(0.2, |_| {}).unwrap();
        // Whole periods of the sleeper passing, about 1 s.
        let periods = (1.0 * f1).floor();
        let steps = (periods / f1 / dt).round() as usize;
        let mut x = Vec::with_capacity(steps);
        for _ in 0..steps {
            sim.step().unwrap();
            x.push(sim.wheelsets().iter().next().unwrap().latest().contact[0].force);
        }
        // The window holds steps * dt, within a step of whole periods: the harmonic's
        // frequency is taken from the samples' span.
        let f1w = periods / (steps as f64 * dt);
        let mean = x.iter().sum::<f64>() / x.len() as f64;
        let y: Vec<f64> = x.iter().map(|v| v - mean).collect();
        let (lo, hi) = x
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &v| (l.min(v), h.max(v)));
        println!(
            "| {n} | {:.2} | {:.2} | {:.3} | {:.3} at {:.0} | {:.2} |",
            dt * 1e6,
            (hi - lo) / 1e3,
            amplitude(&y, dt, f1w) / 1e3,
            amplitude(&y, dt, n as f64 * f1w) / 1e3,
            n as f64 * f1,
            mean / 1e3
        );
    }
}
