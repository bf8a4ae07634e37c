//! The coupled vehicle-track-contact simulation.
//!
//! One step, in the order of `docs/MODEL.md`: at `t_j` the wheel displacements and the axle
//! angle give the rail displacement under each wheel (3.23), then the contact forces
//! `P_j`; vehicle and track are then advanced to `t_(j+1)` with `P_j`. The run starts
//! from the static equilibrium of the whole system, solved directly
//! ([`super::static_start`]).

use super::clock::{Clock, StepPlan, Stepping};
use super::sites::{Site, sites};
use super::static_start::{contact_law, static_loads};
use super::wheelset::{Sample, Wheelset, Wheelsets, contact_states, wheel_loads};
use crate::contact::ContactLaw;
use crate::error::{Error, Result, finite, non_negative, num, out_of_range, positive};
use crate::limits::{
    DISPLACEMENT_LIMIT, HEALTH_CHECK_INTERVAL, MAX_NODE_STEPS_PER_CALL, MIN_DT_FRACTION,
    force_limit, within,
};
use crate::sim::{DEFAULT_DT_FRACTION, Scenario, TrackSpec, VehicleSpec};
use crate::track::{PointLoad, SimdLevel, Track};
use crate::vehicle::{LumpedTrack, LumpedWheels, RollPlaneVehicle};
use crate::wheel::WheelProfile;

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

/// A running coupled simulation: the track-carrying co-simulation unit, on the fixed
/// grid `t_k = k dt` of its step.
#[derive(Debug, Clone)]
pub struct Simulation {
    pub(super) scenario: Scenario,
    pub(super) track: TrackState,
    pub(super) vehicle: VehicleState,
    /// The wheelsets, the leading one first (`d_1 = 0`): the one place the wheels live.
    /// The vehicle models carry one wheelset, so there is exactly one.
    pub(super) wheelsets: Wheelsets,
    /// The wheel loads of every wheelset passed to the track, two per wheelset.
    pub(super) loads: Vec<PointLoad>,
    pub(super) law: ContactLaw,
    pub(super) clock: Clock,
    /// Steps taken since the start, over every change of the step.
    pub(super) steps: u64,
    pub(super) static_load: [f64; 2],
    /// Critical step of the explicit scheme (s), the contact's stiffness included; NaN
    /// for the lumped track.
    pub(super) critical_step: f64,
    /// Largest contact force a physical run reaches (N) ([`crate::limits::force_limit`]).
    pub(super) force_limit: f64,
    /// Instructions the whole coupled step is compiled for (see [`Simulation::step`]).
    pub(super) simd: SimdLevel,
    /// The observation points ([`Scenario::sites`]).
    pub(super) sites: Vec<Site>,
}

/// Runs `f` compiled for `level`, AVX2 at most (see [`SimdLevel::run`]).
// The coupled step outside the track loops, which have their own AVX-512 copy, is
// compiled as for AVX2 (1,096 instructions baseline, 870 AVX2). Nothing in it is
// contracted into FMA (the track loops it calls are, at AVX2 and AVX-512: see
// `SimdLevel`).
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

