//! Vertical accelerations of the wheels and of the rail under them: what on-board and
//! wayside flat detectors measure (axle-box accelerometers, rail accelerometers), as
//! the central second difference of the displacements at the engine's steps, the
//! scheme's own acceleration (3.11).

/// The signals of a wheelset whose accelerations are kept: the wheel centres and the
/// rail under them `[wheel left, wheel right, rail left, rail right]` (m, up).
pub const SIGNALS: usize = 4;

/// The accelerations of a wheelset's signals (wheels, rail under them) with their
/// extremes since the start. The engine records the sample that drives each step
/// (its crate-private `record`); the acceleration at the current time `t` is
/// `(z(t) - 2 z(t - dt) + z(t - 2 dt)) / dt^2`, the central second difference at
/// `t - dt`, one step behind (where the step changed, the difference of the two
/// slopes over the mean step): summed twice it gives the displacements
/// back exactly. The run starts in the static state: the wheels at rest, as if they
/// had stood still before it; the rail under a moving wheel is not a material point
/// (the wheel moves over the grid's nodes and sleepers), so its acceleration starts a
/// step later, with the second difference of the first three samples (0 before).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accelerations {
    /// The displacements of the last two recorded samples, the latest first (m).
    z: [[f64; SIGNALS]; 2],
    /// The step taken after each of them (s): after the latest, the spacing to the
    /// sample now; after the one before, the spacing to the latest. Equal but where
    /// the step changed.
    h: [f64; 2],
    /// Samples recorded, up to 2.
    recorded: u8,
    /// Largest and smallest acceleration of the recorded samples (m/s^2).
    max: [f64; SIGNALS],
    min: [f64; SIGNALS],
}

impl Accelerations {
    /// Nothing recorded: finite extremes that give way to any value, so that a state
    /// saved before the first step serialises.
    pub const NONE: Accelerations = Accelerations {
        z: [[0.0; SIGNALS]; 2],
        h: [1.0; 2],
        recorded: 0,
        max: [f64::MIN; SIGNALS],
        min: [f64::MAX; SIGNALS],
    };

    /// Values in a state vector.
    pub(crate) const LEN: usize = 4 * SIGNALS + 3;

    /// The second difference of `z`, the displacements now, over the recorded
    /// history: `(z - 2 z_1 + z_2) / h^2` on equal steps, and where the step changed
    /// the difference of the two slopes over the mean step, `2 ((z - z_1) / h_1 - (z_1 -
    /// z_2) / h_2) / (h_1 + h_2)`.
    #[inline(always)]
    fn second_difference(&self, z: &[f64; SIGNALS]) -> [f64; SIGNALS] {
        if self.recorded == 0 {
            return [0.0; SIGNALS];
        }
        let [a, b] = &self.z;
        let [h1, h2] = self.h;
        let uneven = h1 != h2;
        let k = 1.0 / (h1 * h1);
        // A plain loop: `std::array::from_fn` was left out of line once the coupled
        // step had two copies calling it (60 instructions a step, issue 42).
        let mut d = [0.0; SIGNALS];
        for (i, di) in d.iter_mut().enumerate() {
            *di = if self.recorded == 1 && i >= 2 {
                // The rail under a wheel before its second sample.
                0.0
            } else if uneven {
                2.0 * ((z[i] - a[i]) / h1 - (a[i] - b[i]) / h2) / (h1 + h2)
            } else {
                (z[i] - 2.0 * a[i] + b[i]) * k
            };
        }
        d
    }

    /// Takes the displacements `z` (m) of the sample that drives the step `dt` (s)
    /// about to be taken: the acceleration at the step before joins the extremes.
    #[inline(always)]
    pub(crate) fn record(&mut self, z: [f64; SIGNALS], dt: f64) {
        if self.recorded == 0 {
            // At rest at the start.
            self.z = [z, z];
            self.h = [dt, dt];
            self.recorded = 1;
            self.max = [0.0; SIGNALS];
            self.min = [0.0; SIGNALS];
            return;
        }
        let a = self.second_difference(&z);
        self.recorded = 2;
        for i in 0..SIGNALS {
            self.max[i] = self.max[i].max(a[i]);
            self.min[i] = self.min[i].min(a[i]);
        }
        self.z = [z, self.z[0]];
        self.h = [dt, self.h[0]];
    }

