//! The roll-plane vehicle as a co-simulation unit: driven by contact forces from
//! outside, it reports wheel displacements and the axle angle. Its partner, the track
//! with the contact, is a [`crate::sim::Simulation`] with
//! [`crate::sim::VehicleSpec::External`] wheels.
//!
//! Coupled with a communication step equal to the track's step, in the order of
//! `MODEL.md` (vehicle outputs -> track inputs -> track outputs -> vehicle inputs ->
//! both step), the pair performs exactly the arithmetic of the monolithic
//! [`crate::sim::Simulation`].

use crate::error::{Error, Result, finite, non_negative, num, out_of_range, positive};
use crate::limits::{MIN_DT_FRACTION, MIN_STEP_FRACTION, check, within};
use crate::vehicle::{RollPlaneParams, RollPlaneVehicle};
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
}

/// The six-DOF vehicle stepped by communication steps, with its inputs held.
#[derive(Debug, Clone)]
pub struct VehicleUnit {
    params: VehicleUnitParams,
    vehicle: RollPlaneVehicle,
    dt_base: f64,
    t0: f64,
    k: u64,
    /// Communication time not yet stepped (s): steps shorter than
    /// [`MIN_STEP_FRACTION`] of the base step are carried over to the next call.
    pending: f64,
    force: [f64; 2],
    max_force: [f64; 2],
    min_force: [f64; 2],
}

