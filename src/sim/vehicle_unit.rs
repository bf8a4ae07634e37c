//! The roll-plane vehicle as a co-simulation unit: driven by contact forces from
//! outside, it reports wheel displacements and the axle angle. Its partner, the track
//! with the contact, is a [`crate::sim::Simulation`] with
//! [`crate::sim::VehicleSpec::External`] wheels.
//!
//! Coupled with a communication step equal to the track's step, in the order of
//! `docs/MODEL.md` (vehicle outputs -> track inputs -> track outputs -> vehicle inputs ->
//! both step), the pair performs exactly the arithmetic of the monolithic
//! [`crate::sim::Simulation`].

use super::clock::{Clock, ForceExtremes, StepPlan, Stepping};
use crate::error::{Error, Result, finite, non_negative, num, out_of_range, positive};
use crate::limits::{
    MAX_VEHICLE_STEPS_PER_CALL, MIN_DT_FRACTION, MIN_STEP_FRACTION, check, within,
};
use crate::vehicle::{RollPlaneParams, RollPlaneVehicle, SprungBogie};
use nalgebra::Vector6;

/// Parameters of a [`VehicleUnit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleUnitParams {
    /// The roll-plane vehicle.
    pub vehicle: RollPlaneParams,
    /// Forward speed `V` (m/s): turns the axle at `V / R_w`.
    pub speed: f64,
    /// Nominal wheel radius `R_w` (m).
    pub wheel_radius: f64,
    /// Base step (s); 0 takes [`RollPlaneParams::default_dt`].
    pub dt: f64,
    /// Wheel-centre displacements `[left, right]` (m) of the static equilibrium, as the
    /// track computed them: the vehicle starts at rest on them.
    pub static_wheel_z: [f64; 2],
    /// The axle-box interface: the unit is the vehicle above its primary suspension
    /// ([`crate::vehicle::SprungBogie::new`]), the primary forces come in
    /// (held over each communication step) and the side frames' motion goes out; its
    /// partner carries the wheelset and the primary suspension
    /// ([`crate::sim::VehicleSpec::AxleBox`]). `false`: the whole vehicle with the
    /// contact forces in.
    pub axle_box: bool,
}

/// The six-DOF roll-plane vehicle (3.1-3.3, 3.24-3.27) as a co-simulation unit: the
/// contact forces `[left, right]` (N) come in and are held over each communication step;
/// the wheel-centre displacements (m), the axle angle (rad) and the bodies' motion go
/// out. It follows the master's clock in equal substeps of at most its base step
/// ([`VehicleUnit::plan_to`], [`VehicleUnit::advance`]).
#[derive(Debug, Clone)]
pub struct VehicleUnit {
    params: VehicleUnitParams,
    vehicle: RollPlaneVehicle,
    /// With the axle-box interface: the bodies above the primary suspension, which step
    /// instead of `vehicle` (then at rest on the static wheel heights).
    sprung: Option<SprungBogie>,
    /// Equal substeps of at most the base step; steps shorter than
    /// [`MIN_STEP_FRACTION`] of it are carried over to the next call. Its step is the
    /// vehicle's.
    clock: Clock,
    force: [f64; 2],
    extremes: ForceExtremes,
}

/// Values of a [`VehicleUnit`] state vector ahead of the vehicle's: the clock
/// (`t0`, `k`, the carried time), then the held forces `[left, right]` (N), then the
/// force extremes.
const HEAD: usize = 3 + 2 + ForceExtremes::LEN;

