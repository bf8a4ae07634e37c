//! The model behind each FMU, as the FMI 2.0 layer sees it ([`Model`] for
//! [`FmuModel`]): building from the variables, inputs (taken in `inputs.rs`), stepping
//! on the model's own grid, health checks of the outputs, and the state vector of FMU
//! states. What the model holds is in `unit.rs`.

use super::Kind;
use super::datum::InputDatum;
use super::derivatives::{name_of, no_derivative, wheel_input};
use super::parameters::{check_table, scenario, vehicle_unit_params, with_tables};
use super::partner::PartnerWatch;
use super::unit::{Engine, FmuModel, Published};
use super::watch::ContactWatch;
use crate::error::{Error, num};
use crate::fmu::fmi2::{Model, OutputFault, StepError, StepFault, StepWarning};
use crate::fmu::vars::{FmuTable, TRAILING, VarSpec, enums, vr};
use crate::limits::{FORCE_LIMIT_FACTOR, force_limit, within};
use crate::sim::{Sample, Simulation, TrackSpec, VehicleState, VehicleUnit};
use std::sync::Arc;

/// TrackContact's automatic step (`solver.dt = 0`) fitted to the master's first
/// communication step `h` (s): the step nearest the automatic one (at most 0.1 % longer)
/// that `h` is a whole multiple of, so that the track's grid meets the master's points (a step between
/// grid points cost 3 to 6 % on the peak); `None` when `h` already is a multiple, when
/// `solver.dt` was given, or when the fitted step would be below half the automatic one
/// (a communication step that short warns instead).
fn fitted_step(sim: &Simulation, h: f64) -> Option<f64> {
    let dt = sim.dt();
    if sim.scenario().dt != 0.0 || h.is_nan() || h <= 0.0 {
        return None;
    }
    let ratio = h / dt;
    if (ratio - ratio.round()).abs() <= 1e-9 * ratio.max(1.0) {
        return None;
    }
    // The nearest whole number of steps, unless that lengthens the step by more than
    // 0.1 % (the automatic step is 0.9 of the critical one, so that stays stable).
    let mut n = ratio.round().max(1.0);
    if h / n > 1.001 * dt {
        n = ratio.ceil();
    }
    let fitted = h / n;
    (fitted >= 0.5 * dt).then_some(fitted)
}

impl FmuModel {
    /// The refusal of a force `x` (N) beyond the force limit.
    #[cold]
    #[inline(never)]
    fn force_fault(&self, spec: &VarSpec, x: f64, time: f64) -> OutputFault {
        let axle_box = self
            .simulation()
            .is_some_and(|s| matches!(s.vehicle(), VehicleState::AxleBox(_)));
        let cause = match self.kind {
            Kind::TrackContact if axle_box => {
                "likely the side-frame inputs diverged: a communication step beyond the \
                 bogie model's stable step (the primary dampers against the side frames), \
                 or side frames far from the axle boxes"
            }
            Kind::TrackContact => {
                "likely the wheel inputs press the wheel into the rail far beyond a running \
                 wheel's overlap"
            }
            _ => "the run diverged, or its parameters are far from a railway",
        };
        // The input datum's offsets, where they may explain it.
        let datum = match self.kind {
            Kind::TrackContact => self.datum.explain(axle_box),
            _ => None,
        };
        let datum = datum.map_or(String::new(), |d| format!("; {d}"));
        OutputFault {
            message: format!(
                "`{}` = {} N at t = {time} s is beyond {} N ({FORCE_LIMIT_FACTOR} times the \
                 static wheel load), which no physical run reaches: {cause}{datum}",
                spec.name,
                num(x),
                num(self.force_limit),
            ),
            stops_run: self.kind != Kind::TrackContact,
        }
    }
}

impl Model for FmuModel {
    const CALCULATED: usize = Published::LEN;

    fn read_string(spec: &crate::fmu::vars::VarSpec, value: &str) -> Result<Arc<str>, Error> {
        check_table(spec.name, value)
    }

    fn check_real(spec: &crate::fmu::vars::VarSpec, value: f64) -> Result<(), Error> {
        crate::limits::check(spec.name, value).map(|_| ())
    }

