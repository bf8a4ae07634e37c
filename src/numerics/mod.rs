//! Numerics with no physics in them: the instruction-set dispatch of the hot loops,
//! the small-angle functions the wheel profile and the contact evaluate, root finding,
//! Gauss-Legendre quadrature, the banded solver of the static start and the central
//! differences of the vehicles' bodies.

mod banded;
mod central_difference;
mod quadrature;
mod roots;
mod simd;
mod small_angle;

pub(crate) use banded::solve_banded_spd;
pub(crate) use central_difference::{CentralDifference, check_critical_step};
pub(crate) use quadrature::gauss_legendre;
pub(crate) use roots::{refine_root, sliver};
pub use simd::{LANES, SimdLevel, inlined};
pub use small_angle::*;
