//! Cost of the reference case (table 4.4, 70 km/h, one 100 mm x 1.5 mm flat,
//! 30 spans) at the seed grid (n = 2, dt = 45 us), for instruction counting:
//! `valgrind --tool=callgrind target/release/examples/engine_step_cost [seconds [repeats]]`.
//! Without valgrind it prints wall time per step and per simulated second. A third
//! argument `baseline`, `avx2` or `avx512` picks the SIMD level (default: the widest).

use std::hint::black_box;
use std::time::Instant;
use wheelflat::sim::{Scenario, Simulation};

fn main() {
    let secs: f64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.3);
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    s.dt = 45e-6;
    let mut sim = Simulation::new(&s).unwrap();
    if let Some(level) = std::env::args().nth(3) {
        use wheelflat::track::SimdLevel;
        let level = match level.as_str() {
            "baseline" => SimdLevel::Baseline,
            "avx2" => SimdLevel::Avx2,
            "avx512" => SimdLevel::Avx512,
            other => panic!("unknown SIMD level {other}: baseline, avx2 or avx512"),
        };
        sim.set_simd(level).unwrap();
    }
    let repeats: u64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let n = (secs / sim.dt()).round() as u64;
    let mut e = sim.clone();
    let t0 = Instant::now();
    for _ in 0..repeats {
        e = sim.clone();
        for _ in 0..n {
            // The sample is kept where step returns it (no copy into black_box).
            black_box(e.step().as_ref().unwrap());
        }
    }
    let w = t0.elapsed().as_secs_f64() / repeats as f64;
    println!(
        "{n} steps: {:.1} ns per step, {:.2} ms per simulated second; peak left {:.1} kN",
        w / n as f64 * 1e9,
        w / (n as f64 * sim.dt()) * 1e3,
        e.max_force()[0] / 1e3
    );
}
