//! The radial spring stiffness `K_w` from a Hertz coefficient and a static load (thesis
//! 2.25 with 2.6, the static overlap from Hertz's law 2.26, 1.3).

use super::perfect::perfect_patch;
use crate::error::{Result, out_of_range, positive};

/// Radial spring stiffness `K_w` (N/m/rad) that carries the static wheel load
/// `static_load` (N) at the overlap Hertz contact with coefficient `ch` (N/m^1.5) gives
/// it, on a wheel of radius `radius` (m) (2.25, 2.26):
/// `delta_0 = (P_0 / C_H)^(2/3)`, `K_w = P_0 / (2 R_w (sin a - a cos a))`,
/// `a = acos((R_w - delta_0)/R_w)`. For small overlaps
/// `K_w ~= 3 C_H R_w^(1/2) / (4 sqrt 2)`.
///
/// # Errors
/// [`crate::Error::Parameter`] naming `contact.CH`, `static wheel load` or
/// `wheel.radius` when one is not finite and positive, and `contact.CH` when the static
/// overlap `delta_0` reaches the wheel radius.
pub fn kw_from_hertz(ch: f64, static_load: f64, radius: f64) -> Result<f64> {
    positive("contact.CH", ch, "N/m^1.5")?;
    positive("static wheel load", static_load, "N")?;
    positive("wheel.radius", radius, "m")?;
    let delta0 = (static_load / ch).powf(2.0 / 3.0);
    if delta0 >= radius {
        return Err(out_of_range(
            "contact.CH",
            ch,
            "large enough that the static overlap is below the wheel radius",
        ));
    }
    // The same closed form the adaptive law evaluates, so P(delta_0) = P_0 to rounding.
    Ok(static_load / (2.0 * radius * perfect_patch(delta0, radius).1))
}
