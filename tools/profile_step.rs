//! Times the parts of one coupled step of the reference case at the seed grid
//! (n = 2, dt = 45 us, 30 spans): the track step alone at every SIMD level this CPU
//! has, and the whole coupled step. Levels are timed in interleaved rounds and the
//! fastest round is kept, which is what a noisy shared machine allows.
//! `cargo run --release --example profile_step`
use std::hint::black_box;
use std::time::Instant;
use wheelflat::sim::{Scenario, Simulation, TrackSpec};
use wheelflat::track::{PointLoad, SimdLevel, Track};

fn main() {
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    s.dt = 45e-6;
    let TrackSpec::Discrete(p) = s.track else {
        unreachable!()
    };
    let loads = [
        PointLoad {
            rail: 0,
            position: 5.0,
            force: 1e5,
        },
        PointLoad {
            rail: 1,
            position: 5.0,
            force: 1e5,
        },
    ];
    let levels = SimdLevel::available();
    let mut tracks: Vec<Track> = levels
        .iter()
        .map(|l| {
            let mut t = Track::new(p, 45e-6).unwrap();
            t.set_simd(*l).unwrap();
            t
        })
        .collect();
    let mut best = vec![f64::INFINITY; levels.len()];
    let n = 20_000;
    for _round in 0..15 {
        for (t, b) in tracks.iter_mut().zip(best.iter_mut()) {
            let t0 = Instant::now();
            for _ in 0..n {
                t.step(black_box(&loads));
            }
            *b = b.min(t0.elapsed().as_secs_f64() / n as f64);
        }
    }
    for (l, b) in levels.iter().zip(&best) {
        println!(
            "track step {:>9}: {:6.1} ns ({} nodes per rail) -> {:.2} ms per simulated s",
            format!("{l:?}"),
            b * 1e9,
            tracks[0].nodes(),
            b / 45e-6 * 1e3
        );
    }
    let sim = Simulation::new(&s).unwrap();
    let mut perfect = s.clone();
    perfect.flats = [vec![], vec![]];
    let sim_p = Simulation::new(&perfect).unwrap();
    let steps = (0.3 / sim.dt()) as usize;
    let (mut bf, mut bp) = (f64::INFINITY, f64::INFINITY);
    for _round in 0..10 {
        for (sim, b) in [(&sim, &mut bf), (&sim_p, &mut bp)] {
            let mut a = sim.clone();
            let t0 = Instant::now();
            for _ in 0..steps {
                // The sample is kept where step returns it (no copy into black_box).
                black_box(a.step().as_ref().unwrap());
            }
            *b = b.min(t0.elapsed().as_secs_f64() / steps as f64);
        }
    }
    println!(
        "coupled step, reference flat: {:.1} ns -> {:.2} ms per simulated s",
        bf * 1e9,
        bf / 45e-6 * 1e3
    );
    println!(
        "coupled step, perfect wheels: {:.1} ns -> {:.2} ms per simulated s",
        bp * 1e9,
        bp / 45e-6 * 1e3
    );
}
