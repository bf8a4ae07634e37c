//! The rails' vertical profile drawn from a standard track-geometry spectrum: the US
//! FRA classes 1 to 6 and the German (ORE B176) low and high levels, seeded, over a
//! band of wavelengths, the rails independent or joined by the German cross-level
//! spectrum (`docs/MODEL.md`, "Random rail profiles and roughness").
//!
//! Each spectrum is a one-sided density `S(Omega)` (m^2 per rad/m) in the wavenumber
//! `Omega = 2 pi / lambda` (rad/m): the profile's variance over a band is the integral
//! of `S` over it.

use super::*;
use crate::error::num;
use crate::numerics::{CosineSeries, Stream};

/// FRA: `Omega_c` (rad/m) and the scale `k` of Hamid and Yang's form (below).
const FRA_OMEGA_C: f64 = 0.8245;
const FRA_K: f64 = 0.25;
/// FRA classes 1 to 6: `A_v` (cm^2 rad/m).
const FRA_A_V: [f64; 6] = [1.2107, 1.0181, 0.6816, 0.5376, 0.2095, 0.0339];
/// ORE B176: `Omega_c`, `Omega_r`, `Omega_s` (rad/m) and `A_v` (m rad) of the low and
/// high levels.
const ORE_OMEGA_C: f64 = 0.8246;
const ORE_OMEGA_R: f64 = 0.0206;
const ORE_OMEGA_S: f64 = 0.4380;
const ORE_A_V: [f64; 2] = [4.032e-7, 1.080e-6];

/// The shortest ramp (m) over which a drawn profile comes in.
pub const MIN_RAMP: f64 = 1.0;

/// Terms of the drawn profile in each one-third octave of wavenumber.
pub const TERMS_PER_THIRD_OCTAVE: usize = 8;

/// A standard spectrum of the rails' vertical profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrackSpectrum {
    /// US FRA track class 1 (worst) to 6 (best), in the form of Hamid and Yang
    /// (Transportation Research Record 838, 1981) as Garg and Dukkipati (Dynamics of
    /// Railway Vehicle Systems, 1984, table 4.6) give it:
    /// `S = k A_v Omega_c^2 / (Omega^2 (Omega^2 + Omega_c^2))`, `k = 0.25`,
    /// `Omega_c = 0.8245 rad/m`, `A_v` = 1.2107, 1.0181, 0.6816, 0.5376, 0.2095, 0.0339
    /// cm^2 rad/m; valid for wavelengths of 1.5 to 300 m.
    Fra(u8),
    /// The German spectrum (ORE B176, 1989), low level: `S = A_v Omega_c^2 / ((Omega^2 +
    /// Omega_r^2)(Omega^2 + Omega_c^2))`, `Omega_c = 0.8246`, `Omega_r = 0.0206 rad/m`,
    /// `A_v = 4.032e-7 m rad`.
    OreLow,
    /// The German spectrum, high level: `A_v = 1.080e-6 m rad`.
    OreHigh,
}

impl TrackSpectrum {
    /// The spectrum's name as the parameter `rail.spectrum` gives it (`fra_class_4`,
    /// `ore_high`).
    pub fn name(&self) -> String {
        match self {
            TrackSpectrum::Fra(c) => format!("fra_class_{c}"),
            TrackSpectrum::OreLow => "ore_low".into(),
            TrackSpectrum::OreHigh => "ore_high".into(),
        }
    }

    /// Every spectrum, FRA classes 1 to 6, then the German low and high levels.
    pub fn all() -> [TrackSpectrum; 8] {
        [1, 2, 3, 4, 5, 6]
            .map(TrackSpectrum::Fra)
            .into_iter()
            .chain([TrackSpectrum::OreLow, TrackSpectrum::OreHigh])
            .collect::<Vec<_>>()
            .try_into()
            .expect("eight spectra")
    }

    fn ore_a_v(&self) -> Option<f64> {
        match self {
            TrackSpectrum::Fra(_) => None,
            TrackSpectrum::OreLow => Some(ORE_A_V[0]),
            TrackSpectrum::OreHigh => Some(ORE_A_V[1]),
        }
    }

