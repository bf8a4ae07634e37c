//! A simulation built from its scenario: the checks of every parameter, the time step
//! and its stability limit, the endless track's window, the wheelsets and their
//! vehicles, the static start.

use super::clock::{Clock, Stepping};
use super::inputs::InputRates;
use super::motion::{Motion, Window};
use super::simulation::{Simulation, TrackState};
use super::sites::sites;
use super::static_start::{contact_law, static_loads};
use super::vehicle_state::VehicleState;
use super::wheelset::{Wheelset, Wheelsets};
use crate::contact::{ContactLaw, hertz_half_length};
use crate::error::{Error, Result, finite, num, out_of_range, positive};
use crate::limits::{MAX_RAIL_SEGMENTS, MIN_DT_FRACTION, force_limit};
use crate::numerics::CosineSeries;
use crate::sim::Roughness;
use crate::sim::{DEFAULT_DT_FRACTION, Scenario, TrackSpec, TrackWindow, VehicleSpec};
use crate::track::{
    PointLoad, RailEnds, RailProfile, RandomProfile, SimdLevel, Track, TrackParams,
};
use crate::vehicle::{LumpedTrack, LumpedWheels, RailVehicle, RollPlaneVehicle};
use crate::wheel::WheelProfile;
use std::sync::Arc;

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

/// Sets `p.spans` to the window `spec` around wheelsets `d_max` (m) long whose leading
/// one starts at `x0` (m), and places the window: `ceil((ahead + behind + 2 layer +
/// d_max) / a) + 1` spans, node 0 at the whole span `j = ceil((x0 - (L - ahead -
/// layer)) / a)`, so that at least `ahead` (and the layer beyond it) lies ahead of the
/// leading wheelset and `behind` behind the last.
///
/// Errors: `ahead` or `behind` below [`MIN_WINDOW_SIDE`] or one sleeper spacing, or not
/// finite; a layer or its rate out of range; pinned rail ends; a window of more rail
/// segments than [`MAX_RAIL_SEGMENTS`] (named by `track.window.ahead`).
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
    finite("track.window.layer", spec.layer, "m")?;
    if !(0.0..=MAX_WINDOW_SIDE).contains(&spec.layer) {
        return Err(out_of_range(
            "track.window.layer",
            spec.layer,
            format!("0 m <= track.window.layer <= {MAX_WINDOW_SIDE} m"),
        ));
    }
    finite("track.window.exact_memory", spec.exact_memory, "s")?;
    if !(0.0..=MAX_EXACT_MEMORY_S).contains(&spec.exact_memory) {
        return Err(out_of_range(
            "track.window.exact_memory",
            spec.exact_memory,
            format!("0 s <= track.window.exact_memory <= {MAX_EXACT_MEMORY_S} s"),
        ));
    }
    if p.ends != RailEnds::Fixed {
        return Err(Error::Unsupported(
            "a moving window on a track with pinned ends (track.window.ahead > 0 needs the \
             fixed rail ends)"
                .into(),
        ));
    }
    // The absorbing layers lie beyond `ahead` and `behind`.
    let l = spec.layer;
    // Spans of a window whose two sides add up to `sum` (m).
    let spans_for = |sum: f64| ((sum + 2.0 * l + d_max) / a).ceil() as usize + 1;
    let spans = spans_for(spec.ahead + spec.behind);
    // The window's own length, named by its own parameters (the fixed track's
    // track.spans, which it replaces, is not the user's to change here).
    let n = p.nodes_per_span.max(1);
    if spans.saturating_mul(n) > MAX_RAIL_SEGMENTS {
        // The longest sum that fits, to the millimetre below (rounding must not put the
        // limit it names, however it is split between ahead and behind, one span over).
        let fits = |sum: f64| spans_for(sum) <= MAX_RAIL_SEGMENTS / n;
        let mut most = (((MAX_RAIL_SEGMENTS / n).saturating_sub(1) as f64 * a - d_max - 2.0 * l)
            * 1e3)
            .floor()
            / 1e3;
        while most > 0.0 && !fits(most + 1e-6) {
            most = ((most * 1e3).round() - 1.0) / 1e3;
        }
        return Err(out_of_range(
            "track.window.ahead",
            spec.ahead,
            format!(
                "track.window.ahead + track.window.behind <= {} m with track.nodes_per_span \
                 = {n}, track.sleeper_spacing = {} m and the wheelsets {} m apart: the \
                 window's {spans} spans x {n} nodes exceed {MAX_RAIL_SEGMENTS} rail segments \
                 (track.window.behind = {} m)",
                num(most.max(0.0)),
                num(a),
                num(d_max),
                num(spec.behind)
            ),
        ));
    }
    p.spans = spans;
    let len = spans as f64 * a;
    let j = ((x0 - (len - spec.ahead - l)) / a).ceil();
    Ok(Window {
        spec,
        origin_span: j as i64,
        shift_at: len - spec.ahead - l,
        spacing: a,
    })
}

