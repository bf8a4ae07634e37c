//! The coupled vehicle-track-contact simulation.
//!
//! One step, in the order of `docs/MODEL.md`: at `t_j` the wheel displacements and the axle
//! angle give the rail displacement under each wheel (3.23), then the contact forces
//! `P_j`; vehicle and track are then advanced to `t_(j+1)` with `P_j`. The run starts
//! from the static equilibrium of the whole system, solved directly
//! ([`super::static_start`]).

use super::clock::{Clock, StepPlan};
use super::motion::{Motion, Window};
use super::sites::Site;
use super::vehicle_state::VehicleState;
use super::wheelset::{Sample, Wheelset, Wheelsets, wheel_loads};
use crate::contact::ContactLaw;
use crate::error::{Error, Result, non_negative, num};
use crate::limits::{DISPLACEMENT_LIMIT, HEALTH_CHECK_INTERVAL, MAX_NODE_STEPS_PER_CALL, within};
use crate::sim::{Scenario, VoidedSleepers};
use crate::track::{PointLoad, RailProfile, SimdLevel, Track};
use crate::vehicle::{Axles, LumpedTrack, MAX_AXLES, RailVehicle};

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

/// A running coupled simulation: the track-carrying co-simulation unit, on the fixed
/// grid `t_k = k dt` of its step.
#[derive(Debug, Clone)]
pub struct Simulation {
    pub(super) scenario: Scenario,
    pub(super) track: TrackState,
    /// The wheelsets, the leading one first (`d_1 = 0`), each with its vehicle: the one
    /// place the wheels live.
    pub(super) wheelsets: Wheelsets,
    pub(super) motion: Motion,
    /// Line coordinate of the track's node 0 (m): 0 on a fixed track, whole spans on an
    /// endless one.
    pub(super) origin: f64,
    /// The endless track's window; `None` on a fixed track.
    pub(super) window: Option<Window>,
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
    /// The vehicle that moves several wheelsets' wheels
    /// ([`VehicleSpec::Carrier`](crate::sim::VehicleSpec::Carrier): the half-car bogie,
    /// the wagons), behind one interface.
    pub(super) carrier: Option<Box<dyn RailVehicle>>,
    /// The first two wheelsets' axle boxes under the same side frames
    /// ([`crate::sim::SideFrameSpec::HalfCar`]).
    pub(super) shared_side_frames: bool,
    /// The hanging sleepers ([`Scenario::voids`]), placed on the track anew whenever an
    /// endless track's window moves.
    pub(super) voids: Option<VoidedSleepers>,
    /// Whether a rail has a profile or a wheel an out-of-roundness.
    pub(super) irregular: bool,
    /// The rails' vertical profiles `[left, right]` ([`Scenario::rails`]).
    pub(super) rails: [RailProfile; 2],
}

/// Runs `f` compiled for `level`, AVX2 at most (see [`SimdLevel::run`]).
// The coupled step outside the track loops, which have their own AVX-512 copy, is
// compiled as for AVX2 (1,096 instructions baseline, 870 AVX2). Nothing in it is
// contracted into FMA (the track loops it calls are, at AVX2 and AVX-512: see
// `SimdLevel`).
#[inline(always)]
pub(super) fn at_level<R>(level: SimdLevel, f: impl FnOnce() -> R) -> R {
    level.min(SimdLevel::Avx2).run(f)
}

/// Whether the wheel and rail displacements of sample `s` lie within
/// [`DISPLACEMENT_LIMIT`].
#[inline(always)]
fn displacements_within(s: &Sample) -> bool {
    let (zw, zr) = (s.wheel_z, s.rail_z);
    within(zw[0], DISPLACEMENT_LIMIT)
        && within(zw[1], DISPLACEMENT_LIMIT)
        && within(zr[0], DISPLACEMENT_LIMIT)
        && within(zr[1], DISPLACEMENT_LIMIT)
}

