//! Numerics with no physics in them: the instruction-set dispatch of the hot loops and
//! the small-angle functions the wheel profile and the contact evaluate.

mod simd;
mod small_angle;

pub use simd::{LANES, SimdLevel, inlined};
pub use small_angle::*;