/// The exact ends' memory in steps of `dt` (s) ([`TrackWindow::exact_memory`]), 0 for
/// none.
///
/// Errors: a memory shorter than [`crate::track::MIN_EXACT_MEMORY`] steps or longer than
/// [`crate::track::MAX_EXACT_MEMORY`] steps; exact ends with an absorbing layer, voided
/// sleepers or supports that can lift (the track beyond the window must be the linear
/// track of the thesis).
fn exact_memory_steps(w: &TrackWindow, s: &Scenario, p: &TrackParams, dt: f64) -> Result<usize> {
    let m = w.exact_memory;
    if m == 0.0 {
        return Ok(0);
    }
    let name = "track.window.exact_memory";
    let longest = (MAX_EXACT_MEMORY_S).min(crate::track::MAX_EXACT_MEMORY as f64 * dt);
    let shortest = crate::track::MIN_EXACT_MEMORY as f64 * dt;
    if !(m >= shortest && m <= longest) {
        return Err(out_of_range(
            name,
            m,
            format!(
                "0 (fixed ends), or {} steps ({} s) to {} s",
                crate::track::MIN_EXACT_MEMORY,
                num(shortest),
                num(longest)
            ),
        ));
    }
    let why = if w.layer > 0.0 {
        Some("an absorbing layer (track.window.layer > 0)")
    } else if s.voids.is_some() {
        Some("voided sleepers (the track beyond the window must be linear)")
    } else if p.supports.law == crate::track::SupportLaw::Tensionless {
        Some("supports that can lift (the track beyond the window must be linear)")
    } else {
        None
    };
    if let Some(why) = why {
        return Err(out_of_range(name, m, format!("0 with {why}")));
    }
    Ok((m / dt).round() as usize)
}

/// Longest window side (m) ([`TrackWindow`]).
pub const MAX_WINDOW_SIDE: f64 = 1000.0;

