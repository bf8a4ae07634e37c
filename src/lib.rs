//! # wheelflat
//!
//! Wheel-flat impact loads in railway vehicle-track dynamics: the coupled model of
//! the seed thesis (adaptive radial-spring contact, two Timoshenko rails on discrete
//! sleepers, six-degree-of-freedom roll-plane vehicle, central finite differences)
//! as a pure Rust library. See `../shared/MODEL.md` for conventions.
//!
//! Modules, bottom up: [`wheel`] (wheel radius with flats), [`contact`] (normal
//! contact laws), [`track`] (rails, pads, sleepers, ballast), [`vehicle`] (roll-plane
//! vehicle and the alternative loads), [`sim`] (the thesis' parameter sets, the coupled
//! time stepping and the co-simulation units).

// Index loops over the two wheels/rails mirror the equations' subscripts.
#![allow(clippy::needless_range_loop)]

pub mod contact;
pub mod error;
pub mod fmu;
pub mod limits;
pub mod numerics;
pub mod sim;
pub mod track;
pub mod vehicle;
pub mod wheel;

pub use error::{Error, Result};
