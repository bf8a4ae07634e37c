//! The coupled vehicle-track-contact solver.
//!
//! One step, in the order of `MODEL.md`: at `t_j` the wheel displacements and the axle
//! angle give the rail displacement under each wheel, then the contact forces `P_j`;
//! vehicle and track are then advanced to `t_(j+1)` with `P_j`. The run starts from
//! the static equilibrium of the whole system, solved directly.

use crate::contact::{ContactLaw, ContactModel, ContactState, kw_from_hertz};
use crate::error::{Error, Result, finite, non_negative, num, out_of_range, positive};
use crate::limits::{
    DISPLACEMENT_LIMIT, HEALTH_CHECK_INTERVAL, MAX_STATIC_OVERLAP, MAX_STATIC_RAIL_DEFLECTION,
    MIN_DT_FRACTION, force_limit, within,
};
use crate::profile::WheelProfile;
use crate::sim::{DEFAULT_DT_FRACTION, Scenario, TrackSpec, VehicleSpec};
use crate::track::{PointLoad, SimdLevel, Track};
use crate::vehicle::{LumpedTrack, LumpedWheels, RollPlaneVehicle};
use std::cell::Cell;

/// Track state of a simulation.
// Not boxed: the variant is touched every step and there is one per simulation.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum TrackState {
    /// Discrete Timoshenko track.
    Discrete(Track),
    /// Chapter-2 lumped track.
    Lumped(LumpedTrack),
}

/// Vehicle state of a simulation.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum VehicleState {
    /// Six-DOF roll-plane vehicle.
    RollPlane(RollPlaneVehicle),
    /// Chapter-2 lumped wheels.
    LumpedWheels(LumpedWheels),
    /// Constant loads (N), no contact.
    ConstantLoad([f64; 2]),
    /// Wheels moved from outside.
    External {
        /// Wheel-centre displacements `[left, right]` (m), inputs.
        wheel_z: [f64; 2],
        /// Axle rotation angle (rad) given at `since`.
        rotation: f64,
        /// Time (s) at which `rotation` was given; between inputs the axle turns at
        /// `V / R_w`.
        since: f64,
    },
}

/// Everything reported at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Time `t_j` (s).
    pub time: f64,
    /// Wheel position along the track (m).
    pub position: f64,
    /// Axle rotation angle `gamma` (rad).
    pub rotation: f64,
    /// Wheel-centre displacements `[left, right]` (m).
    pub wheel_z: [f64; 2],
    /// Rail displacements under the wheels (m).
    pub rail_z: [f64; 2],
    /// Contact states (force, overlap, patch angles, length).
    pub contact: [ContactState; 2],
}

/// A running coupled simulation.
#[derive(Debug, Clone)]
pub struct Simulation {
    scenario: Scenario,
    track: TrackState,
    vehicle: VehicleState,
    wheels: [WheelProfile; 2],
    law: ContactLaw,
    dt: f64,
    /// Time at which the current step size began (s).
    t0: f64,
    /// Steps taken since `t0`.
    k: u64,
    steps: u64,
    static_load: [f64; 2],
    /// Critical step of the explicit scheme (s), the contact's stiffness included; NaN
    /// for the lumped track.
    critical_step: f64,
    /// Largest contact force a physical run reaches (N) ([`crate::limits::force_limit`]).
    force_limit: f64,
    max_force: [f64; 2],
    min_force: [f64; 2],
    /// The sample at the current time and inputs, once computed (a co-simulation
    /// master reads the outputs and then steps: the contact is evaluated once).
    cached: Cell<Option<Sample>>,
    /// The sample of the latest step, built here in place by [`Simulation::step`].
    latest: Sample,
    /// Instructions the whole coupled step is compiled for (see [`Simulation::step`]).
    simd: SimdLevel,
}

/// The two wheel loads `p` (N) at position `x` (m), left and right rail.
fn wheel_loads(x: f64, p: [f64; 2]) -> [PointLoad; 2] {
    [
        PointLoad {
            rail: 0,
            position: x,
            force: p[0],
        },
        PointLoad {
            rail: 1,
            position: x,
            force: p[1],
        },
    ]
}

/// The contact states of sample `s`, whose head (time, rotation, wheel and rail
/// displacements) is set, written in place.
#[inline(always)]
fn contact_states(
    vehicle: &VehicleState,
    law: &ContactLaw,
    wheels: &[WheelProfile; 2],
    s: &mut Sample,
) {
    match vehicle {
        VehicleState::ConstantLoad(p) => {
            for (c, &force) in s.contact.iter_mut().zip(p) {
                *c = ContactState {
                    force,
                    intervals: 1,
                    ..Default::default()
                };
            }
        }
        _ => {
            let gamma = wrap_turns(s.rotation);
            for i in 0..2 {
                let overlap = s.rail_z[i] - s.wheel_z[i];
                law.evaluate_into(&wheels[i], gamma, overlap, &mut s.contact[i]);
            }
        }
    }
}