    fn build(
        table: &'static FmuTable,
        values: &[f64],
        contents: &[Arc<str>],
    ) -> Result<Self, Error> {
        let kind = Kind::from_guid(table.guid).ok_or_else(|| {
            Error::Unsupported(format!("no model for the FMU {}", table.model_identifier))
        })?;
        let (engine, published) = match kind {
            Kind::Vehicle(_) => {
                let p = vehicle_unit_params(kind, values);
                let u = VehicleUnit::new(&p)?;
                let published = Published {
                    static_load: u.static_load(),
                    static_wheel_z: p.static_wheel_z,
                    trailing_static_wheel_z: p.trailing_static_wheel_z,
                    step: u.dt_base(),
                    critical_step: u.critical_step(),
                    kw_used: 0.0,
                };
                (Engine::Vehicle(Box::new(u)), published)
            }
            Kind::TrackContact | Kind::CoupledSystem => {
                let sim = Simulation::new(&with_tables(scenario(kind, values), contents)?)?;
                let mut trailing_static_wheel_z = [[0.0; 2]; TRAILING];
                for (z, k) in trailing_static_wheel_z.iter_mut().zip(1..) {
                    if let Some(s) = sim.sample_of(k) {
                        *z = s.wheel_z;
                    }
                }
                let published = Published {
                    static_load: sim.static_load(),
                    static_wheel_z: sim.wheel_z(),
                    trailing_static_wheel_z,
                    step: sim.dt(),
                    critical_step: sim.critical_step(),
                    kw_used: sim.contact_law().kw,
                };
                (Engine::Sim(Box::new(sim)), published)
            }
        };
        let datum = match &engine {
            Engine::Sim(sim) if kind == Kind::TrackContact => {
                let n = sim.wheelsets().len();
                let statics = (0..n)
                    .map(|k| match sim.side_frames_of(k) {
                        Some((z, _)) => z,
                        None => sim.sample_of(k).map_or([0.0; 2], |s| s.wheel_z),
                    })
                    .collect();
                // The FMI layer holds the enumeration to its items (its range, at set).
                let relative = match enums::input_datum::Item::of(values[vr::INPUTS_DATUM as usize])
                    .expect("inputs.datum is one of its items")
                {
                    enums::input_datum::Item::FirstStep => true,
                    enums::input_datum::Item::Absolute => false,
                };
                InputDatum::new(relative, statics)
            }
            _ => InputDatum::new(false, Vec::new()),
        };
        let watch = match &engine {
            Engine::Sim(sim) => ContactWatch::new(sim.wheelsets().len()),
            Engine::Vehicle(_) => ContactWatch::new(0),
        };
        // vehicle.sideframe.source = auto with nothing to fit: said at initialisation.
        let (partner, unused_auto) = match &engine {
            Engine::Sim(sim) if kind == Kind::TrackContact => {
                // The FMI layer holds the enumeration to its items (its range, at set).
                let auto = match enums::side_frame_source::Item::of(
                    values[vr::VEHICLE_SIDEFRAME_SOURCE as usize],
                )
                .expect("vehicle.sideframe.source is one of its items")
                {
                    enums::side_frame_source::Item::Configured => false,
                    enums::side_frame_source::Item::Auto => true,
                };
                let partner = PartnerWatch::new(sim, auto)?;
                let unused = auto && partner.is_none();
                (partner, unused)
            }
            _ => (None, false),
        };
        let spans = values[vr::TRACK_SPANS as usize];
        let default_spans = table.var(vr::TRACK_SPANS).map(|v| v.start);
        let unused_spans = match &engine {
            Engine::Sim(sim) if sim.scenario().window.is_some() => {
                (Some(spans) != default_spans).then_some(spans)
            }
            _ => None,
        };
        Ok(FmuModel {
            kind,
            engine,
            force_limit: force_limit(published.static_load),
            published,
            last_step: 0.0,
            datum,
            watch,
            partner,
            unused_auto,
            master_end: 0.0,
            started: false,
            off_grid_steps: 0,
            unused_spans,
        })
    }

    fn calculated(&self) -> Vec<f64> {
        self.published.to_array().to_vec()
    }

