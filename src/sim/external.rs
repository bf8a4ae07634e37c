//! [`Simulation`]'s inputs from a vehicle outside it: the wheels moved from outside
//! ([`VehicleSpec::External`](super::VehicleSpec::External)), where the track-carrying
//! co-simulation unit takes the wheel heights, the axle angle and their rates
//! ([`InputRates`], kept in `inputs.rs`) from the vehicle unit; and the side frames over
//! wheelsets on their primary suspension, with the primary forces they feel.

use super::inputs::InputRates;
use super::simulation::Simulation;
use super::vehicle_state::VehicleState;
use crate::error::{Error, Result, finite, out_of_range};
use crate::limits::{DISPLACEMENT_LIMIT, within};

impl Simulation {
    /// Sets the wheel inputs of a simulation with [`VehicleSpec::External`](super::VehicleSpec::External) wheels:
    /// wheel-centre displacements `[left, right]` (m) and the axle rotation angle (rad)
    /// at the current time ([`Simulation::set_wheel_z`], [`Simulation::set_rotation`]).
    pub fn set_wheel_inputs(&mut self, z: [f64; 2], gamma: f64) -> Result<()> {
        self.set_wheel_z(z)?;
        self.set_rotation(gamma)
    }

    /// [`Simulation::set_wheel_inputs`] of wheelset `k` (0 the leading one).
    /// Errors as there, and a wheelset the simulation does not have.
    pub fn set_wheelset_inputs(&mut self, k: usize, z: [f64; 2], gamma: f64) -> Result<()> {
        self.set_wheel_z_of(k, z)?;
        self.set_rotation_of(k, gamma)
    }

    /// Sets the wheel-centre displacements of the leading wheelset
    /// ([`Simulation::set_wheel_z_of`]).
    pub fn set_wheel_z(&mut self, z: [f64; 2]) -> Result<()> {
        self.set_wheel_z_of(0, z)
    }

    /// Sets the axle rotation angle of the leading wheelset
    /// ([`Simulation::set_rotation_of`]).
    pub fn set_rotation(&mut self, gamma: f64) -> Result<()> {
        self.set_rotation_of(0, gamma)
    }

    /// The external wheels of wheelset `k`.
    fn external(&mut self, k: usize) -> Result<&mut VehicleState> {
        let n = self.wheelsets.len();
        let w = self.wheelsets.get_mut(k).ok_or_else(|| {
            out_of_range(
                "wheelset index",
                k as f64,
                format!(
                    "0 (the leading wheelset) to {} (wheelset[{n}]), the wheelsets of this \
                     simulation",
                    n - 1
                ),
            )
        })?;
        match &mut w.vehicle {
            v @ VehicleState::External { .. } => Ok(v),
            _ => Err(Self::not_external()),
        }
    }

    /// Sets the wheel-centre displacements `[left, right]` (m) of wheelset `k` (0 the
    /// leading one) of a simulation with
    /// [`VehicleSpec::External`](super::VehicleSpec::External) wheels. The axle rotation is not touched: it keeps
    /// turning at `V / R_w` from the last angle given to [`Simulation::set_rotation_of`].
    /// Refused for any other vehicle, a wheelset the simulation does not have, and
    /// outside `|z| <=` [`crate::limits::DISPLACEMENT_LIMIT`]. Derivatives given at an
    /// earlier time ([`Simulation::set_wheel_rate_of`]) are dropped: the new heights
    /// are held; those given at this time stay.
    pub fn set_wheel_z_of(&mut self, k: usize, z: [f64; 2]) -> Result<()> {
        for (name, x) in [("wheel.left.z", z[0]), ("wheel.right.z", z[1])] {
            if !within(x, DISPLACEMENT_LIMIT) {
                return Err(out_of_range(
                    name,
                    x,
                    format!(
                        "-{DISPLACEMENT_LIMIT} m <= {name} <= {DISPLACEMENT_LIMIT} m (static \
                         wheel heights are about -1.4 mm)"
                    ),
                ));
            }
        }
        let now = self.time();
        if let VehicleState::External { wheel_z, rates, .. } = self.external(k)? {
            for side in 0..2 {
                Self::give_height(wheel_z, rates, side, z[side], now);
            }
        }
        self.clear_cache();
        Ok(())
    }

