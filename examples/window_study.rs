//! The endless track's window against a long fixed track: the reference flat case
//! (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left wheel) and two wheelsets
//! 1.8 m apart with the flat on the front one, each over `DURATION` s (default 1 s) on
//! windows of several lengths ahead and behind, against the same run on a 600-span
//! fixed track started in its middle (the impacts at the same places relative to the
//! sleepers). Prints, per window: the largest force of each wheelset against the
//! reference's, the largest difference of the whole force history over the static
//! load, and the wall time. A window `AHEAD:BEHIND:LAYER:RATE` adds absorbing layers of
//! LAYER m with the largest damping rate RATE (1/s) beyond both sides (issue 29);
//! `AHEAD:BEHIND:0:0:MEMORY` makes the window's ends exact with MEMORY s of memory
//! (`TrackWindow::exact_memory`); the window `0:0` is the thesis' fixed 30-span track
//! instead.
//!
//! With `DEFAULT_START=1` the runs start where the FMUs start (1.37 m, two spans from
//! the fixed track's end) and last `DURATION` s (then 0.95 s: the wheel's whole run on
//! the fixed 30-span track), one wheelset only, and `0:0` is among the default windows:
//! the FMUs' old default (the fixed track) against their new one (10 m a side).
//! `SPEED` (m/s) sets the speed (default 70 km/h).
//!
//! With `BINS=1` it prints (to stderr) the largest difference of the leading wheelset's
//! force (N) in every 5 ms of the run. With `WHEN=1` it prints (to stderr) when the leading wheelset's history differs by
//! more than half its largest difference. With `SPECTRUM=1` each row also names the frequency of the largest line of the
//! leading wheelset's history difference between 100 Hz and 5 kHz (a Hann-windowed DFT
//! in 2 Hz steps).
//! `cargo run --release --example window_study [AHEAD:BEHIND[:LAYER:RATE]]...`
use std::time::Instant;
use wheelflat::sim::{Scenario, Simulation, TrackWindow, TrailingWheelset};

#[path = "../tools/spectrum.rs"]
mod spectrum;

/// Left-wheel force history of every wheelset (N), one row per step.
fn history(s: &Scenario, duration: f64) -> (Vec<Vec<f64>>, f64) {
    let mut sim = Simulation::new(s).unwrap();
    let n = (duration / sim.dt()).round() as usize;
    let mut h = Vec::with_capacity(n);
    let t0 = Instant::now();
    for _ in 0..n {
        // The fixed track ends the run where the wheel leaves it (`0:0` at speed).
        if sim.step().is_err() {
            break;
        }
        h.push(
            sim.wheelsets()
                .iter()
                .map(|w| w.latest().contact[0].force)
                .collect(),
        );
    }
    (h, t0.elapsed().as_secs_f64())
}

/// Frequency (Hz) of the largest line of `e` (sampled every `dt` s) between 100 Hz and
/// 5 kHz: a Hann-windowed DFT in 2 Hz steps.
fn strongest_line(e: &[f64], dt: f64) -> f64 {
    let w = spectrum::hann(e);
    (50..2500)
        .map(|k| 2.0 * k as f64)
        .map(|f| (f, spectrum::power(&w, dt, f)))
        .fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a })
        .0
}

