//! What a contact law reports for one wheel at one instant ([`ContactState`]): the
//! force, the overlap and the patch.

/// What the contact model reports for one wheel at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactState {
    /// Normal contact force `P` (N), >= 0, pushes the wheel up and the rail down.
    pub force: f64,
    /// Overlap `delta_c = z_rail - z_wheel` (m) (2.7); negative when apart.
    pub overlap: f64,
    /// Front contact angle `alpha_f` (rad), the foremost compressed spring (2.22);
    /// 0 when out of contact.
    pub front_angle: f64,
    /// Rear contact angle `alpha_r` (rad), the rearmost compressed spring (2.22).
    pub rear_angle: f64,
    /// Contact length along the rail between the rear and front contact points (m),
    /// `h (tan alpha_f - tan alpha_r)`.
    pub length: f64,
    /// Number of separate contact intervals (0: loss of contact, 2 or more: split patch).
    pub intervals: u32,
}

impl ContactState {
    /// True when the wheel has lost contact with the rail.
    pub fn lost(&self) -> bool {
        self.intervals == 0
    }
}
