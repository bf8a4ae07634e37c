//! Track: two Timoshenko rails (3.4, 3.5, 3.10) on discrete sleepers with bounce and
//! roll (3.6-3.9, 3.16), rail pads and ballast, solved by explicit central
//! differences in time and space (3.11, 3.12, 3.18).
//!
//! An endless track is a window of this track that moves with the wheels by whole
//! sleeper spans ([`Track::shift_spans`]).
//!
//! Grid: `dx = a / n`, nodes `k = 0..=K` with `K = N n` on each rail, sleepers at
//! every n-th node, both ends included (N spans = N + 1 sleepers). Rail ends are
//! fixed (`Z = theta = 0`). A point force `F` enters its node's equation as `F / dx`;
//! a moving wheel load is shared between the two nodes around it by (3.22) and the
//! rail displacement under the wheel is interpolated by (3.23).
//!
//! Sign conventions: displacements up, pad force (3.9)
//! `F = -K_p (Z_rail - Z_seat) - C_p (dZ_rail/dt - dZ_seat/dt)` acts up on the rail and
//! down on the sleeper; pad damper velocities are backward differences so the rail
//! update stays explicit; ballast damping uses central differences (3.18).

mod absorbing;
mod irregularity;
mod kernels;
mod observe;
mod params;
mod probe;
mod receptance;
mod receptance_fit;
#[cfg(test)]
mod reference_tests;
mod spectra;
mod state;
mod static_solve;
mod stepper;
mod storage;
mod supports;
#[cfg(test)]
mod supports_tests;
#[cfg(test)]
mod tests;
mod transparent;
mod window;

pub use crate::numerics::SimdLevel;
pub use irregularity::{
    FOLLOWABLE, FOLLOWABLE_SOURCE, MAX_RAIL_IRREGULARITY, MIN_DEFECT_LENGTH, RailDefect,
    RailProfile,
};
pub use observe::{RailResponse, SupportResponse};
pub use params::{RailBetweenNodes, RailEnds, RailSection, TrackParams};
pub use probe::perturbation_growth;
pub use receptance::{
    LoadAt, LoadedRails, RECEPTANCE_FREQUENCY_RANGE, ReceptanceSetup, ResponseAt, log_frequencies,
    track_receptance,
};
pub use receptance_fit::{FitOptions, FitParameter, FittedValue, ReceptanceFit, fit_receptance};
pub use spectra::{
    MIN_RAMP, PROFILE_BAND, ProfileSpec, RandomProfile, TERMS_PER_THIRD_OCTAVE, TrackSpectrum,
};
pub use stepper::{PointLoad, Track};
pub use supports::{MAX_VOID_GAP, SupportLaw, Supports};
pub use transparent::{MAX_EXACT_MEMORY, MIN_EXACT_MEMORY};

// What the files of the track share (each begins with `use super::*`).
use crate::error::{Error, Result, out_of_range, positive};
use crate::limits::{MAX_NODES_PER_SPAN, MAX_RAIL_SEGMENTS, check};
use crate::numerics::{LANES, inlined, solve_banded_spd};
use kernels::*;
use nalgebra::{DMatrix, DVector, Matrix4, SymmetricEigen};
use storage::*;
use supports::*;
