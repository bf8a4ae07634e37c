//! The reflection of a window end, with and without an absorbing layer, against
//! frequency (issue 29). A short raised-cosine force pulse (0.1 ms, its spectrum flat
//! within 1.5 dB to 5 kHz) pushes both rails of the table 4.4 track (n = 8) down at
//! mid-span; the rail deflection under it is recorded for `DURATION` s (default 0.5) on:
//! - the reference: 600 spans, the load in the middle;
//! - an end `L` m from the load (the other end 300 spans away), fixed or with a layer of
//!   `ell` m and largest rate `eta` (1/s) beyond it.
//!
//! The difference from the reference is the end's echo `E(f)`. A fixed end reflects
//! every propagating wave whole (`|R| = 1`, no energy is lost there), and the track
//! between the load and the end is the same, so the layer's reflection coefficient is
//! `|R(f)| = |E_layer(f)| / |E_fixed(f)|`, given per band as the ratio of the echoes'
//! energies' square roots. A layer of rate 0 is that much more plain track, the
//! comparison that counts: a layer is worth having where it reflects less than the
//! plain track of its length. Default: `L` = 8 m, layers of 8, 20 and 40 m, and last
//! (`0:-1`) the exact ends of `Track::set_exact_ends` remembering the whole record.
//! `cargo run --release --example window_reflection [L [ell:eta]...]`
use wheelflat::sim::{Scenario, Simulation, TrackSpec};
use wheelflat::track::{PointLoad, Track, TrackParams};

#[path = "../tools/spectrum.rs"]
mod spectrum;

const BANDS: [f64; 10] = [
    0.0, 100.0, 200.0, 400.0, 700.0, 800.0, 1000.0, 1500.0, 3000.0, 5000.0,
];

/// The table 4.4 track of `spans` spans and the default step (s), 0.9 of the
/// critical step (which does not depend on the track's length).
fn params(spans: usize) -> (TrackParams, f64) {
    let dt = Simulation::new(&Scenario::table_4_4()).unwrap().dt();
    let mut s = Scenario::table_4_4();
    s.set_spans(spans);
    let TrackSpec::Discrete(p) = s.track else {
        unreachable!()
    };
    (p, dt)
}

/// Rail deflection under the load (m) at every step, the load at mid-span of span `j`
/// of a track of `spans` spans, absorbing layers of `ell` m and rate `eta` at its ends.
fn response(spans: usize, j: usize, ell: f64, eta: f64, duration: f64) -> (Vec<f64>, f64) {
    let (p, dt) = params(spans);
    let a = p.sleeper_spacing;
    let mut t = Track::new(p, dt).unwrap();
    let n = (duration / dt).round() as usize;
    if eta < 0.0 {
        // Exact ends remembering the whole record.
        t.set_exact_ends(n).unwrap();
    } else if ell > 0.0 {
        t.set_absorbing_ends(ell, eta).unwrap();
    }
    let x = (j as f64 + 0.5) * a;
    let pulse = 1e-4;
    let mut u = Vec::with_capacity(n);
    for k in 0..n {
        let tk = k as f64 * dt;
        let f = if tk < pulse {
            50e3 * (1.0 - (2.0 * std::f64::consts::PI * tk / pulse).cos())
        } else {
            0.0
        };
        let loads = [
            PointLoad {
                rail: 0,
                position: x,
                force: f,
            },
            PointLoad {
                rail: 1,
                position: x,
                force: f,
            },
        ];
        t.step(&loads);
        u.push(t.rail_z_at(0, x));
    }
    (u, dt)
}

/// Energy of `e` in each band: a plain DFT over the band's bins of `e` under a Hann
/// window (the records end while the slowest waves still ring), zero-padded to 2x.
fn band_energy(e: &[f64], dt: f64) -> Vec<f64> {
    let w = spectrum::hann(e);
    let df = 1.0 / (2.0 * w.len() as f64 * dt);
    (0..BANDS.len() - 1)
        .map(|b| {
            let (k0, k1) = (
                (BANDS[b] / df).ceil() as usize,
                (BANDS[b + 1] / df) as usize,
            );
            (k0.max(1)..k1)
                .map(|k| spectrum::power(&w, dt, k as f64 * df))
                .sum()
        })
        .collect()
}

