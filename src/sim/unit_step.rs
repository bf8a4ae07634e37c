//! The vehicle unit in time: the number of substeps a communication step takes, the
//! step with the forces held ([`VehicleUnit::advance`]) and the step planned to the
//! master's clock ([`VehicleUnit::plan_to`], [`VehicleUnit::advance_to`]).

use super::clock::StepPlan;
use super::vehicle_unit::{Body, VehicleUnit};
use crate::error::{Result, positive};
use crate::limits::MAX_VEHICLE_STEPS_PER_CALL;

impl VehicleUnit {
    /// Number of steps a communication step `h` (s) takes, with the time carried over
    /// from earlier calls: `ceil((h + carried) / dt_base)`, first reduced by `tolerance`
    /// (s), the rounding of the master's clock, so a step that is a whole multiple of the
    /// base step up to that rounding takes exactly that many steps; 0 when the sum is
    /// below [`crate::limits::MIN_STEP_FRACTION`] of the base step.
    pub fn steps_for(&self, h: f64, tolerance: f64) -> f64 {
        self.clock.substeps(h, tolerance).n
    }

    /// Advances by a communication step `h` (s) with the contact forces held, in
    /// [`VehicleUnit::steps_for`] equal steps. When they are that many steps of the step
    /// in use to within `tolerance` (s), they are taken as they are; otherwise the step
    /// changes to `(h + carried) / n`: first-order accurate at the change and stable for
    /// any sequence of changes, since every step stays below half the critical step. A
    /// step (with what was carried) shorter than [`crate::limits::MIN_STEP_FRACTION`] of the base step
    /// is carried over to the next call instead: a step that short would round the
    /// velocities away (ratios of consecutive steps of 5,000 let the vehicle sink
    /// millimetres over minutes), so the model time lags the master's by at most that.
    ///
    /// Errors: `h` not positive; a vehicle displacement beyond
    /// [`crate::limits::BODY_DISPLACEMENT_LIMIT`] or a wheel beyond
    /// [`crate::limits::DISPLACEMENT_LIMIT`] ([`crate::Error::Diverged`]).
    pub fn advance(&mut self, h: f64, tolerance: f64) -> Result<()> {
        positive("communication step", h, "s")?;
        self.check_held_forces()?;
        let s = self.clock.substeps(h, tolerance);
        if s.n == 0.0 {
            self.clock.carried = s.total;
            return Ok(());
        }
        self.clock.carried = 0.0;
        if let Some(dt) = s.dt {
            match &mut self.body {
                Body::Whole(b) => b.change_dt(dt)?,
                Body::Sprung(b) => b.change_dt(dt)?,
            }
            self.clock.restart(dt);
        }
        for k in 0..self.wheelsets() {
            self.extremes[k].record(self.force[k]);
        }
        let n = s.n as u64;
        let dt = self.clock.dt;
        match &mut self.body {
            Body::Whole(b) => (0..n).for_each(|_| {
                // The wheels at the start of each step, as the engine samples them.
                let w = b.wheelsets();
                for (a, z) in self.accelerations.iter_mut().zip(b.wheel_z()).take(w) {
                    a.record([z[0], z[1], 0.0, 0.0], dt);
                }
                b.step(&self.force)
            }),
            Body::Sprung(b) => (0..n).for_each(|_| b.step(&self.force)),
        }
        for _ in 0..n {
            self.clock.tick();
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
}
