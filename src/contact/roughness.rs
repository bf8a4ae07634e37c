//! Short-wave roughness of the rail and the wheel from a one-third octave band spectrum
//! (the ISO 3095 limit as a ready choice), drawn with a seed and seen by the contact
//! through its patch: the roughness averaged over the patch's length (`docs/MODEL.md`,
//! "Random rail profiles and roughness").

use crate::error::{Error, Result, out_of_range};
use crate::numerics::{CosineSeries, Stream, Table};
use std::f64::consts::TAU;

/// The rail roughness limit of ISO 3095:2013 (6.2.5, the reference track), one-third
/// octave bands: centre wavelength (m) and level `L = 20 log10(r / 1 um)` (dB).
pub const ISO_3095_LIMIT: [(f64, f64); 22] = [
    (0.00315, -11.0),
    (0.004, -10.4),
    (0.005, -9.8),
    (0.0063, -9.2),
    (0.008, -8.6),
    (0.01, -8.0),
    (0.0125, -7.4),
    (0.016, -6.8),
    (0.02, -6.2),
    (0.025, -5.6),
    (0.0315, -5.0),
    (0.04, -3.2),
    (0.05, -1.1),
    (0.063, 0.9),
    (0.08, 2.9),
    (0.1, 4.9),
    (0.125, 7.0),
    (0.16, 9.0),
    (0.2, 11.0),
    (0.25, 13.0),
    (0.315, 15.0),
    (0.4, 17.1),
];

/// The name that gives [`ISO_3095_LIMIT`] in `roughness.rail` and `roughness.wheel`.
pub const ISO_3095_NAME: &str = "iso3095";

/// Terms drawn in each one-third octave band.
pub const TERMS_PER_BAND: usize = 4;

/// The band centres' range (m) and the levels' (dB re 1 um): short waves, below those
/// of the track's profile; 40 dB is 100 um in one band.
pub const ROUGHNESS_WAVELENGTHS: (f64, f64) = (0.001, 1.0);
/// See [`ROUGHNESS_WAVELENGTHS`].
pub const ROUGHNESS_LEVELS: (f64, f64) = (-60.0, 40.0);

/// A roughness spectrum in one-third octave bands: centre wavelengths (m, ascending,
/// neighbours a third of an octave apart: a ratio of 1.2 to 1.33, as the nominal
/// centres 25, 31.5, 40 ... mm are) and levels (dB re 1 um, the band's RMS roughness
/// `r = 1 um 10^(L / 20)`). Band `i` holds the wavelengths within `2^(+-1/6)` of its
/// centre.
#[derive(Debug, Clone, PartialEq)]
pub struct RoughnessSpectrum {
    bands: Vec<(f64, f64)>,
}

impl RoughnessSpectrum {
    /// The ISO 3095 limit ([`ISO_3095_LIMIT`]).
    pub fn iso3095() -> Self {
        RoughnessSpectrum {
            bands: ISO_3095_LIMIT.to_vec(),
        }
    }

    /// From `text`: [`ISO_3095_NAME`], or a table of centre wavelength (m) against level
    /// (dB re 1 um), one band a line or `;`-separated ([`Table::parse`]). `name` names
    /// the parameter in errors.
    pub fn parse(text: &str, name: &str) -> Result<Self> {
        if text.trim() == ISO_3095_NAME {
            return Ok(Self::iso3095());
        }
        let t = Table::parse(text, name)?;
        let (x, y) = t.points();
        let s = RoughnessSpectrum {
            bands: x.iter().copied().zip(y.iter().copied()).collect(),
        };
        s.validate(name)?;
        Ok(s)
    }

    /// Checks the bands; `name` names the parameter.
    pub fn validate(&self, name: &str) -> Result<()> {
        for &(l, db) in &self.bands {
            if !(ROUGHNESS_WAVELENGTHS.0..=ROUGHNESS_WAVELENGTHS.1).contains(&l) {
                return Err(out_of_range(
                    &format!("{name} (centre wavelength)"),
                    l,
                    format!(
                        "{} m <= wavelength <= {} m",
                        ROUGHNESS_WAVELENGTHS.0, ROUGHNESS_WAVELENGTHS.1
                    ),
                ));
            }
            if !(ROUGHNESS_LEVELS.0..=ROUGHNESS_LEVELS.1).contains(&db) {
                return Err(out_of_range(
                    &format!("{name} (level at {l} m)"),
                    db,
                    format!(
                        "{} dB <= level <= {} dB re 1 um",
                        ROUGHNESS_LEVELS.0, ROUGHNESS_LEVELS.1
                    ),
                ));
            }
        }
        for w in self.bands.windows(2) {
            let r = w[1].0 / w[0].0;
            if !(1.2..=1.33).contains(&r) {
                return Err(Error::Table(format!(
                    "{name}: the bands at {} m and {} m are not a third of an octave apart \
                     (ratio {r:.3}; allowed 1.2 to 1.33): give one line per one-third octave \
                     band, ascending, with no band left out",
                    w[0].0, w[1].0
                )));
            }
        }
        Ok(())
    }

