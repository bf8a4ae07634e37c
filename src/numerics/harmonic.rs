//! The discrete Fourier transform of a sampled signal at one frequency, and the amplitude
//! of one harmonic in it.

use nalgebra::Complex;
use std::f64::consts::TAU;

/// `sum_j x_j e^(-i 2 pi f j dt)` (the samples' own units; no `dt` factor, which
/// cancels in a ratio), by a rotating phasor renewed every 512 samples.
pub fn dft(x: &[f64], dt: f64, f: f64) -> Complex<f64> {
    let w = TAU * f * dt;
    let step = Complex::new(w.cos(), -w.sin());
    let mut sum = Complex::new(0.0, 0.0);
    for (b, block) in x.chunks(512).enumerate() {
        let phase = w * (512 * b) as f64;
        let mut e = Complex::new(phase.cos(), -phase.sin());
        for &v in block {
            sum += e * v;
            e *= step;
        }
    }
    sum
}

/// Amplitude of the harmonic of frequency `f` (Hz) in `x`, sampled every `dt` (s) from
/// t = 0: `2 |sum x_j e^(-i 2 pi f j dt)| / N`, the signal's own units. Exact for a
/// signal that is a sum of harmonics when the samples span a whole number of periods
/// of each (then the others and a constant contribute nothing); otherwise the leakage
/// of a constant is at most `2 |mean| / (pi f N dt)`, so take the mean out first. An
/// empty `x` gives 0.
pub fn harmonic_amplitude(x: &[f64], dt: f64, f: f64) -> f64 {
    if x.is_empty() {
        return 0.0;
    }
    2.0 * dft(x, dt, f).norm() / x.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_dft_of_a_pulse_is_its_integral_at_low_frequency() {
        let x = [0.0, 1.0, 2.0, 1.0];
        let s = dft(&x, 1e-4, 0.0);
        assert_eq!((s.re, s.im), (4.0, 0.0));
        let long: Vec<f64> = (0..2000).map(|j| (j as f64 * 0.37).sin()).collect();
        let direct: Complex<f64> = long
            .iter()
            .enumerate()
            .map(|(j, v)| Complex::from_polar(*v, -TAU * 800.0 * j as f64 * 1e-5))
            .sum();
        assert!((dft(&long, 1e-5, 800.0) - direct).norm() < 1e-9);
    }

    #[test]
    fn a_sum_of_harmonics_over_whole_periods_gives_each_amplitude() {
        // 3 sin(2 pi 28 t + 0.3) + 0.5 cos(2 pi 224 t) + 107 over one second, 50 us.
        let dt = 50e-6;
        let x: Vec<f64> = (0..20_000)
            .map(|j| {
                let t = j as f64 * dt;
                107.0
                    + 3.0 * (std::f64::consts::TAU * 28.0 * t + 0.3).sin()
                    + 0.5 * (std::f64::consts::TAU * 224.0 * t).cos()
            })
            .collect();
        assert!((harmonic_amplitude(&x, dt, 28.0) - 3.0).abs() < 1e-9);
        assert!((harmonic_amplitude(&x, dt, 224.0) - 0.5).abs() < 1e-9);
        assert!(harmonic_amplitude(&x, dt, 56.0) < 1e-9);
        assert_eq!(harmonic_amplitude(&[], dt, 28.0), 0.0);
    }
}
