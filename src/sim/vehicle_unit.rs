//! The roll-plane vehicle as a co-simulation unit: driven by contact forces from
//! outside, it reports wheel displacements and the axle angle. Its partner, the track
//! with the contact, is a [`crate::sim::Simulation`] with
//! [`crate::sim::VehicleSpec::External`] wheels.
//!
//! Coupled with a communication step equal to the track's step, in the order of
//! `docs/MODEL.md` (vehicle outputs -> track inputs -> track outputs -> vehicle inputs ->
//! both step), the pair performs exactly the arithmetic of the monolithic
//! [`crate::sim::Simulation`].
//!
//! Its stepping is in `unit_step.rs`, its health checks and state vector in
//! `unit_state.rs`.

use super::accelerations::Accelerations;
use super::clock::{Clock, ForceExtremes, Stepping};
use crate::error::{Error, Result, finite, non_negative, num, out_of_range};
use crate::limits::{MIN_DT_FRACTION, check};
use crate::vehicle::{
    Axles, Bodies, CONTACT_STIFFNESS, CarrierSpec, ExchangeLimits, MAX_AXLES, RailVehicle,
    SprungVehicle,
};

/// Parameters of a [`VehicleUnit`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleUnitParams {
    /// The vehicle, any kind of the registry ([`crate::vehicle::VEHICLE_KINDS`]): the
    /// roll-plane vehicle on one wheelset, the half-car bogie, the wagons.
    pub model: CarrierSpec,
    /// Forward speed `V` (m/s): turns the axle at `V / R_w`.
    pub speed: f64,
    /// Nominal wheel radius `R_w` (m).
    pub wheel_radius: f64,
    /// Base step (s); 0 takes the vehicle's [`crate::vehicle::CarrierModel::default_dt`].
    pub dt: f64,
    /// Wheel-centre displacements `[left, right]` (m) of the static equilibrium, as the
    /// track computed them: the vehicle starts at rest on them.
    pub static_wheel_z: [f64; 2],
    /// The axle-box interface: the unit is the vehicle above its primary suspension
    /// ([`crate::vehicle::CarrierModel::sprung`]), the primary forces come in
    /// (held over each communication step) and the side frames' motion goes out; its
    /// partner carries the wheelset and the primary suspension
    /// ([`crate::sim::VehicleSpec::AxleBox`]). `false`: the whole vehicle with the
    /// contact forces in.
    pub axle_box: bool,
    /// The static wheel-centre displacements `[left, right]` (m) of the wheelsets
    /// behind the leading one, for a vehicle on several wheelsets.
    pub trailing_static_wheel_z: [[f64; 2]; MAX_AXLES - 1],
}

impl VehicleUnitParams {
    /// The static wheel-centre displacements of every wheelset (m), the leading one
    /// first.
    pub fn static_wheels(&self) -> Axles {
        let t = &self.trailing_static_wheel_z;
        [self.static_wheel_z, t[0], t[1], t[2]]
    }
}

/// What a [`VehicleUnit`] steps: the whole vehicle under the contact forces of its
/// wheels, or the vehicle above its primary suspension under the primary forces at its
/// axle boxes (its partner carries the wheelsets).
#[derive(Debug, Clone)]
pub(super) enum Body {
    /// The whole vehicle, the contact forces in.
    Whole(Box<dyn RailVehicle>),
    /// The vehicle above its primary suspension, the primary forces in.
    Sprung(Box<dyn SprungVehicle>),
}

/// A vehicle as a co-simulation unit: the six-DOF roll-plane vehicle (3.1-3.3,
/// 3.24-3.27), the half-car bogie ([`crate::vehicle::HalfCarBogie`], two wheelsets) or the wagon
/// ([`crate::vehicle::Wagon`], four). The contact
/// forces `[left, right]` (N) of each wheelset come in and are held over each
/// communication step (with the axle-box interface, the primary forces); the
/// wheel-centre displacements (m), the axle angle (rad) and the bodies' motion go out.
/// It follows the master's clock in equal substeps of at most its base step
/// ([`VehicleUnit::plan_to`], [`VehicleUnit::advance`]).
#[derive(Debug, Clone)]
pub struct VehicleUnit {
    pub(super) params: VehicleUnitParams,
    pub(super) body: Body,
    /// Equal substeps of at most the base step; steps shorter than
    /// [`crate::limits::MIN_STEP_FRACTION`] of it are carried over to the next call. Its step is the
    /// vehicle's.
    pub(super) clock: Clock,
    /// The held forces of each wheelset (N); those past the vehicle's wheelsets unused.
    pub(super) force: Axles,
    /// The forces that hold the vehicle at rest (N): contact forces, or primary forces
    /// with the axle-box interface.
    pub(super) rest: Axles,
    pub(super) extremes: [ForceExtremes; MAX_AXLES],
    /// The wheels' accelerations of each wheelset (the rail signals unused).
    pub(super) accelerations: [Accelerations; MAX_AXLES],
    /// The axle rotation (rad) at `since` (s), from which it turns at the speed held
    /// since ([`VehicleUnit::set_speed`]).
    pub(super) rotation_ref: f64,
    pub(super) since: f64,
    /// With the axle-box interface: the largest stable communication steps of the
    /// exchange, estimated at the start ([`ExchangeLimits`]).
    pub(super) exchange: Option<ExchangeLimits>,
}

