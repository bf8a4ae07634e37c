//! The exact window ends' kernel (issue 29, `Track::set_exact_ends`) and the echo of an
//! approximation of it.
//!
//! `cargo run --release --example exact_kernel dump M FILE` writes the kernel's M + 1
//! lags of the table 4.4 track (n = 8, the converged default step) as little-endian
//! f64, lag by lag, each a 4 x 4 matrix row by row. `dump M FILE E` writes the kernel
//! of the exterior's rail node E instead (0 the end node, untapered; n = 8 the node
//! that becomes the end when the window moves a span; issue 42).
//!
//! `cargo run --release --example exact_kernel echo FILE [DURATION]` reads such a
//! kernel (any approximation of the dumped one), makes it both ends' boundary on a
//! 13-span track with a 0.1 ms pulse on both rails at mid-span of span 6 (the ends
//! 4.1 m away), and prints, over DURATION s (default 0.5), the largest echo (difference
//! from a track long enough not to echo in that time) against the fixed ends' echo and
//! against the exact kernel truncated at the file's length.
use wheelflat::sim::{Scenario, Simulation, TrackSpec};
use wheelflat::track::{PointLoad, Track, TrackParams};

fn params(spans: usize) -> (TrackParams, f64) {
    let dt = Simulation::new(&Scenario::table_4_4()).unwrap().dt();
    let mut s = Scenario::table_4_4();
    s.set_spans(spans);
    let TrackSpec::Discrete(p) = s.track else {
        unreachable!()
    };
    (p, dt)
}

/// Rail deflection under the pulse at mid-span of span `j` of `spans` spans over `n`
/// steps, with exact ends of `memory` lags (0: fixed ends) whose kernel is `kernel`
/// (`None`: the exact one).
fn response(
    spans: usize,
    j: usize,
    n: usize,
    memory: usize,
    kernel: Option<&[[[f64; 4]; 4]]>,
) -> Vec<f64> {
    let (p, dt) = params(spans);
    let x = (j as f64 + 0.5) * p.sleeper_spacing;
    let mut t = Track::new(p, dt).unwrap();
    t.set_exact_ends(memory).unwrap();
    if let Some(h) = kernel {
        t.set_exact_end_kernel(h).unwrap();
    }
    (0..n)
        .map(|k| {
            let tk = k as f64 * dt;
            let force = if tk < 1e-4 {
                50e3 * (1.0 - (2.0 * std::f64::consts::PI * tk / 1e-4).cos())
            } else {
                0.0
            };
            let loads = [0, 1].map(|rail| PointLoad {
                rail,
                position: x,
                force,
            });
            t.step(&loads);
            t.rail_z_at(0, x)
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("dump") => {
            let m: usize = args[1].parse().expect("M");
            let (p, dt) = params(13);
            let mut t = Track::new(p, dt).unwrap();
            if let Err(e) = t.set_exact_ends(m) {
                eprintln!("M = {m}: {e}");
                std::process::exit(2);
            }
            // With a node E, the exterior's node E (0 the end, untapered).
            let n = p.nodes_per_span;
            let kernel = match args.get(3).map(|e| e.parse::<usize>()) {
                Some(Ok(e)) if e <= n => t.exact_exterior_kernel(e),
                Some(_) => {
                    eprintln!(
                        "E = {}: a node of the exterior's first span, 0 to {n}",
                        args[3]
                    );
                    std::process::exit(2);
                }
                None => t.exact_end_kernel(),
            };
            let bytes: Vec<u8> = kernel
                .expect("exact ends were set")
                .iter()
                .flatten()
                .flatten()
                .flat_map(|x| x.to_le_bytes())
                .collect();
            std::fs::write(&args[2], bytes).unwrap();
            println!("dt {dt} s, {} lags written to {}", m + 1, args[2]);
        }
        Some("echo") => {
            let raw = std::fs::read(&args[1]).unwrap();
            let v: Vec<f64> = raw
                .chunks(8)
                .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
                .collect();
            let h: Vec<[[f64; 4]; 4]> = v
                .chunks(16)
                .map(|c| std::array::from_fn(|o| std::array::from_fn(|i| c[4 * o + i])))
                .collect();
            let duration: f64 = args.get(2).map_or(0.5, |d| d.parse().unwrap());
            let dt = params(13).1;
            let n = (duration / dt).round() as usize;
            let far = n.div_ceil(16) + 2;
            let reference = response(2 * far + 1, far, n, 0, None);
            let echo = |u: Vec<f64>| {
                u.iter()
                    .zip(&reference)
                    .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            };
            let fixed = echo(response(13, 6, n, 0, None));
            let truncated = echo(response(13, 6, n, h.len() - 1, None));
            let approx = echo(response(13, 6, n, h.len() - 1, Some(&h)));
            println!(
                "over {duration} s, {} lags: largest echo / fixed ends' echo: exact kernel \
                 truncated {:.2e}, this kernel {:.2e}",
                h.len() - 1,
                truncated / fixed,
                approx / fixed
            );
        }
        _ => eprintln!("exact_kernel dump M FILE [E] | echo FILE [DURATION]"),
    }
}