/// Angle `a` (rad) wrapped into [0, 2 pi).
///
/// The whole number of turns is taken off by truncation rather than `rem_euclid`
/// (a libm `fmod` call): the result differs by a rounding of the turns removed,
/// which is below the rounding already in the unwrapped angle.
#[inline]
fn wrap_turns(a: f64) -> f64 {
    use std::f64::consts::TAU;
    if !a.is_finite() || a.abs() > 1e15 {
        return a.rem_euclid(TAU);
    }
    let r = a - (a * (1.0 / TAU)) as i64 as f64 * TAU;
    if r < 0.0 { r + TAU } else { r }
}

/// Runs `f` compiled for `level`, AVX2 at most (see [`SimdLevel::run`]): the coupled
/// step outside the track loops, which have their own AVX-512 copy, is compiled as for
/// AVX2 (1,096 instructions baseline, 870 AVX2). Nothing in it is contracted into FMA
/// (the track loops it calls are, at AVX2 and AVX-512: see [`SimdLevel`]).
#[inline(always)]
fn at_level<R>(level: SimdLevel, f: impl FnOnce() -> R) -> R {
    level.min(SimdLevel::Avx2).run(f)
}

/// The contact stiffness passed to the track's stability limit is this many times the
/// perfect wheel's `dP / d delta` at the force limit: a flat in the patch raises it by at
/// most 2.03 times at equal force, and by 1.46 times at the force limit
/// (`examples/stability_limit.rs`).
pub const CONTACT_STIFFNESS_MARGIN: f64 = 2.0;

/// Time step used when the scenario asks for the default (`dt = 0`) (s), without the
/// contact's stiffness ([`Simulation::new`] takes it into account; the two agree for
/// every physical contact: see `docs/VALIDATION.md`).
pub fn default_dt(scenario: &Scenario) -> f64 {
    match &scenario.track {
        TrackSpec::Discrete(t) => DEFAULT_DT_FRACTION * t.critical_time_step().0,
        TrackSpec::Lumped(_) => 1e-6,
    }
}