impl VehicleUnit {
    /// Builds the vehicle at rest on the static wheel displacements, carrying the static
    /// wheel load on each wheel.
    ///
    /// Errors: a parameter outside its physical range ([`crate::Error::Parameter`], naming
    /// it); a step outside [`MIN_DT_FRACTION`] of the critical step of the fastest
    /// suspension mode up to half of it; a static state beyond the health bounds.
    pub fn new(p: &VehicleUnitParams) -> Result<Self> {
        check("speed", p.speed)?;
        check("wheel.radius", p.wheel_radius)?;
        non_negative("solver.dt", p.dt, "s")?;
        check("static_wheel_z.left", p.static_wheel_z[0])?;
        check("static_wheel_z.right", p.static_wheel_z[1])?;
        let c = p.model.model();
        c.validate()?;
        let n = c.wheelsets();
        for (z, k) in p.trailing_static_wheel_z.iter().take(n - 1).zip(2..) {
            check(&format!("wheelset[{k}].static_wheel_z.left"), z[0])?;
            check(&format!("wheelset[{k}].static_wheel_z.right"), z[1])?;
        }
        let (critical, default_dt) = (c.critical_time_step(), c.default_dt());
        let dt = if p.dt == 0.0 { default_dt } else { p.dt };
        if !(dt >= MIN_DT_FRACTION * critical && dt <= 0.5 * critical) {
            return Err(out_of_range(
                "solver.dt",
                dt,
                format!(
                    "0 (the default, {} s) or {} s <= solver.dt <= {} s (half the critical step \
                     {} s of the fastest suspension mode: the step changes that communication \
                     steps force stay stable below it)",
                    num(default_dt),
                    num(MIN_DT_FRACTION * critical),
                    num(0.5 * critical),
                    num(critical)
                ),
            ));
        }
        let wheels = p.static_wheels();
        // At rest on the static wheels: the forces that hold it there.
        let (body, force) = if p.axle_box {
            let mut b = c.sprung(dt)?;
            let force = b.set_static(&wheels)?;
            (Body::Sprung(b), force)
        } else {
            let mut b = c.whole(dt)?;
            let force = b.set_static(&wheels)?;
            (Body::Whole(b), force)
        };
        let mut unit = VehicleUnit {
            params: *p,
            body,
            clock: Clock::new(dt, Stepping::Substeps),
            force,
            rest: force,
            extremes: force.map(ForceExtremes::at),
            accelerations: [Accelerations::NONE; MAX_AXLES],
            rotation_ref: 0.0,
            since: 0.0,
            exchange: None,
        };
        unit.exchange = match &unit.body {
            Body::Sprung(b) => Some(b.exchange_limits(&wheels, dt, CONTACT_STIFFNESS)?),
            Body::Whole(_) => None,
        };
        // At rest beyond the health bounds: the suspension does not carry the vehicle
        // (not the forces, which are the static ones here).
        match unit.check_states() {
            Err(Error::Diverged {
                what, value, limit, ..
            }) => {
                let stiffnesses = c
                    .stiffnesses()
                    .iter()
                    .map(|(name, k)| format!("{name} = {} N/m", num(*k)))
                    .collect::<Vec<_>>()
                    .join(", ");
                return Err(Error::Unsupported(format!(
                    "static equilibrium of the vehicle: at rest {what} = {} beyond {}, which no \
                     physical run reaches: the suspension is too soft to carry the vehicle \
                     ({stiffnesses}); stiffer springs carry it",
                    num(value),
                    num(limit),
                )));
            }
            other => other?,
        }
        Ok(unit)
    }