impl VehicleUnit {
    /// Builds the vehicle at rest on the static wheel displacements, carrying the static
    /// wheel load on each wheel.
    ///
    /// Errors: a parameter outside its physical range ([`Error::Parameter`], naming
    /// it); a step outside [`MIN_DT_FRACTION`] of the critical step of the fastest
    /// suspension mode up to half of it; a static state beyond the health bounds.
    pub fn new(p: &VehicleUnitParams) -> Result<Self> {
        check("speed", p.speed)?;
        check("wheel.radius", p.wheel_radius)?;
        non_negative("solver.dt", p.dt, "s")?;
        check("static_wheel_z.left", p.static_wheel_z[0])?;
        check("static_wheel_z.right", p.static_wheel_z[1])?;
        p.vehicle.validate()?;
        let critical = p.vehicle.critical_time_step();
        let dt = if p.dt == 0.0 {
            p.vehicle.default_dt()
        } else {
            p.dt
        };
        if !(dt >= MIN_DT_FRACTION * critical && dt <= 0.5 * critical) {
            return Err(out_of_range(
                "solver.dt",
                dt,
                format!(
                    "0 (the default, {} s) or {} s <= solver.dt <= {} s (half the critical step \
                     {} s of the fastest suspension mode: the step changes that communication \
                     steps force stay stable below it)",
                    num(p.vehicle.default_dt()),
                    num(MIN_DT_FRACTION * critical),
                    num(0.5 * critical),
                    num(critical)
                ),
            ));
        }
        let mut vehicle = RollPlaneVehicle::new(p.vehicle, dt)?;
        vehicle.set_static(p.static_wheel_z)?;
        let sprung = if p.axle_box {
            let mut b = SprungBogie::new(p.vehicle, dt)?;
            b.set_static(p.static_wheel_z)?;
            Some(b)
        } else {
            None
        };
        // The held inputs start static: the contact forces, or the primary forces.
        let w = match &sprung {
            Some(_) => vehicle.bearing_forces(),
            None => [p.vehicle.static_wheel_load(); 2],
        };
        let unit = VehicleUnit {
            params: *p,
            vehicle,
            sprung,
            clock: Clock::new(dt, Stepping::Substeps),
            force: w,
            extremes: ForceExtremes::at(w),
        };
        unit.check_states()?;
        Ok(unit)
    }