    fn fra_scale(c: u8) -> f64 {
        // cm^2 rad/m to m^2 rad/m, times k.
        FRA_K * FRA_A_V[(c.clamp(1, 6) - 1) as usize] * 1e-4
    }

    /// The vertical profile's one-sided density `S(Omega)` (m^2 per rad/m) at the
    /// wavenumber `omega` (rad/m).
    pub fn vertical(&self, omega: f64) -> f64 {
        let w2 = omega * omega;
        match *self {
            TrackSpectrum::Fra(c) => {
                Self::fra_scale(c) * FRA_OMEGA_C.powi(2) / (w2 * (w2 + FRA_OMEGA_C.powi(2)))
            }
            _ => {
                let a = self.ore_a_v().unwrap_or(0.0);
                a * ORE_OMEGA_C.powi(2) / ((w2 + ORE_OMEGA_R.powi(2)) * (w2 + ORE_OMEGA_C.powi(2)))
            }
        }
    }

    /// The vertical profile's variance (m^2) between the wavenumbers `lo` and `hi`
    /// (rad/m): the closed-form integral of [`TrackSpectrum::vertical`] (partial
    /// fractions).
    pub fn vertical_variance(&self, lo: f64, hi: f64) -> f64 {
        let f = |w: f64| match *self {
            TrackSpectrum::Fra(c) => {
                Self::fra_scale(c) * (-1.0 / w - (w / FRA_OMEGA_C).atan() / FRA_OMEGA_C)
            }
            _ => {
                let a = self.ore_a_v().unwrap_or(0.0);
                let (c2, r2) = (ORE_OMEGA_C.powi(2), ORE_OMEGA_R.powi(2));
                a * c2 / (c2 - r2)
                    * ((w / ORE_OMEGA_R).atan() / ORE_OMEGA_R
                        - (w / ORE_OMEGA_C).atan() / ORE_OMEGA_C)
            }
        };
        f(hi) - f(lo)
    }

    /// The German cross-level spectrum as the density of the height difference of the
    /// rails, left minus right (m^2 per rad/m): `4 A_v Omega_c^2 Omega^2 / ((Omega^2 +
    /// Omega_r^2)(Omega^2 + Omega_c^2)(Omega^2 + Omega_s^2))`, `Omega_s = 0.4380 rad/m`.
    /// ORE B176 gives the cross-level angle's density, `A_v / b^2` times the same
    /// fraction, with `b` half the distance between the rails' running circles; the
    /// height difference is `2 b` times the angle, so `b` drops out. `None` for the FRA
    /// classes (no cross-level spectrum here).
    pub fn cross_level(&self, omega: f64) -> Option<f64> {
        let a = self.ore_a_v()?;
        let w2 = omega * omega;
        Some(
            4.0 * a * ORE_OMEGA_C.powi(2) * w2
                / ((w2 + ORE_OMEGA_R.powi(2))
                    * (w2 + ORE_OMEGA_C.powi(2))
                    * (w2 + ORE_OMEGA_S.powi(2))),
        )
    }
}

/// A random profile of both rails from a [`TrackSpectrum`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProfileSpec {
    /// The spectrum.
    pub spectrum: TrackSpectrum,
    /// The seed: the same seed draws the same rails.
    pub seed: u64,
    /// The band's shortest and longest wavelengths (m).
    pub band: (f64, f64),
    /// `false`: each rail drawn from the vertical spectrum on its own; `true` (German
    /// levels only, `rail.spectrum.rails = cross_level`): the mean of the rails from the vertical spectrum and their
    /// difference from the cross-level spectrum.
    pub cross_level: bool,
    /// Length (m) over which the profile grows from nothing (smoothly) from
    /// the leading wheelset's start position, so that the run starts at rest on
    /// ideal rails; at least [`MIN_RAMP`].
    pub ramp: f64,
}

/// The band's wavelength limits (m): the contact must follow the profile as it follows
/// a measured one (wavelengths above ten patch lengths,
/// [`super::MIN_DEFECT_LENGTH`]), and a run is at most some kilometres.
pub const PROFILE_BAND: (f64, f64) = (MIN_DEFECT_LENGTH, 1000.0);