/// The largest memory of exact window ends, [`TrackWindow::exact_memory`] (s): 1 s
/// (69,400 steps at the converged default step; the track's own limit is
/// [`crate::track::MAX_EXACT_MEMORY`] steps).
pub const MAX_EXACT_MEMORY_S: f64 = 1.0;
/// Shortest window side (m) ([`TrackWindow`]): at 4 m a side the reference flat's peak
/// is off by 0.12 % and its force history by 16 % of the static load
/// (`examples/window_study.rs`); shorter windows are further off.
pub const MIN_WINDOW_SIDE: f64 = 4.0;

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
        s.validate()?;
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
        let vehicle = |axle: usize| -> Result<VehicleState> {
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
                VehicleSpec::External { .. } => VehicleState::External {
                    wheel_z: [0.0; 2],
                    rotation: 0.0,
                    since: 0.0,
                    rates: InputRates::default(),
                },
                // A vehicle on several wheelsets ([`VehicleSpec::carrier`]) moves them.
                VehicleSpec::Carrier(_) => VehicleState::OnBogie { axle },
            })
        };
        let (rails, roughness) = random_irregularities(s, static_load);
        let lead = Wheelset::new(s.wheel_radius, &s.flats, 0.0, vehicle(0)?, "")?
            .with_roundness(s.roundness.clone())
            .with_roughness(roughness(0));
        let trailing = s
            .trailing
            .iter()
            .zip(2..)
            .map(|(w, k)| {
                let name = format!("wheelset[{k}].");
                Ok(
                    Wheelset::new(s.wheel_radius, &w.flats, w.offset, vehicle(k - 1)?, &name)?
                        .with_roundness(w.roundness.clone())
                        .with_roughness(roughness(k - 1)),
                )
            })
            .collect::<Result<Vec<_>>>()?;
        let wheelsets = Wheelsets::new(lead, trailing);
        let carrier = carrier_on(s, dt)?;
        let origin = window.map_or(0.0, |w: Window| w.origin());
        let track = match &track_spec {
            TrackSpec::Discrete(p) => {
                p.validate()?;
                let len = p.running_length();
                for w in wheelsets.iter() {
                    let x = w.position(s.start_position) - origin;
                    if !(x > 0.0 && x < len) {
                        return Err(out_of_range(
                            "start_position",
                            s.start_position,
                            format!(
                                "every wheelset on the track's running length, 0 < x < {len} m \
                                 (the last span, to the fixed rail end, carries no wheel; wheelset at \
                                 {} m behind the leading one: {} m; an endless track, \
                                 track.window.ahead > 0, carries wheelsets anywhere)",
                                num(w.offset()),
                                num(x)
                            ),
                        ));
                    }
                }
                let mut t = Track::new(*p, dt)?;
                if let Some(w) = &window {
                    // Checks the rate too, with or without a layer.
                    t.set_absorbing_ends(w.spec.layer, w.spec.layer_rate)?;
                    t.set_exact_ends(exact_memory_steps(&w.spec, s, p, dt)?)?;
                }
                TrackState::Discrete(t)
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
        let irregular = rails.iter().any(RailProfile::is_some)
            || wheelsets.iter().any(Wheelset::is_out_of_round);
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
            carrier,
            shared_side_frames,
            voids: s.voids,
            irregular,
            rails,
        };
        if let (Some(v), None, TrackState::Discrete(t)) = (&sim.voids, &sim.window, &sim.track) {
            // On a fixed track every hanging sleeper must be one of its sleepers.
            let (a, spans) = (t.params().sleeper_spacing, t.params().spans);
            // A run longer than the track has sleepers has no position at all: name the
            // count, not an empty range of positions (issue 38, N15).
            if v.sleepers > spans + 1 {
                return Err(out_of_range(
                    "track.void.sleepers",
                    v.sleepers as f64,
                    format!(
                        "1 <= track.void.sleepers <= {} (the fixed track's sleepers: \
                         track.spans + 1, track.spans = {spans})",
                        spans + 1
                    ),
                ));
            }
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
}

/// The vehicle on several wheelsets of the scenario `s`, stepped with `dt` (s): the
/// half-car bogie on exactly two wheelsets, the trailing one at its wheelbase; the
/// wagon on exactly four, at its wheelbase `a` and bogie centre distance `d` (offsets
/// `a`, `d`, `d + a`). `None` for a vehicle on each wheelset.
///
/// Errors: another number of wheelsets (named `wheelsets`), an offset other than the
/// vehicle's (named `wheelset[k].offset`), the vehicle's own refusals
/// ([`crate::vehicle::CarrierModel::whole`]).
fn carrier_on(s: &Scenario, dt: f64) -> Result<Option<Box<dyn RailVehicle>>> {
    let Some(c) = s.vehicle.carrier() else {
        return Ok(None);
    };
    let (offsets, what) = (c.offsets(), c.name());
    if s.trailing.len() != offsets.len() {
        return Err(out_of_range(
            "wheelsets",
            (s.trailing.len() + 1) as f64,
            format!("{} with {what}", offsets.len() + 1),
        ));
    }
    for ((w, &(x, rule)), k) in s.trailing.iter().zip(&offsets).zip(2..) {
        if (w.offset - x).abs() > 1e-9 * x {
            return Err(out_of_range(
                &format!("wheelset[{k}].offset"),
                w.offset,
                format!("{} m, {rule} in {what}", num(x)),
            ));
        }
    }
    c.whole(dt).map(Some)
}

/// The rails' profiles with what `s.random` draws on them, and a function giving
/// wheelset `k`'s (0 the leading one) drawn wheel roughness `[left, right]`; the patch
/// the roughness is seen through is `s.random`'s, or the Hertz patch under the static
/// wheel load `static_load` `[left, right]` (N).
#[allow(clippy::type_complexity)]
fn random_irregularities(
    s: &Scenario,
    static_load: [f64; 2],
) -> (
    [RailProfile; 2],
    impl Fn(usize) -> [Option<Arc<CosineSeries>>; 2] + '_,
) {
    let r = &s.random;
    let half = move |side: usize, patch: f64| {
        if patch > 0.0 {
            0.5 * patch
        } else {
            hertz_half_length(s.wheel_radius, static_load[side], s.hertz_coefficient)
        }
    };
    let mut rails = s.rails.clone();
    let profile = r.profile.map(|p| p.series());
    for (side, rail) in rails.iter_mut().enumerate() {
        let mut series = profile
            .as_ref()
            .map(|p| p[side].clone())
            .unwrap_or_default();
        if let Some(Roughness {
            rail: Some(sp),
            seed,
            patch_length,
            ..
        }) = &r.roughness
        {
            series = series.joined(&sp.rail(*seed, side, half(side, *patch_length)));
        }
        if !series.is_empty() {
            rail.random = Some(Arc::new(RandomProfile {
                series,
                start: s.start_position,
                ramp: r.profile.map_or(0.0, |p| p.ramp),
            }));
        }
    }
    let wheels = move |k: usize| match &r.roughness {
        Some(Roughness {
            wheel: Some(sp),
            seed,
            patch_length,
            ..
        }) => [0, 1].map(|side| {
            Some(Arc::new(sp.wheel(
                *seed,
                k,
                side,
                s.wheel_radius,
                half(side, *patch_length),
            )))
        }),
        _ => [None, None],
    };
    (rails, wheels)
}