    /// TrackContact: the wheel heights when one of them changed, the axle rotation
    /// when it changed (not at every step: the track turns the axle on at `V / R_w`
    /// from the last rotation it was given, so setting a wheel height alone leaves it
    /// turning). RollPlaneVehicle: the contact forces.
    fn set_inputs(&mut self, values: &[f64], changed: &[u32]) -> Result<(), Error> {
        self.take_inputs(values, changed)
    }

    /// TrackContact's wheel heights not set by the master: the static heights of the
    /// wheelset's wheels, so that an unconnected wheel starts at rest.
    fn input_at_rest(&self, r: u32) -> Option<f64> {
        self.rest_input(r)
    }

    type Outputs = Option<Sample>;

    fn outputs(&self) -> Option<Sample> {
        self.simulation().map(Simulation::sample)
    }

    fn output(&self, sample: &Option<Sample>, vr: u32) -> f64 {
        self.output_value(vr, sample.as_ref())
    }

    /// A force beyond [`FORCE_LIMIT_FACTOR`] times the static wheel load (at least 2 MN)
    /// is refused; for the FMUs whose forces are their own state (not TrackContact's,
    /// which come back with other inputs) it stops the run.
    #[inline]
    fn check_output(&self, spec: &VarSpec, x: f64, time: f64) -> Result<(), OutputFault> {
        if within(x, self.force_limit) || spec.unit != "N" {
            Ok(())
        } else {
            Err(self.force_fault(spec, x, time))
        }
    }

    /// `stopTime` beyond the time the wheel reaches the end of the track; `track.spans`
    /// set on the endless track, which does not use it.
    fn initialised_warning(&self, start: f64, stop: Option<f64>) -> Option<String> {
        let spans = self.unused_spans.map(|n| {
            format!(
                "track.spans = {n} is not used: the endless track (track.window.ahead > 0, \
                 the default since issue 29) sets its own length; track.window.ahead = 0 \
                 gives the fixed track of track.spans spans"
            )
        });
        let auto = self.unused_auto.then(|| {
            "vehicle.sideframe.source = auto is not used: TrackContact fits side frames only \
             at the axle boxes (interface = axle_box) under the side frames it carries \
             (vehicle.model = roll_plane, half_car or wagon; nothing with two_axle)"
                .to_string()
        });
        // The fixed track's stop time and the endless track's spans never meet.
        spans
            .or(auto)
            .or_else(|| self.unreachable_stop(start, stop))
    }

    /// The track-carrying FMUs step on their fixed grid `t_k = k solver.step` and stop
    /// at the grid point nearest `end` (`k = round(end / solver.step)`): a step within
    /// the master's clock rounding of a whole multiple of `solver.step` runs as that many
    /// steps, the internal step never changes (the explicit scheme is not stable under
    /// every sequence of step changes near its limit), and the model time never drifts
    /// from the master's by more than half a step. RollPlaneVehicle cuts the step into
    /// equal steps (see [`VehicleUnit::advance`]); both units refuse more work than one call
    /// may do before anything moves ([`Simulation::plan_to`], [`VehicleUnit::plan_to`]). CoupledSystem has no inputs: the
    /// sample at the end of the step is final, so a value beyond the health bounds
    /// there fails this step.
    fn advance_to(&mut self, end: f64, clock: f64) -> Result<(), StepError> {
        self.advance(end, clock, false).map(|_| ())
    }

    /// A track-carrying model stops after the internal step at whose end a wheel came
    /// into contact or lost it ([`crate::sim::Simulation::advance_to_contact_change`]);
    /// a vehicle's FMU, which sees forces, not contact, never stops early.
    fn advance_to_event(
        &mut self,
        end: f64,
        clock: f64,
    ) -> Result<Option<(f64, String)>, StepError> {
        self.advance(end, clock, true)
    }

    fn step_fault(e: &Error) -> StepFault {
        match e {
            Error::OffTrack { .. } => StepFault::Ended,
            Error::Diverged { .. } | Error::NonFinite { .. } => StepFault::Stopped,
            _ => StepFault::Refused,
        }
    }

