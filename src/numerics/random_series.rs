//! A stationary random signal of given spectrum as a sum of cosines with random phases
//! (the spectral representation of Shinozuka and Deodatis, Appl. Mech. Rev. 44, 1991),
//! its bands' wavenumbers drawn at random within sub-bands so the sum never repeats.

use super::LANES;
use rand_core::RngCore;
use rand_pcg::Pcg64;
use std::f64::consts::TAU;

/// The pseudo-random numbers of one seeded stream: PCG64 (`rand_pcg`'s `Lcg128Xsl64`,
/// whose output for a state and stream is fixed across versions; O'Neill, PCG, 2014),
/// the seed its state and `stream` its stream (its increment), so that each rail and each
/// wheel draws its own numbers from one seed.
pub struct Stream(Pcg64);

impl Stream {
    /// Stream `stream` of seed `seed`.
    pub fn new(seed: u64, stream: u64) -> Self {
        Stream(Pcg64::new(u128::from(seed), u128::from(stream)))
    }

    /// A number uniform in [0, 1), from the top 53 bits of the next word.
    pub fn uniform(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// `h(s) = sum_j a_j cos(k_j s + phi_j)`: a signal along a coordinate `s` (m along the
/// rail, or rad round a wheel) of wavenumbers `k_j` (rad per unit of `s`), amplitudes
/// `a_j` and phases `phi_j` (rad). Its mean square over a long run is `sum a_j^2 / 2`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct CosineSeries {
    k: Vec<f64>,
    a: Vec<f64>,
    phi: Vec<f64>,
}

impl CosineSeries {
    /// No terms: zero everywhere.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds the term `a cos(k s + phi)`.
    pub fn push(&mut self, k: f64, a: f64, phi: f64) {
        self.k.push(k);
        self.a.push(a);
        self.phi.push(phi);
    }

    /// Adds `terms` terms for the band of wavenumbers `[k_lo, k_hi]` (rad per unit of
    /// `s`, `0 < k_lo < k_hi`) holding the variance `variance(k0, k1)` between `k0` and
    /// `k1` (the spectrum integrated there): the band is split into `terms` sub-bands
    /// of equal ratio; each term's wavenumber is drawn log-uniform within its sub-band,
    /// its amplitude is `sqrt(2 var)` of its sub-band's variance times `filter(k)` (1 for
    /// none), its phase uniform in [0, 2 pi). Without the filter the terms' mean square
    /// is the band's variance exactly. `wavenumber` maps the drawn wavenumber onto the
    /// one used (the identity, or the nearest whole number of waves round a wheel).
    pub fn add_band(
        &mut self,
        (k_lo, k_hi): (f64, f64),
        terms: usize,
        variance: impl Fn(f64, f64) -> f64,
        filter: impl Fn(f64) -> f64,
        wavenumber: impl Fn(f64) -> f64,
        rng: &mut Stream,
    ) {
        let ratio = (k_hi / k_lo).powf(1.0 / terms as f64);
        for j in 0..terms {
            let (k0, k1) = (k_lo * ratio.powi(j as i32), k_lo * ratio.powi(j as i32 + 1));
            let k = wavenumber(k0 * ratio.powf(rng.uniform()));
            let phi = TAU * rng.uniform();
            self.push(k, (2.0 * variance(k0, k1)).sqrt() * filter(k), phi);
        }
    }

    /// Multiplies every amplitude by `factor`.
    pub fn scaled(mut self, factor: f64) -> Self {
        self.a.iter_mut().for_each(|a| *a *= factor);
        self
    }

    /// The terms of both.
    pub fn joined(mut self, other: &CosineSeries) -> Self {
        self.k.extend(&other.k);
        self.a.extend(&other.a);
        self.phi.extend(&other.phi);
        self
    }

    /// Number of terms.
    pub fn len(&self) -> usize {
        self.k.len()
    }

    /// Whether it has no terms.
    pub fn is_empty(&self) -> bool {
        self.k.is_empty()
    }

