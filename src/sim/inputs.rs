//! The rates of a wheelset's inputs given from outside ([`InputRates`]): how the
//! wheel heights and the axle angle move between inputs, and their place in the
//! state vector. [`super::Simulation`] takes the inputs in `external.rs`.

/// Time derivatives of a wheelset's external inputs: the wheel heights follow
/// `z(t) = z + z' tau + z'' tau^2 / 2` and the axle angle `gamma(t) = gamma + gamma'
/// tau` over the communication step, `tau` from the time they were given, instead of
/// being held (the heights) or turning at `V / R_w` (the angle).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InputRates {
    /// Time (s) each wheel height `[left, right]` was last given at, with or without
    /// derivatives; it extrapolates from its value then.
    pub z_since: [f64; 2],
    /// `[[z' left, z' right] (m/s), [z'' left, z'' right] (m/s^2)]`.
    pub z: [[f64; 2]; 2],
    /// Whether derivatives of each wheel height `[left, right]` were given.
    pub z_given: [bool; 2],
    /// Whether the axle angle's rate was given (else it turns at `V / R_w`).
    pub rotation_given: bool,
    /// Time (s) the angle's rate was given at.
    pub rotation_since: f64,
    /// The axle angle's rate `gamma'` (rad/s).
    pub rotation: f64,
}

impl InputRates {
    /// Values in a state vector.
    pub(super) const LEN: usize = 11;

    /// Whether the wheel heights move between inputs.
    #[inline(always)]
    pub fn moves(&self) -> bool {
        self.z_given[0] || self.z_given[1]
    }

    /// The wheel heights (m) at time `t` (s) from `z` given at [`InputRates::z_since`].
    #[inline]
    pub(super) fn wheel_z_at(&self, z: [f64; 2], t: f64) -> [f64; 2] {
        [0, 1].map(|i| {
            let tau = t - self.z_since[i];
            z[i] + tau * (self.z[0][i] + 0.5 * tau * self.z[1][i])
        })
    }

    pub(super) fn to_array(self) -> [f64; Self::LEN] {
        let [[a, b], [c, d]] = self.z;
        let flag = |x: bool| f64::from(u8::from(x));
        [
            self.z_since[0],
            self.z_since[1],
            a,
            b,
            c,
            d,
            flag(self.z_given[0]),
            flag(self.z_given[1]),
            flag(self.rotation_given),
            self.rotation_since,
            self.rotation,
        ]
    }

    pub(super) fn from_slice(v: &[f64]) -> InputRates {
        InputRates {
            z_since: [v[0], v[1]],
            z: [[v[2], v[3]], [v[4], v[5]]],
            z_given: [v[6] != 0.0, v[7] != 0.0],
            rotation_given: v[8] != 0.0,
            rotation_since: v[9],
            rotation: v[10],
        }
    }
}