fn main() {
    let default_start = std::env::var("DEFAULT_START").is_ok();
    let duration: f64 = std::env::var("DURATION")
        .ok()
        .map_or(if default_start { 0.95 } else { 1.0 }, |v| {
            v.parse().expect("DURATION")
        });
    let mut windows: Vec<(f64, f64, f64, f64, f64)> = std::env::args()
        .skip(1)
        .map(|a| {
            let v: Vec<f64> = a.split(':').map(|x| x.parse().expect("a number")).collect();
            match v[..] {
                [x, y] => (x, y, 0.0, 0.0, 0.0),
                [x, y, l, r] => (x, y, l, r, 0.0),
                [x, y, l, r, m] => (x, y, l, r, m),
                _ => panic!(
                    "AHEAD:BEHIND, AHEAD:BEHIND:LAYER:RATE or AHEAD:BEHIND:LAYER:RATE:MEMORY"
                ),
            }
        })
        .collect();
    if windows.is_empty() {
        windows = if default_start {
            [0.0, 6.0, 8.0, 10.0, 12.0, 20.0].to_vec()
        } else {
            [4.0, 8.0, 12.0, 16.0, 20.0, 30.0].to_vec()
        }
        .into_iter()
        .map(|x| (x, x, 0.0, 0.0, 0.0))
        .collect();
    }
    let cases: &[bool] = if default_start {
        &[false]
    } else {
        &[false, true]
    };
    for &bogie in cases {
        let mut base = Scenario::table_4_4_flat();
        if let Ok(v) = std::env::var("SPEED") {
            base.speed = v.parse().expect("SPEED in m/s");
        }
        if !default_start {
            base.start_position = 10.0 * 0.685;
        }
        if bogie {
            base.trailing.push(TrailingWheelset {
                offset: 1.8,
                ..Default::default()
            });
        }
        let a = 0.685;
        let mut fixed = base.clone();
        fixed.set_spans(600);
        fixed.start_position = base.start_position + 290.0 * a;
        let (reference, wall) = history(&fixed, duration);
        let load = Simulation::new(&base).unwrap().static_load()[0];
        let peaks = |h: &[Vec<f64>]| {
            (0..h[0].len())
                .map(|k| h.iter().map(|r| r[k]).fold(f64::MIN, f64::max))
                .collect::<Vec<_>>()
        };
        let p_ref = peaks(&reference);
        println!(
            "\n{}: 600-span fixed track, peaks {:?} kN, {:.2} s wall",
            if bogie {
                "two wheelsets 1.8 m apart, flat on the front one"
            } else {
                "one wheelset, the reference flat case"
            },
            p_ref
                .iter()
                .map(|p| (p / 100.0).round() / 10.0)
                .collect::<Vec<_>>(),
            wall
        );
        println!(
            "| ahead (m) | behind (m) | layer (m) | rate (1/s) | exact ends' memory (s) | spans | peak error per wheelset (%) | largest history difference / static load (%) | wall (s) |"
        );
        println!("|---|---|---|---|---|---|---|---|---|");
        for &(ahead, behind, layer, layer_rate, exact_memory) in &windows {
            let mut s = base.clone();
            s.window = (ahead > 0.0).then_some(TrackWindow {
                ahead,
                behind,
                layer,
                layer_rate,
                exact_memory,
            });
            let spans = Simulation::new(&s).unwrap().rail_nodes() / 2 / 8;
            let (h, wall) = history(&s, duration);
            let p = peaks(&h);
            // Over the run's own length (a fixed track may end it early).
            let p_ref = peaks(&reference[..h.len()]);
            let errs: Vec<String> = p
                .iter()
                .zip(&p_ref)
                .map(|(a, b)| format!("{:+.3}", 100.0 * (a - b) / b))
                .collect();
            let diff = h
                .iter()
                .zip(&reference)
                .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
                .fold(0.0, f64::max);
            if std::env::var("BINS").is_ok() {
                let dt = duration / reference.len() as f64;
                let b = (0.005 / dt) as usize;
                let mut line = String::new();
                for (i, c) in h.chunks(b).zip(reference.chunks(b)).enumerate() {
                    let m =
                        c.0.iter()
                            .zip(c.1)
                            .map(|(a, b)| (a[0] - b[0]).abs())
                            .fold(0.0, f64::max);
                    line += &format!(" {}:{:.0}", i * 5, m);
                }
                eprintln!("{line}");
            }
            if std::env::var("WHEN").is_ok() {
                let dt = duration / reference.len() as f64;
                for (j, (a, b)) in h.iter().zip(&reference).enumerate() {
                    if (a[0] - b[0]).abs() > 0.5 * diff {
                        eprintln!("t = {:.4} s: {:.0} N", j as f64 * dt, a[0] - b[0]);
                    }
                }
            }
            let line = if std::env::var("SPECTRUM").is_ok() {
                let e: Vec<f64> = h.iter().zip(&reference).map(|(a, b)| a[0] - b[0]).collect();
                format!(
                    " {:.0} Hz |",
                    strongest_line(&e, duration / reference.len() as f64)
                )
            } else {
                String::new()
            };
            let until = if h.len() < reference.len() {
                format!(
                    " (to {:.3} s)",
                    duration * h.len() as f64 / reference.len() as f64
                )
            } else {
                String::new()
            };
            println!(
                "| {ahead} | {behind} | {layer} | {layer_rate} | {exact_memory} | {spans}{until} | {} | {:.3} | {wall:.2} |{line}",
                errs.join(", "),
                100.0 * diff / load
            );
        }
    }
}
