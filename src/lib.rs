//! # wheelflat
//!
//! Wheel-flat impact loads in railway vehicle-track dynamics: the coupled model of
//! J. J. Zhu's thesis *Development of an adaptive contact model for analysis of
//! wheel-rail impact load due to wheel flats* (called the thesis in these docs):
//! adaptive radial-spring contact, two Timoshenko rails on discrete sleepers, a
//! six-degree-of-freedom roll-plane vehicle, central finite differences. Conventions
//! (signs, indices, angles) and the thesis' misprints are in `docs/MODEL.md`; the layout
//! and where a change lands in `docs/ARCHITECTURE.md`.
//!
//! Modules, bottom up:
//! - [`numerics`], [`error`], [`limits`]: no physics: the SIMD dispatch, small-angle
//!   polynomials, root finding and quadrature; the error type; the physical ranges of
//!   the parameters and the health bounds of a run;
//! - [`wheel`]: the wheel radius with flats, placed by the axle rotation (2.9-2.21);
//! - [`contact`]: the normal contact laws, adaptive and Hertz (2.5-2.8, 2.22-2.26, 1.3);
//! - [`track`]: two Timoshenko rails on sleepers, pads and ballast (3.4-3.23);
//! - [`vehicle`]: the roll-plane vehicle and the chapter-2 lumped models (3.1-3.3, 2.27),
//!   and the vehicles on several wheelsets (the half-car bogie, the wagons);
//! - [`sim`]: scenarios (the thesis' parameter sets), the coupled simulation and the
//!   co-simulation units;
//! - [`fmu`]: the FMI 2.0 co-simulation units (a model-independent FMI layer, the
//!   binding of the models behind the FMUs listed in [`fmu::Kind`], the C boundary).

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