impl ProfileSpec {
    /// Checks the fields; errors name the parameter (`rail.spectrum.*`).
    pub fn validate(&self) -> Result<()> {
        let (lo, hi) = self.band;
        // The shortest up to the longest's limit less a third of an octave (the
        // table's 500 m), the longest from the shortest's plus one (0.2 m).
        for (name, v, range) in [
            (
                "rail.spectrum.shortest_wavelength",
                lo,
                (PROFILE_BAND.0, 500.0),
            ),
            (
                "rail.spectrum.longest_wavelength",
                hi,
                (0.2, PROFILE_BAND.1),
            ),
        ] {
            if !(range.0..=range.1).contains(&v) {
                return Err(out_of_range(
                    name,
                    v,
                    format!("{} m <= wavelength <= {} m", range.0, range.1),
                ));
            }
        }
        if hi < 1.26 * lo {
            return Err(out_of_range(
                "rail.spectrum.longest_wavelength",
                hi,
                format!(
                    "at least a third of an octave above rail.spectrum.shortest_wavelength \
                     ({} m): >= {} m",
                    num(lo),
                    num((1.26e6 * lo).round() / 1e6)
                ),
            ));
        }
        if self.cross_level && self.spectrum.cross_level(1.0).is_none() {
            return Err(out_of_range(
                "rail.spectrum.rails",
                2.0,
                format!(
                    "1 (independent) with rail.spectrum = {}: only the German levels \
                     (ore_low, ore_high) have the cross-level spectrum that 2 (cross_level) \
                     draws",
                    self.spectrum.name()
                ),
            ));
        }
        if !(MIN_RAMP..=PROFILE_BAND.1).contains(&self.ramp) {
            return Err(out_of_range(
                "rail.spectrum.ramp",
                self.ramp,
                format!(
                    "{MIN_RAMP} m <= ramp <= {} m (the wheels start on ideal rails: a profile \
                     at full height at the start would jump under them at the first step)",
                    PROFILE_BAND.1
                ),
            ));
        }
        Ok(())
    }

    /// The wavenumber band (rad/m), low to high.
    pub fn wavenumbers(&self) -> (f64, f64) {
        (TAU / self.band.1, TAU / self.band.0)
    }

    /// The vertical profile's variance over the band (m^2), from the closed form.
    pub fn variance(&self) -> f64 {
        let (lo, hi) = self.wavenumbers();
        self.spectrum.vertical_variance(lo, hi)
    }

    /// The drawn heights of the rails `[left, right]` (m, up) against the line
    /// position (m), without the ramp: [`TERMS_PER_THIRD_OCTAVE`] terms in each third
    /// of an octave of the band, each rail from its own stream of the seed (streams 0
    /// and 1; with the cross-level spectrum the mean from stream 0 and the difference
    /// from stream 2).
    pub fn series(&self) -> [CosineSeries; 2] {
        let (lo, hi) = self.wavenumbers();
        let terms = TERMS_PER_THIRD_OCTAVE * ((3.0 * (hi / lo).log2()).ceil() as usize).max(1);
        let draw = |stream: u64,
                    density: &dyn Fn(f64) -> f64,
                    closed: Option<&dyn Fn(f64, f64) -> f64>| {
            let mut s = CosineSeries::new();
            let mut rng = Stream::new(self.seed, stream);
            let variance = |k0: f64, k1: f64| match closed {
                Some(f) => f(k0, k1),
                None => integrate(density, k0, k1),
            };
            s.add_band((lo, hi), terms, variance, |_| 1.0, |k| k, &mut rng);
            s
        };
        let sp = self.spectrum;
        let vertical = |w: f64| sp.vertical(w);
        let closed = |a: f64, b: f64| sp.vertical_variance(a, b);
        if self.cross_level {
            let mean = draw(0, &vertical, Some(&closed));
            let diff = draw(2, &|w| sp.cross_level(w).unwrap_or(0.0), None);
            [
                mean.clone().joined(&diff.clone().scaled(0.5)),
                mean.joined(&diff.scaled(-0.5)),
            ]
        } else {
            [
                draw(0, &vertical, Some(&closed)),
                draw(1, &vertical, Some(&closed)),
            ]
        }
    }
}

