//! The wheel of the thesis: a nominal circle with flats (2.9-2.21, several flats as in
//! 6.1).

use super::flat::{Flat, FlatSpec, validate_flat};
use crate::error::{Result, out_of_range, positive};

/// Most flats one wheel may carry.
pub const MAX_FLATS: usize = 8;

/// A wheel of nominal radius `R_w` with up to [`MAX_FLATS`] flats. Where flats overlap,
/// the larger radius reduction wins; elsewhere the radius is `R_w`.
#[derive(Debug, Clone, PartialEq)]
pub struct FlattedWheel {
    /// Nominal rolling radius `R_w` (m).
    radius: f64,
    // 1 / (2 R_w) (1/m), kept so that the contact does not divide by the radius on
    // every evaluation.
    half_inv_radius: f64,
    flats: Vec<Flat>,
}

impl FlattedWheel {
    /// A perfect wheel of radius `radius` (m).
    ///
    /// # Errors
    /// [`crate::Error::Parameter`] naming `wheel.radius` unless it is finite and positive.
    pub fn perfect(radius: f64) -> Result<Self> {
        positive("wheel.radius", radius, "m")?;
        Ok(FlattedWheel {
            radius,
            half_inv_radius: 0.5 / radius,
            flats: Vec::new(),
        })
    }

    /// A wheel of radius `radius` (m) with the flats `flats`; `name` prefixes parameter
    /// names in errors (e.g. `flat.left`). A flat of zero length and no (or zero)
    /// depth is no flat. An unset depth takes (2.15) for a haversine flat and (2.13)
    /// for a chord flat.
    ///
    /// # Errors
    /// [`crate::Error::Parameter`] naming the radius (`wheel.radius`) or the flat's
    /// `length`, `depth` or `angle` (`{name}[k]`, k from 1): a non-finite value, a
    /// negative length or one beyond a quarter of the circumference, a depth not in
    /// (0, `R_w`) or above [`crate::limits::MAX_FLAT_DEPTH`], a chord depth more than
    /// 2 % from (2.13), a depth without length, or more than [`MAX_FLATS`] flats.
    pub fn new(radius: f64, flats: &[FlatSpec], name: &str) -> Result<Self> {
        let mut w = Self::perfect(radius)?;
        for (k, spec) in flats.iter().enumerate() {
            let p = format!("{name}[{}]", k + 1);
            if let Some(flat) = validate_flat(radius, spec, &p)? {
                if w.flats.len() == MAX_FLATS {
                    return Err(out_of_range(
                        &format!("{p}.length"),
                        spec.length,
                        format!("at most {MAX_FLATS} flats per wheel"),
                    ));
                }
                w.flats.push(flat);
            }
        }
        Ok(w)
    }

    /// Nominal rolling radius `R_w` (m).
    #[inline]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// `1 / (2 R_w)` (1/m): an overlap `delta` times it is `sin^2(alpha_w / 2)`, the
    /// perfect-wheel patch angle `alpha_w` of (2.6).
    #[inline]
    pub(crate) fn half_inv_radius(&self) -> f64 {
        self.half_inv_radius
    }

    /// The validated flats.
    pub fn flats(&self) -> &[Flat] {
        &self.flats
    }

    /// Radius reduction (m) at space angle `alpha` (rad) for axle rotation `gamma` (rad).
    /// Where flats overlap, the larger reduction wins.
    #[inline]
    pub fn reduction(&self, alpha: f64, gamma: f64) -> f64 {
        let mut f = 0.0f64;
        for fl in &self.flats {
            f = f.max(fl.reduction_at(alpha, gamma));
        }
        f
    }

    /// Index of the flat whose reduction is largest (and positive) at space angle
    /// `alpha` (rad) for axle rotation `gamma` (rad): the flat that shapes the wheel
    /// there.
    pub fn dominant_flat(&self, alpha: f64, gamma: f64) -> Option<usize> {
        let mut best = None;
        let mut f = 0.0f64;
        for (i, fl) in self.flats.iter().enumerate() {
            let r = fl.reduction_at(alpha, gamma);
            if r > f {
                f = r;
                best = Some(i);
            }
        }
        best
    }

    /// Instantaneous radius `R_i` (m) at space angle `alpha` for axle rotation `gamma` (2.18).
    #[inline]
    pub fn radius_at(&self, alpha: f64, gamma: f64) -> f64 {
        self.radius - self.reduction(alpha, gamma)
    }
}
