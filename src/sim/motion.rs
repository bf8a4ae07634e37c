//! The longitudinal motion ([`Motion`]) and the endless track's window ([`Window`]) as
//! a simulation keeps them, in line coordinates, with their place in the state vector.
//! [`super::Simulation`]'s methods on them are in `travel.rs`.

use crate::sim::TrackWindow;

/// The longitudinal motion: the leading wheelset at `x = x_ref + V (t - t_ref)` (m, line
/// coordinates) and axles that roll without slip at `gamma = gamma_ref + V (t - t_ref) /
/// R_w` (rad), the speed `V` (m/s) held since `t_ref` (s). A new speed starts a new
/// piece ([`super::Simulation::set_speed`]); a constant speed keeps `t_ref = 0`, so the position
/// is `x_0 + V t` exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    pub(super) x_ref: f64,
    pub(super) t_ref: f64,
    pub(super) speed: f64,
    pub(super) rotation_ref: f64,
}

impl Motion {
    /// Values in the state vector.
    pub(super) const LEN: usize = 4;
    pub(super) fn to_array(self) -> [f64; 4] {
        [self.x_ref, self.t_ref, self.speed, self.rotation_ref]
    }
    pub(super) fn from_slice(v: &[f64]) -> Motion {
        Motion {
            x_ref: v[0],
            t_ref: v[1],
            speed: v[2],
            rotation_ref: v[3],
        }
    }
}

/// The window of an endless track as the simulation moves it: the track's node 0 lies
/// at `origin_span` sleeper spans in line coordinates, and the window moves when the
/// leading wheelset passes `shift_at` (m, track coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Window {
    pub(super) spec: TrackWindow,
    pub(super) origin_span: i64,
    pub(super) shift_at: f64,
    /// Sleeper spacing `a` (m): the window moves by whole spans.
    pub(super) spacing: f64,
}

impl Window {
    /// Line coordinate of the track's node 0 (m).
    pub(super) fn origin(&self) -> f64 {
        self.origin_span as f64 * self.spacing
    }
}