    /// Parameters.
    pub fn params(&self) -> &VehicleUnitParams {
        &self.params
    }
    /// Number of wheelsets: 1 for the roll-plane vehicle, 2 for the half-car bogie and
    /// the two-axle wagon, 4 for the four-axle wagon.
    pub fn wheelsets(&self) -> usize {
        self.params.model.model().wheelsets()
    }
    /// Static load on each wheel `[left, right]` (N).
    pub fn static_load(&self) -> [f64; 2] {
        [self.params.model.model().static_wheel_load(); 2]
    }
    /// Base step (s).
    pub fn dt_base(&self) -> f64 {
        self.clock.base
    }
    /// The substep in use (s).
    pub fn dt(&self) -> f64 {
        self.clock.dt
    }
    /// Critical step of the vehicle's explicit scheme (s).
    pub fn critical_step(&self) -> f64 {
        match &self.body {
            Body::Whole(b) => b.critical_time_step(),
            Body::Sprung(b) => b.critical_time_step(),
        }
    }
    /// Time (s).
    pub fn time(&self) -> f64 {
        self.clock.time()
    }
    /// Communication time carried over to the next call, not yet stepped (s).
    pub fn carried(&self) -> f64 {
        self.clock.carried
    }
    /// Axle rotation angle (rad) (2.17): `V t / R_w` at a constant speed, and in
    /// general the rotation at the last change of speed plus `V (t - t_change) / R_w`.
    pub fn rotation(&self) -> f64 {
        self.rotation_ref
            + self.params.speed * (self.time() - self.since) / self.params.wheel_radius
    }

    /// Forward speed `V` (m/s).
    pub fn speed(&self) -> f64 {
        self.params.speed
    }

    /// Sets the forward speed `V` (m/s), held from now on: the axle turns on from the
    /// rotation reached at `V / R_w`, as the track's motion does
    /// ([`crate::sim::Simulation::set_speed`]).
    ///
    /// Errors: `V` outside its physical range ([`crate::limits::check`]); nothing
    /// changes then.
    pub fn set_speed(&mut self, v: f64) -> Result<()> {
        check("speed", v)?;
        if v != self.params.speed {
            self.rotation_ref = self.rotation();
            self.since = self.time();
            self.params.speed = v;
        }
        Ok(())
    }
    /// Wheel-centre displacements `[left, right]` (m) of the leading wheelset.
    pub fn wheel_z(&self) -> [f64; 2] {
        self.wheel_z_of(0).unwrap_or([0.0; 2])
    }
    /// Wheel-centre displacements `[left, right]` (m) of wheelset `k` (0 the leading
    /// one); the static ones with the axle-box interface (the partner carries the
    /// wheelsets); `None` for a wheelset the vehicle does not have.
    pub fn wheel_z_of(&self, k: usize) -> Option<[f64; 2]> {
        if k >= self.wheelsets() {
            return None;
        }
        Some(match &self.body {
            Body::Whole(b) => b.wheel_z()[k],
            Body::Sprung(_) => self.params.static_wheels()[k],
        })
    }
    /// Wheel-centre velocities `[left, right]` (m/s) of wheelset `k`, backward
    /// differences over the last step (first order in the step); 0 with the axle-box
    /// interface (the partner carries the wheelsets); `None` for a wheelset the
    /// vehicle does not have.
    pub fn wheel_velocity_of(&self, k: usize) -> Option<[f64; 2]> {
        if k >= self.wheelsets() {
            return None;
        }
        Some(match &self.body {
            Body::Whole(b) => b.wheel_velocities()[k],
            Body::Sprung(_) => [0.0; 2],
        })
    }
    /// The bodies' motion (m, rad); with the axle-box interface the wheelsets' are
    /// their static ones (the partner carries them).
    pub fn bodies(&self) -> Bodies {
        match &self.body {
            Body::Whole(b) => b.bodies(),
            Body::Sprung(b) => b.bodies(),
        }
    }
    /// Primary suspension (bearing) forces `[left, right]` (N) of the leading
    /// wheelset, pressing it down; with the axle-box interface the held inputs.
    pub fn bearing_forces(&self) -> [f64; 2] {
        self.bearing_forces_of(0).unwrap_or([0.0; 2])
    }
    /// [`VehicleUnit::bearing_forces`] of wheelset `k`; `None` for a wheelset the
    /// vehicle does not have.
    pub fn bearing_forces_of(&self, k: usize) -> Option<[f64; 2]> {
        if k >= self.wheelsets() {
            return None;
        }
        Some(match &self.body {
            Body::Whole(b) => b.bearing_forces()[k],
            Body::Sprung(_) => self.force[k],
        })
    }
    /// The side frames' displacements and velocities `[left, right]` (m, m/s) at the
    /// current time above the leading wheelset's axle boxes, the velocities backward
    /// differences over the last step.
    pub fn side_frames(&self) -> ([f64; 2], [f64; 2]) {
        self.side_frames_of(0).unwrap_or(([0.0; 2], [0.0; 2]))
    }
    /// [`VehicleUnit::side_frames`] above wheelset `k`'s axle boxes (the half-car's
    /// side frames pitch); `None` for a wheelset the vehicle does not have.
    pub fn side_frames_of(&self, k: usize) -> Option<([f64; 2], [f64; 2])> {
        if k >= self.wheelsets() {
            return None;
        }
        let (z, v) = match &self.body {
            Body::Whole(b) => b.side_frames(),
            Body::Sprung(b) => b.side_frames(),
        };
        Some((z[k], v[k]))
    }
    /// With the axle-box interface, the largest communication steps (s) at which the
    /// explicit exchange of the primary forces stays stable under a sequential and a
    /// Jacobi master, estimated from the spectral radius of the exchange's
    /// amplification matrix with every term that crosses the cut, springs and dampers
    /// ([`SprungVehicle::exchange_limits`]; measured on the track within
    /// 0.7 to 1 times the measured limits, `examples/axle_box_masters.rs`). `None`
    /// without the axle-box interface.
    pub fn exchange_limits(&self) -> Option<ExchangeLimits> {
        self.exchange
    }