    /// Sets the wheel-centre displacement `z` (m) of one wheel, `side` 0 (left) or 1
    /// (right), of wheelset `k`, as [`Simulation::set_wheel_z_of`] both; the other
    /// wheel keeps moving as it was.
    pub fn set_wheel_side_z_of(&mut self, k: usize, side: usize, z: f64) -> Result<()> {
        let name = Self::wheel_name(k, side);
        if !within(z, DISPLACEMENT_LIMIT) {
            return Err(out_of_range(
                &name,
                z,
                format!("-{DISPLACEMENT_LIMIT} m <= {name} <= {DISPLACEMENT_LIMIT} m"),
            ));
        }
        let now = self.time();
        if let VehicleState::External { wheel_z, rates, .. } = self.external(k)? {
            Self::give_height(wheel_z, rates, side.min(1), z, now);
        }
        self.clear_cache();
        Ok(())
    }

    /// Takes the input derivatives of each external wheelset from `before`, a
    /// simulation of the same scenario at the same time (rebuilt after a parameter
    /// changed): the wheel heights' and the axle angle's rates, from the inputs as they
    /// are set now.
    pub fn carry_input_rates_from(&mut self, before: &Simulation) {
        for (w, b) in self.wheelsets.iter_mut().zip(before.wheelsets.iter()) {
            if let (
                VehicleState::External { rates, .. },
                VehicleState::External { rates: old, .. },
            ) = (&mut w.vehicle, &b.vehicle)
            {
                *rates = *old;
            }
        }
        self.clear_cache();
    }

    /// The name of wheelset `k`'s wheel height on `side` (0 left, 1 right).
    fn wheel_name(k: usize, side: usize) -> String {
        let prefix = if k == 0 {
            String::new()
        } else {
            format!("wheelset[{}].", k + 1)
        };
        let s = if side == 0 { "left" } else { "right" };
        format!("{prefix}wheel.{s}.z")
    }

    /// One wheel's height `z` (m) given at `now` (s): its derivatives given at an
    /// earlier time are dropped (the height is held), those given now stay, and the
    /// height's polynomial is anchored now whatever came first at this point, the height
    /// or its derivatives (the standard fixes no order; derivatives first given late
    /// were anchored at the last time derivatives were dropped, 0 at first).
    fn give_height(wheel_z: &mut [f64; 2], rates: &mut InputRates, side: usize, z: f64, now: f64) {
        wheel_z[side] = z;
        if rates.z_since[side] != now {
            if rates.z_given[side] {
                rates.z[0][side] = 0.0;
                rates.z[1][side] = 0.0;
                rates.z_given[side] = false;
            }
            rates.z_since[side] = now;
        }
    }

    /// Sets the time derivative of order `order` (1 or 2) of wheelset `k`'s wheel
    /// height on side `side` (0 left, 1 right) at the current time, `value` (m/s or
    /// m/s^2): from now on the height follows its Taylor polynomial instead of being
    /// held, until it is set again at a later time ([`Simulation::set_wheel_z_of`]).
    /// The height it starts from is the one it has now.
    ///
    /// Errors: as [`Simulation::set_wheel_z_of`]; an order other than 1 or 2; a value
    /// not finite or beyond 1e3 m/s (first order) or 1e7 m/s^2 (second).
    pub fn set_wheel_rate_of(
        &mut self,
        k: usize,
        side: usize,
        order: usize,
        value: f64,
    ) -> Result<()> {
        let side = side.min(1);
        Self::check_wheel_rate(&Self::wheel_name(k, side), order, value)?;
        let now = self.time();
        if let VehicleState::External { wheel_z, rates, .. } = self.external(k)? {
            if rates.z_since[side] != now {
                // The height it has now, from which the new derivatives extrapolate.
                let z = rates.wheel_z_at(*wheel_z, now)[side];
                Self::give_height(wheel_z, rates, side, z, now);
            }
            rates.z[order - 1][side] = value;
            rates.z_given[side] = true;
        }
        self.clear_cache();
        Ok(())
    }

