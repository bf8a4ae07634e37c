//! Spectra for the window examples (`examples/window_study.rs`,
//! `examples/window_reflection.rs`): a record under a Hann window, and the power of such
//! a record at one frequency (one term of its discrete Fourier transform). A handful of
//! lines or bands is wanted, not a whole spectrum, so the terms are summed directly.

use std::f64::consts::PI;

/// `e` under a Hann window of its own length.
pub fn hann(e: &[f64]) -> Vec<f64> {
    let m = e.len() as f64;
    e.iter()
        .enumerate()
        .map(|(i, x)| x * 0.5 * (1.0 - (2.0 * PI * i as f64 / m).cos()))
        .collect()
}

/// `|sum_i w_i exp(-2 pi j f i dt)|^2` of the record `w` sampled every `dt` (s), at the
/// frequency `f` (Hz).
pub fn power(w: &[f64], dt: f64, f: f64) -> f64 {
    let (mut re, mut im) = (0.0, 0.0);
    for (i, x) in w.iter().enumerate() {
        let (s, c) = (2.0 * PI * f * i as f64 * dt).sin_cos();
        re += x * c;
        im -= x * s;
    }
    re * re + im * im
}