impl Simulation {
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
    /// The rail `rail` (0 left, 1 right) under the wheel of wheelset `k` (0 the leading
    /// one) at `t_j`: its displacement (m), bending moment (N m) and shear force (N)
    /// ([`crate::track::Track::rail_response`]); `None` for the lumped track or a
    /// wheelset `k` the simulation does not have.
    pub fn rail_under_wheel_of(&self, k: usize, rail: usize) -> Option<crate::track::RailResponse> {
        let w = self.wheelsets.get(k)?;
        let x = w.position(self.position()) - self.origin;
        match &self.track {
            TrackState::Discrete(t) => Some(t.rail_response(rail, x)),
            TrackState::Lumped(_) => None,
        }
    }
    /// [`Simulation::rail_under_wheel_of`] the leading wheelset.
    pub fn rail_under_wheel(&self, rail: usize) -> Option<crate::track::RailResponse> {
        self.rail_under_wheel_of(0, rail)
    }
    /// The observation points ([`Scenario::sites`]), with what the track feels there at
    /// `t_j` and its extremes since the start.
    pub fn sites(&self) -> &[Site] {
        &self.sites
    }

    /// Rail nodes of the discrete track, both rails (the work of one track step scales
    /// with it); 2 for the lumped track.
    pub fn rail_nodes(&self) -> usize {
        match &self.track {
            TrackState::Discrete(t) => 2 * t.nodes(),
            TrackState::Lumped(_) => 2,
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
    /// The leading wheelset's vehicle.
    pub fn vehicle(&self) -> &VehicleState {
        &self.lead().vehicle
    }
    /// The scenario (on an endless track, with the window's spans).
    pub fn scenario(&self) -> &Scenario {
        &self.scenario
    }

    /// The leading wheelset, whose sample the outputs report.
    #[inline(always)]
    pub(super) fn lead(&self) -> &Wheelset {
        self.wheelsets.lead()
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
            let len = t.params().running_length();
            let xt = x - self.origin;
            if !(xt > 0.0 && xt < len) {
                return Err(Error::OffTrack {
                    position: x,
                    length: len,
                    time: self.time(),
                });
            }
        }
        // The cached sample, if the outputs were read at this instant, is used up here;
        // otherwise the sample is built in place in `latest` and copied out once the
        // step is done.
        if let Some(s) = self.wheelsets.lead().cached.take() {
            self.wheelsets.lead_mut().latest = s;
        } else {
            self.sample_in_place(0);
        }
        if !displacements_within(&self.lead().latest) {
            return Err(self.displacement_diverged(self.lead()));
        }
        if !self.wheelsets.trailing().is_empty() {
            self.sample_trailing()?;
        }
        let time = self.lead().latest.time;
        self.advance_with(x, time)?;
        if self.steps.is_multiple_of(HEALTH_CHECK_INTERVAL) {
            self.check_states()?;
        }
        Ok(self.lead().latest)
    }

    /// The samples at `t_j` of the wheelsets behind the leading one, in place, with
    /// their displacements checked as the leading one's. Out of line, so that a single
    /// wheelset's step stays small, but compiled at the step's level as the step is
    /// (with AVX2's three-operand forms the contact solves take fewer instructions; no
    /// product is fused, so the bits are the baseline's).
    #[inline(never)]
    fn sample_trailing(&mut self) -> Result<()> {
        at_level(
            self.simd,
            #[inline(always)]
            || self.sample_trailing_body(),
        )
    }

    /// [`Simulation::sample_trailing`], inlined into each level's copy.
    #[inline(always)]
    fn sample_trailing_body(&mut self) -> Result<()> {
        for k in 0..self.wheelsets.trailing().len() {
            if let Some(s) = self.wheelsets.trailing()[k].cached.take() {
                self.wheelsets.trailing_mut()[k].latest = s;
            } else {
                self.sample_in_place(k + 1);
            }
            let s = &self.wheelsets.trailing()[k].latest;
            if !displacements_within(s) {
                return Err(self.displacement_diverged(&self.wheelsets.trailing()[k]));
            }
        }
        Ok(())
    }

    /// The wheelsets behind the leading one: their contact forces checked against the
    /// force limit, then their extremes and vehicles advanced.
    #[inline(never)]
    fn advance_trailing(&mut self, time: f64) -> Result<()> {
        at_level(
            self.simd,
            #[inline(always)]
            || self.advance_trailing_body(time),
        )
    }

    /// [`Simulation::advance_trailing`], inlined into each level's copy.
    #[inline(always)]
    fn advance_trailing_body(&mut self, time: f64) -> Result<()> {
        let lim = self.force_limit;
        for w in self.wheelsets.trailing() {
            let p = w.forces();
            if !(within(p[0], lim) && within(p[1], lim)) {
                return Err(self.force_diverged(p, time));
            }
        }
        let dt = self.clock.dt;
        for w in self.wheelsets.trailing_mut() {
            let p = w.forces();
            w.extremes.record(p);
            w.record_accelerations(dt);
            w.vehicle.step(p);
        }
        Ok(())
    }

    /// Advances `n` steps of [`Simulation::dt`]. A run whose end would carry the
    /// leading wheelset off a fixed track is refused with [`Error::OffTrack`] before
    /// anything moves (an endless track has no end); a value beyond the health bounds
    /// stops it with [`Error::Diverged`].
    pub fn advance_steps(&mut self, n: u64) -> Result<()> {
        self.check_on_track(n)?;
        for _ in 0..n {
            self.step()?;
        }
        Ok(())
    }

    /// [`Simulation::advance_steps`] that stops after the first step at whose end a
    /// wheel of any wheelset has come into contact or lost it ([`Simulation::contacts`]
    /// changed), or at the last step on a fixed track that `n` steps would leave: the
    /// steps taken and, where it stopped early, why, in words.
    /// The contact at each step's end is the one the next step starts from (computed
    /// once, as a master's read of the outputs computes it), so the run's bits are
    /// [`Simulation::advance_steps`]'s.
    pub fn advance_steps_to_contact_change(&mut self, n: u64) -> Result<(u64, Option<String>)> {
        // On a fixed track, a run that would leave it stops at its last step on it
        // instead, an early end too; with no step left, the run ends as in
        // `advance_steps`.
        let (n, track_end) = match self.check_on_track(n) {
            Ok(()) => (n, false),
            Err(e) => {
                let (mut on, mut off) = (0, n);
                while off - on > 1 {
                    let mid = on + (off - on) / 2;
                    match self.check_on_track(mid) {
                        Ok(()) => on = mid,
                        Err(_) => off = mid,
                    }
                }
                if on == 0 {
                    return Err(e);
                }
                (on, true)
            }
        };
        let before = self.contacts();
        for k in 1..=n {
            self.step()?;
            let now = self.contacts();
            if now != before && (k < n || track_end) {
                return Ok((k, Some(self.describe_contact_change(before, now))));
            }
        }
        let end = track_end.then(|| {
            format!(
                "at t = {} s the wheel is at the end of the fixed track's running length: a \
                 further step ends the run",
                self.time()
            )
        });
        Ok((n, end))
    }

    /// Which wheels touch their rail now: bit `2 k` the left wheel of wheelset `k` (0 the
    /// leading one), bit `2 k + 1` its right wheel; a wheel touches when its contact
    /// force is positive.
    pub fn contacts(&self) -> u64 {
        (0..self.wheelsets.len())
            .filter_map(|k| self.sample_of(k).map(|s| (k, s)))
            .fold(0, |bits, (k, s)| {
                let left = u64::from(s.contact[0].force > 0.0);
                let right = u64::from(s.contact[1].force > 0.0);
                bits | left << (2 * k) | right << (2 * k + 1)
            })
    }

    #[cold]
    fn describe_contact_change(&self, before: u64, now: u64) -> String {
        let changed: Vec<String> = (0..2 * self.wheelsets.len())
            .filter(|b| (before ^ now) >> b & 1 == 1)
            .map(|b| {
                let side = if b % 2 == 0 { "left" } else { "right" };
                let what = if now >> b & 1 == 1 {
                    "came into contact (an impact)"
                } else {
                    "lost contact"
                };
                format!("the {side} wheel of wheelset {} {what}", b / 2 + 1)
            })
            .collect();
        format!("at t = {} s {}", self.time(), changed.join(", "))
    }

    /// Refuses with [`Error::OffTrack`] `n` steps that would carry the leading wheelset
    /// off a fixed track.
    fn check_on_track(&self, n: u64) -> Result<()> {
        if let (TrackState::Discrete(t), None) = (&self.track, &self.window) {
            let len = t.params().running_length();
            let t_end = self.clock.time_after(n);
            let m = &self.motion;
            let end = m.x_ref + m.speed * (t_end - m.t_ref);
            if !(end - self.origin > 0.0 && end - self.origin < len) {
                return Err(Error::OffTrack {
                    position: end,
                    length: len,
                    time: t_end,
                });
            }
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

    /// [`Simulation::advance_to`] that stops after the first step at whose end a wheel
    /// came into contact or lost it ([`Simulation::advance_steps_to_contact_change`]):
    /// the change in words where it stopped early (the time is then
    /// [`Simulation::time`]).
    pub fn advance_to_contact_change(&mut self, plan: StepPlan) -> Result<Option<String>> {
        Ok(self.advance_steps_to_contact_change(plan.steps as u64)?.1)
    }

    /// Advances vehicle and track from `t_j` (s) with the contact forces of the
    /// wheelsets' samples at `t_j`, the leading wheelset at position `x` (m, line
    /// coordinates); then moves an endless track's window if the leading wheelset has
    /// passed its mark.
    #[inline(always)]
    fn advance_with(&mut self, x: f64, time: f64) -> Result<()> {
        let p = self.lead().forces();
        let lim = self.force_limit;
        if !(within(p[0], lim) && within(p[1], lim)) {
            return Err(self.force_diverged(p, time));
        }
        if !self.wheelsets.trailing().is_empty() {
            self.advance_trailing(time)?;
        }
        let dt = self.clock.dt;
        let lead = self.wheelsets.lead_mut();
        lead.extremes.record(p);
        lead.record_accelerations(dt);
        lead.vehicle.step(p);
        if self.shared_side_frames {
            self.share_side_frames();
        }
        if self.carrier.is_some() {
            self.step_carrier();
        }
        match &mut self.track {
            TrackState::Discrete(t) => {
                wheel_loads(
                    x - self.origin,
                    &self.wheelsets,
                    Wheelset::forces,
                    &mut self.loads,
                );
                t.step(&self.loads);
                if !self.sites.is_empty() {
                    for site in &mut self.sites {
                        site.record(t, self.origin);
                    }
                }
            }
            TrackState::Lumped(t) => t.step(self.wheelsets.lead().forces()),
        }
        self.steps += 1;
        self.clock.tick();
        if let Some(w) = &self.window
            && self.position() - self.origin > w.shift_at
        {
            self.move_window()?;
        }
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
        for w in self.wheelsets.iter_mut() {
            match &mut w.vehicle {
                VehicleState::RollPlane(v) => v.change_dt(dt)?,
                VehicleState::AxleBox(link) => link.change_dt(dt)?,
                VehicleState::ConstantLoad(_)
                | VehicleState::External { .. }
                | VehicleState::OnBogie { .. } => {}
                VehicleState::LumpedWheels(_) => {
                    return Err(Error::Unsupported(
                        "changing the step of the lumped wheels".into(),
                    ));
                }
            }
        }
        if let Some(b) = &mut self.carrier {
            b.change_dt(dt)?;
        }
        self.clock.restart(dt);
        self.clear_cache();
        Ok(())
    }

    /// The vehicle that carries several wheelsets (the half-car bogie, the wagons),
    /// when there is one ([`crate::sim::VehicleSpec::Carrier`]).
    pub fn carrier(&self) -> Option<&dyn RailVehicle> {
        self.carrier.as_deref()
    }

    /// With a bogie's side frames over two wheelsets' axle boxes
    /// ([`crate::sim::SideFrameSpec::HalfCar`]: wheelsets 1 and 2, and 3 and 4 with
    /// four): each wheelset's primary forces of the step into its partner's, which they
    /// move through the side frames' pitch.
    #[inline(never)]
    fn share_side_frames(&mut self) {
        for pair in [0, 2] {
            let last = [pair, pair + 1].map(|k| match self.wheelsets.get(k).map(|w| &w.vehicle) {
                Some(VehicleState::AxleBox(link)) => Some(link.last_force()),
                _ => None,
            });
            if let [Some(a), Some(b)] = last {
                for (k, f) in [(pair, b), (pair + 1, a)] {
                    if let Some(VehicleState::AxleBox(link)) =
                        self.wheelsets.get_mut(k).map(|w| &mut w.vehicle)
                    {
                        link.set_partner_force(f);
                    }
                }
            }
        }
    }

    /// Advances the vehicle on several wheelsets one step under the contact forces of
    /// its wheelsets' samples at `t_j` (which moves their wheels: they are its).
    #[inline(never)]
    fn step_carrier(&mut self) {
        if let Some(b) = &mut self.carrier {
            let mut p: Axles = [[0.0; 2]; MAX_AXLES];
            for (pk, w) in p.iter_mut().zip(self.wheelsets.iter()).take(b.wheelsets()) {
                *pk = w.forces();
            }
            b.step(&p);
        }
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