/// The integral of `f` over `[a, b]` by 8-point Gauss-Legendre on 4 equal pieces (the
/// cross-level density over one term's sub-band, a twenty-fourth of an octave: smooth).
fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (x, w) = crate::numerics::gauss_legendre::<8>();
    let pieces = 4;
    let h = (b - a) / pieces as f64;
    (0..pieces)
        .map(|p| {
            let c = a + h * (p as f64 + 0.5);
            x.iter()
                .zip(&w)
                .map(|(x, w)| w * f(c + 0.5 * h * x))
                .sum::<f64>()
                * 0.5
                * h
        })
        .sum()
}

/// One rail's random profile along the line: drawn terms (a [`ProfileSpec`]'s, and the
/// rail's roughness through the contact filter) grown from nothing over a ramp.
#[derive(Debug, Clone, PartialEq)]
pub struct RandomProfile {
    /// Height (m, up) against the line position (m).
    pub series: CosineSeries,
    /// Where the ramp begins (m): nothing before it.
    pub start: f64,
    /// The ramp's length (m); 0: no ramp, full height everywhere (the rails' roughness
    /// without a drawn profile: the static start stands the wheels on it).
    pub ramp: f64,
}

impl RandomProfile {
    /// The height (m, up) and its slope at `x` (m): with no ramp (0) the terms
    /// everywhere; else the terms times the ramp's factor
    /// `q^3 (10 - 15 q + 6 q^2)`, `q = (x - start) / ramp`, over the ramp (its slope and
    /// curvature 0 at both ends, so the wheel meets no jump of acceleration), 1 beyond,
    /// 0 before.
    #[inline]
    pub fn at(&self, x: f64) -> (f64, f64) {
        if self.ramp <= 0.0 {
            return self.series.eval(x);
        }
        let u = x - self.start;
        if u <= 0.0 {
            return (0.0, 0.0);
        }
        let (h, s) = self.series.eval(x);
        if u >= self.ramp {
            return (h, s);
        }
        let q = u / self.ramp;
        let w = q * q * q * (10.0 + q * (-15.0 + 6.0 * q));
        let dw = 30.0 * q * q * (1.0 - q) * (1.0 - q) / self.ramp;
        (w * h, w * s + dw * h)
    }
}

