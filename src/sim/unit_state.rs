//! The vehicle unit's health checks (its held forces, its bodies) and its state
//! vector: everything that determines its continuation, so that a saved run continues
//! bit for bit (FMU states of RollPlaneVehicle, HalfCarBogie and Wagon).

use super::accelerations::Accelerations;
use super::clock::ForceExtremes;
use super::vehicle_unit::{Body, VehicleUnit};
use crate::error::{Error, Result, num, out_of_range};
use crate::limits::{MIN_STEP_FRACTION, check, within};

impl VehicleUnit {
    /// The body's state vector.
    pub(super) fn body_state(&self) -> Vec<f64> {
        match &self.body {
            Body::Whole(b) => b.state_vector(),
            Body::Sprung(b) => b.state_vector(),
        }
    }

    /// Values ahead of the body's in a state vector: the clock (3), the motion (speed,
    /// rotation at the last change of speed, its time), then per wheelset the held
    /// forces (2) and the extremes.
    pub(super) fn head_len(&self) -> usize {
        6 + self.wheelsets() * (2 + ForceExtremes::LEN + Accelerations::LEN)
    }

    /// Everything that determines the continuation: the clock (`t0` (s), `k`, the
    /// carried time (s)), the motion (the speed (m/s), the rotation (rad) at its last
    /// change and that time (s)), the held forces `[left, right]` (N) of each wheelset, the
    /// largest and smallest forces `[left, right]` (N) of each, the wheels'
    /// accelerations' history and extremes of each ([`Accelerations`]), then the
    /// vehicle's step and displacements; [`VehicleUnit::set_state_vector`] restores it exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let c = &self.clock;
        let n = self.wheelsets();
        let mut v = vec![
            c.t0,
            c.k as f64,
            c.carried,
            self.params.speed,
            self.rotation_ref,
            self.since,
        ];
        v.extend(self.force[..n].iter().flatten());
        for e in &self.extremes[..n] {
            v.extend(e.to_array());
        }
        for a in &self.accelerations[..n] {
            v.extend(a.to_array());
        }
        v.extend(self.body_state());
        v
    }

    /// Restores a state written by [`VehicleUnit::state_vector`] of a unit with the
    /// same parameters. Refused: a wrong length, a clock that is not finite from 0 on, a
    /// step count that is not a whole number below 2^53, a carried time not below the
    /// least step, a force beyond 1e7 N, a step outside
    /// [`MIN_STEP_FRACTION`]` dt_base ..= dt_base`, and a state beyond the health bounds
    /// ([`VehicleUnit::check_states`]).
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let head = self.head_len();
        let len = head + self.body_state().len();
        if v.len() != len {
            return Err(out_of_range(
                "vehicle unit state length",
                v.len() as f64,
                format!("{len} values"),
            ));
        }
        let count = crate::limits::is_count;
        let min_step = MIN_STEP_FRACTION * self.clock.base;
        if !(v[0].is_finite() && v[0] >= 0.0 && count(v[1]) && v[2] >= 0.0 && v[2] < min_step) {
            return Err(out_of_range(
                "state: clock",
                v[0],
                "t0 finite and >= 0 s, step count a whole number in [0, 2^53), carried time \
                 below the least step",
            ));
        }
        if check("speed", v[3]).is_err() || !v[4].is_finite() || !(v[5].is_finite() && v[5] >= 0.0)
        {
            return Err(out_of_range(
                "state: motion",
                v[3],
                "a speed in its range, a finite rotation, a time of change >= 0 s",
            ));
        }
        // The held forces and their extremes (the accelerations after them are checked
        // where they are read).
        let forces_end = 6 + self.wheelsets() * (2 + ForceExtremes::LEN);
        for &f in &v[6..forces_end] {
            if !within(f, 1e7) {
                return Err(out_of_range("state: contact force", f, "|F| <= 1e7 N"));
            }
        }
        let dt = v[head];
        if !(dt >= min_step && dt <= self.clock.base) {
            return Err(out_of_range(
                "state: step",
                dt,
                format!("{} s <= dt <= {} s", num(min_step), num(self.clock.base)),
            ));
        }
        let body = &v[head..];
        match &mut self.body {
            Body::Whole(b) => b.set_state_vector(body)?,
            Body::Sprung(b) => b.set_state_vector(body)?,
        }
        self.clock.dt = dt;
        self.clock.t0 = v[0];
        self.clock.k = v[1] as u64;
        self.clock.carried = v[2];
        self.params.speed = v[3];
        self.rotation_ref = v[4];
        self.since = v[5];
        let n = self.wheelsets();
        for k in 0..n {
            self.force[k] = [v[6 + 2 * k], v[7 + 2 * k]];
            let e = 6 + 2 * n + ForceExtremes::LEN * k;
            self.extremes[k] = ForceExtremes::from_slice(&v[e..e + ForceExtremes::LEN]);
            let a = 6 + n * (2 + ForceExtremes::LEN) + Accelerations::LEN * k;
            let a = &v[a..a + Accelerations::LEN];
            if let Some(&bad) = a.iter().find(|x| !x.is_finite()) {
                return Err(out_of_range(
                    "vehicle unit state: accelerations",
                    bad,
                    "finite",
                ));
            }
            self.accelerations[k] = Accelerations::from_slice(a);
        }
        self.check_states()
    }

    /// The FMU name of wheelset `k`'s held force on `side`.
    pub(super) fn force_name(&self, k: usize, side: &str) -> String {
        let kind = if self.is_axle_box() {
            "axle_box"
        } else {
            "contact"
        };
        let prefix = if k == 0 {
            String::new()
        } else {
            format!("wheelset[{}].", k + 1)
        };
        format!("{prefix}{kind}.{side}.force")
    }

    /// Refuses held forces beyond [`crate::limits::force_limit`] of the static loads (20
    /// times the larger, at least 2 MN), which no physical run reaches.
    pub(super) fn check_held_forces(&self) -> Result<()> {
        let lim = crate::limits::force_limit(self.static_load());
        for k in 0..self.wheelsets() {
            for (s, side) in ["left", "right"].into_iter().enumerate() {
                let x = self.force[k][s];
                if !within(x, lim) {
                    let name = self.force_name(k, side);
                    return Err(Error::Input {
                        value: x,
                        allowed: format!(
                            "|{name}| <= {} N ({} times the static wheel load, at least {} N), \
                             which no physical run exceeds; the step was not taken: likely the \
                             partner diverged",
                            num(lim),
                            crate::limits::FORCE_LIMIT_FACTOR,
                            num(crate::limits::FORCE_LIMIT_FACTOR
                                * crate::limits::FORCE_LIMIT_MIN_STATIC_LOAD)
                        ),
                        name,
                    });
                }
            }
        }
        Ok(())
    }

    /// Checks the bodies and the wheels against the health bounds of [`crate::limits`].
    pub fn check_states(&self) -> Result<()> {
        let bad = match &self.body {
            Body::Whole(b) => b.beyond_bounds(),
            Body::Sprung(b) => b.beyond_bounds(),
        };
        match bad {
            None => Ok(()),
            Some((what, value, limit)) => Err(Error::Diverged {
                what: what.into(),
                value,
                limit,
                time: self.time(),
                cause: format!(
                    "likely forces that do not carry the vehicle (held {}: {} against a \
                     static load of {} N per wheel){}",
                    if self.is_axle_box() {
                        "axle_box.*.force"
                    } else {
                        "contact.*.force"
                    },
                    (0..self.wheelsets())
                        .map(|k| {
                            let prefix = if k == 0 {
                                String::new()
                            } else {
                                format!("wheelset[{}].", k + 1)
                            };
                            format!(
                                "{prefix}left {} N, {prefix}right {} N",
                                num(self.force[k][0]),
                                num(self.force[k][1])
                            )
                        })
                        .collect::<Vec<_>>()
                        .join(", "),
                    num(self.static_load()[0]),
                    match self.exchange {
                        Some(e) => format!(
                            "; with the axle-box interface, communication steps above about \
                             {} s under a Jacobi master and {} s under a sequential one (the \
                             primary springs and dampers exchanged explicitly against the side \
                             frames' inertia) are unstable",
                            num(e.jacobi),
                            num(e.sequential)
                        ),
                        None => String::new(),
                    }
                ),
            }),
        }
    }
}
