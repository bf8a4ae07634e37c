//! Wheel-rail normal contact: the thesis' adaptive radial-spring model (thesis 2.1-2.8,
//! 2.22-2.26) and Hertz point contact (1.3) for comparison, behind one interface
//! ([`ContactLaw`]), and the calibration of the radial stiffness `K_w` from a Hertz
//! coefficient.
//!
//! The adaptive force is the integral of the radial springs over the region where
//! they are compressed:
//!
//! `P = K_w * integral of max(0, R(alpha) cos(alpha) - h) d alpha`, `h = R_w - delta_c`,
//!
//! over `|alpha| <= acos(h / R_w)`. With no flat in that range it is the closed form
//! (2.5); otherwise the sign changes of the integrand are bracketed and refined, and
//! every contact interval is integrated by Gauss-Legendre quadrature, so full, partial,
//! asymmetric and split patches are all exact to quadrature accuracy.

mod adaptive;
mod calibration;
mod hertz;
mod law;
mod perfect;
mod roughness;
mod state;
#[cfg(test)]
mod tests;

pub use adaptive::adaptive_numeric;
pub use calibration::kw_from_hertz;
pub use law::{ContactLaw, ContactModel};
pub use perfect::{patch_angle, perfect_wheel_force};
pub use roughness::{
    ISO_3095_LIMIT, ISO_3095_NAME, RoughnessSpectrum, band_rms, contact_filter, hertz_half_length,
};
pub use state::ContactState;