use std::f64::consts::TAU;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fra_class_4_over_the_sources_band_has_about_25_mm_rms() {
        // The figure: FRA class 4 over 1.5 to 300 m, about 25 mm.
        let s = TrackSpectrum::Fra(4);
        let sigma = s.vertical_variance(TAU / 300.0, TAU / 1.5).sqrt();
        assert!((sigma - 0.0253).abs() < 0.0005, "{sigma}");
    }

    #[test]
    fn the_closed_forms_are_the_integrals_of_the_densities() {
        for sp in TrackSpectrum::all() {
            for (lo, hi) in [(TAU / 30.0, TAU / 1.5), (0.05, 0.07), (1.0, 10.0)] {
                let n = 20_000;
                let f = |w: f64| sp.vertical(w);
                // Midpoint rule on a log grid, independent of the closed form.
                let r = (hi / lo).ln();
                let num: f64 = (0..n)
                    .map(|i| {
                        let w = lo * (r * (i as f64 + 0.5) / n as f64).exp();
                        f(w) * w * r / n as f64
                    })
                    .sum();
                let c = sp.vertical_variance(lo, hi);
                assert!((num / c - 1.0).abs() < 1e-6, "{sp:?} {lo} {hi}: {num} {c}");
            }
        }
    }

    #[test]
    fn a_drawn_rail_holds_the_bands_variance_and_its_rms_over_a_long_run() {
        for sp in TrackSpectrum::all() {
            let spec = ProfileSpec {
                spectrum: sp,
                seed: 3,
                band: (1.5, 30.0),
                cross_level: false,
                ramp: 0.0,
            };
            let [l, r] = spec.series();
            for s in [&l, &r] {
                assert!((s.mean_square() / spec.variance() - 1.0).abs() < 1e-9);
            }
            assert_ne!(l, r);
        }
        // Sampled over 20 km every 0.1 m, one seed: within 2 % of the closed form.
        let spec = ProfileSpec {
            spectrum: TrackSpectrum::Fra(4),
            seed: 11,
            band: (1.5, 30.0),
            cross_level: false,
            ramp: 0.0,
        };
        let [l, _] = spec.series();
        let n = 200_000;
        let ms = (0..n).map(|i| l.at(i as f64 * 0.1).0.powi(2)).sum::<f64>() / n as f64;
        assert!(
            (ms.sqrt() / spec.variance().sqrt() - 1.0).abs() < 0.02,
            "{ms}"
        );
    }

    #[test]
    fn the_cross_level_spectrum_sets_the_rails_difference() {
        let spec = ProfileSpec {
            spectrum: TrackSpectrum::OreHigh,
            seed: 5,
            band: (1.5, 30.0),
            cross_level: true,
            ramp: 0.0,
        };
        let [l, r] = spec.series();
        let (lo, hi) = spec.wavenumbers();
        let diff = integrate(&|w| spec.spectrum.cross_level(w).unwrap(), lo, hi);
        let n = 100_000;
        let (mut md, mut mm) = (0.0, 0.0);
        for i in 0..n {
            let x = i as f64 * 0.2;
            let (a, b) = (l.at(x).0, r.at(x).0);
            md += (a - b).powi(2) / n as f64;
            mm += (0.5 * (a + b)).powi(2) / n as f64;
        }
        assert!((md / diff - 1.0).abs() < 0.05, "{md} {diff}");
        assert!((mm / spec.variance() - 1.0).abs() < 0.05, "{mm}");
        let bad = ProfileSpec {
            spectrum: TrackSpectrum::Fra(4),
            ..spec
        };
        let e = bad.validate().unwrap_err().to_string();
        assert!(
            e.contains("rail.spectrum.rails") && e.contains("fra_class_4"),
            "{e}"
        );
    }

    #[test]
    fn the_ramp_starts_at_rest_and_reaches_full_height() {
        let spec = ProfileSpec {
            spectrum: TrackSpectrum::Fra(4),
            seed: 1,
            band: (1.5, 30.0),
            cross_level: false,
            ramp: 5.0,
        };
        let [l, _] = spec.series();
        let p = RandomProfile {
            series: l.clone(),
            start: 2.0,
            ramp: 5.0,
        };
        assert_eq!(p.at(1.0), (0.0, 0.0));
        assert_eq!(p.at(2.0), (0.0, 0.0));
        let (h, s) = p.at(2.0 + 1e-6);
        assert!(h.abs() < 1e-12 && s.abs() < 1e-6);
        assert_eq!(p.at(8.0), l.at(8.0));
        // The slope is the derivative on the ramp.
        let (x, e) = (4.3, 1e-6);
        let fd = (p.at(x + e).0 - p.at(x - e).0) / (2.0 * e);
        assert!((fd - p.at(x).1).abs() < 1e-7);
    }

    #[test]
    fn bad_bands_are_refused_with_the_parameter() {
        let ok = ProfileSpec {
            spectrum: TrackSpectrum::OreLow,
            seed: 0,
            band: (1.5, 30.0),
            cross_level: true,
            ramp: 2.0,
        };
        assert!(ok.validate().is_ok());
        for (spec, name) in [
            (
                ProfileSpec {
                    band: (0.01, 30.0),
                    ..ok
                },
                "shortest_wavelength",
            ),
            (
                ProfileSpec {
                    band: (1.5, 5000.0),
                    ..ok
                },
                "longest_wavelength",
            ),
            (
                ProfileSpec {
                    band: (10.0, 5.0),
                    ..ok
                },
                "longest_wavelength",
            ),
            (ProfileSpec { ramp: -1.0, ..ok }, "rail.spectrum.ramp"),
        ] {
            let e = spec.validate().unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }
}