/// The time step (s) of scenario `s` with contact law `law` under the static loads
/// `static_load` (N), and the discrete track's critical step (s) with what sets it: the
/// scenario's step, or [`DEFAULT_DT_FRACTION`] of the critical step when it is 0. The
/// critical step includes [`CONTACT_STIFFNESS_MARGIN`] times the contact's stiffness
/// under the force limit (table 4.2 and section 4.2.2 without the contact).
///
/// Errors: track parameters [`crate::track::TrackParams::validate`] refuses; a step
/// above the critical step ([`Error::UnstableTimeStep`]) or below [`MIN_DT_FRACTION`] of
/// it.
fn time_step(
    s: &Scenario,
    law: &ContactLaw,
    static_load: [f64; 2],
) -> Result<(f64, Option<(f64, String)>)> {
    let critical = match &s.track {
        TrackSpec::Discrete(p) => {
            p.validate()?;
            let perfect = WheelProfile::perfect(s.wheel_radius)?;
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
    Ok((dt, critical))
}

impl Simulation {
    /// Builds the models, checks every parameter and puts the system in static
    /// equilibrium at the start position.
    ///
    /// Errors: a parameter outside its physical range ([`Error::Parameter`], naming
    /// it); a time step above the critical step ([`Error::UnstableTimeStep`]); a start
    /// outside the discrete track; a contact or track too soft to carry the static
    /// wheel load; a static state beyond the health bounds.
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
        let static_load = static_loads(&s.vehicle)?;
        let law = contact_law(s, static_load)?;
        let (dt, critical) = time_step(s, &law, static_load)?;
        let wheelsets = Wheelsets::new(Wheelset::new(s.wheel_radius, &s.flats, 0.0)?);
        let track = match &s.track {
            TrackSpec::Discrete(p) => {
                p.validate()?;
                let len = p.length();
                for w in wheelsets.iter() {
                    let x = w.position(s.start_position);
                    if !(x > 0.0 && x < len) {
                        return Err(out_of_range(
                            "start_position",
                            x,
                            format!("inside the track, 0 < x < {len} m"),
                        ));
                    }
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
        let load = PointLoad {
            rail: 0,
            position: 0.0,
            force: 0.0,
        };
        let mut sim = Simulation {
            scenario: s.clone(),
            track,
            vehicle,
            loads: vec![load; 2 * wheelsets.len()],
            wheelsets,
            law,
            clock: Clock::new(dt, Stepping::Grid),
            steps: 0,
            static_load,
            critical_step: critical.map_or(f64::NAN, |c| c.0),
            force_limit: force_limit(static_load),
            simd: SimdLevel::detect(),
            sites: Vec::new(),
        };
        sim.set_static()?;
        sim.check_static_sag()?;
        sim.check_states()?;
        match &sim.track {
            TrackState::Discrete(t) => sim.sites = sites(t, &s.sites)?,
            TrackState::Lumped(_) if !s.sites.is_empty() => {
                return Err(Error::Unsupported(
                    "observation points on the lumped track (it has no rails)".into(),
                ));
            }
            TrackState::Lumped(_) => {}
        }
        Ok(sim)
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.clock.dt
    }
    /// Current time `t_j` (s).
    pub fn time(&self) -> f64 {
        self.clock.time()
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }
    /// The rail `rail` (0 left, 1 right) under the leading wheelset's wheel at `t_j`:
    /// its displacement (m), bending moment (N m) and shear force (N)
    /// ([`crate::track::Track::rail_response`]); `None` for the lumped track.
    pub fn rail_under_wheel(&self, rail: usize) -> Option<crate::track::RailResponse> {
        let x = self.lead().position(self.position());
        match &self.track {
            TrackState::Discrete(t) => Some(t.rail_response(rail, x)),
            TrackState::Lumped(_) => None,
        }
    }
    /// The observation points ([`Scenario::sites`]), with what the track feels there at
    /// `t_j` and its extremes since the start.
    pub fn sites(&self) -> &[Site] {
        &self.sites
    }
    /// Position of the leading wheelset at the current time (m): `x_0 + V t`.
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

    /// Time (s) at which the leading wheelset reaches the end of the discrete track,
    /// from the start; `None` for the lumped track or at speed 0.
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
    /// The wheelsets, the leading one first.
    pub fn wheelsets(&self) -> &Wheelsets {
        &self.wheelsets
    }
    /// Largest contact force per wheel of the leading wheelset since the start (N);
    /// `f64::MIN` before the first step.
    pub fn max_force(&self) -> [f64; 2] {
        self.lead().max_force()
    }
    /// Smallest contact force per wheel of the leading wheelset since the start (N);
    /// `f64::MAX` before the first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.lead().min_force()
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

    /// The leading wheelset, whose sample the outputs report.
    #[inline(always)]
    fn lead(&self) -> &Wheelset {
        self.wheelsets.lead()
    }

    /// Forgets the cached samples: the time or the inputs changed.
    #[inline]
    pub(super) fn clear_cache(&self) {
        self.wheelsets.clear_cache();
    }

    /// Wheel-centre displacements `[left, right]` (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        match &self.vehicle {
            VehicleState::RollPlane(v) => v.wheel_z(),
            VehicleState::LumpedWheels(v) => v.wheel_z(),
            VehicleState::ConstantLoad(_) => self.rail_z(),
            VehicleState::External { wheel_z, .. } => *wheel_z,
        }
    }

    /// Rail displacements under the wheels of the leading wheelset (m) (3.23).
    pub fn rail_z(&self) -> [f64; 2] {
        self.rail_z_under(self.lead().position(self.position()))
    }

    /// Rail displacements (m) under wheels at position `x` (m).
    #[inline(always)]
    fn rail_z_under(&self, x: f64) -> [f64; 2] {
        match &self.track {
            TrackState::Discrete(t) => t.rail_z_pair(x),
            TrackState::Lumped(t) => t.rail_z(),
        }
    }

    /// Everything at the current time for the leading wheelset, contact forces
    /// included.
    pub fn sample(&self) -> Sample {
        if let Some(s) = self.lead().cached.get() {
            return s;
        }
        let s = self.compute_sample_dispatched();
        self.lead().cached.set(Some(s));
        s
    }

    // `compute_sample` compiled for the SIMD level, as in `step` (a co-simulation master
    // reads the outputs before it steps, so this is where its contact forces are
    // computed).
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
        contact_states(&self.vehicle, &self.law, self.lead().wheels(), &mut s);
        s
    }

    /// Everything of the leading wheelset's sample at the current time but the contact
    /// states: time (s), position (m), axle rotation (rad), wheel and rail displacements
    /// (m).
    #[inline(always)]
    fn sample_head(&self) -> (f64, f64, f64, [f64; 2], [f64; 2]) {
        let time = self.time();
        let x = self.scenario.start_position + self.scenario.speed * time;
        let position = self.lead().position(x);
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

    /// Advances one step and returns the leading wheelset's sample at `t_j` whose
    /// contact forces drove it: wheel and rail displacements at `t_j` give the contact
    /// forces `P_j`, which advance vehicle and track to `t_(j+1)` (`docs/MODEL.md`).
    ///
    /// Errors: the leading wheelset off the discrete track ([`Error::OffTrack`]); a
    /// value beyond the health bounds of [`crate::limits`] ([`Error::Diverged`]).
    pub fn step(&mut self) -> Result<Sample> {
        // The whole step (sample, contact, vehicle, track) is compiled once per
        // `SimdLevel` and dispatched here: with AVX2 the scalar code gets three-operand
        // instructions and the vehicle's 6 x 6 products whole 4-lane vectors (an AVX-512
        // CPU runs this copy too, with the track loops in their AVX-512 form). Only the
        // track loops use FMA, the same way at AVX2 and AVX-512, so those two give the
        // same results bit for bit (see `SimdLevel`).
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
        if let Some(s) = self.wheelsets.lead().cached.take() {
            self.wheelsets.lead_mut().latest = s;
        } else {
            let head = self.sample_head();
            let (wheels, s) = self.wheelsets.lead_mut().parts_mut();
            (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = head;
            contact_states(&self.vehicle, &self.law, wheels, s);
        }
        let s = &self.lead().latest;
        let (zw, zr) = (s.wheel_z, s.rail_z);
        if !(within(zw[0], DISPLACEMENT_LIMIT)
            && within(zw[1], DISPLACEMENT_LIMIT)
            && within(zr[0], DISPLACEMENT_LIMIT)
            && within(zr[1], DISPLACEMENT_LIMIT))
        {
            return Err(self.displacement_diverged());
        }
        self.advance_with(x, s.time)?;
        if self.steps.is_multiple_of(HEALTH_CHECK_INTERVAL) {
            self.check_states()?;
        }
        Ok(self.lead().latest)
    }

    /// Advances `n` steps of [`Simulation::dt`]. A run whose end would carry the wheel
    /// off the track is refused with [`Error::OffTrack`] before anything moves; a
    /// value beyond the health bounds stops it with [`Error::Diverged`].
    pub fn advance_steps(&mut self, n: u64) -> Result<()> {
        if let TrackState::Discrete(t) = &self.track {
            let len = t.params().length();
            let t_end = self.clock.time_after(n);
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

    /// Plans a communication step to the grid point nearest the master's model time
    /// `end` (s), measured from the start of the run: `round(end / dt)` steps from the
    /// start when the step never changed, none when that point is behind. A
    /// communication step within the master's clock rounding of a whole multiple of the
    /// step runs as that many steps, the step never changes (the explicit scheme is not
    /// stable under every sequence of step changes near its limit), and the model time
    /// stays within half a step of the master's. `tolerance` (s), the rounding of the
    /// master's clock, is not needed on the grid.
    ///
    /// Refused before anything moves, with the reason in words: more than
    /// [`MAX_NODE_STEPS_PER_CALL`] rail-node updates (steps times
    /// [`Simulation::rail_nodes`]).
    // Inlined into the FMU's step, as the arithmetic was before it moved here.
    #[inline(always)]
    pub fn plan_to(&self, end: f64, tolerance: f64) -> std::result::Result<StepPlan, String> {
        let plan = self.clock.plan_to(end, tolerance);
        let cost = plan.steps * self.rail_nodes() as f64;
        if cost > MAX_NODE_STEPS_PER_CALL {
            return Err(self.too_much_work(plan.steps, cost));
        }
        Ok(plan)
    }

    /// The reason [`Simulation::plan_to`] refuses `n` steps costing `cost` rail-node
    /// updates.
    #[cold]
    #[inline(never)]
    fn too_much_work(&self, n: f64, cost: f64) -> String {
        format!(
            "{n} steps of solver.step = {} s on {} rail nodes, {} node updates; the \
             most one call may do is {MAX_NODE_STEPS_PER_CALL:e} (about a second on the \
             default track)",
            self.dt(),
            self.rail_nodes(),
            num(cost)
        )
    }

    /// Takes a communication step planned by [`Simulation::plan_to`]. Errors as
    /// [`Simulation::advance_steps`].
    #[inline]
    pub fn advance_to(&mut self, plan: StepPlan) -> Result<()> {
        self.advance_steps(plan.steps as u64)
    }

    /// Advances vehicle and track from `t_j` (s) with the contact forces of the
    /// wheelsets' samples at `t_j`, the leading wheelset at position `x` (m).
    #[inline(always)]
    fn advance_with(&mut self, x: f64, time: f64) -> Result<()> {
        let p = self.lead().forces();
        let lim = self.force_limit;
        if !(within(p[0], lim) && within(p[1], lim)) {
            return Err(self.force_diverged(p, time));
        }
        self.wheelsets.lead_mut().extremes.record(p);
        match &mut self.vehicle {
            VehicleState::RollPlane(v) => v.step(p),
            VehicleState::LumpedWheels(v) => v.step(p),
            VehicleState::ConstantLoad(_) | VehicleState::External { .. } => {}
        }
        match &mut self.track {
            TrackState::Discrete(t) => {
                wheel_loads(x, &self.wheelsets, Wheelset::forces, &mut self.loads);
                t.step(&self.loads);
                if !self.sites.is_empty() {
                    for site in &mut self.sites {
                        site.record(t);
                    }
                }
            }
            TrackState::Lumped(t) => t.step(p),
        }
        self.steps += 1;
        self.clock.tick();
        Ok(())
    }

    /// Changes the time step to `dt` (s) from now on (track and vehicle keep their
    /// displacements and backward-difference velocities). Refused above the track's
    /// critical step. Only the discrete track with the roll-plane vehicle or constant
    /// loads supports it.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        if dt == self.clock.dt {
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
        self.clock.restart(dt);
        self.clear_cache();
        Ok(())
    }

    /// Runs for `duration` (s) from now, rounded to a whole number of steps of
    /// [`Simulation::dt`], calling `each` with the sample of every step as
    /// [`Simulation::step`] returns it (at the step's start `t_j`).
    ///
    /// Errors: `duration` negative or not finite; the errors of [`Simulation::step`]
    /// (the wheel leaving the track, a value beyond the health bounds), after which
    /// the samples up to the failing step have been handed to `each`.
    pub fn run(&mut self, duration: f64, mut each: impl FnMut(&Sample)) -> Result<()> {
        non_negative("duration", duration, "s")?;
        let n = (duration / self.clock.dt).round() as u64;
        for _ in 0..n {
            let s = self.step()?;
            each(&s);
        }
        Ok(())
    }
}