impl Simulation {
    /// Builds the models, checks every parameter and puts the system in static
    /// equilibrium at the start position.
    pub fn new(scenario: &Scenario) -> Result<Self> {
        let s = scenario;
        positive("wheel.radius", s.wheel_radius, "m")?;
        finite("speed", s.speed, "m/s")?;
        if s.speed < 0.0 {
            return Err(out_of_range("speed", s.speed, ">= 0 m/s"));
        }
        finite("start_position", s.start_position, "m")?;
        non_negative("solver.dt", s.dt, "s")?;
        non_negative("contact.Kw", s.kw, "N/m/rad")?;
        non_negative("contact.CH", s.hertz_coefficient, "N/m^1.5")?;
        // The contact law first: its stiffness under the largest force a run reaches
        // enters the stability limit of the track.
        let static_load = match &s.vehicle {
            VehicleSpec::RollPlane(p) => [p.static_wheel_load(); 2],
            VehicleSpec::LumpedWheels(p) => [p.load; 2],
            VehicleSpec::ConstantLoad(p) => {
                non_negative("load.left", p[0], "N")?;
                non_negative("load.right", p[1], "N")?;
                *p
            }
            VehicleSpec::External { static_load } => {
                non_negative("static_load.left", static_load[0], "N")?;
                non_negative("static_load.right", static_load[1], "N")?;
                *static_load
            }
        };
        let law = match s.contact_model {
            ContactModel::Adaptive => {
                let kw = if s.kw > 0.0 {
                    s.kw
                } else {
                    kw_from_hertz(s.hertz_coefficient, static_load[0].max(1.0), s.wheel_radius)?
                };
                ContactLaw::adaptive(kw)?
            }
            ContactModel::Hertz => ContactLaw::hertz(s.hertz_coefficient)?,
        };
        // A contact so soft that the static load sinks the wheel far into the rail is not
        // a wheel on a rail.
        let load = static_load[0].max(static_load[1]);
        let perfect = WheelProfile::perfect(s.wheel_radius)?;
        let overlap = law.overlap_for_force(&perfect, 0.0, load);
        if load > 0.0 && !within(overlap, MAX_STATIC_OVERLAP) {
            let (name, value) = match (s.contact_model, s.kw > 0.0) {
                (ContactModel::Adaptive, true) => ("contact.Kw", s.kw),
                _ => ("contact.CH", s.hertz_coefficient),
            };
            return Err(out_of_range(
                name,
                value,
                format!(
                    "a contact that carries the static wheel load {} N with an overlap of at \
                     most {MAX_STATIC_OVERLAP} m (this one: {} m; wheel on rail: about 0.1 mm)",
                    num(load),
                    num(overlap)
                ),
            ));
        }
        let critical = match &s.track {
            TrackSpec::Discrete(p) => {
                p.validate()?;
                let kc = law.stiffness(&perfect, 0.0, force_limit(static_load));
                Some(p.critical_time_step_with_contact(CONTACT_STIFFNESS_MARGIN * kc))
            }
            TrackSpec::Lumped(_) => None,
        };
        let dt = match (s.dt, &critical) {
            (0.0, Some((c, _))) => DEFAULT_DT_FRACTION * c,
            (0.0, None) => default_dt(s),
            (dt, _) => dt,
        };
        if let Some((c, limit)) = &critical {
            if dt > *c {
                return Err(Error::UnstableTimeStep {
                    dt,
                    critical: *c,
                    limit: limit.clone(),
                });
            }
            if dt < MIN_DT_FRACTION * c {
                return Err(out_of_range(
                    "solver.dt",
                    dt,
                    format!(
                        "0 (the default, {} s) or {} s <= solver.dt <= {} s (the critical step; \
                         a step below {MIN_DT_FRACTION} of it resolves nothing more)",
                        num(DEFAULT_DT_FRACTION * c),
                        num(MIN_DT_FRACTION * c),
                        num(*c)
                    ),
                ));
            }
        }
        let wheels = [
            WheelProfile::new(s.wheel_radius, &s.flats[0], "flat.left")?,
            WheelProfile::new(s.wheel_radius, &s.flats[1], "flat.right")?,
        ];
        let track = match &s.track {
            TrackSpec::Discrete(p) => {
                p.validate()?;
                let len = p.length();
                if !(s.start_position > 0.0 && s.start_position < len) {
                    return Err(out_of_range(
                        "start_position",
                        s.start_position,
                        format!("inside the track, 0 < x < {len} m"),
                    ));
                }
                TrackState::Discrete(Track::new(*p, dt)?)
            }
            TrackSpec::Lumped(p) => TrackState::Lumped(LumpedTrack::new(*p, dt)?),
        };
        let vehicle = match &s.vehicle {
            VehicleSpec::RollPlane(p) => VehicleState::RollPlane(RollPlaneVehicle::new(*p, dt)?),
            VehicleSpec::LumpedWheels(p) => VehicleState::LumpedWheels(LumpedWheels::new(*p, dt)?),
            VehicleSpec::ConstantLoad(p) => VehicleState::ConstantLoad(*p),
            VehicleSpec::External { .. } => VehicleState::External {
                wheel_z: [0.0; 2],
                rotation: 0.0,
                since: 0.0,
            },
        };
        let mut sim = Simulation {
            scenario: s.clone(),
            track,
            vehicle,
            wheels,
            law,
            dt,
            t0: 0.0,
            k: 0,
            steps: 0,
            static_load,
            critical_step: critical.map_or(f64::NAN, |c| c.0),
            force_limit: force_limit(static_load),
            // The extremes of no force at all: finite, so that a state saved before the
            // first step serialises (f64::MIN and f64::MAX give way to any force).
            max_force: [f64::MIN; 2],
            min_force: [f64::MAX; 2],
            cached: Cell::new(None),
            latest: Sample::default(),
            simd: SimdLevel::detect(),
        };
        sim.set_static()?;
        if let (TrackSpec::Discrete(p), TrackState::Discrete(_)) = (&s.track, &sim.track) {
            let z = sim.rail_z();
            let sag = z[0].abs().max(z[1].abs());
            if !within(sag, MAX_STATIC_RAIL_DEFLECTION) {
                // Named: the support softest against table 4.4's (pads 140 MN/m, ballast
                // 40 MN/m); the message gives all that carry the load.
                let (name, value) = if p.ballast_stiffness / 40e6 < p.pad_stiffness / 140e6 {
                    ("track.ballast.stiffness", p.ballast_stiffness)
                } else {
                    ("track.pad.stiffness", p.pad_stiffness)
                };
                return Err(out_of_range(
                    name,
                    value,
                    format!(
                        "a track that carries the static wheel load {} N with a rail deflection \
                         of at most {MAX_STATIC_RAIL_DEFLECTION} m (this one: {} m with \
                         track.pad.stiffness = {} N/m, track.ballast.stiffness = {} N/m, \
                         track.rail.EI = {} N m^2, track.rail.kAG = {} N, track.sleeper_spacing \
                         = {} m; table 4.4: 1.3 mm)",
                        num(load),
                        num(sag),
                        num(p.pad_stiffness),
                        num(p.ballast_stiffness),
                        num(p.rail.ei),
                        num(p.rail.kag),
                        num(p.sleeper_spacing)
                    ),
                ));
            }
        }
        sim.check_states()?;
        Ok(sim)
    }