    /// The bands: centre wavelength (m) and level (dB re 1 um).
    pub fn bands(&self) -> &[(f64, f64)] {
        &self.bands
    }

    /// The RMS roughness (m) of the whole spectrum, unfiltered.
    pub fn rms(&self) -> f64 {
        self.bands
            .iter()
            .map(|&(_, db)| band_rms(db).powi(2))
            .sum::<f64>()
            .sqrt()
    }

    /// The drawn roughness along a coordinate, filtered by the patch: [`TERMS_PER_BAND`]
    /// terms in each band, drawn log-uniform in wavenumber, each band's variance `r^2`
    /// shared evenly in log wavenumber, each term's amplitude times
    /// [`contact_filter`]`(k, half_length)`. `scale` turns the wavenumber per metre
    /// into the coordinate's (1 along the rail, the wheel radius round a wheel, where a
    /// term's number of waves per turn is rounded to a whole one, at least 1).
    fn series(&self, rng: &mut Stream, half_length: f64, scale: Option<f64>) -> CosineSeries {
        let mut s = CosineSeries::new();
        let whole = |k: f64| match scale {
            None => k,
            Some(r) => (k * r).round().max(1.0),
        };
        let per_metre = |k: f64| scale.map_or(k, |r| k / r);
        for &(l, db) in &self.bands {
            let (k_lo, k_hi) = (
                TAU / (l * 2f64.powf(1.0 / 6.0)),
                TAU / (l * 2f64.powf(-1.0 / 6.0)),
            );
            let r2 = band_rms(db).powi(2);
            let ln = (k_hi / k_lo).ln();
            s.add_band(
                (k_lo, k_hi),
                TERMS_PER_BAND,
                |k0, k1| r2 * (k1 / k0).ln() / ln,
                |k| contact_filter(per_metre(k), half_length),
                whole,
                rng,
            );
        }
        s
    }

    /// Rail `rail`'s (0 left, 1 right) roughness (m, up) against the line position (m),
    /// seen through a patch of half-length `half_length` (m): stream `16 + rail` of
    /// `seed`.
    pub fn rail(&self, seed: u64, rail: usize, half_length: f64) -> CosineSeries {
        self.series(&mut Stream::new(seed, 16 + rail as u64), half_length, None)
    }

    /// The roughness of wheel `side` (0 left, 1 right) of wheelset `wheelset` (0 the
    /// leading one) as a radius deviation (m, positive larger) against the wheel angle
    /// (rad), on a wheel of `radius` (m), seen through a patch of half-length
    /// `half_length` (m): whole numbers of waves per turn, stream `32 + 2 wheelset +
    /// side` of `seed`.
    pub fn wheel(
        &self,
        seed: u64,
        wheelset: usize,
        side: usize,
        radius: f64,
        half_length: f64,
    ) -> CosineSeries {
        let stream = 32 + 2 * wheelset as u64 + side as u64;
        self.series(&mut Stream::new(seed, stream), half_length, Some(radius))
    }
}

/// A band's RMS roughness (m) at level `db` (dB re 1 um).
pub fn band_rms(db: f64) -> f64 {
    1e-6 * 10f64.powf(db / 20.0)
}

/// The contact filter: the roughness `cos(k x)` of wavenumber `k` (rad/m) averaged over
/// the patch `[x - a, x + a]` is `sin(k a) / (k a)` times itself.
pub fn contact_filter(k: f64, a: f64) -> f64 {
    let u = k * a;
    if u.abs() < 1e-8 { 1.0 } else { u.sin() / u }
}