    /// When the wheel is within [`END_ZONE_SPANS`](super::END_ZONE_SPANS) sleeper spans of the fixed rail end,
    /// where the end's reflections raise the impact forces (by 20 to 35 % within the
    /// last span, table 4.4); for the vehicles with the axle-box interface, a
    /// communication step above the Jacobi estimate of [`VehicleUnit::exchange_limits`]; for
    /// TrackContact at the contact interface, what its contact watch sees (`watch.rs`); for a vehicle's
    /// first step, forces off its forces at rest.
    fn step_warning(&mut self, time: f64, at_stop: bool) -> Option<StepWarning> {
        self.warning_after_step(time, at_stop)
    }

    /// TrackContact at the axle boxes: the fitted side frames taken
    /// (`vehicle.sideframe.source = auto`).
    fn take_events(&mut self) -> Vec<String> {
        self.partner
            .as_mut()
            .map_or_else(Vec::new, |p| p.take_events())
    }

    /// The engine's state, then TrackContact's input datum.
    fn state_vector(&self) -> Result<Vec<f64>, Error> {
        let mut v = match &self.engine {
            Engine::Vehicle(u) => u.state_vector(),
            Engine::Sim(sim) => sim.state_vector()?,
        };
        v.extend(self.datum.state());
        Ok(v)
    }

    fn set_state_vector(&mut self, v: &[f64]) -> Result<(), Error> {
        let n = self.datum.state_len();
        let Some(split) = v.len().checked_sub(n) else {
            return Err(crate::error::out_of_range(
                "state length",
                v.len() as f64,
                format!("at least {n} values"),
            ));
        };
        let (engine, datum) = v.split_at(split);
        let mut restored = self.datum.clone();
        restored.restore(datum)?;
        match &mut self.engine {
            Engine::Vehicle(u) => u.set_state_vector(engine)?,
            Engine::Sim(sim) => sim.set_state_vector(engine)?,
        }
        self.datum = restored;
        self.watch.restart();
        if let Some(p) = &mut self.partner {
            p.restart();
        }
        if let Engine::Sim(sim) = &self.engine {
            self.master_end = sim.time();
            // The step in use, fitted to a master's first step or not.
            self.published.step = sim.dt();
        }
        Ok(())
    }

    /// TrackContact (contact interface): the wheel heights' derivatives of order 1 and
    /// 2, the axle angle's of order 1 (its rate); the inputs of a wheelset the model
    /// does not have are kept unused.
    fn set_input_derivative(&mut self, r: u32, order: i32, value: f64) -> Result<(), Error> {
        let Engine::Sim(sim) = &mut self.engine else {
            return Err(no_derivative(r));
        };
        if self.kind != Kind::TrackContact || matches!(sim.vehicle(), VehicleState::AxleBox(_)) {
            return Err(no_derivative(r));
        }
        let Some((k, which)) = wheel_input(r) else {
            return Err(no_derivative(r));
        };
        // Checked whether or not the model has the wheelset.
        let name = name_of(r);
        let order = order.max(0) as usize;
        match which {
            2 => Simulation::check_rotation_rate(&name, order, value)?,
            _ => Simulation::check_wheel_rate(&name, order, value)?,
        }
        if k >= sim.wheelsets().len() {
            return Ok(());
        }
        match which {
            2 => sim.set_rotation_rate_of(k, value),
            side => sim.set_wheel_rate_of(k, side, order, value),
        }
    }

    /// TrackContact: the derivatives the replaced model's wheels had (a parameter set
    /// after them in initialization mode rebuilt the model).
    fn carry_inputs_from(&mut self, old: &Self) {
        if let (Engine::Sim(sim), Engine::Sim(before)) = (&mut self.engine, &old.engine) {
            sim.carry_input_rates_from(before);
        }
    }

    /// RollPlaneVehicle, HalfCarBogie and Wagon, first order: the wheel-centre and
    /// side-frame velocities (backward differences over the last step) and the axle's
    /// rate `speed / wheel.radius`.
    fn output_derivative(&self, r: u32, order: i32) -> Result<f64, Error> {
        self.vehicle_output_derivative(r, order)
    }