    /// Whether the unit is the vehicle above its primary suspension.
    pub fn is_axle_box(&self) -> bool {
        matches!(self.body, Body::Sprung(_))
    }
    /// The forces `[left, right]` (N) of wheelset `k` that hold the vehicle at rest
    /// (contact, or primary with the axle-box interface); `None` for a wheelset the
    /// vehicle does not have.
    pub fn rest_forces_of(&self, k: usize) -> Option<[f64; 2]> {
        (k < self.wheelsets()).then(|| self.rest[k])
    }

    /// The held forces `[left, right]` (N) of wheelset `k` (contact, or primary with the
    /// axle-box interface); `None` for a wheelset the vehicle does not have.
    pub fn held_forces_of(&self, k: usize) -> Option<[f64; 2]> {
        (k < self.wheelsets()).then(|| self.force[k])
    }
    /// The held contact forces `[left, right]` (N) of the leading wheelset; with the
    /// axle-box interface the held primary forces.
    pub fn forces(&self) -> [f64; 2] {
        self.force[0]
    }
    /// The vertical accelerations of wheelset `k`'s wheels `[left, right]` (m/s^2)
    /// now, with their largest and smallest of the steps taken: the second difference
    /// of the wheel heights at the unit's steps ([`Accelerations`]); zeros with the
    /// axle-box interface (the partner carries the wheelsets).
    pub fn wheel_accelerations(&self, k: usize) -> [[f64; 2]; 3] {
        let Some(z) = self.wheel_z_of(k) else {
            return [[0.0; 2]; 3];
        };
        let a = &self.accelerations[k.min(MAX_AXLES - 1)];
        let now = a.now([z[0], z[1], 0.0, 0.0]);
        [now, a.max(now), a.min(now)].map(|x| [x[0], x[1]])
    }

    /// Largest contact force per wheel of wheelset `k` that has driven a step (N); the
    /// static load before the first step.
    pub fn max_force_of(&self, k: usize) -> [f64; 2] {
        self.extremes[k.min(MAX_AXLES - 1)].max
    }
    /// Smallest contact force per wheel of wheelset `k` that has driven a step (N).
    pub fn min_force_of(&self, k: usize) -> [f64; 2] {
        self.extremes[k.min(MAX_AXLES - 1)].min
    }
    /// Largest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn max_force(&self) -> [f64; 2] {
        self.max_force_of(0)
    }
    /// Smallest contact force per wheel that has driven a step (N); the static load
    /// before the first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.min_force_of(0)
    }

    /// Sets the contact forces `[left, right]` (N) of the leading wheelset, held over
    /// the next communication step. Errors as [`VehicleUnit::set_forces_of`].
    pub fn set_forces(&mut self, p: [f64; 2]) -> Result<()> {
        self.set_forces_of(0, p)
    }

    /// Sets the contact forces `[left, right]` (N) of wheelset `k` (with the axle-box
    /// interface the primary forces), held over the next communication step. Forces no
    /// physical run reaches are refused by the step that would use them
    /// ([`VehicleUnit::advance`]).
    ///
    /// Errors: a wheelset the vehicle does not have; a force not finite; nothing is set
    /// then.
    pub fn set_forces_of(&mut self, k: usize, p: [f64; 2]) -> Result<()> {
        if k >= self.wheelsets() {
            return Err(out_of_range(
                "wheelset",
                k as f64 + 1.0,
                format!("1 to {}", self.wheelsets()),
            ));
        }
        for (side, x) in [("left", p[0]), ("right", p[1])] {
            finite(&self.force_name(k, side), x, "N")?;
        }
        self.force[k] = p;
        Ok(())
    }
}