    /// Refuses a wheel height's derivative (named `name`) of an order other than 1 or 2,
    /// or a value not finite or beyond 1e3 m/s (first order) or 1e7 m/s^2 (second).
    pub fn check_wheel_rate(name: &str, order: usize, value: f64) -> Result<()> {
        let limit = match order {
            1 => 1e3,
            2 => 1e7,
            _ => {
                return Err(out_of_range(
                    &format!("derivative order of {name}"),
                    order as f64,
                    "1 or 2 (the wheel heights follow a polynomial of degree 2 at most)",
                ));
            }
        };
        if !within(value, limit) {
            return Err(out_of_range(
                &format!("d^{order}/dt^{order} {name}"),
                value,
                format!("|value| <= {limit} (m/s^{order}), finite"),
            ));
        }
        Ok(())
    }

    /// Refuses an axle angle's rate (named `name`) of an order other than 1, or not
    /// finite or beyond 1e4 rad/s.
    pub fn check_rotation_rate(name: &str, order: usize, value: f64) -> Result<()> {
        if order != 1 {
            return Err(out_of_range(
                &format!("derivative order of {name}"),
                order as f64,
                "1 (the axle angle turns at the rate given)",
            ));
        }
        if !within(value, 1e4) {
            return Err(out_of_range(
                &format!("d/dt {name}"),
                value,
                "|value| <= 1e4 rad/s, finite",
            ));
        }
        Ok(())
    }

    /// Sets the axle angle's rate `value` (rad/s) of wheelset `k` at the current time:
    /// from now on the angle turns at it instead of `V / R_w`, until the angle is set
    /// again at a later time ([`Simulation::set_rotation_of`]).
    ///
    /// Errors: as [`Simulation::set_rotation_of`]; a rate not finite or beyond 1e4
    /// rad/s.
    pub fn set_rotation_rate_of(&mut self, k: usize, value: f64) -> Result<()> {
        Self::check_rotation_rate("wheel.rotation", 1, value)?;
        let now = self.time();
        let rolling = self.motion.speed / self.scenario.wheel_radius;
        if let VehicleState::External {
            rotation,
            since,
            rates,
            ..
        } = self.external(k)?
        {
            // The angle now, as it has turned since it was given.
            let rate = if rates.rotation_given {
                rates.rotation
            } else {
                rolling
            };
            *rotation += rate * (now - *since);
            *since = now;
            rates.rotation_given = true;
            rates.rotation_since = now;
            rates.rotation = value;
        }
        self.clear_cache();
        Ok(())
    }

    /// Sets the axle rotation angle `gamma` (rad) of wheelset `k` (0 the leading one)
    /// at the current time of a simulation with
    /// [`VehicleSpec::External`](super::VehicleSpec::External) wheels; from now on the
    /// axle rolls without slip from it (2.17). Refused for any other vehicle, a
    /// wheelset the simulation does not have, and a non-finite angle.
    pub fn set_rotation_of(&mut self, k: usize, gamma: f64) -> Result<()> {
        finite("wheel.rotation", gamma, "rad")?;
        let now = self.time();
        if let VehicleState::External {
            rotation,
            since,
            rates,
            ..
        } = self.external(k)?
        {
            *rotation = gamma;
            *since = now;
            if rates.rotation_since != now {
                rates.rotation_given = false;
                rates.rotation = 0.0;
            }
        }
        self.clear_cache();
        Ok(())
    }