    /// `sum a_j^2 / 2`: the mean square over a long run.
    pub fn mean_square(&self) -> f64 {
        self.a.iter().map(|a| 0.5 * a * a).sum()
    }

    /// The terms `(k, a, phi)`.
    pub fn terms(&self) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
        self.k
            .iter()
            .zip(&self.a)
            .zip(&self.phi)
            .map(|((&k, &a), &p)| (k, a, p))
    }

    /// `h(s)` and `dh/ds` ([`CosineSeries::at`]) at the widest vector level this CPU has,
    /// out of line: the coupled step calls it only on a drawn track, and inlined it
    /// grew the step's code for every run (3 % more instructions a step on ideal rails).
    #[inline(never)]
    pub fn eval(&self, s: f64) -> (f64, f64) {
        super::SimdLevel::detect().run(
            #[inline(always)]
            || self.at(s),
        )
    }

    /// `h(s)` and `dh/ds`: the terms in blocks of [`LANES`], each block's cosines and
    /// sines by `sin_cos_reduced` (plain products and sums, which vectorise and give
    /// the same bits in scalar and vector code), the blocks' sums added in order.
    #[inline(always)]
    pub fn at(&self, s: f64) -> (f64, f64) {
        let (mut h, mut d) = ([0.0; LANES], [0.0; LANES]);
        let k = self.k.chunks_exact(LANES);
        let a = self.a.chunks_exact(LANES);
        let phi = self.phi.chunks_exact(LANES);
        let (kr, ar, pr) = (k.remainder(), a.remainder(), phi.remainder());
        for ((k, a), phi) in k.zip(a).zip(phi) {
            for l in 0..LANES {
                let (sin, cos) = sin_cos_reduced(k[l] * s + phi[l]);
                h[l] += a[l] * cos;
                d[l] -= a[l] * k[l] * sin;
            }
        }
        for l in 0..kr.len() {
            let (sin, cos) = sin_cos_reduced(kr[l] * s + pr[l]);
            h[l] += ar[l] * cos;
            d[l] -= ar[l] * kr[l] * sin;
        }
        (h.iter().sum(), d.iter().sum())
    }
}