/// The Hertz contact patch's half-length (m) along the rail under the static wheel load
/// `load` (N), for the Hertz law `P = C_H delta^1.5` (`ch`, N/m^1.5) and a wheel of
/// `radius` (m): `a = sqrt(R_w delta_0)`, `delta_0 = (P / C_H)^(2/3)` (Hertz's circular
/// patch; Johnson, Contact Mechanics, 1985, 4.2).
pub fn hertz_half_length(radius: f64, load: f64, ch: f64) -> f64 {
    (radius * (load / ch).powf(2.0 / 3.0)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_iso_limit_reads_by_name_and_a_table_is_checked() {
        let iso = RoughnessSpectrum::parse("iso3095", "roughness.rail").unwrap();
        assert_eq!(iso.bands().len(), 22);
        assert!(iso.validate("x").is_ok());
        // Its RMS: the bands' powers summed (each 1 um 10^(L/20)).
        let rms: f64 = ISO_3095_LIMIT
            .iter()
            .map(|(_, l)| (1e-6 * 10f64.powf(l / 20.0)).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!((iso.rms() - rms).abs() < 1e-15);
        assert!((iso.rms() - 11.74e-6).abs() < 0.01e-6, "{}", iso.rms());
        let t =
            RoughnessSpectrum::parse("0.025 -5; 0.0315 -4; 0.04 -3", "roughness.wheel").unwrap();
        assert_eq!(t.bands().len(), 3);
        let e = RoughnessSpectrum::parse("0.025 -5; 0.04 -3", "roughness.wheel")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("roughness.wheel") && e.contains("third of an octave"),
            "{e}"
        );
        let e = RoughnessSpectrum::parse("0.025 -5; 0.0315 90", "roughness.rail")
            .unwrap_err()
            .to_string();
        assert!(e.contains("roughness.rail") && e.contains("90"), "{e}");
    }

    #[test]
    fn the_drawn_rail_roughness_holds_each_bands_power_through_the_filter() {
        let iso = RoughnessSpectrum::iso3095();
        // Without a patch (a = 0) the terms hold the spectrum's power exactly.
        let s = iso.rail(4, 0, 0.0);
        assert_eq!(s.len(), 22 * TERMS_PER_BAND);
        assert!((s.mean_square().sqrt() / iso.rms() - 1.0).abs() < 1e-12);
        // Through a 7 mm half-patch each term is the average of its wave over the patch.
        let a = 0.007;
        let f = iso.rail(4, 0, a);
        for ((k, af, _), (_, a0, _)) in f.terms().zip(s.terms()) {
            let avg: f64 = {
                let n = 2000;
                (0..n)
                    .map(|i| (k * (-a + 2.0 * a * (i as f64 + 0.5) / n as f64)).cos())
                    .sum::<f64>()
                    / n as f64
            };
            assert!((af - a0 * avg).abs() < 1e-6 * a0, "{k}");
        }
        // Waves shorter than the patch are all but gone: the 4 mm band's terms.
        let short: f64 = f.terms().take(2 * TERMS_PER_BAND).map(|t| t.1.abs()).sum();
        assert!(short < 0.2 * s.terms().take(2 * TERMS_PER_BAND).map(|t| t.1).sum::<f64>());
    }

    #[test]
    fn a_wheels_roughness_closes_round_the_wheel() {
        let iso = RoughnessSpectrum::iso3095();
        let w = iso.wheel(9, 1, 1, 0.46, 0.007);
        for (n, _, _) in w.terms() {
            assert_eq!(n, n.round());
            assert!(n >= 1.0);
        }
        let (a, b) = (w.at(0.3), w.at(0.3 + TAU));
        assert!((a.0 - b.0).abs() < 1e-15 && (a.1 - b.1).abs() < 1e-12);
        assert_ne!(w, iso.wheel(9, 1, 0, 0.46, 0.007));
        assert_ne!(w, iso.wheel(9, 0, 1, 0.46, 0.007));
    }

    #[test]
    fn the_hertz_half_length_is_hertz() {
        // delta = (P / C_H)^(2/3); a^2 = R delta (a sphere of radius R on a plane).
        let (r, p, ch): (f64, f64, f64) = (0.46, 1e5, 1e11);
        let d = (p / ch).powf(2.0 / 3.0);
        assert!((hertz_half_length(r, p, ch) - (r * d).sqrt()).abs() < 1e-15);
        assert!((p - ch * d.powf(1.5)).abs() < 1e-6);
    }
}
