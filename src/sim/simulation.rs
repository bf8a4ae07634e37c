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
    DISPLACEMENT_LIMIT, HEALTH_CHECK_INTERVAL, MAX_NODE_STEPS_PER_CALL, MAX_WHEELSETS,
    MIN_DT_FRACTION, force_limit, within,
};
use crate::sim::{
    DEFAULT_DT_FRACTION, Scenario, TrackSpec, TrackWindow, VehicleSpec, VoidedSleepers,
};
use crate::track::{PointLoad, RailProfile, SimdLevel, Track, TrackParams};
use crate::vehicle::{HalfCarBogie, LumpedTrack, LumpedWheels, RollPlaneVehicle};
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
    /// The wheelset of the roll-plane vehicle with its primary suspension, the bogie
    /// above it outside ([`crate::vehicle::PrimaryLink`]): the side frames' motion is
    /// the input, the primary forces the output.
    AxleBox(crate::vehicle::PrimaryLink),
    /// A wheelset of the half-car bogie ([`Simulation::bogie`]), which moves its
    /// wheels: their displacements `[left, right]` (m) after the bogie's last step.
    OnBogie {
        /// Wheel-centre displacements `[left, right]` (m).
        wheel_z: [f64; 2],
    },
    /// Wheels moved from outside.
    External {
        /// Wheel-centre displacements `[left, right]` (m), inputs.
        wheel_z: [f64; 2],
        /// Axle rotation angle (rad) given at `since`.
        rotation: f64,
        /// Time (s) at which `rotation` was given; between inputs the axle turns at
        /// `V / R_w`.
        since: f64,
        /// The inputs' time derivatives, when the master gives them (FMI's
        /// `fmi2SetRealInputDerivatives`); zero: the inputs are held.
        rates: InputRates,
    },
}

/// Time derivatives of a wheelset's external inputs: the wheel heights follow
/// `z(t) = z + z' tau + z'' tau^2 / 2` and the axle angle `gamma(t) = gamma + gamma'
/// tau` over the communication step, `tau` from the time they were given, instead of
/// being held (the heights) or turning at `V / R_w` (the angle).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct InputRates {
    /// Time (s) each wheel height `[left, right]` was last given at, with or without
    /// derivatives; it extrapolates from its value then.
    pub z_since: [f64; 2],
    /// `[[z' left, z' right] (m/s), [z'' left, z'' right] (m/s^2)]`.
    pub z: [[f64; 2]; 2],
    /// Whether derivatives of each wheel height `[left, right]` were given.
    pub z_given: [bool; 2],
    /// Whether the axle angle's rate was given (else it turns at `V / R_w`).
    pub rotation_given: bool,
    /// Time (s) the angle's rate was given at.
    pub rotation_since: f64,
    /// The axle angle's rate `gamma'` (rad/s).
    pub rotation: f64,
}

impl InputRates {
    /// Values in a state vector.
    pub(super) const LEN: usize = 11;

    /// Whether the wheel heights move between inputs.
    #[inline(always)]
    pub fn moves(&self) -> bool {
        self.z_given[0] || self.z_given[1]
    }

    /// The wheel heights (m) at time `t` (s) from `z` given at [`InputRates::z_since`].
    #[inline]
    pub(super) fn wheel_z_at(&self, z: [f64; 2], t: f64) -> [f64; 2] {
        [0, 1].map(|i| {
            let tau = t - self.z_since[i];
            z[i] + tau * (self.z[0][i] + 0.5 * tau * self.z[1][i])
        })
    }

    pub(super) fn to_array(self) -> [f64; Self::LEN] {
        let [[a, b], [c, d]] = self.z;
        let flag = |x: bool| f64::from(u8::from(x));
        [
            self.z_since[0],
            self.z_since[1],
            a,
            b,
            c,
            d,
            flag(self.z_given[0]),
            flag(self.z_given[1]),
            flag(self.rotation_given),
            self.rotation_since,
            self.rotation,
        ]
    }

    pub(super) fn from_slice(v: &[f64]) -> InputRates {
        InputRates {
            z_since: [v[0], v[1]],
            z: [[v[2], v[3]], [v[4], v[5]]],
            z_given: [v[6] != 0.0, v[7] != 0.0],
            rotation_given: v[8] != 0.0,
            rotation_since: v[9],
            rotation: v[10],
        }
    }
}

