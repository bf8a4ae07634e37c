//! Times the parts of one coupled step of the reference case (seed grid).
use std::time::Instant;
use wheelflat::params::{Scenario, TrackSpec};
use wheelflat::track::{PointLoad, Track};

fn main() {
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    let TrackSpec::Discrete(p) = s.track else {
        unreachable!()
    };
    let mut t = Track::new(p, 45e-6).unwrap();
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
    let n = 200_000;
    let t0 = Instant::now();
    for _ in 0..n {
        t.step(std::hint::black_box(&loads));
    }
    let per = t0.elapsed().as_secs_f64() / n as f64;
    println!(
        "track step: {:.1} ns ({} nodes per rail) -> {:.2} ms per simulated s at 45 us",
        per * 1e9,
        t.nodes(),
        per / 45e-6 * 1e3
    );
    let z = t.rail_z(0);
    let subn = |v: &[f64]| {
        v.iter()
            .filter(|v| v.abs() < 2.3e-308 && **v != 0.0)
            .count()
    };
    let sub = subn(z) + subn(t.rail_z(1)) + subn(t.rail_theta(0)) + subn(t.rail_theta(1));
    println!(
        "subnormal sleeper bounce {}, roll {}",
        subn(t.sleeper_z()),
        subn(t.sleeper_roll())
    );
    println!("subnormal rail values: {sub}");
    let mut t2 = Track::new(p, 45e-6).unwrap();
    let t0 = Instant::now();
    for _ in 0..n {
        t2.step(std::hint::black_box(&[]));
    }
    println!(
        "track step, zero state: {:.1} ns",
        t0.elapsed().as_secs_f64() / n as f64 * 1e9
    );
    let sim = wheelflat::solver::Simulation::new(&{
        let mut s = s.clone();
        s.flats = [vec![], vec![]];
        s.dt = 45e-6;
        s
    })
    .unwrap();
    let mut a = sim.clone();
    let t0 = Instant::now();
    for _ in 0..n / 10 {
        std::hint::black_box(a.step().unwrap());
    }
    let per = t0.elapsed().as_secs_f64() / (n / 10) as f64;
    println!("coupled step, perfect wheels: {:.1} ns", per * 1e9);
}