    /// The accelerations (m/s^2) when the displacements are `z` (m) now, a step after
    /// the latest recorded sample.
    pub fn now(&self, z: [f64; SIGNALS]) -> [f64; SIGNALS] {
        self.second_difference(&z)
    }

    /// The largest acceleration of the steps taken (m/s^2; the one `now` before the
    /// first step, the rest at the start after it): the value now is not among them,
    /// so that they do not move with a master's inputs.
    pub fn max(&self, now: [f64; SIGNALS]) -> [f64; SIGNALS] {
        if self.recorded == 0 { now } else { self.max }
    }

    /// The smallest acceleration of the steps taken (m/s^2), as [`Accelerations::max`].
    pub fn min(&self, now: [f64; SIGNALS]) -> [f64; SIGNALS] {
        if self.recorded == 0 { now } else { self.min }
    }

    /// `d a / d z` (1/s^2) of signal `i`'s acceleration now against its displacement
    /// now: `1 / dt^2` once its history is there, else 0.
    pub fn gain(&self, i: usize) -> f64 {
        let [h1, h2] = self.h;
        match self.recorded {
            0 => 0.0,
            1 if i >= 2 => 0.0,
            _ if h1 != h2 => 2.0 / (h1 * (h1 + h2)),
            _ => 1.0 / (h1 * h1),
        }
    }

    /// The values of a state vector.
    pub(crate) fn to_array(self) -> [f64; Self::LEN] {
        let mut v = [0.0; Self::LEN];
        let parts = self.z[0]
            .iter()
            .chain(&self.z[1])
            .chain(&self.max)
            .chain(&self.min);
        for (slot, &x) in v.iter_mut().zip(parts.chain(&self.h)) {
            *slot = x;
        }
        v[Self::LEN - 1] = self.recorded as f64;
        v
    }

    /// The inverse of [`Accelerations::to_array`], from the first
    /// [`Accelerations::LEN`] values of `v`.
    pub(crate) fn from_slice(v: &[f64]) -> Accelerations {
        let part = |k: usize| -> [f64; SIGNALS] { std::array::from_fn(|i| v[k * SIGNALS + i]) };
        Accelerations {
            z: [part(0), part(1)],
            max: part(2),
            min: part(3),
            h: [v[4 * SIGNALS], v[4 * SIGNALS + 1]],
            recorded: v[Self::LEN - 1].clamp(0.0, 2.0) as u8,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_parabola_has_its_acceleration_and_the_state_round_trips() {
        // z = 3 t^2 / 2 + 0.1 t: the second difference is exactly 3 m/s^2; the run
        // starts at rest, so the first step's acceleration is (z_1 - z_0) / dt^2.
        let dt = 1e-3;
        let z = |j: u32| {
            let t = j as f64 * dt;
            let v = 1.5 * t * t + 0.1 * t;
            [v, -v, 2.0 * v, 0.0]
        };
        let mut a = Accelerations::NONE;
        assert_eq!(a.now(z(0)), [0.0; 4]);
        a.record(z(0), dt);
        let first = a.now(z(1));
        assert!((first[0] - (z(1)[0] - z(0)[0]) / (dt * dt)).abs() < 1e-9);
        assert_eq!(
            first[2], 0.0,
            "the rail under the wheel starts a step later"
        );
        for j in 1..50 {
            a.record(z(j), dt);
        }
        let now = a.now(z(50));
        assert!(
            (now[0] - 3.0).abs() < 1e-6 && (now[1] + 3.0).abs() < 1e-6,
            "{now:?}"
        );
        assert!((now[2] - 6.0).abs() < 1e-6 && now[3] == 0.0);
        assert!(a.max(now)[0] > 100.0 && a.min(now)[1] < -100.0);
        assert_eq!(
            a.max([1e9; 4])[0],
            a.max(now)[0],
            "the value now is not an extreme"
        );
        assert_eq!(Accelerations::from_slice(&a.to_array()), a);
        assert_eq!(
            Accelerations::from_slice(&Accelerations::NONE.to_array()),
            Accelerations::NONE
        );
    }
}
