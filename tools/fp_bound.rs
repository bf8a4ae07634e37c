//! The track step against the machine it runs on (issue 42): the fraction of the
//! floating-point ports' bound that the track's loops reach, at each vector level this
//! CPU has (AVX2, AVX-512; the baseline has no bound to speak of), for tracks of the
//! thesis' fixed 30 spans, of the FMUs' default window (10 m a side, 31 spans) and of
//! the converged window (20 m a side, 60 spans), all at the converged default grid
//! (n = 8, its default step). Each is stepped as a fixed track of that many spans: a
//! window's shift (a copy of the state, about a step's cost each sleeper span the wheel
//! travels) is not in it.
//!
//! The bound counts the vector floating-point instructions of the loops of
//! `src/track/kernels.rs` over the padded, phase-blocked slots (`n x 2 x S` rail
//! slots, `S` the sleepers rounded up to 8), as (multiply-adds and products, sums,
//! logic) a vector: the rail stencil (6, 4, 0), two chains of three multiply-adds
//! with a sum and a difference each; block 0 adds (1, 0, 2), the pad force and the
//! two masks; the sleepers (14, 6, 0), the pad forces and the sleeper update. The
//! ports are those of Intel's Golden Cove cores (Sapphire Rapids, the machines this
//! project has run on): 512-bit vectors on two ports (0 and 5), each taking any of
//! them; 256-bit ones on three (0, 1, 5), products and multiply-adds on two of them
//! (0, 1). On other cores the bound is that model's, not theirs (the output says so).
//! Cycles are wall time at the clock `/proc/cpuinfo` names: on a virtual machine its
//! nominal clock (turbo makes the fraction look better than it is), on bare metal the
//! clock of the moment. Each track is timed over `STEPS` steps (default 20,000) under
//! two moving wheel loads, the levels interleaved, best of five rounds.
//!
//! `cargo run --release --example fp_bound`

use std::hint::black_box;
use std::time::Instant;
use wheelflat::numerics::LANES;
use wheelflat::sim::{Scenario, Simulation, TrackState, TrackWindow};
use wheelflat::track::{PointLoad, SimdLevel, Track};

/// The ports' bound (cycles) of a step of a track of `spans` spans, `n` nodes a span,
/// at `level`.
fn bound_cycles(spans: usize, n: usize, level: SimdLevel) -> f64 {
    let width = if level == SimdLevel::Avx512 { 8 } else { 4 };
    let v = ((spans + 1).next_multiple_of(LANES) / width) as f64;
    let (stencil, block0, sleepers) = (2.0 * n as f64 * v, 2.0 * v, v);
    let fma = 6.0 * stencil + block0 + 14.0 * sleepers;
    let all = fma + 4.0 * stencil + 2.0 * block0 + 6.0 * sleepers;
    if level == SimdLevel::Avx512 {
        all / 2.0
    } else {
        (fma / 2.0).max(all / 3.0)
    }
}

/// The CPU's model name from `/proc/cpuinfo`.
fn model() -> String {
    let info = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
    info.lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map_or("unknown".into(), |m| m.trim().to_string())
}

/// The machine's clock (Hz) as `/proc/cpuinfo` names it.
fn clock() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("cpu MHz"))?;
    Some(line.split(':').nth(1)?.trim().parse::<f64>().ok()? * 1e6)
}

fn main() {
    let steps: usize = std::env::var("STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let hz = clock();
    let levels: Vec<SimdLevel> = SimdLevel::available()
        .into_iter()
        .filter(|l| *l > SimdLevel::Baseline)
        .collect();
    let cases = [
        ("the thesis' fixed 30-span track", None),
        (
            "the default window, 10 m a side",
            Some(TrackWindow::DEFAULT),
        ),
        (
            "the converged window, 20 m a side",
            Some(TrackWindow::CONVERGED),
        ),
    ];
    println!(
        "CPU: {} (the bound is Golden Cove's port model: tools/fp_bound.rs)",
        model()
    );
    match hz {
        Some(hz) => println!("clock (/proc/cpuinfo): {:.0} MHz", hz / 1e6),
        None => println!("no clock in /proc/cpuinfo: cycles not shown"),
    }
    for (name, window) in cases {
        let mut s = Scenario::table_4_4_flat();
        s.window = window;
        let sim = Simulation::new(&s).unwrap();
        let TrackState::Discrete(t) = sim.track() else {
            unreachable!("table 4.4 has the discrete track")
        };
        let (p, dt) = (*t.params(), t.dt());
        let mut tracks: Vec<Track> = levels
            .iter()
            .map(|&l| {
                let mut t = Track::new(p, dt).unwrap();
                t.set_simd(l).unwrap();
                t
            })
            .collect();
        let mut best = vec![f64::INFINITY; levels.len()];
        let mid = 0.5 * p.length();
        for _ in 0..5 {
            for (k, t) in tracks.iter_mut().enumerate() {
                let t0 = Instant::now();
                for j in 0..steps {
                    let x = mid + 1e-4 * (j % 1000) as f64;
                    let loads = [0, 1].map(|rail| PointLoad {
                        rail,
                        position: x,
                        force: 1e5,
                    });
                    t.step(black_box(&loads));
                }
                best[k] = best[k].min(t0.elapsed().as_secs_f64() / steps as f64);
            }
        }
        println!("{name}: {} spans, n = {}", p.spans, p.nodes_per_span);
        for (l, w) in levels.iter().zip(&best) {
            let bound_cycles = bound_cycles(p.spans, p.nodes_per_span, *l);
            match hz {
                Some(hz) => println!(
                    "  {l:?}: {:.3} us a step, {:.0} cycles; the ports' bound {bound_cycles:.0} cycles: {:.0} % of it",
                    w * 1e6,
                    w * hz,
                    100.0 * bound_cycles / (w * hz)
                ),
                None => println!(
                    "  {l:?}: {:.3} us a step; the ports' bound {bound_cycles:.0} cycles",
                    w * 1e6
                ),
            }
        }
    }
}
