//! Wheel profile: nominal radius with haversine or chord flats (thesis 2.9-2.21).
//!
//! Angles are measured at the wheel centre from the downward vertical (the
//! nominal contact point), positive towards the direction of travel ("front").
//! A flat whose centre sits at wheel angle `beta_0` when the axle rotation angle
//! is zero is found, at axle rotation `gamma`, at the space angle
//! `beta_0 - gamma` (2.17-2.21), wrapped into (-pi, pi].
//!
//! The rest of the crate sees a wheel through [`WheelProfile`], an enumeration over
//! the kinds of profile; [`FlattedWheel`] is today's only kind.

mod flat;
mod flatted;
mod profile;
mod roundness;
#[cfg(test)]
mod tests;

pub use flat::{Flat, FlatShape, FlatSpec};
pub use flatted::{FlattedWheel, MAX_FLATS};
pub use profile::WheelProfile;
pub use roundness::{MAX_RADIUS_DEVIATION, OutOfRoundness};