impl VehicleState {
    /// Wheel-centre displacements `[left, right]` (m); `None` for constant loads (the
    /// wheels then ride on the rail).
    #[inline(always)]
    pub(super) fn wheel_z(&self) -> Option<[f64; 2]> {
        match self {
            VehicleState::RollPlane(v) => Some(v.wheel_z()),
            VehicleState::LumpedWheels(v) => Some(v.wheel_z()),
            VehicleState::ConstantLoad(_) => None,
            VehicleState::External { wheel_z, .. } | VehicleState::OnBogie { wheel_z } => {
                Some(*wheel_z)
            }
            VehicleState::AxleBox(link) => Some(link.body().wheel_z()),
        }
    }

    /// Advances the vehicle one step under the contact forces `p` `[left, right]` (N).
    #[inline(always)]
    fn step(&mut self, p: [f64; 2]) {
        match self {
            VehicleState::RollPlane(v) => v.step(p),
            VehicleState::LumpedWheels(v) => v.step(p),
            VehicleState::AxleBox(link) => link.step(p),
            VehicleState::ConstantLoad(_)
            | VehicleState::External { .. }
            | VehicleState::OnBogie { .. } => {}
        }
    }
}

/// The longitudinal motion: the leading wheelset at `x = x_ref + V (t - t_ref)` (m, line
/// coordinates) and axles that roll without slip at `gamma = gamma_ref + V (t - t_ref) /
/// R_w` (rad), the speed `V` (m/s) held since `t_ref` (s). A new speed starts a new
/// piece ([`Simulation::set_speed`]); a constant speed keeps `t_ref = 0`, so the position
/// is `x_0 + V t` exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    pub(super) x_ref: f64,
    pub(super) t_ref: f64,
    pub(super) speed: f64,
    pub(super) rotation_ref: f64,
}

impl Motion {
    /// Values in the state vector.
    pub(super) const LEN: usize = 4;
    pub(super) fn to_array(self) -> [f64; 4] {
        [self.x_ref, self.t_ref, self.speed, self.rotation_ref]
    }
    pub(super) fn from_slice(v: &[f64]) -> Motion {
        Motion {
            x_ref: v[0],
            t_ref: v[1],
            speed: v[2],
            rotation_ref: v[3],
        }
    }
}

/// The window of an endless track as the simulation moves it: the track's node 0 lies
/// at `origin_span` sleeper spans in line coordinates, and the window moves when the
/// leading wheelset passes `shift_at` (m, track coordinates).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Window {
    pub(super) spec: TrackWindow,
    pub(super) origin_span: i64,
    pub(super) shift_at: f64,
    /// Sleeper spacing `a` (m): the window moves by whole spans.
    pub(super) spacing: f64,
}