    /// Static equilibrium of the whole system at the start position: static wheel
    /// loads from the vehicle, track deflection under them (direct solve), overlaps
    /// from the inverse contact law, then the vehicle resting on those wheel heights.
    fn set_static(&mut self) -> Result<()> {
        self.cached.set(None);
        let x = self.scenario.start_position;
        let p = self.static_load;
        let zr = match &mut self.track {
            TrackState::Discrete(t) => {
                t.set_static(&wheel_loads(x, p))?;
                [t.rail_z_at(0, x), t.rail_z_at(1, x)]
            }
            TrackState::Lumped(t) => {
                t.set_static(p);
                t.rail_z()
            }
        };
        let delta = [
            self.law.overlap_for_force(&self.wheels[0], 0.0, p[0]),
            self.law.overlap_for_force(&self.wheels[1], 0.0, p[1]),
        ];
        let zw = [zr[0] - delta[0], zr[1] - delta[1]];
        match &mut self.vehicle {
            VehicleState::RollPlane(v) => v.set_static(zw)?,
            VehicleState::LumpedWheels(v) => v.set_static(zw),
            VehicleState::ConstantLoad(_) => {}
            VehicleState::External { wheel_z, .. } => *wheel_z = zw,
        }
        Ok(())
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Current time `t_j` (s).
    pub fn time(&self) -> f64 {
        self.t0 + self.k as f64 * self.dt
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// Wheel position at the current time (m).
    pub fn position(&self) -> f64 {
        self.scenario.start_position + self.scenario.speed * self.time()
    }
    /// Axle rotation angle at the current time (rad) (2.17).
    pub fn rotation(&self) -> f64 {
        match &self.vehicle {
            VehicleState::External {
                rotation, since, ..
            } => {
                *rotation + self.scenario.speed * (self.time() - since) / self.scenario.wheel_radius
            }
            _ => self.scenario.speed * self.time() / self.scenario.wheel_radius,
        }
    }

    /// Rail nodes of the discrete track, both rails (the work of one track step scales
    /// with it); 2 for the lumped track.
    pub fn rail_nodes(&self) -> usize {
        match &self.track {
            TrackState::Discrete(t) => 2 * t.nodes(),
            TrackState::Lumped(_) => 2,
        }
    }

    /// Time (s) at which the wheel reaches the end of the discrete track, from the start;
    /// `None` for the lumped track or at speed 0.
    pub fn time_at_track_end(&self) -> Option<f64> {
        let s = &self.scenario;
        match &self.track {
            TrackState::Discrete(t) if s.speed > 0.0 => {
                Some((t.params().length() - s.start_position) / s.speed)
            }
            _ => None,
        }
    }

    /// Critical step of the explicit scheme (s), with the contact stiffness under the
    /// largest force a run reaches ([`crate::track::TrackParams::critical_time_step_with_contact`]);
    /// NaN for the lumped track.
    pub fn critical_step(&self) -> f64 {
        self.critical_step
    }

    /// Static wheel loads (N).
    pub fn static_load(&self) -> [f64; 2] {
        self.static_load
    }
    /// The contact law in use (with the calibrated `K_w`).
    pub fn contact_law(&self) -> &ContactLaw {
        &self.law
    }
    /// Largest contact force per wheel since the start (N); `f64::MIN` before the first
    /// step.
    pub fn max_force(&self) -> [f64; 2] {
        self.max_force
    }
    /// Smallest contact force per wheel since the start (N); `f64::MAX` before the
    /// first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.min_force
    }
    /// Track state.
    pub fn track(&self) -> &TrackState {
        &self.track
    }
    /// Vehicle state.
    pub fn vehicle(&self) -> &VehicleState {
        &self.vehicle
    }
    /// The scenario.
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// Wheel-centre displacements (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        match &self.vehicle {
            VehicleState::RollPlane(v) => v.wheel_z(),
            VehicleState::LumpedWheels(v) => v.wheel_z(),
            VehicleState::ConstantLoad(_) => self.rail_z(),
            VehicleState::External { wheel_z, .. } => *wheel_z,
        }
    }

    /// Sets the wheel inputs of a simulation with [`VehicleSpec::External`] wheels:
    /// wheel-centre displacements `[left, right]` (m) and the axle rotation angle (rad)
    /// at the current time ([`Simulation::set_wheel_z`], [`Simulation::set_rotation`]).
    pub fn set_wheel_inputs(&mut self, z: [f64; 2], gamma: f64) -> Result<()> {
        self.set_wheel_z(z)?;
        self.set_rotation(gamma)
    }

    /// Sets the wheel-centre displacements `[left, right]` (m) of a simulation with
    /// [`VehicleSpec::External`] wheels. The axle rotation is not touched: it keeps
    /// turning at `V / R_w` from the last angle given to [`Simulation::set_rotation`].
    /// Refused for any other vehicle, and outside `|z| <=`
    /// [`crate::limits::DISPLACEMENT_LIMIT`].
    pub fn set_wheel_z(&mut self, z: [f64; 2]) -> Result<()> {
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
        match &mut self.vehicle {
            VehicleState::External { wheel_z, .. } => {
                *wheel_z = z;
                self.cached.set(None);
                Ok(())
            }
            _ => Err(Self::not_external()),
        }
    }

    /// Sets the axle rotation angle `gamma` (rad) at the current time of a simulation
    /// with [`VehicleSpec::External`] wheels; from now on the axle turns at `V / R_w`
    /// from it (2.17). Refused for any other vehicle and for a non-finite angle.
    pub fn set_rotation(&mut self, gamma: f64) -> Result<()> {
        finite("wheel.rotation", gamma, "rad")?;
        let now = self.time();
        match &mut self.vehicle {
            VehicleState::External {
                rotation, since, ..
            } => {
                *rotation = gamma;
                *since = now;
                self.cached.set(None);
                Ok(())
            }
            _ => Err(Self::not_external()),
        }
    }

    fn not_external() -> Error {
        Error::Unsupported("wheel inputs for a simulation that has its own vehicle".into())
    }

    /// Rail displacements under the wheels (m) (3.23).
    pub fn rail_z(&self) -> [f64; 2] {
        self.rail_z_under(self.position())
    }

    /// Rail displacements (m) under wheels at position `x` (m).
    #[inline(always)]
    fn rail_z_under(&self, x: f64) -> [f64; 2] {
        match &self.track {
            TrackState::Discrete(t) => t.rail_z_pair(x),
            TrackState::Lumped(t) => t.rail_z(),
        }
    }

    /// Everything at the current time, contact forces included.
    pub fn sample(&self) -> Sample {
        if let Some(s) = self.cached.get() {
            return s;
        }
        let s = self.compute_sample_dispatched();
        self.cached.set(Some(s));
        s
    }

    /// [`Simulation::compute_sample`] compiled for the SIMD level, as in
    /// [`Simulation::step`] (a co-simulation master reads the outputs before it steps,
    /// so this is where its contact forces are computed).
    fn compute_sample_dispatched(&self) -> Sample {
        at_level(
            self.simd,
            #[inline(always)]
            || self.compute_sample(),
        )
    }

    #[inline(always)]
    fn compute_sample(&self) -> Sample {
        let mut s = Sample::default();
        (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = self.sample_head();
        contact_states(&self.vehicle, &self.law, &self.wheels, &mut s);
        s
    }

    /// Everything of the sample at the current time but the contact states: time (s),
    /// position (m), axle rotation (rad), wheel and rail displacements (m).
    #[inline(always)]
    fn sample_head(&self) -> (f64, f64, f64, [f64; 2], [f64; 2]) {
        let time = self.time();
        let position = self.scenario.start_position + self.scenario.speed * time;
        let (rotation, wheel_z) = (self.rotation(), self.wheel_z());
        (
            time,
            position,
            rotation,
            wheel_z,
            self.rail_z_under(position),
        )
    }

    /// Instructions the coupled step runs with.
    pub fn simd(&self) -> SimdLevel {
        self.simd
    }

    /// Makes the coupled step (track loops included) use `level`; refused when this
    /// CPU lacks it. AVX2 and AVX-512 give bit-identical results; the baseline, which
    /// rounds the track loops' products separately, agrees with them to rounding.
    pub fn set_simd(&mut self, level: SimdLevel) -> Result<()> {
        if let TrackState::Discrete(t) = &mut self.track {
            t.set_simd(level)?;
        } else if level > SimdLevel::detect() {
            return Err(Error::Unsupported(format!(
                "simd = {level:?}: this CPU supports up to {:?}",
                SimdLevel::detect()
            )));
        }
        self.simd = level;
        Ok(())
    }

    /// Advances one step and returns the sample at `t_j` whose contact forces drove it.
    ///
    /// The whole step (sample, contact, vehicle, track) is compiled once per
    /// [`SimdLevel`] and dispatched here: with AVX2 the scalar code gets three-operand
    /// instructions and the vehicle's 6 x 6 products whole 4-lane vectors (an AVX-512
    /// CPU runs this copy too, with the track loops in their AVX-512 form). Only the
    /// track loops use FMA, the same way at AVX2 and AVX-512, so those two give the
    /// same results bit for bit (see [`SimdLevel`]).
    pub fn step(&mut self) -> Result<Sample> {
        at_level(
            self.simd,
            #[inline(always)]
            || self.step_body(),
        )
    }

    /// [`Simulation::step`], inlined into each level's copy.
    #[inline(always)]
    fn step_body(&mut self) -> Result<Sample> {
        let x = self.position();
        if let TrackState::Discrete(t) = &self.track {
            let len = t.params().length();
            if !(x > 0.0 && x < len) {
                return Err(Error::OffTrack {
                    position: x,
                    length: len,
                    time: self.time(),
                });
            }
        }
        // The cached sample, if the outputs were read at this instant, is used up here;
        // otherwise the sample is built in place in `latest` and copied out once the
        // step is done (a sample built in a temporary was copied at once, and the
        // copy's wide loads waited on the narrow stores that had just built it).
        if let Some(s) = self.cached.take() {
            self.latest = s;
        } else {
            let head = self.sample_head();
            let s = &mut self.latest;
            (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = head;
            contact_states(&self.vehicle, &self.law, &self.wheels, s);
        }
        let s = &self.latest;
        let (zw, zr) = (s.wheel_z, s.rail_z);
        if !(within(zw[0], DISPLACEMENT_LIMIT)
            && within(zw[1], DISPLACEMENT_LIMIT)
            && within(zr[0], DISPLACEMENT_LIMIT)
            && within(zr[1], DISPLACEMENT_LIMIT))
        {
            return Err(self.displacement_diverged());
        }
        self.advance_with(x, [s.contact[0].force, s.contact[1].force], s.time)?;
        if self.steps.is_multiple_of(HEALTH_CHECK_INTERVAL) {
            self.check_states()?;
        }
        Ok(self.latest)
    }

    /// Checks every state of the track and the vehicle against the health bounds of
    /// [`crate::limits`]: rail and sleeper displacements within
    /// [`DISPLACEMENT_LIMIT`], vehicle bodies within
    /// [`crate::limits::BODY_DISPLACEMENT_LIMIT`], all
    /// finite. Run every [`HEALTH_CHECK_INTERVAL`] steps and after the static solve.
    pub fn check_states(&self) -> Result<()> {
        if let TrackState::Discrete(t) = &self.track {
            let m = t.max_abs_displacement();
            if !within(m, DISPLACEMENT_LIMIT) {
                return Err(Error::Diverged {
                    what: "largest rail or sleeper displacement (m)".into(),
                    value: m,
                    limit: DISPLACEMENT_LIMIT,
                    time: self.time(),
                    cause: self.likely_cause(),
                });
            }
        }
        if let VehicleState::RollPlane(v) = &self.vehicle
            && let Some((what, value, limit)) = v.beyond_bounds()
        {
            return Err(Error::Diverged {
                what: format!("vehicle {what}"),
                value,
                limit,
                time: self.time(),
                cause: self.likely_cause(),
            });
        }
        Ok(())
    }

    /// The error for a wheel or rail displacement under the wheel of the latest sample
    /// beyond the bound.
    #[cold]
    #[inline(never)]
    fn displacement_diverged(&self) -> Error {
        // The caller found one of the four displacements beyond the bound, and they
        // lead the list; the fallback is never taken.
        self.sample_beyond_bounds(&self.latest)
            .unwrap_or_else(|| Error::NonFinite {
                what: "wheel or rail under the wheel".into(),
                time: self.latest.time,
            })
    }

    /// The first value of sample `s` (or of the force extremes) beyond the health
    /// bounds, as the error that names it: wheel and rail under the wheel within
    /// [`DISPLACEMENT_LIMIT`], contact forces and their extremes within the force limit.
    fn sample_beyond_bounds(&self, s: &Sample) -> Option<Error> {
        let lim = self.force_limit;
        let values = [
            ("wheel.left.z (m)", s.wheel_z[0], DISPLACEMENT_LIMIT),
            ("wheel.right.z (m)", s.wheel_z[1], DISPLACEMENT_LIMIT),
            (
                "rail.left.z under the wheel (m)",
                s.rail_z[0],
                DISPLACEMENT_LIMIT,
            ),
            (
                "rail.right.z under the wheel (m)",
                s.rail_z[1],
                DISPLACEMENT_LIMIT,
            ),
            ("contact.left.force (N)", s.contact[0].force, lim),
            ("contact.right.force (N)", s.contact[1].force, lim),
            (
                "contact.left.max_force (N)",
                self.max_force[0].max(0.0),
                lim,
            ),
            (
                "contact.right.max_force (N)",
                self.max_force[1].max(0.0),
                lim,
            ),
            (
                "contact.left.min_force (N)",
                self.min_force[0].min(0.0),
                lim,
            ),
            (
                "contact.right.min_force (N)",
                self.min_force[1].min(0.0),
                lim,
            ),
        ];
        let (what, value, limit) = values.into_iter().find(|(_, x, l)| !within(*x, *l))?;
        Some(Error::Diverged {
            what: what.into(),
            value,
            limit,
            time: s.time,
            cause: self.likely_cause(),
        })
    }

    /// The error for a contact force beyond [`crate::limits::force_limit`].
    #[cold]
    #[inline(never)]
    fn force_diverged(&self, p: [f64; 2], time: f64) -> Error {
        let i = usize::from(within(p[0], self.force_limit));
        let side = ["left", "right"][i];
        Error::Diverged {
            what: format!("contact.{side}.force (N)"),
            value: p[i],
            limit: self.force_limit,
            time,
            cause: format!(
                "{} times the static wheel load {} N; {}",
                crate::limits::FORCE_LIMIT_FACTOR,
                num(self.static_load[0].max(self.static_load[1])),
                self.likely_cause()
            ),
        }
    }

    /// What most likely drove a value beyond the health bounds, in words.
    fn likely_cause(&self) -> String {
        let step = match &self.track {
            TrackState::Discrete(t) => format!(
                "solver.step = {} s is {:.3} of the critical step {} s, so the explicit \
                 scheme should be stable: check parameters far from a railway",
                num(self.dt),
                self.dt / t.dt_critical(),
                num(t.dt_critical())
            ),
            TrackState::Lumped(_) => "the explicit scheme diverged".into(),
        };
        match &self.vehicle {
            VehicleState::External { wheel_z, .. } => format!(
                "likely the wheel inputs (wheel.left.z = {} m, wheel.right.z = {} m) press \
                 the wheel into the rail far beyond a running wheel's overlap; else {step}",
                num(wheel_z[0]),
                num(wheel_z[1])
            ),
            _ => step,
        }
    }

    /// Advances `n` steps of [`Simulation::dt`]. A run whose end would carry the wheel
    /// off the track is refused with [`Error::OffTrack`] before anything moves; a
    /// value beyond the health bounds stops it with [`Error::Diverged`].
    pub fn advance_steps(&mut self, n: u64) -> Result<()> {
        if let TrackState::Discrete(t) = &self.track {
            let len = t.params().length();
            let t_end = self.t0 + (self.k + n) as f64 * self.dt;
            let end = self.scenario.start_position + self.scenario.speed * t_end;
            if !(end > 0.0 && end < len) {
                return Err(Error::OffTrack {
                    position: end,
                    length: len,
                    time: t_end,
                });
            }
        }
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    /// Advances vehicle and track from `t_j` (s) with the contact forces `p` (N) of
    /// the sample at `t_j`, the wheels at position `x` (m).
    #[inline(always)]
    fn advance_with(&mut self, x: f64, p: [f64; 2], time: f64) -> Result<()> {
        let lim = self.force_limit;
        if !(within(p[0], lim) && within(p[1], lim)) {
            return Err(self.force_diverged(p, time));
        }
        for i in 0..2 {
            self.max_force[i] = self.max_force[i].max(p[i]);
            self.min_force[i] = self.min_force[i].min(p[i]);
        }
        match &mut self.vehicle {
            VehicleState::RollPlane(v) => v.step(p),
            VehicleState::LumpedWheels(v) => v.step(p),
            VehicleState::ConstantLoad(_) | VehicleState::External { .. } => {}
        }
        match &mut self.track {
            TrackState::Discrete(t) => t.step(&wheel_loads(x, p)),
            TrackState::Lumped(t) => t.step(p),
        }
        self.steps += 1;
        self.k += 1;
        Ok(())
    }

    /// Changes the time step to `dt` (s) from now on (track and vehicle keep their
    /// displacements and backward-difference velocities). Refused above the track's
    /// critical step. Only the discrete track with the roll-plane vehicle or constant
    /// loads supports it.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        if dt == self.dt {
            return Ok(());
        }
        match &mut self.track {
            TrackState::Discrete(t) => t.change_dt(dt)?,
            TrackState::Lumped(_) => {
                return Err(Error::Unsupported(
                    "changing the step of the lumped track".into(),
                ));
            }
        }
        match &mut self.vehicle {
            VehicleState::RollPlane(v) => v.change_dt(dt)?,
            VehicleState::ConstantLoad(_) | VehicleState::External { .. } => {}
            VehicleState::LumpedWheels(_) => {
                return Err(Error::Unsupported(
                    "changing the step of the lumped wheels".into(),
                ));
            }
        }
        self.t0 = self.time();
        self.k = 0;
        self.dt = dt;
        self.cached.set(None);
        Ok(())
    }

    /// Everything that determines the continuation (clock, force extremes, track and
    /// vehicle states); [`Simulation::set_state_vector`] restores it exactly. Only for
    /// the discrete track with the roll-plane vehicle or constant loads.
    pub fn state_vector(&self) -> Result<Vec<f64>> {
        let mut v = vec![
            self.dt,
            self.t0,
            self.k as f64,
            self.steps as f64,
            self.max_force[0],
            self.max_force[1],
            self.min_force[0],
            self.min_force[1],
        ];
        match &self.track {
            TrackState::Discrete(t) => v.extend(t.state_vector()),
            TrackState::Lumped(_) => return Err(Self::no_state()),
        }
        match &self.vehicle {
            VehicleState::RollPlane(r) => v.extend(r.state_vector()),
            VehicleState::ConstantLoad(_) => {}
            VehicleState::External {
                wheel_z,
                rotation,
                since,
            } => v.extend([wheel_z[0], wheel_z[1], *rotation, *since]),
            VehicleState::LumpedWheels(_) => return Err(Self::no_state()),
        }
        Ok(v)
    }

    fn no_state() -> Error {
        Error::Unsupported(
            "state vector of a lumped model (only the discrete track with the roll-plane \
             vehicle or constant loads has one)"
                .into(),
        )
    }

    /// Restores a state written by [`Simulation::state_vector`] of a simulation built
    /// from the same scenario. Refused: a wrong length, a step outside what
    /// [`Simulation::new`] accepts, a clock or step count that is not a whole number
    /// below 2^53, and a state beyond the health bounds ([`Simulation::check_health`]),
    /// which then stays in the simulation: rebuild it.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if let (Some(&dt), TrackState::Discrete(_)) = (v.first(), &self.track) {
            let c = self.critical_step;
            if !(dt >= MIN_DT_FRACTION * c && dt <= c) {
                return Err(out_of_range(
                    "state: step",
                    dt,
                    format!("{} s <= dt <= {} s", num(MIN_DT_FRACTION * c), num(c)),
                ));
            }
        }
        let count = crate::limits::is_count;
        if v.len() >= 4 && !(v[1].is_finite() && v[1] >= 0.0 && count(v[2]) && count(v[3])) {
            return Err(out_of_range(
                "state: clock",
                v[1],
                "t0 finite and >= 0 s, step counts whole numbers in [0, 2^53)",
            ));
        }
        let nt = match &self.track {
            TrackState::Discrete(t) => t.state_len(),
            TrackState::Lumped(_) => return Err(Self::no_state()),
        };
        let nv = match &self.vehicle {
            VehicleState::RollPlane(_) => 13,
            VehicleState::ConstantLoad(_) => 0,
            VehicleState::External { .. } => 4,
            VehicleState::LumpedWheels(_) => return Err(Self::no_state()),
        };
        if v.len() != 8 + nt + nv {
            return Err(out_of_range(
                "simulation state length",
                v.len() as f64,
                format!("{} values for this scenario", 8 + nt + nv),
            ));
        }
        if let TrackState::Discrete(t) = &mut self.track {
            t.set_state_vector(&v[8..8 + nt])?;
        }
        match &mut self.vehicle {
            VehicleState::RollPlane(r) => r.set_state_vector(&v[8 + nt..])?,
            VehicleState::External {
                wheel_z,
                rotation,
                since,
            } => {
                let e = &v[8 + nt..];
                *wheel_z = [e[0], e[1]];
                *rotation = e[2];
                *since = e[3];
            }
            _ => {}
        }
        self.dt = v[0];
        self.t0 = v[1];
        self.k = v[2] as u64;
        self.steps = v[3] as u64;
        self.max_force = [v[4], v[5]];
        self.min_force = [v[6], v[7]];
        self.cached.set(None);
        self.check_health()
    }

    /// [`Simulation::check_states`], and the sample at the current time: wheel and rail
    /// under the wheel within [`DISPLACEMENT_LIMIT`], contact forces within the force
    /// limit, the force extremes finite.
    pub fn check_health(&self) -> Result<()> {
        self.check_states()?;
        self.check_sample()
    }

    /// The sample part of [`Simulation::check_health`]: cheap (the sample is cached and
    /// used by the next step).
    pub fn check_sample(&self) -> Result<()> {
        match self.sample_beyond_bounds(&self.sample()) {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Runs until `duration` (s) from now, calling `each` with every sample.
    pub fn run(&mut self, duration: f64, mut each: impl FnMut(&Sample)) -> Result<()> {
        non_negative("duration", duration, "s")?;
        let n = (duration / self.dt).round() as u64;
        for _ in 0..n {
            let s = self.step()?;
            each(&s);
        }
        Ok(())
    }
}