    /// Sets the side frames' displacements `z` and velocities `v` `[left, right]` (m,
    /// m/s) above the axle boxes of wheelset `k` (0 the leading one) of a simulation
    /// with [`VehicleSpec::AxleBox`](super::VehicleSpec::AxleBox) wheelsets, at the
    /// current time; from now on the side frames move on at `v` until set again
    /// ([`crate::vehicle::PrimaryLink::set_side_frames`]). Refused for any other
    /// vehicle, a wheelset the simulation does not have, and values not finite or
    /// beyond [`crate::limits::BODY_DISPLACEMENT_LIMIT`] (m) or 100 m/s.
    pub fn set_side_frames_of(&mut self, k: usize, z: [f64; 2], v: [f64; 2]) -> Result<()> {
        use crate::limits::BODY_DISPLACEMENT_LIMIT;
        let named = [
            ("side_frame.left.z", z[0], BODY_DISPLACEMENT_LIMIT, "m"),
            ("side_frame.right.z", z[1], BODY_DISPLACEMENT_LIMIT, "m"),
            ("side_frame.left.v", v[0], 100.0, "m/s"),
            ("side_frame.right.v", v[1], 100.0, "m/s"),
        ];
        for (name, x, lim, unit) in named {
            if !within(x, lim) {
                return Err(out_of_range(
                    name,
                    x,
                    format!("-{lim} {unit} <= {name} <= {lim} {unit}"),
                ));
            }
        }
        let n = self.wheelsets.len();
        let w = self.wheelsets.get_mut(k).ok_or_else(|| {
            out_of_range(
                "wheelset index",
                k as f64,
                format!("0 to {} (the wheelsets of this simulation)", n - 1),
            )
        })?;
        match &mut w.vehicle {
            VehicleState::AxleBox(link) => {
                link.set_side_frames(z, v);
                Ok(())
            }
            _ => Err(Error::Unsupported(
                "side-frame inputs for a simulation whose wheelsets are not cut at the axle \
                 boxes"
                    .into(),
            )),
        }
    }

    /// The side frames' displacements and velocities `[left, right]` (m, m/s) last set
    /// for wheelset `k` (at the static start, where the primary springs carry the
    /// static loads); `None` for a wheelset the simulation does not have or not cut at
    /// its axle boxes.
    pub fn side_frames_of(&self, k: usize) -> Option<([f64; 2], [f64; 2])> {
        match &self.wheelsets.get(k)?.vehicle {
            VehicleState::AxleBox(link) => Some(link.side_frames()),
            _ => None,
        }
    }

    /// The primary forces `[left, right]` (N) of wheelset `k` at the current time
    /// (the axle-box interface: the wheelset's and the side frames' motion now), what a
    /// master that steps every unit from the same point hands the bogie; `None` for a
    /// wheelset without the axle-box interface.
    pub fn primary_force_of(&self, k: usize) -> Option<[f64; 2]> {
        match &self.wheelsets.get(k)?.vehicle {
            VehicleState::AxleBox(link) => Some(link.force_now()),
            _ => None,
        }
    }

    /// Carries side frames of `inertia` above every wheelset's axle boxes from now on
    /// ([`crate::vehicle::PrimaryLink::set_inertia`]).
    ///
    /// Errors: no wheelset cut at its axle boxes; an inertia the links refuse (nothing
    /// changed then).
    pub fn set_side_frame_inertia(
        &mut self,
        inertia: crate::vehicle::SideFrameInertia,
    ) -> Result<()> {
        // Every link carries the same side frames: the first refuses them (before any
        // change) or none does.
        let mut cut = false;
        for w in self.wheelsets.iter_mut() {
            if let VehicleState::AxleBox(link) = &mut w.vehicle {
                link.set_inertia(inertia)?;
                cut = true;
            }
        }
        if !cut {
            return Err(Error::Unsupported(
                "side frames of a simulation not cut at its axle boxes".into(),
            ));
        }
        Ok(())
    }

    /// The primary suspension of wheelset `k`: its forces `[left, right]` (N, pressing
    /// the wheelset down) averaged over the steps since the side frames were last set
    /// (the impulse the bogie takes over its communication step), and the axle boxes'
    /// displacements and velocities at `t_j` (m, m/s); `None` for a wheelset the
    /// simulation does not have or not cut at its axle boxes.
    pub fn primary_of(&self, k: usize) -> Option<([f64; 2], [f64; 2], [f64; 2])> {
        match &self.wheelsets.get(k)?.vehicle {
            VehicleState::AxleBox(link) => {
                let b = link.body();
                Some((link.mean_force(), b.wheel_z(), b.box_velocity()))
            }
            _ => None,
        }
    }

    fn not_external() -> Error {
        Error::Unsupported("wheel inputs for a simulation that has its own vehicle".into())
    }
}