impl Window {
    /// Line coordinate of the track's node 0 (m).
    pub(super) fn origin(&self) -> f64 {
        self.origin_span as f64 * self.spacing
    }
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
    /// The half-car bogie that moves the two wheelsets ([`VehicleSpec::HalfCar`]).
    pub(super) bogie: Option<Box<HalfCarBogie>>,
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
fn time_step_of(
    s: &Scenario,
    track: &TrackSpec,
    law: &ContactLaw,
    static_load: [f64; 2],
) -> Result<(f64, Option<(f64, String)>)> {
    let critical = match track {
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

/// Sets `p.spans` to the window `spec` around wheelsets `d_max` (m) long whose leading
/// one starts at `x0` (m), and places the window: `ceil((ahead + behind + d_max) / a) +
/// 1` spans, node 0 at the whole span `j = ceil((x0 - (L - ahead)) / a)`, so that at
/// least `ahead` lies ahead of the leading wheelset and `behind` behind the last.
///
/// Errors: `ahead` or `behind` below [`MIN_WINDOW_SIDE`] or one sleeper spacing, or not
/// finite; a window longer than the track may be.
fn window_spans(p: &mut TrackParams, spec: TrackWindow, d_max: f64, x0: f64) -> Result<Window> {
    let a = p.sleeper_spacing;
    positive("track.sleeper_spacing", a, "m")?;
    for (name, v) in [
        ("track.window.ahead", spec.ahead),
        ("track.window.behind", spec.behind),
    ] {
        finite(name, v, "m")?;
        let least = MIN_WINDOW_SIDE.max(a);
        if !(v >= least && v <= MAX_WINDOW_SIDE) {
            return Err(out_of_range(
                name,
                v,
                format!(
                    "{} m <= {name} <= {MAX_WINDOW_SIDE} m (at least {MIN_WINDOW_SIDE} m and \
                     one sleeper spacing; 20 m is converged)",
                    num(least)
                ),
            ));
        }
    }
    let spans = ((spec.ahead + spec.behind + d_max) / a).ceil() as usize + 1;
    p.spans = spans;
    let len = spans as f64 * a;
    let j = ((x0 - (len - spec.ahead)) / a).ceil();
    Ok(Window {
        spec,
        origin_span: j as i64,
        shift_at: len - spec.ahead,
        spacing: a,
    })
}

/// Longest window side (m) ([`TrackWindow`]).
pub const MAX_WINDOW_SIDE: f64 = 1000.0;
/// Shortest window side (m) ([`TrackWindow`]): at 4 m a side the reference flat's peak
/// is off by 0.12 % and its force history by 16 % of the static load
/// (`examples/window_study.rs`); shorter windows are further off.
pub const MIN_WINDOW_SIDE: f64 = 4.0;
/// Largest start position (m) by magnitude: a double resolves 1e-9 m there, well
/// below a step's travel (0.3 mm at 70 km/h), so positions integrate the speed.
pub const MAX_START_POSITION: f64 = 1e7;

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
        // The half-car bogie's wheelbase is the second wheelset's offset here: a refusal
        // names that, the variable a user of the scenario (CoupledSystem) sets.
        if let VehicleSpec::HalfCar(p) = &s.vehicle {
            p.validate().map_err(|e| {
                e.renamed(
                    "vehicle.wheelbase",
                    "wheelset[2].offset",
                    "(the half-car bogie's wheelbase)",
                )
            })?;
        }
        positive("wheel.radius", s.wheel_radius, "m")?;
        finite("speed", s.speed, "m/s")?;
        if s.speed < 0.0 {
            return Err(out_of_range("speed", s.speed, ">= 0 m/s"));
        }
        finite("start_position", s.start_position, "m")?;
        if s.start_position.abs() > MAX_START_POSITION {
            return Err(out_of_range(
                "start_position",
                s.start_position,
                format!(
                    "-{MAX_START_POSITION:e} m <= start_position <= {MAX_START_POSITION:e} m \
                     (positions along the line keep 1e-9 m of resolution there)"
                ),
            ));
        }
        non_negative("solver.dt", s.dt, "s")?;
        non_negative("contact.Kw", s.kw, "N/m/rad")?;
        non_negative("contact.CH", s.hertz_coefficient, "N/m^1.5")?;
        if s.trailing.len() + 1 > MAX_WHEELSETS {
            return Err(out_of_range(
                "wheelsets",
                (s.trailing.len() + 1) as f64,
                format!("1 to {MAX_WHEELSETS} wheelsets"),
            ));
        }
        for (k, w) in s.trailing.iter().enumerate() {
            let name = format!("wheelset[{}].offset", k + 2);
            positive(&name, w.offset, "m")?;
            let before = if k == 0 {
                0.0
            } else {
                s.trailing[k - 1].offset
            };
            // Wheels of the same rail cannot overlap: one wheel diameter apart at least.
            let least = before + 2.0 * s.wheel_radius;
            if w.offset.is_nan() || w.offset < least {
                return Err(out_of_range(
                    &name,
                    w.offset,
                    format!(
                        ">= {} m, the wheelset ahead's offset {} m plus a wheel diameter \
                         (wheelsets in order, the leading one first)",
                        num(least),
                        num(before)
                    ),
                ));
            }
        }
        // The contact law first: its stiffness under the largest force a run reaches
        // enters the stability limit of the track.
        let static_load = static_loads(&s.vehicle)?;
        let law = contact_law(s, static_load)?;
        let mut track_spec = s.track;
        let mut window = None;
        let d_max = s.trailing.last().map_or(0.0, |w| w.offset);
        if let Some(spec) = s.window {
            let TrackSpec::Discrete(p) = &mut track_spec else {
                return Err(Error::Unsupported(
                    "an endless track of the lumped model (it has no rails)".into(),
                ));
            };
            window = Some(window_spans(p, spec, d_max, s.start_position)?);
        }
        let (dt, critical) = time_step_of(s, &track_spec, &law, static_load)?;
        let (frame_inertia, shared_side_frames) = match &s.vehicle {
            VehicleSpec::AxleBox { side_frames, .. } => side_frames.inertia(s)?,
            _ => (crate::vehicle::SideFrameInertia::single(1.0), false),
        };
        let vehicle = || -> Result<VehicleState> {
            Ok(match &s.vehicle {
                VehicleSpec::RollPlane(p) => {
                    VehicleState::RollPlane(RollPlaneVehicle::new(*p, dt)?)
                }
                VehicleSpec::LumpedWheels(p) => {
                    VehicleState::LumpedWheels(LumpedWheels::new(*p, dt)?)
                }
                VehicleSpec::ConstantLoad(p) => VehicleState::ConstantLoad(*p),
                VehicleSpec::AxleBox { vehicle, .. } => VehicleState::AxleBox(
                    crate::vehicle::PrimaryLink::new(vehicle, dt, frame_inertia)?,
                ),
                VehicleSpec::HalfCar(_) => VehicleState::OnBogie { wheel_z: [0.0; 2] },
                VehicleSpec::External { .. } => VehicleState::External {
                    wheel_z: [0.0; 2],
                    rotation: 0.0,
                    since: 0.0,
                    rates: InputRates::default(),
                },
            })
        };
        let lead = Wheelset::new(s.wheel_radius, &s.flats, 0.0, vehicle()?, "")?
            .with_roundness(s.roundness.clone());
        let trailing = s
            .trailing
            .iter()
            .zip(2..)
            .map(|(w, k)| {
                let name = format!("wheelset[{k}].");
                Ok(
                    Wheelset::new(s.wheel_radius, &w.flats, w.offset, vehicle()?, &name)?
                        .with_roundness(w.roundness.clone()),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let wheelsets = Wheelsets::new(lead, trailing);
        let bogie = match &s.vehicle {
            VehicleSpec::HalfCar(p) => Some(Box::new(half_car_on(p, s, dt)?)),
            _ => None,
        };
        let origin = window.map_or(0.0, |w: Window| w.origin());
        let track = match &track_spec {
            TrackSpec::Discrete(p) => {
                p.validate()?;
                let len = p.length();
                for w in wheelsets.iter() {
                    let x = w.position(s.start_position) - origin;
                    if !(x > 0.0 && x < len) {
                        return Err(out_of_range(
                            "start_position",
                            s.start_position,
                            format!(
                                "every wheelset inside the track, 0 < x < {len} m (wheelset at \
                                 {} m behind the leading one: {} m; an endless track, \
                                 track.window.ahead > 0, carries wheelsets anywhere)",
                                num(w.offset()),
                                num(x)
                            ),
                        ));
                    }
                }
                TrackState::Discrete(Track::new(*p, dt)?)
            }
            TrackSpec::Lumped(p) => {
                if wheelsets.len() > 1 {
                    return Err(Error::Unsupported(
                        "several wheelsets on the lumped track (one mass under one wheel)".into(),
                    ));
                }
                TrackState::Lumped(LumpedTrack::new(*p, dt)?)
            }
        };
        let load = PointLoad {
            rail: 0,
            position: 0.0,
            force: 0.0,
        };
        let mut scenario = s.clone();
        scenario.track = track_spec;
        let mut sim = Simulation {
            scenario,
            track,
            loads: vec![load; 2 * wheelsets.len()],
            wheelsets,
            motion: Motion {
                x_ref: s.start_position,
                t_ref: 0.0,
                speed: s.speed,
                rotation_ref: 0.0,
            },
            origin,
            window,
            law,
            clock: Clock::new(dt, Stepping::Grid),
            steps: 0,
            static_load,
            critical_step: critical.map_or(f64::NAN, |c| c.0),
            force_limit: force_limit(static_load),
            simd: SimdLevel::detect(),
            sites: Vec::new(),
            bogie,
            shared_side_frames,
            voids: s.voids,
            irregular: s.rails.iter().any(RailProfile::is_some)
                || s.roundness
                    .iter()
                    .chain(s.trailing.iter().flat_map(|w| &w.roundness))
                    .any(Option::is_some),
            rails: s.rails.clone(),
        };
        if let (Some(v), None, TrackState::Discrete(t)) = (&sim.voids, &sim.window, &sim.track) {
            // On a fixed track every hanging sleeper must be one of its sleepers.
            let (a, spans) = (t.params().sleeper_spacing, t.params().spans);
            let first = (v.position / a).round();
            if !(first >= 0.0 && first + v.sleepers as f64 - 1.0 <= spans as f64) {
                return Err(out_of_range(
                    "track.void.position",
                    v.position,
                    format!(
                        "a run of track.void.sleepers = {} sleepers within the fixed track's {} \
                         sleepers: -{} m <= track.void.position < {} m",
                        v.sleepers,
                        spans + 1,
                        num(0.5 * a),
                        num((spans as f64 + 1.5 - v.sleepers as f64) * a)
                    ),
                ));
            }
        }
        sim.place_voids()?;
        sim.set_static()?;
        sim.check_static_sag()?;
        sim.check_states()?;
        match &sim.track {
            TrackState::Discrete(t) => {
                sim.sites = sites(t, sim.origin, sim.window.is_some(), &s.sites)?
            }
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
    /// Position of the leading wheelset at the current time (m, line coordinates):
    /// `x_0 + V t` at constant speed, the integral of the speed in general
    /// ([`Simulation::set_speed`]).
    #[inline(always)]
    pub fn position(&self) -> f64 {
        let m = &self.motion;
        m.x_ref + m.speed * (self.time() - m.t_ref)
    }
    /// Forward speed (m/s) from now on.
    pub fn speed(&self) -> f64 {
        self.motion.speed
    }
    /// Line coordinate of the track's left end (m): 0 on a fixed track; on an endless
    /// track, where the window begins now.
    pub fn track_origin(&self) -> f64 {
        self.origin
    }
    /// The endless track's window, `None` on a fixed track.
    pub fn window(&self) -> Option<TrackWindow> {
        self.window.map(|w| w.spec)
    }
    /// Axle rotation angle of the axles that roll without slip at the current time
    /// (rad) (2.17): the leading wheelset's, unless its rotation is an input.
    #[inline(always)]
    fn rolling_rotation(&self) -> f64 {
        let m = &self.motion;
        m.rotation_ref + m.speed * (self.time() - m.t_ref) / self.scenario.wheel_radius
    }
    /// Axle rotation angle of wheelset `w` at the current time (rad) (2.17).
    #[inline(always)]
    fn rotation_of(&self, w: &Wheelset) -> f64 {
        match &w.vehicle {
            VehicleState::External {
                rotation,
                since,
                rates,
                ..
            } => {
                if rates.rotation_given {
                    *rotation + rates.rotation * (self.time() - since)
                } else {
                    *rotation
                        + self.motion.speed * (self.time() - since) / self.scenario.wheel_radius
                }
            }
            _ => self.rolling_rotation(),
        }
    }
    /// Axle rotation angle of the leading wheelset at the current time (rad) (2.17).
    pub fn rotation(&self) -> f64 {
        self.rotation_of(self.lead())
    }

    /// Changes the forward speed to `v` (m/s) from the current time: the position and
    /// the rolling axles integrate the speed held over each step (the master's
    /// zero-order hold). Standstill (`v = 0`) is allowed; a speed at which a fixed
    /// track would end within the current step is refused at the next step
    /// ([`Error::OffTrack`]).
    ///
    /// Errors: `v` not finite or outside 0 to 200 m/s (named `speed`).
    pub fn set_speed(&mut self, v: f64) -> Result<()> {
        crate::limits::check("speed", v)?;
        // -0 is 0.
        let v = v + 0.0;
        if v == self.motion.speed {
            return Ok(());
        }
        let now = self.time();
        let (x, gamma) = (self.position(), self.rolling_rotation());
        let speed = self.motion.speed;
        let radius = self.scenario.wheel_radius;
        for w in self.wheelsets.iter_mut() {
            if let VehicleState::External {
                rotation,
                since,
                rates,
                ..
            } = &mut w.vehicle
            {
                if rates.rotation_given {
                    *rotation += rates.rotation * (now - *since);
                } else {
                    *rotation += speed * (now - *since) / radius;
                }
                *since = now;
            }
        }
        self.motion = Motion {
            x_ref: x,
            t_ref: now,
            speed: v,
            rotation_ref: gamma,
        };
        self.clear_cache();
        Ok(())
    }

    /// Rail nodes of the discrete track, both rails (the work of one track step scales
    /// with it); 2 for the lumped track.
    pub fn rail_nodes(&self) -> usize {
        match &self.track {
            TrackState::Discrete(t) => 2 * t.nodes(),
            TrackState::Lumped(_) => 2,
        }
    }

    /// Time (s) at which the leading wheelset reaches the end of a fixed discrete
    /// track at the current speed; `None` for the lumped track, an endless track or
    /// at standstill.
    pub fn time_at_track_end(&self) -> Option<f64> {
        let v = self.motion.speed;
        match &self.track {
            TrackState::Discrete(t) if v > 0.0 && self.window.is_none() => {
                Some(self.time() + (t.params().length() - (self.position() - self.origin)) / v)
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
    fn lead(&self) -> &Wheelset {
        self.wheelsets.lead()
    }

    /// Forgets the cached samples: the time or the inputs changed.
    #[inline]
    pub(super) fn clear_cache(&self) {
        self.wheelsets.clear_cache();
    }

    /// Wheel-centre displacements `[left, right]` (m) of the leading wheelset.
    pub fn wheel_z(&self) -> [f64; 2] {
        self.wheel_z_of(self.lead())
    }

    /// Wheel-centre displacements `[left, right]` (m) of wheelset `w` (on the rails
    /// under constant loads).
    #[inline(always)]
    fn wheel_z_of(&self, w: &Wheelset) -> [f64; 2] {
        if let VehicleState::External { wheel_z, rates, .. } = &w.vehicle
            && rates.moves()
        {
            return rates.wheel_z_at(*wheel_z, self.time());
        }
        match w.vehicle.wheel_z() {
            Some(z) => z,
            None => self.rail_z_under(w.position(self.position()) - self.origin),
        }
    }

    /// Rail displacements under the wheels of the leading wheelset (m) (3.23).
    pub fn rail_z(&self) -> [f64; 2] {
        self.rail_z_under(self.lead().position(self.position()) - self.origin)
    }

    /// Rail displacements (m) under wheels at track position `x` (m).
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
        self.sample_of_wheelset(self.lead())
    }

    /// Everything at the current time for wheelset `k` (0 the leading one), contact
    /// forces included; `None` for a wheelset the simulation does not have.
    pub fn sample_of(&self, k: usize) -> Option<Sample> {
        Some(self.sample_of_wheelset(self.wheelsets.get(k)?))
    }

    /// Wheelset `k`'s sample at the current time if it was already computed (a master
    /// read the outputs since the state last changed), without computing it.
    pub fn computed_sample_of(&self, k: usize) -> Option<Sample> {
        self.wheelsets.get(k)?.cached.get()
    }

    fn sample_of_wheelset(&self, w: &Wheelset) -> Sample {
        if let Some(s) = w.cached.get() {
            return s;
        }
        // `compute_sample` compiled for the SIMD level, as in `step` (a co-simulation
        // master reads the outputs before it steps, so this is where its contact
        // forces are computed).
        let s = at_level(
            self.simd,
            #[inline(always)]
            || self.compute_sample(w),
        );
        w.cached.set(Some(s));
        s
    }

    #[inline(always)]
    fn compute_sample(&self, w: &Wheelset) -> Sample {
        // The step before's contact forces start the contact's solve, as in `step`
        // (the same bits whether a master reads the outputs before stepping or not).
        let mut s = Sample {
            contact: w.latest().contact,
            ..Sample::default()
        };
        (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = self.sample_head(w);
        let compliance = self.compliance_under(s.position - self.origin);
        let shift = self.irregularity_of(w, s.position, s.rotation);
        contact_states(&w.vehicle, &self.law, w.wheels(), compliance, shift, &mut s);
        s
    }

    /// What the rails' profiles and the wheels' out-of-roundness add to the overlaps
    /// `[left, right]` (m) of wheelset `w` at line position `x` (m) and axle rotation
    /// `gamma` (rad): the rail's height there plus the wheel's radius deviation at the
    /// angle that touches the rail (`docs/MODEL.md`, "Measured irregularities");
    /// `None` when there are none.
    #[inline(always)]
    pub(super) fn irregularity_of(&self, w: &Wheelset, x: f64, gamma: f64) -> Option<[f64; 2]> {
        if !self.irregular {
            return None;
        }
        Some([0, 1].map(|i| self.rails[i].at(x).0 + w.radius_deviation(i, gamma)))
    }

    /// The overlap's change `[left, right]` (m) of wheelset `k` (0 the leading one)
    /// from the rails' profiles and its wheels' out-of-roundness now; zeros when there
    /// are none.
    pub fn irregularity(&self, k: usize) -> [f64; 2] {
        self.wheelsets.get(k).map_or([0.0; 2], |w| {
            self.irregularity_of(w, w.position(self.position()), self.rotation_of(w))
                .unwrap_or([0.0; 2])
        })
    }

    /// The rail's local compliance (m/N) under wheels at track position `x` (m):
    /// [`crate::track::Track::shear_compliance`]; 0 on the lumped track.
    #[inline(always)]
    fn compliance_under(&self, x: f64) -> f64 {
        match &self.track {
            TrackState::Discrete(t) => t.shear_compliance(x),
            TrackState::Lumped(_) => 0.0,
        }
    }

    /// The rail's local compliance (m/N) under wheelset `k` (0 the leading one) now, in
    /// series with its contacts ([`crate::track::Track::shear_compliance`]); 0 on the
    /// lumped track and for a wheelset the simulation does not have.
    pub fn contact_compliance_of(&self, k: usize) -> f64 {
        match self.wheelsets.get(k) {
            Some(w) => self.compliance_under(w.position(self.position()) - self.origin),
            None => 0.0,
        }
    }

    /// Everything of wheelset `w`'s sample at the current time but the contact states:
    /// time (s), position (m, line coordinates), axle rotation (rad), wheel and rail
    /// displacements (m).
    #[inline(always)]
    fn sample_head(&self, w: &Wheelset) -> (f64, f64, f64, [f64; 2], [f64; 2]) {
        let time = self.time();
        let m = &self.motion;
        let x = m.x_ref + m.speed * (time - m.t_ref);
        let position = w.position(x);
        let (rotation, wheel_z) = (self.rotation_of(w), self.wheel_z_of(w));
        (
            time,
            position,
            rotation,
            wheel_z,
            self.rail_z_under(position - self.origin),
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
        // step is done (a sample built in a temporary was copied at once, and the
        // copy's wide loads waited on the narrow stores that had just built it).
        if let Some(s) = self.wheelsets.lead().cached.take() {
            self.wheelsets.lead_mut().latest = s;
        } else {
            let head = self.sample_head(self.lead());
            let compliance = self.compliance_under(head.1 - self.origin);
            let shift = self.irregularity_of(self.lead(), head.1, head.2);
            let (wheels, vehicle, s) = self.wheelsets.lead_mut().parts_mut();
            (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = head;
            contact_states(vehicle, &self.law, wheels, compliance, shift, s);
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
    /// their displacements checked as the leading one's.
    #[inline(never)]
    fn sample_trailing(&mut self) -> Result<()> {
        for k in 0..self.wheelsets.trailing().len() {
            let w = &self.wheelsets.trailing()[k];
            let s = match w.cached.take() {
                Some(s) => s,
                None => self.compute_sample(w),
            };
            self.wheelsets.trailing_mut()[k].latest = s;
            if !displacements_within(&s) {
                return Err(self.displacement_diverged(&self.wheelsets.trailing()[k]));
            }
        }
        Ok(())
    }

    /// The wheelsets behind the leading one: their contact forces checked against the
    /// force limit, then their extremes and vehicles advanced.
    #[inline(never)]
    fn advance_trailing(&mut self, time: f64) -> Result<()> {
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
        if let (TrackState::Discrete(t), None) = (&self.track, &self.window) {
            let len = t.params().length();
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
        if self.bogie.is_some() {
            self.step_bogie();
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

    /// Moves the endless track's window forward by the whole spans that put the
    /// leading wheelset back within `ahead` of the window's end.
    #[cold]
    #[inline(never)]
    fn move_window(&mut self) -> Result<()> {
        let x = self.position();
        let (Some(w), TrackState::Discrete(t)) = (&mut self.window, &mut self.track) else {
            return Ok(());
        };
        let beyond = x - self.origin - w.shift_at;
        let m = ((beyond / w.spacing).floor() as usize + 1).min(t.params().spans - 1);
        t.shift_spans(m)?;
        w.origin_span += m as i64;
        self.origin = w.origin();
        self.place_voids()?;
        self.clear_cache();
        Ok(())
    }

    /// Position along the line (m) of the sleeper of the longest lift of any support
    /// since the start ([`Track::longest_lift`]); 0 when none has lifted.
    pub fn longest_lift_position(&self) -> f64 {
        match &self.track {
            TrackState::Discrete(t) => match t.longest_lift() {
                (0.0, _) => 0.0,
                // The sleeper's index along the line times the spacing: the same
                // number for the same sleeper whatever the window's origin.
                (_, i) => {
                    let a = t.params().sleeper_spacing;
                    ((self.origin / a).round() + i as f64) * a
                }
            },
            TrackState::Lumped(_) => 0.0,
        }
    }

    /// Puts the hanging sleepers ([`Scenario::voids`]) where they lie in the track as
    /// it is now (an endless track's window moves over them).
    pub(super) fn place_voids(&mut self) -> Result<()> {
        let (Some(v), TrackState::Discrete(t)) = (&self.voids, &mut self.track) else {
            if self.voids.is_some() {
                return Err(Error::Unsupported(
                    "hanging sleepers on the lumped track (it has no sleepers)".into(),
                ));
            }
            return Ok(());
        };
        let p = t.params();
        let gaps = v.gaps(self.origin, p.spans + 1, p.sleeper_spacing)?;
        t.set_sleeper_gaps(&gaps)
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
        if let Some(b) = &mut self.bogie {
            b.change_dt(dt)?;
        }
        self.clock.restart(dt);
        self.clear_cache();
        Ok(())
    }

    /// The half-car bogie, when it carries the wheelsets
    /// ([`VehicleSpec::HalfCar`]).
    pub fn bogie(&self) -> Option<&HalfCarBogie> {
        self.bogie.as_deref()
    }

    /// With the half-car bogie's side frames over the first two wheelsets' axle boxes
    /// ([`crate::sim::SideFrameSpec::HalfCar`]): each wheelset's primary forces of the
    /// step into the other's, which they move through the side frames' pitch.
    #[inline(never)]
    fn share_side_frames(&mut self) {
        let last = [0, 1].map(|k| match self.wheelsets.get(k).map(|w| &w.vehicle) {
            Some(VehicleState::AxleBox(link)) => Some(link.last_force()),
            _ => None,
        });
        if let [Some(a), Some(b)] = last {
            for (k, f) in [(0, b), (1, a)] {
                if let Some(VehicleState::AxleBox(link)) =
                    self.wheelsets.get_mut(k).map(|w| &mut w.vehicle)
                {
                    link.set_partner_force(f);
                }
            }
        }
    }

    /// Advances the half-car bogie one step under the contact forces of its two
    /// wheelsets' samples at `t_j`, then moves their wheels.
    #[inline(never)]
    fn step_bogie(&mut self) {
        let p = [0, 1].map(|k| self.wheelsets.get(k).map_or([0.0; 2], Wheelset::forces));
        if let Some(b) = &mut self.bogie {
            b.step(p);
        }
        self.sync_bogie_wheels();
    }

    /// The bogie's wheel displacements into its wheelsets.
    pub(super) fn sync_bogie_wheels(&mut self) {
        let Some(b) = &self.bogie else { return };
        let z = b.wheel_z();
        for (k, zk) in z.into_iter().enumerate() {
            if let Some(VehicleState::OnBogie { wheel_z }) =
                self.wheelsets.get_mut(k).map(|w| &mut w.vehicle)
            {
                *wheel_z = zk;
            }
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

/// The half-car bogie of `p` for the scenario `s`, stepped with `dt` (s): it needs
/// exactly two wheelsets, the trailing one at the bogie's wheelbase.
///
/// Errors: another number of wheelsets (named `wheelsets`), a trailing offset other
/// than the wheelbase (named `wheelset[2].offset`), the bogie's own refusals
/// ([`HalfCarBogie::new`]).
fn half_car_on(p: &crate::vehicle::HalfCarParams, s: &Scenario, dt: f64) -> Result<HalfCarBogie> {
    if s.trailing.len() != 1 {
        return Err(out_of_range(
            "wheelsets",
            (s.trailing.len() + 1) as f64,
            "2 with the half-car bogie (vehicle.model = half_car): its two wheelsets",
        ));
    }
    let offset = s.trailing[0].offset;
    if (offset - p.wheelbase).abs() > 1e-9 * p.wheelbase {
        return Err(out_of_range(
            "wheelset[2].offset",
            offset,
            format!("the half-car bogie's wheelbase, {} m", num(p.wheelbase)),
        ));
    }
    HalfCarBogie::new(*p, dt)
}