/// `(sin x, cos x)` to the rounding of the argument (`4e-16 |x|`, checked to `|x| = 1e6`): `x` reduced by the
/// nearest multiple of `pi / 2` (Cody and Waite's two-part constant), the Taylor series
/// of sine and cosine to the 17th and 16th powers on `[-pi/4, pi/4]` (truncation below
/// 2e-18), the quadrant chosen by arithmetic, not branches, so that a loop of it
/// vectorises.
#[inline(always)]
pub fn sin_cos_reduced(x: f64) -> (f64, f64) {
    const HALF_PI_HI: f64 = 1.570_796_326_734_125_6; // 33 bits of pi / 2
    const HALF_PI_LO: f64 = 6.077_100_506_506_192e-11; // pi / 2 - HALF_PI_HI
    // Rounding to the nearest whole number by adding and taking off 1.5 2^52 (valid
    // below 2^51): no call to `round`, which the baseline (SSE2) has no instruction for.
    const ROUND: f64 = 6_755_399_441_055_744.0;
    let n = (x * std::f64::consts::FRAC_2_PI + ROUND) - ROUND;
    let r = (x - n * HALF_PI_HI) - n * HALF_PI_LO;
    let r2 = r * r;
    let s = r
        * (1.0
            + r2 * (-1.0 / 6.0
                + r2 * (1.0 / 120.0
                    + r2 * (-1.0 / 5040.0
                        + r2 * (1.0 / 362_880.0
                            + r2 * (-1.0 / 39_916_800.0
                                + r2 * (1.0 / 6_227_020_800.0
                                    + r2 * (-1.0 / 1_307_674_368_000.0
                                        + r2 * (1.0 / 355_687_428_096_000.0)))))))));
    let c = 1.0
        + r2 * (-0.5
            + r2 * (1.0 / 24.0
                + r2 * (-1.0 / 720.0
                    + r2 * (1.0 / 40_320.0
                        + r2 * (-1.0 / 3_628_800.0
                            + r2 * (1.0 / 479_001_600.0
                                + r2 * (-1.0 / 87_178_291_200.0
                                    + r2 * (1.0 / 20_922_789_888_000.0))))))));
    // The quadrant n mod 4 as q = n - 4 round(n / 4), in -2..=2 (-2 and 2 the same):
    // for n mod 4 = 0, 1, 2, 3, sin x = s, c, -s, -c and cos x = c, -s, -c, s. The
    // choice and the signs by bit masks, exact, so that the loop vectorises.
    let q = n - 4.0 * ((n * 0.25 + ROUND) - ROUND);
    let mask = |b: bool| (b as u64).wrapping_neg();
    let odd = mask(q == 1.0 || q == -1.0);
    let neg_sin = ((q == 2.0 || q == -2.0 || q == -1.0) as u64) << 63;
    let neg_cos = ((q == 1.0 || q == 2.0 || q == -2.0) as u64) << 63;
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let sin = (cb & odd) | (sb & !odd);
    let cos = (sb & odd) | (cb & !odd);
    (f64::from_bits(sin ^ neg_sin), f64::from_bits(cos ^ neg_cos))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_reduced_sine_and_cosine_are_the_library_ones_to_rounding() {
        let mut worst: f64 = 0.0;
        let mut x = -1e6;
        while x < 1e6 {
            let (s, c) = sin_cos_reduced(x);
            let (ls, lc) = x.sin_cos();
            // The argument's own rounding: |x| eps.
            let tol = 4e-16 * x.abs().max(1.0);
            worst = worst.max(((s - ls).abs() / tol).max((c - lc).abs() / tol));
            x += 0.7345;
        }
        assert!(worst < 1.0, "{worst}");
        let (h, p) = (std::f64::consts::FRAC_PI_2, std::f64::consts::PI);
        for x in [0.0, 1e-300, 0.785, h, p, p + 1e-9, -2.0, 1e9 + 0.3] {
            let (s, c) = sin_cos_reduced(x);
            assert!((s - x.sin()).abs() < 1e-15 * x.abs().max(1.0), "{x}");
            assert!((c - x.cos()).abs() < 1e-15 * x.abs().max(1.0), "{x}");
        }
    }

    #[test]
    fn a_band_holds_its_variance_and_draws_the_same_terms_from_the_same_seed() {
        // A flat spectrum of 2e-6 m^2 per rad/m over [1, 10] rad/m: variance 1.8e-5 m^2.
        let var = |k0: f64, k1: f64| 2e-6 * (k1 - k0);
        let draw = |seed, stream| {
            let mut s = CosineSeries::new();
            let mut r = Stream::new(seed, stream);
            s.add_band((1.0, 10.0), 40, var, |_| 1.0, |k| k, &mut r);
            s
        };
        let s = draw(7, 0);
        assert_eq!(s.len(), 40);
        assert!((s.mean_square() - 1.8e-5).abs() < 1e-18);
        assert!(
            s.terms()
                .all(|(k, _, p)| (1.0..=10.0).contains(&k) && (0.0..TAU).contains(&p))
        );
        assert_eq!(s, draw(7, 0));
        assert_ne!(s, draw(8, 0));
        assert_ne!(s, draw(7, 1));
        // The sampled mean square over a long run approaches the terms' (cross terms
        // average out), and the slope is the derivative.
        let n = 200_000;
        let ms: f64 = (0..n).map(|i| s.at(i as f64 * 0.05).0.powi(2)).sum::<f64>() / n as f64;
        assert!((ms / 1.8e-5 - 1.0).abs() < 0.02, "{ms}");
        let (x, e) = (3.7, 1e-6);
        let fd = (s.at(x + e).0 - s.at(x - e).0) / (2.0 * e);
        assert!((fd - s.at(x).1).abs() < 1e-8 * s.at(x).1.abs().max(1e-3));
    }
}