impl VehicleUnit {
    /// Builds the vehicle at rest on the static wheel displacements.
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
        let w = p.vehicle.static_wheel_load();
        let unit = VehicleUnit {
            params: *p,
            vehicle,
            dt_base: dt,
            t0: 0.0,
            k: 0,
            pending: 0.0,
            force: [w, w],
            max_force: [w, w],
            min_force: [w, w],
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
        self.dt_base
    }
    /// Time (s).
    pub fn time(&self) -> f64 {
        self.t0 + self.k as f64 * self.vehicle.dt()
    }
    /// Communication time carried over to the next call, not yet stepped (s).
    pub fn carried(&self) -> f64 {
        self.pending
    }
    /// Axle rotation angle `V t / R_w` (rad) (2.17).
    pub fn rotation(&self) -> f64 {
        self.params.speed * self.time() / self.params.wheel_radius
    }
    /// Wheel-centre displacements `[left, right]` (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        self.vehicle.wheel_z()
    }
    /// Displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}` (m, rad).
    pub fn displacements(&self) -> &Vector6<f64> {
        self.vehicle.displacements()
    }
    /// Primary suspension (bearing) forces `[left, right]` (N), pressing the wheelset down.
    pub fn bearing_forces(&self) -> [f64; 2] {
        self.vehicle.bearing_forces()
    }
    /// The held contact forces `[left, right]` (N).
    pub fn forces(&self) -> [f64; 2] {
        self.force
    }
    /// Largest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn max_force(&self) -> [f64; 2] {
        self.max_force
    }
    /// Smallest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.min_force
    }

    /// Sets the contact forces `[left, right]` (N) held over the next communication step.
    pub fn set_forces(&mut self, p: [f64; 2]) -> Result<()> {
        finite("contact.left.force", p[0], "N")?;
        finite("contact.right.force", p[1], "N")?;
        self.force = p;
        Ok(())
    }

    /// Number of steps a communication step `h` (s) takes, with the time carried over
    /// from earlier calls: `ceil((h + carried) / dt_base)`, first reduced by `tolerance`
    /// (s), the rounding of the master's clock, so a step that is a whole multiple of the
    /// base step up to that rounding takes exactly that many steps; 0 when the sum is
    /// below [`MIN_STEP_FRACTION`] of the base step.
    pub fn steps_for(&self, h: f64, tolerance: f64) -> f64 {
        let total = h + self.pending;
        if total < MIN_STEP_FRACTION * self.dt_base {
            0.0
        } else {
            ((total - tolerance) / self.dt_base).ceil().max(1.0)
        }
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
        let n = self.steps_for(h, tolerance);
        let total = h + self.pending;
        if n == 0.0 {
            self.pending = total;
            return Ok(());
        }
        self.pending = 0.0;
        if (total - n * self.vehicle.dt()).abs() > tolerance {
            self.t0 = self.time();
            self.k = 0;
            self.vehicle.change_dt(total / n)?;
        }
        for i in 0..2 {
            self.max_force[i] = self.max_force[i].max(self.force[i]);
            self.min_force[i] = self.min_force[i].min(self.force[i]);
        }
        for _ in 0..n as u64 {
            self.vehicle.step(self.force);
            self.k += 1;
        }
        self.check_states()
    }

    /// Checks the bodies and the wheels against the health bounds of [`crate::limits`].
    pub fn check_states(&self) -> Result<()> {
        let bad = self.vehicle.beyond_bounds();
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

    /// Everything that determines the continuation; [`VehicleUnit::set_state_vector`]
    /// restores it exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let mut v = vec![
            self.t0,
            self.k as f64,
            self.pending,
            self.force[0],
            self.force[1],
            self.max_force[0],
            self.max_force[1],
            self.min_force[0],
            self.min_force[1],
        ];
        v.extend(self.vehicle.state_vector());
        v
    }

    /// Restores a state written by [`VehicleUnit::state_vector`] of a unit with the
    /// same parameters.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != 22 {
            return Err(out_of_range(
                "vehicle unit state length",
                v.len() as f64,
                "22 values",
            ));
        }
        let count = crate::limits::is_count;
        let min_step = MIN_STEP_FRACTION * self.dt_base;
        if !(v[0].is_finite() && v[0] >= 0.0 && count(v[1]) && v[2] >= 0.0 && v[2] < min_step) {
            return Err(out_of_range(
                "state: clock",
                v[0],
                "t0 finite and >= 0 s, step count a whole number in [0, 2^53), carried time \
                 below the least step",
            ));
        }
        for &f in &v[3..9] {
            if !within(f, 1e7) {
                return Err(out_of_range("state: contact force", f, "|F| <= 1e7 N"));
            }
        }
        let dt = v[9];
        if !(dt >= min_step && dt <= self.dt_base) {
            return Err(out_of_range(
                "state: step",
                dt,
                format!("{} s <= dt <= {} s", num(min_step), num(self.dt_base)),
            ));
        }
        self.vehicle.set_state_vector(&v[9..])?;
        self.t0 = v[0];
        self.k = v[1] as u64;
        self.pending = v[2];
        self.force = [v[3], v[4]];
        self.max_force = [v[5], v[6]];
        self.min_force = [v[7], v[8]];
        self.check_states()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Scenario, Simulation, VehicleSpec};

    /// Couples an external-wheel track simulation with a vehicle unit, as two FMUs
    /// would be coupled, and returns the contact forces per step.
    fn run_pair(s: &Scenario, h_per_dt: u64, steps: usize) -> Vec<[f64; 2]> {
        let VehicleSpec::RollPlane(vp) = s.vehicle else {
            panic!("roll-plane scenario expected")
        };
        let w = vp.static_wheel_load();
        let mut ts = s.clone();
        ts.vehicle = VehicleSpec::External {
            static_load: [w, w],
        };
        let mut track = Simulation::new(&ts).unwrap();
        let mut veh = VehicleUnit::new(&VehicleUnitParams {
            vehicle: vp,
            speed: s.speed,
            wheel_radius: s.wheel_radius,
            dt: 0.0,
            static_wheel_z: track.wheel_z(),
        })
        .unwrap();
        let h = track.dt() * h_per_dt as f64;
        let mut out = Vec::new();
        for _ in 0..steps {
            track
                .set_wheel_inputs(veh.wheel_z(), veh.rotation())
                .unwrap();
            let c = track.sample().contact;
            let p = [c[0].force, c[1].force];
            veh.set_forces(p).unwrap();
            out.push(p);
            track.advance_steps(h_per_dt).unwrap();
            veh.advance(h, 0.0).unwrap();
        }
        out
    }

    #[test]
    fn pair_at_the_track_step_is_the_monolithic_solver_bit_for_bit() {
        let mut s = Scenario::table_4_4_flat();
        s.set_nodes_per_span(2);
        s.dt = 45e-6;
        let steps = 4000; // 0.18 s: passes the first impact of the flat
        let pair = run_pair(&s, 1, steps);
        let mut sim = Simulation::new(&s).unwrap();
        let mut peak = 0.0f64;
        for (j, p) in pair.iter().enumerate() {
            let m = sim.step().unwrap();
            assert_eq!(
                [m.contact[0].force, m.contact[1].force],
                *p,
                "step {j} differs"
            );
            peak = peak.max(p[0]);
        }
        // The run did reach the impact (well above the 107.7 kN static load).
        assert!(peak > 300e3, "peak {peak}");
    }

    /// Table 4.4's vehicle at 20 m/s with step `dt` (0: the default) at rest on
    /// `static_wheel_z`.
    fn table_4_4_unit(
        dt: impl Fn(&RollPlaneParams) -> f64,
        static_wheel_z: [f64; 2],
    ) -> VehicleUnitParams {
        let VehicleSpec::RollPlane(vp) = Scenario::table_4_4().vehicle else {
            unreachable!()
        };
        VehicleUnitParams {
            vehicle: vp,
            speed: 20.0,
            wheel_radius: 0.475,
            dt: dt(&vp),
            static_wheel_z,
        }
    }

    #[test]
    fn state_vector_round_trip_continues_identically() {
        let p = table_4_4_unit(|_| 0.0, [-1e-3, -1.1e-3]);
        let mut a = VehicleUnit::new(&p).unwrap();
        a.set_forces([150e3, 90e3]).unwrap();
        a.advance(3.3e-3, 0.0).unwrap();
        let mut b = VehicleUnit::new(&p).unwrap();
        b.set_state_vector(&a.state_vector()).unwrap();
        a.advance(1e-3, 0.0).unwrap();
        b.advance(1e-3, 0.0).unwrap();
        assert_eq!(a.state_vector(), b.state_vector());
    }

    #[test]
    fn vehicle_default_step_resolves_its_fastest_mode() {
        let s = Scenario::table_4_4();
        let VehicleSpec::RollPlane(vp) = s.vehicle else {
            unreachable!()
        };
        let w = vp.natural_frequencies();
        // Free wheelset (rigid-body) modes are zero; the fastest is a wheelset mode on
        // the primary springs: omega^2 = 2 k1 / m_w bounds it from below.
        assert!(w[0].abs() < 1e-6 * w[5]);
        assert!(w[5] >= (2.0 * vp.primary_stiffness / vp.wheelset_mass).sqrt() * 0.999);
        let dt = vp.default_dt();
        assert!((dt * w[5] - std::f64::consts::TAU / 50.0).abs() < 1e-12);
        assert!(dt < vp.critical_time_step());
    }

    #[test]
    fn any_sequence_of_communication_steps_stays_stable_and_close_to_fixed_steps() {
        // solver.dt at its largest allowed value, half the critical step, and 1e5
        // communication steps cycling through sizes that force a change of the step
        // at almost every call. The wheels rest on linear springs fed back by the
        // master (a stand-in track) and get a 10 ms push of half the static load.
        let p = table_4_4_unit(|vp| 0.5 * vp.critical_time_step(), [-1.4e-3, -1.4e-3]);
        let w = p.vehicle.static_wheel_load();
        let forces = |u: &VehicleUnit, t: f64| {
            let (z, k) = (u.wheel_z(), 2e7);
            let push = if t < 0.01 { 0.5 * w } else { 0.0 };
            [w - k * (z[0] + 1.4e-3) + push, w - k * (z[1] + 1.4e-3)]
        };
        let mut var = VehicleUnit::new(&p).unwrap();
        let mut fixed = VehicleUnit::new(&p).unwrap();
        let dt = var.dt_base();
        // Seven sizes adding up to four steps: every seven calls both runs are at the
        // same time and are compared there.
        let sizes = [0.5, 1.0, 0.23, 0.77, 0.5, 0.1, 0.9];
        let (mut t, mut tf) = (0.0, 0.0);
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for k in 0..7 * 14_286 {
            let h = sizes[k % sizes.len()] * dt;
            var.set_forces(forces(&var, t)).unwrap();
            var.advance(h, 0.0).unwrap();
            t += h;
            if k % sizes.len() == sizes.len() - 1 {
                for _ in 0..4 {
                    fixed.set_forces(forces(&fixed, tf)).unwrap();
                    fixed.advance(dt, 0.0).unwrap();
                    tf += dt;
                }
                let (a, b) = (var.wheel_z()[0] + 1.4e-3, fixed.wheel_z()[0] + 1.4e-3);
                worst = worst.max((a - b).abs());
                largest = largest.max(b.abs());
            }
        }
        assert!((t - tf).abs() < 1e-9 * t, "{t} {tf}");
        // 1e5 steps of on average 0.57 dt: 220 s. Bounded (advance checks the health
        // bounds), and the left wheel's excursion from rest differs from the
        // fixed-step run's by the first-order error of the step changes.
        assert!(t > 200.0, "{t}");
        assert!(
            largest > 1e-3 && worst < 0.1 * largest,
            "{worst} of {largest}"
        );
        println!("largest excursion {largest:e} m, largest difference {worst:e} m");
    }
}