fn main() {
    let duration: f64 = std::env::var("DURATION")
        .ok()
        .map_or(0.5, |v| v.parse().unwrap());
    let mut args = std::env::args().skip(1);
    let l: f64 = args.next().map_or(8.0, |v| v.parse().unwrap());
    let mut layers: Vec<(f64, f64)> = args
        .map(|a| {
            let v: Vec<f64> = a.split(':').map(|x| x.parse().unwrap()).collect();
            (v[0], v[1])
        })
        .collect();
    if layers.is_empty() {
        layers = vec![
            (8.0, 0.0),
            (8.0, 100.0),
            (8.0, 300.0),
            (8.0, 1000.0),
            (8.0, 3000.0),
            (20.0, 0.0),
            (20.0, 100.0),
            (20.0, 1000.0),
            (40.0, 0.0),
            (40.0, 30.0),
            (40.0, 100.0),
            (0.0, -1.0),
        ];
    }
    let a = params(30).0.sleeper_spacing;
    let far = 300;
    let (reference, dt) = response(2 * far, far, 0.0, 0.0, duration);
    let echo = |ell: f64, eta: f64| {
        // The load L m from the end of the plain track (ell m more with the layer).
        let j = ((l + ell.max(0.0)) / a).floor() as usize;
        let (u, _) = response(j + far, j, ell, eta, duration);
        // The reference's load is at span `far`, the window's at `j`: the same place
        // between sleepers, so the direct responses are the same.
        u.iter()
            .zip(&reference)
            .map(|(x, y)| x - y)
            .collect::<Vec<f64>>()
    };
    let fixed = echo(0.0, 0.0);
    let ef = band_energy(&fixed, dt);
    let er = band_energy(&reference, dt);
    print!("fixed end's echo / direct response, per band:");
    for (b, (x, y)) in ef.iter().zip(&er).enumerate() {
        print!(
            " {:.0}-{:.0} Hz {:.4};",
            BANDS[b],
            BANDS[b + 1],
            (x / y).sqrt()
        );
    }
    println!();
    let peak = reference.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let largest = fixed.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    // How long the echo rings: the first and the last time it exceeds 1e-2 and 1e-3 of
    // its largest value (what an exact boundary's memory would have to span).
    let span = |f: f64| {
        let above: Vec<usize> = (0..fixed.len())
            .filter(|&i| fixed[i].abs() > f * largest)
            .collect();
        (
            above[0] as f64 * dt * 1e3,
            above[above.len() - 1] as f64 * dt * 1e3,
        )
    };
    let (a2, b2) = span(1e-2);
    let (a3, b3) = span(1e-3);
    println!(
        "end {l} m from the load; echo of the fixed end, largest {:.2} % of the direct \
         peak; above 1 % of its largest from {a2:.1} to {b2:.1} ms, above 0.1 % from \
         {a3:.1} to {b3:.1} ms",
        100.0 * largest / peak
    );
    print!("| layer (m) | rate (1/s) |");
    for b in 0..BANDS.len() - 1 {
        print!(" {:.0}-{:.0} Hz |", BANDS[b], BANDS[b + 1]);
    }
    println!(" largest echo / fixed end's |");
    println!("|---|---|{}---|", "---|".repeat(BANDS.len() - 1));
    for &(ell, eta) in &layers {
        let e = echo(ell, eta);
        let el = band_energy(&e, dt);
        print!("| {ell} | {eta} |");
        for (x, y) in el.iter().zip(&ef) {
            print!(" {:.3} |", (x / y).sqrt());
        }
        let m = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        println!(" {:.3} |", m(&e) / m(&fixed));
    }
}
