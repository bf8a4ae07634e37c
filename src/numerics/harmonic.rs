//! The amplitude of one harmonic in a sampled signal.

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
    let (mut c, mut s) = (0.0, 0.0);
    for (j, v) in x.iter().enumerate() {
        let (sin, cos) = (std::f64::consts::TAU * f * j as f64 * dt).sin_cos();
        c += v * cos;
        s += v * sin;
    }
    2.0 * c.hypot(s) / x.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

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