    /// TrackContact, every pair its model description declares. Contact interface:
    /// the contact forces and overlaps of each wheelset with respect to its wheel
    /// heights exactly (the contact stiffness `k`,
    /// [`crate::contact::ContactLaw::stiffness_at`], in series with the rail's local
    /// compliance `c` under the wheel ([`crate::track::Track::shear_compliance`]):
    /// `dP/dz = -k / (1 + c k)`; `d delta/dz = -1 / (1 + c k)`); the forces with respect to the axle angle, and the patch's front and rear
    /// angles and length with respect to either input, by central differences of the
    /// law (1e-9 m, 1e-7 rad); the extremes follow the force where it is the extreme
    /// now, else 0. Axle boxes: the primary forces with respect to their side frame's
    /// displacement and velocity exactly (`-K_1`, `-C_1`). Every pair the model
    /// description does not declare is 0; before the first step, the displacement
    /// inputs stand for the static state (`inputs.datum = first_step`): 0.
    fn partial_derivative(&self, unknown: u32, known: u32) -> Result<f64, Error> {
        self.directional_derivative(unknown, known)
    }

    fn model_time(&self) -> (f64, f64) {
        match &self.engine {
            Engine::Vehicle(u) => (u.time() + u.carried(), 0.0),
            Engine::Sim(sim) => (sim.time(), 0.5 * sim.dt()),
        }
    }
}

impl FmuModel {
    /// [`Model::advance_to`], stopping at a change of contact when `early`
    /// ([`Model::advance_to_event`]).
    fn advance(
        &mut self,
        end: f64,
        clock: f64,
        early: bool,
    ) -> Result<Option<(f64, String)>, StepError> {
        let mut event = None;
        match &mut self.engine {
            Engine::Sim(sim) => {
                if self.kind == Kind::TrackContact
                    && self.master_end == 0.0
                    && sim.time() == 0.0
                    && let Some(dt) = fitted_step(sim, end)
                {
                    sim.change_dt(dt)?;
                    self.published.step = dt;
                }
                let plan = sim.plan_to(end, clock).map_err(StepError::TooMuchWork)?;
                if let Some(p) = &mut self.partner {
                    p.before_step(sim, self.last_step);
                }
                let r = if early {
                    sim.advance_to_contact_change(plan)
                } else {
                    sim.advance_to(plan).map(|()| None)
                };
                let end = match r {
                    Ok(Some(what)) => {
                        let t = sim.time();
                        event = Some((t, what));
                        t
                    }
                    Ok(None) => end,
                    Err(mut e) => {
                        // A run beyond the health bounds that the input datum may explain
                        // names it (issue 38, N5).
                        let axle_box = matches!(sim.vehicle(), VehicleState::AxleBox(_));
                        if let (Error::Diverged { cause, .. }, Kind::TrackContact) =
                            (&mut e, self.kind)
                            && let Some(d) = self.datum.explain(axle_box)
                        {
                            cause.push_str("; ");
                            cause.push_str(&d);
                        }
                        return Err(e.into());
                    }
                };
                // The master's step (its clock, not the track's grid).
                self.last_step = end - self.master_end;
                self.master_end = end;
                self.datum.fix();
                if let Some(p) = &mut self.partner {
                    p.after_step(sim);
                }
                if self.kind == Kind::CoupledSystem {
                    sim.check_sample()?;
                }
            }
            Engine::Vehicle(u) => {
                let plan = u.plan_to(end, clock).map_err(StepError::TooMuchWork)?;
                self.last_step = end - (u.time() + u.carried());
                u.advance_to(plan)?;
            }
        }
        Ok(event)
    }

    /// `stopTime` beyond the time the wheel reaches the end of the fixed track.
    fn unreachable_stop(&self, start: f64, stop: Option<f64>) -> Option<String> {
        let (stop, sim) = (stop?, self.simulation()?);
        let t_end = sim.time_at_track_end()?;
        if stop - start < t_end {
            return None;
        }
        let s = sim.scenario();
        let spans = match &s.track {
            TrackSpec::Discrete(t) => {
                ((s.start_position + s.speed * (stop - start)) / t.sleeper_spacing).ceil() + 2.0
            }
            TrackSpec::Lumped(_) => f64::NAN,
        };
        Some(format!(
            "stopTime = {stop} s cannot be reached: the wheel reaches the end of the track's \
             running length (its last sleeper but one) at t = {} s, where fmi2DoStep returns fmi2Discard; track.spans >= {spans} reaches \
             stopTime, and the endless track (track.window.ahead > 0, the default; 20 m is \
             the converged window) any stopTime",
            start + t_end
        ))
    }
}
