//! The one interface through which the rest of the crate sees a wheel: `WheelProfile`,
//! an enumeration over the kinds of profile.

use super::flat::{Flat, FlatSpec};
use super::flatted::FlattedWheel;
use crate::error::Result;

/// A wheel's running surface: its nominal rolling radius `R_w` and the radius
/// `R_i(alpha, gamma) = R_w - f(alpha, gamma)` at space angle `alpha` (rad, from the
/// downward vertical, positive ahead) for axle rotation `gamma` (rad) (2.18), `f` the
/// radius reduction (m).
///
/// One kind today, the nominal circle with flats ([`FlattedWheel`]); a measured radius
/// table would be a second variant. An enumeration rather than a trait: the coupled step
/// evaluates the contact twice per time step, and a match on a one-variant enumeration
/// compiles to nothing (the layout and the code are those of [`FlattedWheel`]), while a
/// trait object would cost an indirect call that the closed-form contact cannot afford
/// and a generic parameter would spread to every holder of a wheel (the solver's left and
/// right wheels, which may then be of different kinds). A law that needs the shape of
/// the surface (the adaptive integral) matches on the kind; the others use the methods
/// here.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum WheelProfile {
    /// The nominal circle with haversine or chord flats (2.9-2.21).
    Flatted(FlattedWheel),
}

impl WheelProfile {
    /// A perfect wheel of radius `radius` (m).
    ///
    /// # Errors
    /// [`crate::Error::Parameter`] naming `wheel.radius` unless it is finite and positive.
    pub fn perfect(radius: f64) -> Result<Self> {
        FlattedWheel::perfect(radius).map(WheelProfile::Flatted)
    }

    /// A wheel of radius `radius` (m) with the flats `flats`; `name` prefixes parameter
    /// names in errors (e.g. `flat.left`). See [`FlattedWheel::new`].
    ///
    /// # Errors
    /// As [`FlattedWheel::new`]: [`crate::Error::Parameter`] naming the radius or the
    /// flat's length, depth or angle that is out of range.
    pub fn new(radius: f64, flats: &[FlatSpec], name: &str) -> Result<Self> {
        FlattedWheel::new(radius, flats, name).map(WheelProfile::Flatted)
    }

    /// Nominal rolling radius `R_w` (m).
    #[inline]
    pub fn radius(&self) -> f64 {
        match self {
            WheelProfile::Flatted(w) => w.radius(),
        }
    }

    /// The wheel's flats (2.9-2.21); empty for a perfect wheel.
    pub fn flats(&self) -> &[Flat] {
        match self {
            WheelProfile::Flatted(w) => w.flats(),
        }
    }

    /// Radius reduction `f` (m) at space angle `alpha` (rad) for axle rotation `gamma`
    /// (rad), >= 0. Where flats overlap, the larger reduction wins.
    #[inline]
    pub fn reduction(&self, alpha: f64, gamma: f64) -> f64 {
        match self {
            WheelProfile::Flatted(w) => w.reduction(alpha, gamma),
        }
    }

    /// Index into [`WheelProfile::flats`] of the flat whose reduction is largest (and
    /// positive) at space angle `alpha` (rad) for axle rotation `gamma` (rad): the flat
    /// that shapes the wheel there; `None` where the wheel is round.
    pub fn dominant_flat(&self, alpha: f64, gamma: f64) -> Option<usize> {
        match self {
            WheelProfile::Flatted(w) => w.dominant_flat(alpha, gamma),
        }
    }

    /// Instantaneous radius `R_i` (m) at space angle `alpha` (rad) for axle rotation
    /// `gamma` (rad) (2.18).
    #[inline]
    pub fn radius_at(&self, alpha: f64, gamma: f64) -> f64 {
        match self {
            WheelProfile::Flatted(w) => w.radius_at(alpha, gamma),
        }
    }
}