    /// Parameters.
    pub fn params(&self) -> &VehicleUnitParams {
        &self.params
    }
    /// Static load on each wheel `[left, right]` (N).
    pub fn static_load(&self) -> [f64; 2] {
        let w = self.params.vehicle.static_wheel_load();
        [w, w]
    }
    /// Base step (s).
    pub fn dt_base(&self) -> f64 {
        self.clock.base
    }
    /// Time (s).
    pub fn time(&self) -> f64 {
        self.clock.time()
    }
    /// Communication time carried over to the next call, not yet stepped (s).
    pub fn carried(&self) -> f64 {
        self.clock.carried
    }
    /// Axle rotation angle `V t / R_w` (rad) (2.17).
    pub fn rotation(&self) -> f64 {
        self.params.speed * self.time() / self.params.wheel_radius
    }
    /// Wheel-centre displacements `[left, right]` (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        self.vehicle.wheel_z()
    }
    /// Displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}` (m, rad); with the
    /// axle-box interface the wheelset's are its static ones (the partner carries it).
    pub fn displacements(&self) -> Vector6<f64> {
        let mut d = *self.vehicle.displacements();
        if let Some(b) = &self.sprung {
            d.fixed_rows_mut::<4>(0).copy_from(b.displacements());
        }
        d
    }
    /// Primary suspension (bearing) forces `[left, right]` (N), pressing the wheelset
    /// down; with the axle-box interface the held inputs.
    pub fn bearing_forces(&self) -> [f64; 2] {
        match &self.sprung {
            Some(_) => self.force,
            None => self.vehicle.bearing_forces(),
        }
    }
    /// The side frames' displacements and velocities `[left, right]` (m, m/s) at the
    /// current time, the velocities backward differences over the last step.
    pub fn side_frames(&self) -> ([f64; 2], [f64; 2]) {
        match &self.sprung {
            Some(b) => b.side_frames(),
            None => {
                let (d, v) = (self.vehicle.displacements(), self.vehicle.velocities());
                ([d[2], d[3]], [v[2], v[3]])
            }
        }
    }
    /// Whether the unit is the vehicle above its primary suspension.
    pub fn is_axle_box(&self) -> bool {
        self.sprung.is_some()
    }
    /// The held contact forces `[left, right]` (N); with the axle-box interface the
    /// held primary forces.
    pub fn forces(&self) -> [f64; 2] {
        self.force
    }
    /// Largest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn max_force(&self) -> [f64; 2] {
        self.extremes.max
    }
    /// Smallest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.extremes.min
    }

    /// Sets the contact forces `[left, right]` (N) held over the next communication step.
    ///
    /// Errors: a force not finite, or beyond [`crate::limits::force_limit`] of the
    /// static loads (20 times the larger, at least 2 MN), which no physical run reaches;
    /// nothing is set then.
    pub fn set_forces(&mut self, p: [f64; 2]) -> Result<()> {
        let lim = crate::limits::force_limit(self.static_load());
        let names = match &self.sprung {
            Some(_) => ["axle_box.left.force", "axle_box.right.force"],
            None => ["contact.left.force", "contact.right.force"],
        };
        for (name, x) in [(names[0], p[0]), (names[1], p[1])] {
            finite(name, x, "N")?;
            if !crate::limits::within(x, lim) {
                return Err(crate::error::out_of_range(
                    name,
                    x,
                    format!(
                        "|{name}| <= {} N ({} times the static wheel load), which no physical \
                         run exceeds",
                        crate::error::num(lim),
                        crate::limits::FORCE_LIMIT_FACTOR
                    ),
                ));
            }
        }
        self.force = p;
        Ok(())
    }

    /// Number of steps a communication step `h` (s) takes, with the time carried over
    /// from earlier calls: `ceil((h + carried) / dt_base)`, first reduced by `tolerance`
    /// (s), the rounding of the master's clock, so a step that is a whole multiple of the
    /// base step up to that rounding takes exactly that many steps; 0 when the sum is
    /// below [`MIN_STEP_FRACTION`] of the base step.
    pub fn steps_for(&self, h: f64, tolerance: f64) -> f64 {
        self.clock.substeps(h, tolerance).n
    }

    /// Advances by a communication step `h` (s) with the contact forces held, in
    /// [`VehicleUnit::steps_for`] equal steps. When they are that many steps of the step
    /// in use to within `tolerance` (s), they are taken as they are; otherwise the step
    /// changes to `(h + carried) / n`: first-order accurate at the change and stable for
    /// any sequence of changes, since every step stays below half the critical step. A
    /// step (with what was carried) shorter than [`MIN_STEP_FRACTION`] of the base step
    /// is carried over to the next call instead: a step that short would round the
    /// velocities away (ratios of consecutive steps of 5,000 let the vehicle sink
    /// millimetres over minutes), so the model time lags the master's by at most that.
    ///
    /// Errors: `h` not positive; a vehicle displacement beyond
    /// [`crate::limits::BODY_DISPLACEMENT_LIMIT`] or a wheel beyond
    /// [`crate::limits::DISPLACEMENT_LIMIT`] ([`Error::Diverged`]).
    pub fn advance(&mut self, h: f64, tolerance: f64) -> Result<()> {
        positive("communication step", h, "s")?;
        let s = self.clock.substeps(h, tolerance);
        if s.n == 0.0 {
            self.clock.carried = s.total;
            return Ok(());
        }
        self.clock.carried = 0.0;
        if let Some(dt) = s.dt {
            match &mut self.sprung {
                Some(b) => b.change_dt(dt)?,
                None => self.vehicle.change_dt(dt)?,
            }
            self.clock.restart(dt);
        }
        self.extremes.record(self.force);
        match &mut self.sprung {
            Some(b) => {
                for _ in 0..s.n as u64 {
                    b.step(self.force);
                    self.clock.tick();
                }
            }
            None => {
                for _ in 0..s.n as u64 {
                    self.vehicle.step(self.force);
                    self.clock.tick();
                }
            }
        }
        self.check_states()
    }

    /// Plans a communication step to the master's model time `end` (s), measured from
    /// the start of the run: [`VehicleUnit::steps_for`] what `end` is ahead of the time
    /// taken in ([`VehicleUnit::time`] and [`VehicleUnit::carried`]), `tolerance` (s)
    /// the rounding of the master's clock. Following the master's clock rather than
    /// summing its steps keeps the unit from drifting by the clock's rounding (1e-7 s
    /// per call at 1e9 s).
    ///
    /// Refused before anything moves, with the reason in words: more than
    /// [`MAX_VEHICLE_STEPS_PER_CALL`] steps.
    pub fn plan_to(&self, end: f64, tolerance: f64) -> std::result::Result<StepPlan, String> {
        let plan = self.clock.plan_to(end, tolerance);
        let n = plan.steps;
        if n > MAX_VEHICLE_STEPS_PER_CALL {
            return Err(format!(
                "{n} steps of solver.step = {} s; the most one call may do is \
                 {MAX_VEHICLE_STEPS_PER_CALL:e} (about two seconds)",
                self.clock.base
            ));
        }
        Ok(plan)
    }

    /// Takes a communication step planned by [`VehicleUnit::plan_to`] with the contact
    /// forces held: [`VehicleUnit::advance`] by what its end is ahead of the time taken
    /// in; nothing when it is not ahead. Errors as [`VehicleUnit::advance`].
    pub fn advance_to(&mut self, plan: StepPlan) -> Result<()> {
        let h = plan.end - self.clock.reached();
        if h > 0.0 {
            self.advance(h, plan.tolerance)
        } else {
            Ok(())
        }
    }

    /// Checks the bodies and the wheels against the health bounds of [`crate::limits`].
    pub fn check_states(&self) -> Result<()> {
        let bad = match &self.sprung {
            Some(b) => b.beyond_bounds(),
            None => self.vehicle.beyond_bounds(),
        };
        match bad {
            None => Ok(()),
            Some((what, value, limit)) => Err(Error::Diverged {
                what: what.into(),
                value,
                limit,
                time: self.time(),
                cause: format!(
                    "likely contact forces that do not carry the vehicle (contact.left.force = {} N, \
                     contact.right.force = {} N against a static load of {} N per wheel)",
                    num(self.force[0]),
                    num(self.force[1]),
                    num(self.static_load()[0])
                ),
            }),
        }
    }

    /// Everything that determines the continuation: the clock (`t0` (s), `k`, the
    /// carried time (s)), the held forces `[left, right]` (N), the largest and smallest
    /// forces `[left, right]` (N), then the vehicle's step and displacements;
    /// [`VehicleUnit::set_state_vector`] restores it exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let c = &self.clock;
        let mut v = vec![c.t0, c.k as f64, c.carried, self.force[0], self.force[1]];
        v.extend(self.extremes.to_array());
        match &self.sprung {
            Some(b) => v.extend(b.state_vector()),
            None => v.extend(self.vehicle.state_vector()),
        }
        v
    }

    /// Restores a state written by [`VehicleUnit::state_vector`] of a unit with the
    /// same parameters. Refused: a wrong length, a clock that is not finite from 0 on, a
    /// step count that is not a whole number below 2^53, a carried time not below the
    /// least step, a force beyond 1e7 N, a step outside
    /// [`MIN_STEP_FRACTION`]` dt_base ..= dt_base`, and a state beyond the health bounds
    /// ([`VehicleUnit::check_states`]).
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let body_len = match &self.sprung {
            Some(b) => b.state_vector().len(),
            None => self.vehicle.state_vector().len(),
        };
        let len = HEAD + body_len;
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
        for &f in &v[3..HEAD] {
            if !within(f, 1e7) {
                return Err(out_of_range("state: contact force", f, "|F| <= 1e7 N"));
            }
        }
        let dt = v[HEAD];
        if !(dt >= min_step && dt <= self.clock.base) {
            return Err(out_of_range(
                "state: step",
                dt,
                format!("{} s <= dt <= {} s", num(min_step), num(self.clock.base)),
            ));
        }
        match &mut self.sprung {
            Some(b) => {
                b.set_state_vector(&v[HEAD..])?;
                self.clock.dt = b.dt();
            }
            None => {
                self.vehicle.set_state_vector(&v[HEAD..])?;
                self.clock.dt = self.vehicle.dt();
            }
        }
        self.clock.t0 = v[0];
        self.clock.k = v[1] as u64;
        self.clock.carried = v[2];
        self.force = [v[3], v[4]];
        self.extremes = ForceExtremes::from_slice(&v[5..HEAD]);
        self.check_states()
    }
}
