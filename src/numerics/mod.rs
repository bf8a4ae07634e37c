//! Numerics with no physics in them: the instruction-set dispatch of the hot loops,
//! the small-angle functions the wheel profile and the contact evaluate, root finding,
//! Gauss-Legendre quadrature, the banded solver of the static start, the central
//! differences of the vehicles' bodies and a signal's DFT at one frequency and the
//! amplitude of a harmonic in it (for
//! measuring the quiet force's spectrum), and a random signal of given spectrum as a
//! sum of cosines (rail profiles, roughness).

mod banded;
mod central_difference;
mod harmonic;
mod modes;
mod quadrature;
mod random_series;
mod roots;
mod simd;
mod small_angle;
mod table;

pub(crate) use banded::solve_banded_spd;
pub(crate) use central_difference::{CentralDifference, check_critical_step, mat_vec_dispatched};
pub use harmonic::{dft, harmonic_amplitude};
pub use modes::natural_frequencies;
pub(crate) use quadrature::gauss_legendre;
pub use random_series::{CosineSeries, Stream};
pub(crate) use roots::{refine_root, sliver};
pub use simd::{LANES, SimdLevel, inlined};
pub use small_angle::*;
pub use table::{MAX_TABLE_POINTS, Table};
