//! Hertz point contact (thesis 1.3), for comparison with the adaptive law.

use super::perfect::patch_angle;
use super::state::ContactState;
use crate::wheel::WheelProfile;

/// The Hertz law's contact stiffness `dP / d delta = 3/2 C_H d^(1/2)` (N/m), `d` the
/// overlap less the radius reduction under the wheel centre; 0 out of contact.
pub(super) fn hertz_stiffness(ch: f64, wheel: &WheelProfile, gamma: f64, overlap: f64) -> f64 {
    let d = overlap - wheel.reduction(0.0, gamma);
    if d > 0.0 { 1.5 * ch * d.sqrt() } else { 0.0 }
}

/// Hertz contact `P = C_H (delta_c - f_0)^(3/2)` (1.3) with the coefficient `ch` =
/// `C_H` (N/m^1.5), for a wheel with profile `wheel` at axle rotation `gamma` (rad)
/// and overlap `overlap` (m); `f_0` is the radius reduction under the wheel centre
/// (`alpha = 0`). The patch reported is that of the nominal circle pressed in by
/// `delta_c - f_0` (2.6).
pub(super) fn hertz(ch: f64, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
    let f0 = wheel.reduction(0.0, gamma);
    let d = overlap - f0;
    if d <= 0.0 {
        return ContactState {
            overlap,
            ..Default::default()
        };
    }
    // The Hertz law knows no patch; report the geometric overlap patch of a
    // circle of the nominal radius pressed in by d.
    let a = patch_angle(d, wheel.radius());
    let h = wheel.radius() - d;
    ContactState {
        force: ch * d * d.sqrt(),
        overlap,
        front_angle: a,
        rear_angle: -a,
        length: 2.0 * h * a.tan(),
        intervals: 1,
    }
}
