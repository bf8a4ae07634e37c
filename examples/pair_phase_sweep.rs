//! The seed's two-flat case (table 5.1 family, 60 mm x 0.8 mm haversine flats):
//! one flat on the left wheel at 90 deg, a like flat on the right wheel at
//! 90 deg + phase, phase swept in 10 deg steps at several speeds, against the same
//! run with the left flat alone. Prints the peak impact force (either wheel) per
//! speed and grid, the worst phase, and the single-flat peak.
//! `cargo run --release --example pair_phase_sweep`
use wheelflat::sim::{Scenario, Simulation, TrackSpec, kmh};
use wheelflat::wheel::FlatSpec;

fn peak(s: &Scenario) -> f64 {
    let mut sim = Simulation::new(s).unwrap();
    let TrackSpec::Discrete(t) = &s.track else {
        unreachable!()
    };
    // Run until the wheel is one span short of the track end.
    let dur = ((t.length() - t.sleeper_spacing - s.start_position) / s.speed).min(0.5);
    sim.run(dur, |_| {}).unwrap();
    let m = sim.max_force();
    m[0].max(m[1])
}

fn main() {
    let flat = |deg: f64| FlatSpec::haversine(0.06, 0.0008, deg.to_radians());
    println!("| speed | n | left flat alone | pair, worst phase | at phase | pair, phase 10 deg |");
    println!("|---|---|---|---|---|---|");
    for n in [2usize, 8] {
        for v in [40.0, 60.0, 80.0, 100.0, 120.0] {
            let mut s = Scenario::table_5_1();
            s.set_nodes_per_span(n);
            s.speed = kmh(v);
            s.flats = [vec![flat(90.0)], vec![]];
            let single = peak(&s);
            let (mut worst, mut at, mut ten) = (0.0f64, 0.0, 0.0);
            for k in 0..36 {
                let phase = 10.0 * k as f64;
                s.flats[1] = vec![flat(90.0 + phase)];
                let p = peak(&s);
                if p > worst {
                    worst = p;
                    at = phase;
                }
                if k == 1 {
                    ten = p;
                }
            }
            println!(
                "| {v} km/h | {n} | {:.1} kN | {:.1} kN | {at} deg | {:.1} kN |",
                single / 1e3,
                worst / 1e3,
                ten / 1e3
            );
        }
    }
}
