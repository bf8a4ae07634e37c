//! The FMI 2.0 co-simulation layer: an [`Instance`] per FMU instance (state machine,
//! variable access through the generated table, model building, stepping, FMU
//! states) in plain Rust, and [`ffi`], the thin C boundary that only converts
//! pointers, catches panics and forwards to it.
//!
//! Three FMUs share one shared library; `fmi2Instantiate` picks the model from the
//! GUID, which identifies exactly one of them.

pub mod ffi;
pub mod vars;

use crate::contact::ContactModel;
use crate::error::Error;
use crate::error::num;
use crate::profile::{FlatShape, FlatSpec};
use crate::sim::{
    Sample, Scenario, Simulation, TrackSpec, VehicleSpec, VehicleState, VehicleUnit,
    VehicleUnitParams,
};
use crate::track::{RailEnds, RailSection, TrackParams};
use crate::vehicle::RollPlaneParams;
use vars::{Causality, FLAT_VRS, FmuTable, N_VR, VarSpec, VarType, enums, vr};

/// `fmi2Status`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
#[repr(i32)]
pub enum Status {
    /// `fmi2OK`
    Ok = 0,
    /// `fmi2Warning`
    Warning = 1,
    /// `fmi2Discard`
    Discard = 2,
    /// `fmi2Error`
    Error = 3,
    /// `fmi2Fatal`
    Fatal = 4,
    /// `fmi2Pending`
    Pending = 5,
}

/// A refused call: the status to return and the message already logged.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// Status returned to the master.
    pub status: Status,
    /// Message sent to the logger.
    pub message: String,
}

/// Result of an FMI call.
pub type FmiResult<T = ()> = std::result::Result<T, Refusal>;

/// Log categories, in the order of the model description.
pub const LOG_CATEGORIES: [&str; 4] = [
    "logStatusError",
    "logStatusWarning",
    "logCalls",
    "logEvents",
];

/// Which of the three FMUs an instance is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Track and contact, wheels as inputs.
    TrackContact,
    /// Roll-plane vehicle, contact forces as inputs.
    RollPlaneVehicle,
    /// The whole model.
    CoupledSystem,
}

impl Kind {
    /// The FMU with this GUID.
    pub fn from_guid(guid: &str) -> Option<Kind> {
        [
            Kind::TrackContact,
            Kind::RollPlaneVehicle,
            Kind::CoupledSystem,
        ]
        .into_iter()
        .find(|k| k.table().guid == guid)
    }
    /// Variable table of this FMU.
    pub fn table(self) -> &'static FmuTable {
        match self {
            Kind::TrackContact => &vars::TRACK_CONTACT,
            Kind::RollPlaneVehicle => &vars::ROLL_PLANE_VEHICLE,
            Kind::CoupledSystem => &vars::COUPLED_SYSTEM,
        }
    }
}

/// States of the FMI 2.0 co-simulation state machine (section 4.2.4 of the standard).
/// `stepInProgress` and `stepCanceled` do not occur: `fmi2DoStep` is synchronous. The
/// discriminants are stored in serialized FMU states.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum Phase {
    /// After `fmi2Instantiate` or `fmi2Reset`.
    Instantiated = 0,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initialization = 1,
    /// Stepping.
    StepComplete = 2,
    /// After `fmi2Terminate`.
    Terminated = 3,
    /// After `fmi2DoStep` returned `fmi2Discard` because the model ended the run (the
    /// wheel reached the end of the track, `fmi2Terminated` status true): outputs can
    /// be read and `fmi2Terminate` called, but no further step is taken.
    StepFailed = 4,
    /// After an internal error: only `fmi2Reset`, `fmi2FreeInstance`, FMU states and
    /// reads for debugging.
    Error = 5,
}

impl Phase {
    /// The phase of a serialized state.
    fn from_u8(p: u8) -> Option<Phase> {
        [
            Phase::Instantiated,
            Phase::Initialization,
            Phase::StepComplete,
            Phase::Terminated,
            Phase::StepFailed,
            Phase::Error,
        ]
        .into_iter()
        .find(|x| *x as u8 == p)
    }
}

/// The FMI 2.0 co-simulation functions, in the order of [`CALLS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[allow(missing_docs)]
pub enum Call {
    GetTypesPlatform,
    GetVersion,
    SetDebugLogging,
    Instantiate,
    FreeInstance,
    SetupExperiment,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetReal,
    GetInteger,
    GetBoolean,
    GetString,
    SetReal,
    SetInteger,
    SetBoolean,
    SetString,
    GetFMUstate,
    SetFMUstate,
    FreeFMUstate,
    SerializedFMUstateSize,
    SerializeFMUstate,
    DeSerializeFMUstate,
    GetDirectionalDerivative,
    SetRealInputDerivatives,
    GetRealOutputDerivatives,
    DoStep,
    CancelStep,
    GetStatus,
    GetRealStatus,
    GetIntegerStatus,
    GetBooleanStatus,
    GetStringStatus,
}

/// Where a function may be called.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Allowed {
    /// Not called on an instance (`fmi2GetTypesPlatform`, `fmi2GetVersion`,
    /// `fmi2Instantiate`).
    NoInstance,
    /// In these phases.
    In(&'static [Phase]),
    /// Never: refused in every phase, for this reason.
    Unsupported(&'static str),
}

use Phase::{
    Error as Err_, Initialization as Ini, Instantiated as Ins, StepComplete as Stc,
    StepFailed as Stf, Terminated as Ter,
};

/// Every phase.
const ALL: &[Phase] = &[Ins, Ini, Stc, Stf, Ter, Err_];
/// Where values can be read (`fmi2GetXXX`; after a failed step and in Error for
/// debugging only).
const READ: &[Phase] = &[Ini, Stc, Stf, Ter, Err_];
/// Where values can be written (`fmi2SetXXX`).
const WRITE: &[Phase] = &[Ins, Ini, Stc];
/// Where the status functions answer.
const STATUS: &[Phase] = &[Stc, Stf, Ter];

/// The one table of the state machine: each function, its C name, and the phases it
/// is allowed in, after the FMI 2.0 co-simulation state table (as the Reference-FMUs
/// masks, without the phases these FMUs never enter). The C layer checks it before
/// every call ([`Instance::check`]).
#[rustfmt::skip]
pub const CALLS: [(Call, &str, Allowed); 34] = [
    (Call::GetTypesPlatform, "fmi2GetTypesPlatform", Allowed::NoInstance),
    (Call::GetVersion, "fmi2GetVersion", Allowed::NoInstance),
    (Call::SetDebugLogging, "fmi2SetDebugLogging", Allowed::In(ALL)),
    (Call::Instantiate, "fmi2Instantiate", Allowed::NoInstance),
    (Call::FreeInstance, "fmi2FreeInstance", Allowed::In(ALL)),
    (Call::SetupExperiment, "fmi2SetupExperiment", Allowed::In(&[Ins])),
    (Call::EnterInitializationMode, "fmi2EnterInitializationMode", Allowed::In(&[Ins])),
    (Call::ExitInitializationMode, "fmi2ExitInitializationMode", Allowed::In(&[Ini])),
    (Call::Terminate, "fmi2Terminate", Allowed::In(&[Stc, Stf])),
    (Call::Reset, "fmi2Reset", Allowed::In(ALL)),
    (Call::GetReal, "fmi2GetReal", Allowed::In(READ)),
    (Call::GetInteger, "fmi2GetInteger", Allowed::In(READ)),
    (Call::GetBoolean, "fmi2GetBoolean", Allowed::In(READ)),
    (Call::GetString, "fmi2GetString", Allowed::In(READ)),
    (Call::SetReal, "fmi2SetReal", Allowed::In(WRITE)),
    (Call::SetInteger, "fmi2SetInteger", Allowed::In(WRITE)),
    (Call::SetBoolean, "fmi2SetBoolean", Allowed::In(WRITE)),
    (Call::SetString, "fmi2SetString", Allowed::In(WRITE)),
    (Call::GetFMUstate, "fmi2GetFMUstate", Allowed::In(ALL)),
    (Call::SetFMUstate, "fmi2SetFMUstate", Allowed::In(ALL)),
    (Call::FreeFMUstate, "fmi2FreeFMUstate", Allowed::In(ALL)),
    (Call::SerializedFMUstateSize, "fmi2SerializedFMUstateSize", Allowed::In(ALL)),
    (Call::SerializeFMUstate, "fmi2SerializeFMUstate", Allowed::In(ALL)),
    (Call::DeSerializeFMUstate, "fmi2DeSerializeFMUstate", Allowed::In(ALL)),
    (
        Call::GetDirectionalDerivative,
        "fmi2GetDirectionalDerivative",
        Allowed::Unsupported("providesDirectionalDerivative is false"),
    ),
    (
        Call::SetRealInputDerivatives,
        "fmi2SetRealInputDerivatives",
        Allowed::Unsupported("canInterpolateInputs is false; inputs are held over a step"),
    ),
    (
        Call::GetRealOutputDerivatives,
        "fmi2GetRealOutputDerivatives",
        Allowed::Unsupported("maxOutputDerivativeOrder is 0"),
    ),
    (Call::DoStep, "fmi2DoStep", Allowed::In(&[Stc])),
    (
        Call::CancelStep,
        "fmi2CancelStep",
        Allowed::Unsupported("fmi2DoStep is synchronous and never returns fmi2Pending"),
    ),
    (
        Call::GetStatus,
        "fmi2GetStatus",
        Allowed::Unsupported("fmi2DoStep is synchronous and never returns fmi2Pending"),
    ),
    (Call::GetRealStatus, "fmi2GetRealStatus", Allowed::In(STATUS)),
    (
        Call::GetIntegerStatus,
        "fmi2GetIntegerStatus",
        Allowed::Unsupported("FMI 2.0 defines no integer status"),
    ),
    (Call::GetBooleanStatus, "fmi2GetBooleanStatus", Allowed::In(STATUS)),
    (
        Call::GetStringStatus,
        "fmi2GetStringStatus",
        Allowed::Unsupported("fmi2PendingStatus never applies: steps are synchronous"),
    ),
];

impl Call {
    /// The C name (`fmi2DoStep`).
    pub fn name(self) -> &'static str {
        CALLS[self as usize].1
    }
    /// Where it may be called.
    pub fn allowed(self) -> Allowed {
        CALLS[self as usize].2
    }
    /// The function with this C name.
    pub fn from_name(name: &str) -> Option<Call> {
        CALLS.iter().find(|c| c.1 == name).map(|c| c.0)
    }
}

/// The running model behind an instance.
#[derive(Debug, Clone)]
enum Model {
    /// Track and contact (a simulation with external wheels), or the whole system.
    Sim(Box<Simulation>),
    /// The vehicle.
    Vehicle(Box<VehicleUnit>),
}

/// Values computed when the model is built, published as calculated parameters.
#[derive(Debug, Clone, Copy, Default)]
struct Published {
    static_load: [f64; 2],
    static_wheel_z: [f64; 2],
    step: f64,
    critical_step: f64,
    kw_used: f64,
}

impl Published {
    /// The values in the order FMU states store them.
    fn to_array(self) -> [f64; 7] {
        let [l, r] = self.static_load;
        let [zl, zr] = self.static_wheel_z;
        [l, r, zl, zr, self.step, self.critical_step, self.kw_used]
    }

    /// The inverse of [`Published::to_array`].
    fn from_array([l, r, zl, zr, step, critical_step, kw_used]: [f64; 7]) -> Self {
        Published {
            static_load: [l, r],
            static_wheel_z: [zl, zr],
            step,
            critical_step,
            kw_used,
        }
    }
}

/// Everything an FMU state holds: enough to continue bit-identically.
#[derive(Debug, Clone)]
pub struct Snapshot {
    kind: Kind,
    phase: Phase,
    values: Vec<f64>,
    model: Option<Model>,
    published: Published,
    time: f64,
    start_time: f64,
    ended: bool,
    /// Why the run had stopped (phase `Error` after a value beyond the health bounds).
    failed: Option<String>,
}

/// A logger: status, category, message.
pub type Logger = Box<dyn FnMut(Status, &str, &str) + Send>;

/// One FMU instance.
pub struct Instance {
    kind: Kind,
    name: String,
    /// Index into the FMU's variable list for each value reference.
    slot: Vec<Option<usize>>,
    /// Current values of parameters and inputs, by value reference.
    values: Vec<f64>,
    phase: Phase,
    model: Option<Model>,
    /// Parameters changed since the model was built.
    dirty: bool,
    published: Published,
    /// Communication time (s): the master's clock, as its `fmi2DoStep` calls carry it.
    time: f64,
    /// `startTime` of `fmi2SetupExperiment` (s): the model's own clock starts at 0 there.
    start_time: f64,
    stop_time: Option<f64>,
    /// The model ended the run (wheel at the track end): `fmi2Terminated` status.
    ended: bool,
    /// Why the run cannot go on (a value beyond the health bounds): `fmi2DoStep` and
    /// outputs are refused until `fmi2Reset` or `fmi2SetFMUstate`.
    failed: Option<String>,
    /// The warning that the wheel nears the fixed rail end was given.
    end_warned: bool,
    logger: Logger,
    logging_on: bool,
    categories: [bool; 4],
}

impl std::fmt::Debug for Instance {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("kind", &self.kind)
            .field("name", &self.name)
            .field("phase", &self.phase)
            .field("time", &self.time)
            .finish()
    }
}

/// The zone at the fixed rail end, in sleeper spans, where [`Instance::do_step`] warns
/// that the end's reflections raise the forces (the default start position, 1.37 m, is
/// two spans from the other end).
pub const END_ZONE_SPANS: f64 = 2.0;

impl Instance {
    /// A new instance of `kind` with start values, logging through `logger`.
    pub fn new(kind: Kind, name: &str, logger: Logger, logging_on: bool) -> Instance {
        let table = kind.table();
        let mut slot = vec![None; N_VR];
        let mut values = vec![f64::NAN; N_VR];
        for (i, v) in table.vars.iter().enumerate() {
            slot[v.vr as usize] = Some(i);
            values[v.vr as usize] = v.start;
        }
        Instance {
            kind,
            name: name.to_string(),
            slot,
            values,
            phase: Phase::Instantiated,
            model: None,
            dirty: true,
            published: Published::default(),
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            ended: false,
            failed: None,
            end_warned: false,
            logger,
            logging_on,
            categories: [true; 4],
        }
    }

    /// Which FMU this is.
    pub fn kind(&self) -> Kind {
        self.kind
    }
    /// Instance name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// State-machine phase. A step that ended the run (`ended`) leaves the instance in
    /// [`Phase::StepFailed`] even where the stepping code left the phase at
    /// `StepComplete`.
    pub fn phase(&self) -> Phase {
        match self.phase {
            Phase::StepComplete if self.ended => Phase::StepFailed,
            p => p,
        }
    }
    /// Communication time (s).
    pub fn time(&self) -> f64 {
        self.time
    }

    // ---------------------------------------------------------------- logging

    /// Sends a message to the logger: errors and warnings always, the other
    /// categories when debug logging is on and the category is selected.
    pub fn log(&mut self, status: Status, category: &str, message: &str) {
        let idx = LOG_CATEGORIES.iter().position(|c| *c == category);
        let always = status >= Status::Warning;
        let on = self.logging_on && idx.is_none_or(|i| self.categories[i]);
        if always || on {
            (self.logger)(status, category, message);
        }
    }

    /// Logs a call (category `logCalls`) when enabled.
    pub fn log_call(&mut self, what: impl FnOnce() -> String) {
        if self.logging_on && self.categories[2] {
            let m = what();
            (self.logger)(Status::Ok, "logCalls", &m);
        }
    }

    fn log_event(&mut self, what: impl FnOnce() -> String) {
        if self.logging_on && self.categories[3] {
            let m = what();
            (self.logger)(Status::Ok, "logEvents", &m);
        }
    }

    /// Logs and returns a refusal.
    pub fn refuse<T>(&mut self, status: Status, message: String) -> FmiResult<T> {
        let cat = if status >= Status::Error {
            "logStatusError"
        } else {
            "logStatusWarning"
        };
        self.log(status, cat, &message);
        Err(Refusal { status, message })
    }

    /// `fmi2SetDebugLogging`: on/off, and the categories to log (all when empty).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> FmiResult {
        let mut sel = [categories.is_empty(); 4];
        for c in categories {
            match LOG_CATEGORIES.iter().position(|x| x == c) {
                Some(i) => sel[i] = true,
                None => {
                    return self.refuse(
                        Status::Error,
                        format!(
                            "fmi2SetDebugLogging: unknown log category \"{c}\"; the categories are {}",
                            LOG_CATEGORIES.join(", ")
                        ),
                    );
                }
            }
        }
        self.logging_on = on;
        self.categories = sel;
        Ok(())
    }

    // ---------------------------------------------------------------- state machine

    /// Refuses `call` unless the table [`CALLS`] allows it in the current phase (or
    /// refuses it as unsupported). The message names the function, the phase, where
    /// the function is allowed and, after a failed step or an internal error, why the
    /// instance is there.
    #[inline]
    pub fn check(&mut self, call: Call) -> FmiResult {
        match call.allowed() {
            Allowed::NoInstance => Ok(()),
            Allowed::In(phases) if phases.contains(&self.phase()) => Ok(()),
            _ => self.refuse_call(call),
        }
    }

    #[cold]
    #[inline(never)]
    fn refuse_call(&mut self, call: Call) -> FmiResult {
        let phases = match call.allowed() {
            Allowed::Unsupported(why) => {
                return self.refuse(
                    Status::Error,
                    format!("{} is not supported: {why}", call.name()),
                );
            }
            Allowed::In(p) => p,
            Allowed::NoInstance => return Ok(()),
        };
        let phase = self.phase();
        let names: Vec<String> = phases.iter().map(|p| format!("{p:?}")).collect();
        let why = match phase {
            Phase::StepFailed if self.ended => format!(
                "; the model ended the run at t = {} s (the wheel reached the end of the \
                 track; fmi2Terminated status is true): outputs can still be read and \
                 fmi2Terminate called; use fmi2Reset to run again",
                self.time
            ),
            Phase::StepFailed => {
                "; a step failed: outputs can still be read and fmi2Terminate called; use \
                 fmi2Reset to run again"
                    .to_string()
            }
            Phase::Error => match &self.failed {
                Some(f) => format!(
                    "; the run stopped at t = {} s: {f}; call fmi2Reset or fmi2SetFMUstate",
                    self.time
                ),
                None => "; an internal error stopped the instance: call fmi2Reset".into(),
            },
            Phase::Terminated => "; use fmi2Reset to run again".into(),
            _ => String::new(),
        };
        self.refuse(
            Status::Error,
            format!(
                "{} is not allowed in state {phase:?}; allowed in: {}{why}",
                call.name(),
                names.join(", ")
            ),
        )
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> FmiResult {
        self.check(Call::SetupExperiment)?;
        if !start.is_finite() {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetupExperiment: startTime = {start} s; allowed: any finite time (the \
                     model starts in static equilibrium at start_position then)"
                ),
            );
        }
        if let Some(t) = stop.filter(|t| !(t.is_finite() && *t > start)) {
            return self.refuse(
                Status::Error,
                format!("fmi2SetupExperiment: stopTime = {t} s; allowed: finite and > startTime"),
            );
        }
        self.stop_time = stop;
        self.start_time = start;
        self.time = start;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> FmiResult {
        self.check(Call::EnterInitializationMode)?;
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: builds the model if parameters changed.
    pub fn exit_initialization(&mut self) -> FmiResult {
        self.check(Call::ExitInitializationMode)?;
        self.ensure_model()?;
        self.phase = Phase::StepComplete;
        self.log_event(|| "initialised in static equilibrium".into());
        self.warn_if_stop_time_unreachable();
        Ok(())
    }

    /// Logs a warning when `stopTime` lies beyond the time the wheel reaches the end of
    /// the track.
    fn warn_if_stop_time_unreachable(&mut self) {
        let (Some(stop), Some(Model::Sim(sim))) = (self.stop_time, &self.model) else {
            return;
        };
        let Some(t_end) = sim.time_at_track_end() else {
            return;
        };
        if stop - self.start_time >= t_end {
            let s = sim.scenario();
            let spans = match &s.track {
                TrackSpec::Discrete(t) => {
                    ((s.start_position + s.speed * (stop - self.start_time)) / t.sleeper_spacing)
                        .ceil()
                        + 2.0
                }
                TrackSpec::Lumped(_) => f64::NAN,
            };
            let m = format!(
                "fmi2ExitInitializationMode: stopTime = {stop} s cannot be reached: the wheel \
                 reaches the end of the track at t = {} s, where fmi2DoStep returns fmi2Discard; \
                 track.spans >= {spans} reaches stopTime",
                self.start_time + t_end
            );
            self.log(Status::Warning, "logStatusWarning", &m);
        }
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> FmiResult {
        self.check(Call::Terminate)?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// `fmi2Reset`: back to the state after instantiation, start values restored.
    pub fn reset(&mut self) -> FmiResult {
        for v in self.kind.table().vars {
            self.values[v.vr as usize] = v.start;
        }
        self.phase = Phase::Instantiated;
        self.model = None;
        self.dirty = true;
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.ended = false;
        self.failed = None;
        self.end_warned = false;
        self.published = Published::default();
        Ok(())
    }

    /// After an internal error: drop the model and require `fmi2Reset`.
    pub fn poison(&mut self) {
        self.model = None;
        self.dirty = true;
        self.phase = Phase::Error;
    }

    // ---------------------------------------------------------------- model

    fn v(&self, r: u32) -> f64 {
        self.values[r as usize]
    }

    /// Track parameters from the variables.
    fn track_params(&self) -> TrackParams {
        TrackParams {
            spans: self.v(vr::TRACK_SPANS) as usize,
            nodes_per_span: self.v(vr::TRACK_NODES_PER_SPAN) as usize,
            sleeper_spacing: self.v(vr::TRACK_SLEEPER_SPACING),
            rail_seat_distance: self.v(vr::TRACK_RAIL_SEAT_DISTANCE),
            rail: RailSection {
                ei: self.v(vr::TRACK_RAIL_EI),
                kag: self.v(vr::TRACK_RAIL_KAG),
                mass: self.v(vr::TRACK_RAIL_MASS),
                rotary_inertia: self.v(vr::TRACK_RAIL_ROTARY_INERTIA),
            },
            pad_stiffness: self.v(vr::TRACK_PAD_STIFFNESS),
            pad_damping: self.v(vr::TRACK_PAD_DAMPING),
            ballast_stiffness: self.v(vr::TRACK_BALLAST_STIFFNESS),
            ballast_damping: self.v(vr::TRACK_BALLAST_DAMPING),
            sleeper_mass: self.v(vr::TRACK_SLEEPER_MASS),
            sleeper_inertia: self.v(vr::TRACK_SLEEPER_INERTIA),
            ends: RailEnds::Fixed,
        }
    }

    fn vehicle_params(&self) -> RollPlaneParams {
        RollPlaneParams {
            carbody_mass: self.v(vr::VEHICLE_CARBODY_MASS),
            bolster_mass: self.v(vr::VEHICLE_BOLSTER_MASS),
            bolster_inertia: self.v(vr::VEHICLE_BOLSTER_INERTIA),
            sideframe_mass: self.v(vr::VEHICLE_SIDEFRAME_MASS),
            wheelset_mass: self.v(vr::VEHICLE_WHEELSET_MASS),
            wheelset_inertia: self.v(vr::VEHICLE_WHEELSET_INERTIA),
            primary_stiffness: self.v(vr::VEHICLE_PRIMARY_STIFFNESS),
            primary_damping: self.v(vr::VEHICLE_PRIMARY_DAMPING),
            primary_spacing: self.v(vr::VEHICLE_PRIMARY_SPACING),
            secondary_stiffness: self.v(vr::VEHICLE_SECONDARY_STIFFNESS),
            secondary_damping: self.v(vr::VEHICLE_SECONDARY_DAMPING),
            secondary_spacing: self.v(vr::VEHICLE_SECONDARY_SPACING),
            gravity: self.v(vr::GRAVITY),
        }
    }

    /// The scenario the variables describe (track-carrying FMUs).
    pub fn scenario(&self) -> Scenario {
        let flats = [0, 1].map(|side| {
            FLAT_VRS[side]
                .iter()
                .map(|f| {
                    let depth = self.v(f[1]);
                    FlatSpec {
                        length: self.v(f[0]),
                        depth: if depth == 0.0 { None } else { Some(depth) },
                        angle: self.v(f[2]),
                        shape: if self.v(f[3]) == enums::flat_shape::CHORD {
                            FlatShape::Chord
                        } else {
                            FlatShape::Haversine
                        },
                    }
                })
                .collect::<Vec<_>>()
        });
        let vehicle = match self.kind {
            Kind::CoupledSystem => VehicleSpec::RollPlane(self.vehicle_params()),
            _ => VehicleSpec::External {
                static_load: [self.v(vr::STATIC_LOAD_LEFT), self.v(vr::STATIC_LOAD_RIGHT)],
            },
        };
        Scenario {
            name: self.kind.table().model_identifier.into(),
            track: TrackSpec::Discrete(self.track_params()),
            vehicle,
            wheel_radius: self.v(vr::WHEEL_RADIUS),
            flats,
            // The table's range holds the enumeration to its items (checked at set).
            contact_model: if self.v(vr::CONTACT_MODEL) == enums::contact_model::HERTZ {
                ContactModel::Hertz
            } else {
                ContactModel::Adaptive
            },
            kw: self.v(vr::CONTACT_KW),
            hertz_coefficient: self.v(vr::CONTACT_CH),
            speed: self.v(vr::SPEED),
            start_position: self.v(vr::START_POSITION),
            dt: self.v(vr::SOLVER_DT),
        }
    }

    fn build(&self) -> crate::Result<(Model, Published)> {
        match self.kind {
            Kind::RollPlaneVehicle => {
                let p = VehicleUnitParams {
                    vehicle: self.vehicle_params(),
                    speed: self.v(vr::SPEED),
                    wheel_radius: self.v(vr::WHEEL_RADIUS),
                    dt: self.v(vr::SOLVER_DT),
                    static_wheel_z: [
                        self.v(vr::STATIC_WHEEL_Z_LEFT),
                        self.v(vr::STATIC_WHEEL_Z_RIGHT),
                    ],
                };
                let u = VehicleUnit::new(&p)?;
                let published = Published {
                    static_load: u.static_load(),
                    static_wheel_z: p.static_wheel_z,
                    step: u.dt_base(),
                    critical_step: p.vehicle.critical_time_step(),
                    kw_used: 0.0,
                };
                Ok((Model::Vehicle(Box::new(u)), published))
            }
            _ => {
                let s = self.scenario();
                let sim = Simulation::new(&s)?;
                let critical_step = sim.critical_step();
                let published = Published {
                    static_load: sim.static_load(),
                    static_wheel_z: sim.wheel_z(),
                    step: sim.dt(),
                    critical_step,
                    kw_used: sim.contact_law().kw,
                };
                Ok((Model::Sim(Box::new(sim)), published))
            }
        }
    }

    fn engine_refusal<T>(&mut self, context: &str, e: Error) -> FmiResult<T> {
        let status = match e {
            Error::OffTrack { .. } => Status::Discard,
            _ => Status::Error,
        };
        self.refuse(status, format!("{context}: {e}"))
    }

    /// Builds the model if there is none or parameters changed, and hands it the
    /// current inputs.
    fn ensure_model(&mut self) -> FmiResult {
        if self.model.is_none() || self.dirty {
            match self.build() {
                Ok((m, p)) => {
                    self.model = Some(m);
                    self.published = p;
                    self.dirty = false;
                    self.log_event(|| "model built: static equilibrium solved".into());
                    self.sync_inputs(true, true)?;
                }
                Err(e) => {
                    self.model = None;
                    return self.engine_refusal("parameters refused", e);
                }
            }
        }
        Ok(())
    }

    /// Pushes input values into the model: the wheel heights when `heights`, the axle
    /// rotation when `rotation` (TrackContact), the contact forces (RollPlaneVehicle).
    /// Called with the inputs a set call changed, and with all of them when the model
    /// is built; not at every step: the track turns the axle on at `V / R_w` from the
    /// last rotation it was given, so setting a wheel height alone leaves it turning.
    fn sync_inputs(&mut self, heights: bool, rotation: bool) -> FmiResult {
        let v = |r: u32| self.values[r as usize];
        let (zl, zr, rot) = (
            v(vr::WHEEL_LEFT_Z),
            v(vr::WHEEL_RIGHT_Z),
            v(vr::WHEEL_ROTATION),
        );
        let forces = [v(vr::CONTACT_LEFT_FORCE), v(vr::CONTACT_RIGHT_FORCE)];
        let r = match (&mut self.model, self.kind) {
            (Some(Model::Sim(sim)), Kind::TrackContact) => {
                let r = if heights {
                    sim.set_wheel_z([zl, zr])
                } else {
                    Ok(())
                };
                r.and_then(|()| {
                    if rotation {
                        sim.set_rotation(rot)
                    } else {
                        Ok(())
                    }
                })
            }
            (Some(Model::Vehicle(u)), _) => u.set_forces(forces),
            _ => Ok(()),
        };
        match r {
            Ok(()) => Ok(()),
            Err(e) => self.engine_refusal("inputs refused", e),
        }
    }

    // ---------------------------------------------------------------- variables

    fn spec(&mut self, call: &str, r: u32) -> FmiResult<&'static VarSpec> {
        match self.slot.get(r as usize).copied().flatten() {
            Some(i) => Ok(&self.kind.table().vars[i]),
            None => self.refuse(
                Status::Error,
                format!(
                    "{call}: unknown value reference {r} for {}",
                    self.kind.table().model_identifier
                ),
            ),
        }
    }

    /// The spec of a value reference already checked by [`Instance::spec`].
    fn known_spec(&self, r: u32) -> &'static VarSpec {
        &self.kind.table().vars[self.slot[r as usize].unwrap_or_default()]
    }

    fn check_type(&mut self, call: &str, s: &VarSpec, real: bool) -> FmiResult {
        let is_real = s.ty == VarType::Real;
        if is_real != real {
            return self.refuse(
                Status::Error,
                format!(
                    "{call}: variable `{}` (value reference {}) is of type {:?}",
                    s.name, s.vr, s.ty
                ),
            );
        }
        Ok(())
    }

    /// Reads variables into `out` (Real or Integer/Enumeration by `real`).
    fn get(&mut self, call: Call, vrs: &[u32], out: &mut [f64], real: bool) -> FmiResult {
        self.check(call)?;
        let call = call.name();
        let mut needs_model = false;
        for &r in vrs {
            let s = self.spec(call, r)?;
            self.check_type(call, s, real)?;
            needs_model |= matches!(
                s.causality,
                Causality::Output | Causality::CalculatedParameter
            );
        }
        if needs_model && self.phase == Phase::Error && self.failed.is_none() {
            return self.refuse(
                Status::Error,
                format!(
                    "{call}: no outputs: an internal error stopped the instance; call fmi2Reset"
                ),
            );
        }
        if needs_model {
            if let Some(why) = &self.failed {
                let m = format!(
                    "{call}: no outputs: the run stopped at t = {} s ({why}); call fmi2Reset or \
                     fmi2SetFMUstate",
                    self.time
                );
                return self.refuse(Status::Error, m);
            }
            self.ensure_model()?;
        }
        let sample = match &self.model {
            Some(Model::Sim(sim)) if needs_model => Some(sim.sample()),
            _ => None,
        };
        let lim = crate::limits::force_limit(self.published.static_load);
        for (o, &r) in out.iter_mut().zip(vrs) {
            let s = self.known_spec(r);
            let computed = !matches!(s.causality, Causality::Parameter | Causality::Input);
            *o = if computed {
                self.computed(s.vr, sample.as_ref())
            } else {
                self.values[s.vr as usize]
            };
            if crate::limits::within(*o, lim) {
                continue;
            }
            if computed && s.unit == "N" && o.is_finite() {
                let (name, x) = (s.name, *o);
                let cause = match self.kind {
                    Kind::TrackContact => {
                        "likely the wheel inputs press the wheel into the rail far beyond a \
                         running wheel's overlap"
                    }
                    _ => "the run diverged, or its parameters are far from a railway",
                };
                let why = format!(
                    "`{name}` = {} N at t = {} s is beyond {} N ({} times the static wheel \
                     load), which no physical run reaches: {cause}",
                    num(x),
                    self.time,
                    num(lim),
                    crate::limits::FORCE_LIMIT_FACTOR
                );
                // Only TrackContact's outputs can come back with other inputs.
                if self.kind != Kind::TrackContact {
                    self.failed = Some(why.clone());
                    self.phase = Phase::Error;
                }
                return self.refuse(Status::Error, format!("{call}: {why}"));
            }
            if !o.is_finite() {
                let (name, x) = (s.name, *o);
                let why = format!("`{name}` = {x} at t = {} s is not finite", self.time);
                self.failed = Some(why.clone());
                self.phase = Phase::Error;
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: {why}; the run cannot go on: call fmi2Reset or fmi2SetFMUstate"
                    ),
                );
            }
        }
        Ok(())
    }

    /// Value of an output or calculated parameter.
    fn computed(&self, r: u32, sample: Option<&Sample>) -> f64 {
        let p = &self.published;
        match r {
            vr::STATIC_LOAD_LEFT => return p.static_load[0],
            vr::STATIC_LOAD_RIGHT => return p.static_load[1],
            vr::STATIC_WHEEL_Z_LEFT => return p.static_wheel_z[0],
            vr::STATIC_WHEEL_Z_RIGHT => return p.static_wheel_z[1],
            vr::SOLVER_STEP => return p.step,
            vr::SOLVER_CRITICAL_STEP => return p.critical_step,
            vr::CONTACT_KW_USED => return p.kw_used,
            _ => {}
        }
        match &self.model {
            Some(Model::Vehicle(u)) => match r {
                vr::WHEEL_LEFT_Z => u.wheel_z()[0],
                vr::WHEEL_RIGHT_Z => u.wheel_z()[1],
                vr::WHEEL_ROTATION => u.rotation(),
                vr::CONTACT_LEFT_MAX_FORCE => u.max_force()[0],
                vr::CONTACT_RIGHT_MAX_FORCE => u.max_force()[1],
                vr::CONTACT_LEFT_MIN_FORCE => u.min_force()[0],
                vr::CONTACT_RIGHT_MIN_FORCE => u.min_force()[1],
                _ => body_output(r, u.displacements(), || u.bearing_forces()),
            },
            Some(Model::Sim(sim)) => {
                let Some(s) = sample else { return f64::NAN };
                let c = &s.contact;
                let vehicle = match sim.vehicle() {
                    VehicleState::RollPlane(v) => Some(v),
                    _ => None,
                };
                match r {
                    vr::CONTACT_LEFT_FORCE => c[0].force,
                    vr::CONTACT_RIGHT_FORCE => c[1].force,
                    vr::CONTACT_LEFT_OVERLAP => c[0].overlap,
                    vr::CONTACT_RIGHT_OVERLAP => c[1].overlap,
                    vr::CONTACT_LEFT_FRONT_ANGLE => c[0].front_angle,
                    vr::CONTACT_RIGHT_FRONT_ANGLE => c[1].front_angle,
                    vr::CONTACT_LEFT_REAR_ANGLE => c[0].rear_angle,
                    vr::CONTACT_RIGHT_REAR_ANGLE => c[1].rear_angle,
                    vr::CONTACT_LEFT_LENGTH => c[0].length,
                    vr::CONTACT_RIGHT_LENGTH => c[1].length,
                    vr::CONTACT_LEFT_INTERVALS => c[0].intervals as f64,
                    vr::CONTACT_RIGHT_INTERVALS => c[1].intervals as f64,
                    vr::CONTACT_LEFT_MAX_FORCE => sim.max_force()[0].max(c[0].force),
                    vr::CONTACT_RIGHT_MAX_FORCE => sim.max_force()[1].max(c[1].force),
                    vr::CONTACT_LEFT_MIN_FORCE => sim.min_force()[0].min(c[0].force),
                    vr::CONTACT_RIGHT_MIN_FORCE => sim.min_force()[1].min(c[1].force),
                    vr::RAIL_LEFT_Z => s.rail_z[0],
                    vr::RAIL_RIGHT_Z => s.rail_z[1],
                    vr::POSITION => s.position,
                    vr::WHEEL_LEFT_Z => s.wheel_z[0],
                    vr::WHEEL_RIGHT_Z => s.wheel_z[1],
                    vr::WHEEL_ROTATION => s.rotation,
                    _ => match vehicle {
                        Some(v) => body_output(r, v.displacements(), || v.bearing_forces()),
                        None => f64::NAN,
                    },
                }
            }
            None => f64::NAN,
        }
    }

    /// Writes variables (Real or Integer/Enumeration by `real`): every value is checked
    /// before any is stored, so a refused call changes nothing.
    fn set(&mut self, call: Call, vrs: &[u32], vals: &[f64], real: bool) -> FmiResult {
        self.check(call)?;
        let call = call.name();
        for (&r, &x) in vrs.iter().zip(vals) {
            let s = self.spec(call, r)?;
            self.check_type(call, s, real)?;
            let settable = matches!(
                (s.causality, self.phase),
                (Causality::Input, _)
                    | (
                        Causality::Parameter,
                        Phase::Instantiated | Phase::Initialization
                    )
            );
            if !settable {
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: variable `{}` ({:?}) cannot be set in state {:?}{}",
                        s.name,
                        s.causality,
                        self.phase,
                        if s.causality == Causality::Parameter {
                            "; parameters are fixed after initialisation (use fmi2Reset)"
                        } else {
                            ""
                        }
                    ),
                );
            }
            if !x.is_finite() || x < s.min || x > s.max {
                let unit = if s.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", s.unit)
                };
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: `{}` = {}{unit} is out of range; allowed: finite, {} <= {} <= {}{unit}",
                        s.name,
                        num(x),
                        num(s.min),
                        s.name,
                        num(s.max)
                    ),
                );
            }
        }
        let (mut heights, mut rotation) = (false, false);
        for (&r, &x) in vrs.iter().zip(vals) {
            let s = self.known_spec(r);
            self.values[s.vr as usize] = x;
            match s.causality {
                Causality::Parameter => self.dirty = true,
                _ if s.vr == vr::WHEEL_ROTATION => rotation = true,
                _ => heights = true,
            }
        }
        if (heights || rotation) && self.model.is_some() && !self.dirty {
            self.sync_inputs(heights, rotation)?;
        }
        Ok(())
    }

    /// `fmi2GetReal`.
    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        self.get(Call::GetReal, vrs, out, true)
    }

    /// `fmi2GetInteger` (integers and enumerations).
    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        let mut tmp = vec![0.0; vrs.len()];
        self.get(Call::GetInteger, vrs, &mut tmp, false)?;
        for (o, t) in out.iter_mut().zip(tmp) {
            *o = t as i32;
        }
        Ok(())
    }

    /// `fmi2SetReal`.
    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> FmiResult {
        self.set(Call::SetReal, vrs, vals, true)
    }

    /// `fmi2SetInteger` (integers and enumerations).
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> FmiResult {
        let tmp: Vec<f64> = vals.iter().map(|&x| x as f64).collect();
        self.set(Call::SetInteger, vrs, &tmp, false)
    }

    /// Boolean and String access: these FMUs have no such variables, so any value
    /// reference is unknown (an empty request succeeds in every state but Instantiated
    /// for reads).
    pub fn no_such_type(&mut self, call: &str, vrs: &[u32]) -> FmiResult {
        match vrs.first() {
            None => Ok(()),
            Some(r) => self.refuse(
                Status::Error,
                format!(
                    "{call}: unknown value reference {r}: {} has no variables of this type",
                    self.kind.table().model_identifier
                ),
            ),
        }
    }

    // ---------------------------------------------------------------- stepping

    /// `fmi2DoStep` from `t` (s) by `h` (s).
    ///
    /// The FMU's clock is the master's: it moves to `t + h` exactly. The track-carrying
    /// FMUs step on their fixed grid `t_k = startTime + k solver.step` and stop at the
    /// grid point nearest `t + h` (`k = round((t + h - startTime) / solver.step)`):
    /// a step within the master's clock rounding of a whole multiple of `solver.step`
    /// runs as that many steps, the internal step never changes (the explicit scheme
    /// is not stable under every sequence of step changes near its limit), and the
    /// model time never drifts from the master's by more than half a step. A step
    /// shorter than half a `solver.step` may advance no grid point; the outputs then
    /// change only through the inputs ([`Simulation::advance_to`]). RollPlaneVehicle cuts
    /// `h` into equal steps ([`VehicleUnit::advance_to`]).
    ///
    /// Refused: `h` not finite and positive, `t + h == t`, `t` not the FMU's time, a
    /// step past `stopTime`, a step that would cost more than
    /// [`crate::limits::MAX_NODE_STEPS_PER_CALL`] rail-node updates (track) or
    /// [`crate::limits::MAX_VEHICLE_STEPS_PER_CALL`] steps (vehicle). The wheel reaching
    /// the end of the track gives `fmi2Discard` before anything moves; a value no
    /// physical run reaches gives `fmi2Error` naming it, and the run can then only be
    /// reset or restored from an FMU state.
    pub fn do_step(&mut self, t: f64, h: f64) -> FmiResult {
        self.check(Call::DoStep)?;
        if !(h.is_finite() && h > 0.0) {
            return self.refuse(
                Status::Error,
                format!("fmi2DoStep: communicationStepSize = {h} s; allowed: finite and > 0 s"),
            );
        }
        // The master's clock may differ from `t + h` of the last call by its rounding.
        let tol = 64.0 * f64::EPSILON * t.abs().max(self.time.abs());
        if !t.is_finite() || (t - self.time).abs() > tol {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: currentCommunicationPoint = {t} s, but the FMU is at {} s \
                     (the end of the last step; allowed: that time to within {} s, the \
                     rounding of the clock)",
                    self.time,
                    num(tol)
                ),
            );
        }
        let end = t + h;
        if end == t {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: communicationStepSize = {h:e} s does not move the clock at t = {t} s \
                     (t + h == t in double precision); allowed: > {:e} s there",
                    f64::EPSILON * t.abs()
                ),
            );
        }
        if let Some(stop) = self.stop_time.filter(|s| end > s + 1e-9 * (1.0 + s.abs())) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: t + h = {end} s is past stopTime = {stop} s of fmi2SetupExperiment"
                ),
            );
        }
        // The rounding of the master's clock: a few units in the last place of the time.
        let clock = 16.0 * f64::EPSILON * t.abs().max(end.abs());
        // The model's own clock starts at 0 at startTime.
        let model_end = end - self.start_time;
        // The steps to take, checked against the work limit before anything moves.
        let plan = match &self.model {
            Some(Model::Sim(sim)) => Some(sim.plan_to(model_end, clock)),
            Some(Model::Vehicle(u)) => Some(u.plan_to(model_end, clock)),
            None => None,
        };
        let plan = match plan.transpose() {
            Ok(plan) => plan,
            Err(w) => {
                return self.refuse(
                    Status::Error,
                    format!(
                        "fmi2DoStep: communicationStepSize = {h} s would take {w}; use shorter \
                         communication steps"
                    ),
                );
            }
        };
        let r = match (&mut self.model, plan) {
            (Some(Model::Sim(sim)), Some(plan)) => sim.advance_to(plan),
            (Some(Model::Vehicle(u)), Some(plan)) => u.advance_to(plan),
            _ => Err(Error::Unsupported("stepping before initialisation".into())),
        };
        // CoupledSystem has no inputs: the sample at the end of the step is final (and
        // cached for the next step), so a value beyond the bounds there fails this step.
        let r = r.and_then(|()| match (self.kind, &self.model) {
            (Kind::CoupledSystem, Some(Model::Sim(sim))) => sim.check_sample(),
            _ => Ok(()),
        });
        if let Err(e) = r {
            match e {
                Error::OffTrack { .. } => {
                    self.ended = true;
                    self.phase = Phase::StepFailed;
                }
                // The state may be partly advanced and beyond the health bounds.
                Error::Diverged { .. } | Error::NonFinite { .. } => {
                    self.failed = Some(e.to_string());
                    self.phase = Phase::Error;
                }
                // Refused arguments: nothing moved.
                _ => {}
            }
            return self.engine_refusal(&format!("fmi2DoStep at t = {t} s, h = {h} s"), e);
        }
        self.time = end;
        self.warn_near_track_end();
        Ok(())
    }

    /// Warns once per run when the wheel comes within [`END_ZONE_SPANS`] sleeper spans of
    /// the fixed rail end, where the end's reflections raise the impact forces (by 20 to
    /// 35 % within the last span, table 4.4).
    fn warn_near_track_end(&mut self) {
        if self.end_warned {
            return;
        }
        let Some(Model::Sim(sim)) = &self.model else {
            return;
        };
        let TrackSpec::Discrete(p) = &sim.scenario().track else {
            return;
        };
        let zone = p.length() - END_ZONE_SPANS * p.sleeper_spacing;
        let x = sim.position();
        if x > zone {
            self.end_warned = true;
            let m = format!(
                "fmi2DoStep: at t = {} s the wheel is at {x:.3} m, within {END_ZONE_SPANS} \
                 sleeper spans of the fixed rail end at {:.3} m: the end's reflections raise \
                 impact forces here (by 20 to 35 % within the last span); keep the impacts \
                 of interest at least {END_ZONE_SPANS} spans from the ends (track.spans)",
                self.time,
                p.length()
            );
            self.log(Status::Warning, "logStatusWarning", &m);
        }
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)`: the model ended the run.
    pub fn terminated_by_model(&self) -> bool {
        self.ended
    }

    // ---------------------------------------------------------------- FMU states

    /// `fmi2GetFMUstate`.
    pub fn get_state(&mut self) -> FmiResult<Snapshot> {
        let t = self.time;
        self.log_event(|| format!("state saved at t = {t} s"));
        Ok(Snapshot {
            kind: self.kind,
            phase: self.phase,
            values: self.values.clone(),
            model: self.model.clone(),
            published: self.published,
            time: self.time,
            start_time: self.start_time,
            ended: self.ended,
            failed: self.failed.clone(),
        })
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, s: &Snapshot) -> FmiResult {
        if s.kind != self.kind {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetFMUstate: the state belongs to {:?}, this instance is {:?}",
                    s.kind, self.kind
                ),
            );
        }
        self.phase = s.phase;
        self.values.clone_from(&s.values);
        self.model.clone_from(&s.model);
        self.dirty = self.model.is_none();
        self.published = s.published;
        self.time = s.time;
        self.start_time = s.start_time;
        self.ended = s.ended;
        self.failed.clone_from(&s.failed);
        let t = self.time;
        self.log_event(|| format!("state restored at t = {t} s"));
        Ok(())
    }

    /// `fmi2SerializeFMUstate`: magic, GUID, phase, clock, values, model state.
    pub fn serialize(&mut self, s: &Snapshot) -> FmiResult<Vec<u8>> {
        let model = match &s.model {
            None => Vec::new(),
            Some(Model::Vehicle(u)) => u.state_vector(),
            Some(Model::Sim(sim)) => match sim.state_vector() {
                Ok(v) => v,
                Err(e) => return self.engine_refusal("fmi2SerializeFMUstate", e),
            },
        };
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        let guid = s.kind.table().guid.as_bytes();
        b.extend_from_slice(&(guid.len() as u64).to_le_bytes());
        b.extend_from_slice(guid);
        b.push(s.phase as u8);
        b.push(s.ended as u8);
        b.push(s.model.is_some() as u8);
        b.extend_from_slice(&s.time.to_le_bytes());
        b.extend_from_slice(&s.start_time.to_le_bytes());
        let failed = s.failed.as_deref().unwrap_or("").as_bytes();
        b.extend_from_slice(&(failed.len() as u64).to_le_bytes());
        b.extend_from_slice(failed);
        for x in s.published.to_array() {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(&(s.values.len() as u64).to_le_bytes());
        for x in &s.values {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(&(model.len() as u64).to_le_bytes());
        for x in &model {
            b.extend_from_slice(&x.to_le_bytes());
        }
        Ok(b)
    }

    /// `fmi2DeSerializeFMUstate`: rebuilds the model from the stored parameters, then
    /// puts the stored dynamic state into it.
    pub fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot> {
        match self.decode(bytes) {
            Ok(s) => Ok(s),
            Err(m) => self.refuse(Status::Error, format!("fmi2DeSerializeFMUstate: {m}")),
        }
    }

    /// The numbers of a serialized state are what an instance can hold: a finite clock
    /// from 0 on, finite calculated values and model state, parameters and inputs
    /// inside their ranges (as fmi2SetReal would take them).
    fn check_stored(
        &self,
        (time, start_time): (f64, f64),
        pubs: &[f64],
        values: &[f64],
        state: &[f64],
    ) -> std::result::Result<(), String> {
        if !(time.is_finite() && start_time.is_finite() && time >= start_time) {
            return Err(format!(
                "stored time {time} s and start time {start_time} s are not finite with the \
                 time at or after the start"
            ));
        }
        if let Some(x) = pubs.iter().find(|x| !x.is_finite()) {
            return Err(format!("a stored calculated parameter is {x}"));
        }
        for v in self.kind.table().vars {
            let x = values[v.vr as usize];
            let known = matches!(v.causality, Causality::Parameter | Causality::Input);
            if known && !(x.is_finite() && x >= v.min && x <= v.max) {
                return Err(format!(
                    "stored `{}` = {x} is out of range (finite, {} to {})",
                    v.name, v.min, v.max
                ));
            }
        }
        if let Some(k) = state.iter().position(|x| !x.is_finite()) {
            return Err(format!("model state [{k}] = {} is not finite", state[k]));
        }
        Ok(())
    }

    fn decode(&mut self, bytes: &[u8]) -> std::result::Result<Snapshot, String> {
        let mut r = Cursor { b: bytes, at: 0 };
        if r.take(MAGIC.len())? != MAGIC {
            return Err("not a wheelflat FMU state (bad magic)".into());
        }
        let n = r.u64()? as usize;
        let guid = r.take(n)?;
        if guid != self.kind.table().guid.as_bytes() {
            return Err(format!(
                "the state was written by another FMU (GUID {}), not {} {}",
                String::from_utf8_lossy(guid),
                self.kind.table().model_identifier,
                self.kind.table().guid
            ));
        }
        let p = r.take(1)?[0];
        let phase = Phase::from_u8(p).ok_or_else(|| format!("bad phase {p}"))?;
        let ended = r.take(1)?[0] != 0;
        let has_model = r.take(1)?[0] != 0;
        let time = r.f64()?;
        let start_time = r.f64()?;
        let n = r.u64()? as usize;
        let failed = std::str::from_utf8(r.take(n)?)
            .map_err(|_| "the stored reason for a stopped run is not UTF-8".to_string())?;
        let failed = (!failed.is_empty()).then(|| failed.to_string());
        if (phase == Phase::Error) != failed.is_some() {
            return Err("a stopped run's state without its reason, or the reverse".into());
        }
        let mut pubs = [0.0; 7];
        for x in &mut pubs {
            *x = r.f64()?;
        }
        let nv = r.u64()? as usize;
        if nv != N_VR {
            return Err(format!("{nv} values; this FMU has {N_VR}"));
        }
        let mut values = Vec::with_capacity(nv);
        for _ in 0..nv {
            values.push(r.f64()?);
        }
        let nm = r.u64()? as usize;
        if nm > bytes.len() / 8 {
            return Err(format!("model state length {nm} exceeds the data"));
        }
        let mut state = Vec::with_capacity(nm);
        for _ in 0..nm {
            state.push(r.f64()?);
        }
        if r.at != bytes.len() {
            return Err(format!("{} trailing bytes", bytes.len() - r.at));
        }
        // A stopped run's model state is beyond the health bounds by definition, and
        // nothing can be read from it or stepped: it is restored as the stopped run
        // without a model (fmi2Reset or another state goes on from there).
        let stopped = phase == Phase::Error;
        let state = if stopped { Vec::new() } else { state };
        self.check_stored((time, start_time), &pubs, &values, &state)?;
        let model = if has_model && !stopped {
            // Build with the stored parameters on a scratch instance, then overwrite
            // the dynamic state.
            let saved = std::mem::replace(&mut self.values, values.clone());
            let built = self.build();
            self.values = saved;
            let (mut m, rebuilt) = built.map_err(|e| format!("stored parameters refused: {e}"))?;
            let again = rebuilt.to_array();
            if let Some(k) = (0..7).find(|&k| again[k].to_bits() != pubs[k].to_bits()) {
                return Err(format!(
                    "stored calculated parameter {k} = {} disagrees with the {} the stored \
                     parameters give",
                    pubs[k], again[k]
                ));
            }
            match &mut m {
                Model::Vehicle(u) => u.set_state_vector(&state),
                Model::Sim(sim) => sim.set_state_vector(&state),
            }
            .map_err(|e| e.to_string())?;
            // The model's clock must be the stored communication time's.
            let (model_time, slack) = match &m {
                Model::Vehicle(u) => (u.time() + u.carried(), 0.0),
                Model::Sim(sim) => (sim.time(), 0.5 * sim.dt()),
            };
            let off = (start_time + model_time - time).abs();
            if off.is_nan() || off > slack + 1e-9 * (1.0 + time.abs()) {
                return Err(format!(
                    "stored time {time} s disagrees with the model's clock {} s",
                    start_time + model_time
                ));
            }
            Some(m)
        } else {
            None
        };
        Ok(Snapshot {
            kind: self.kind,
            phase,
            values,
            model,
            published: Published::from_array(pubs),
            time,
            start_time,
            ended,
            failed,
        })
    }
}

/// Vehicle body outputs from the displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`
/// and the bearing forces; NaN for any other reference.
fn body_output(r: u32, d: &nalgebra::Vector6<f64>, bearing: impl Fn() -> [f64; 2]) -> f64 {
    match r {
        vr::BOLSTER_Z => d[0],
        vr::BOLSTER_ROLL => d[1],
        vr::SIDEFRAME_LEFT_Z => d[2],
        vr::SIDEFRAME_RIGHT_Z => d[3],
        vr::WHEELSET_Z => d[4],
        vr::WHEELSET_ROLL => d[5],
        vr::PRIMARY_LEFT_FORCE => bearing()[0],
        vr::PRIMARY_RIGHT_FORCE => bearing()[1],
        _ => f64::NAN,
    }
}

const MAGIC: &[u8] = b"wheelflat-fmu-state-2\0";

struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> std::result::Result<&'a [u8], String> {
        if n > self.b.len() - self.at {
            return Err(format!(
                "truncated at byte {} ({n} bytes announced, {} left)",
                self.at,
                self.b.len() - self.at
            ));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u64(&mut self) -> std::result::Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn f64(&mut self) -> std::result::Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::{Arc, Mutex};

    fn instance(kind: Kind) -> (Instance, Arc<Mutex<Vec<String>>>) {
        let log = Arc::new(Mutex::new(Vec::new()));
        let l2 = log.clone();
        let logger: Logger = Box::new(move |_, _, m| l2.lock().unwrap().push(m.to_string()));
        (Instance::new(kind, "test", logger, false), log)
    }

    #[test]
    fn default_start_values_are_the_reference_scenario() {
        let (i, _) = instance(Kind::CoupledSystem);
        let mut a = Simulation::new(&i.scenario()).unwrap();
        let mut b = Simulation::new(&Scenario::table_4_4_flat()).unwrap();
        for _ in 0..3000 {
            assert_eq!(a.step().unwrap(), b.step().unwrap());
        }
        // The literal handshake defaults of the table equal what the models compute.
        let w = match Scenario::table_4_4().vehicle {
            VehicleSpec::RollPlane(p) => p.static_wheel_load(),
            _ => unreachable!(),
        };
        let (t, _) = instance(Kind::TrackContact);
        assert_eq!(t.v(vr::STATIC_LOAD_LEFT), w);
        let sim = Simulation::new(&t.scenario()).unwrap();
        assert_eq!(t.v(vr::WHEEL_LEFT_Z), sim.wheel_z()[0]);
        let (v, _) = instance(Kind::RollPlaneVehicle);
        assert_eq!(v.v(vr::STATIC_WHEEL_Z_LEFT), sim.wheel_z()[0]);
        assert_eq!(v.v(vr::CONTACT_LEFT_FORCE), w);
    }

    #[test]
    fn docs_variables_md_is_the_generated_file() {
        // build.rs generates it from the table; a stale copy fails here.
        assert!(
            include_str!("../../docs/VARIABLES.md") == vars::VARIABLES_MD,
            "docs/VARIABLES.md is stale: run `cargo build --release && cargo run --release \
             --bin build_fmus -- fmu docs/VARIABLES.md`"
        );
        for t in vars::FMUS {
            for v in t.vars {
                assert!(vars::VARIABLES_MD.contains(&format!("| `{}` |", v.name)));
            }
        }
    }

    #[test]
    fn refusals_name_the_variable_and_leave_the_instance_usable() {
        let (mut i, log) = instance(Kind::TrackContact);
        assert!(i.do_step(0.0, 1e-5).is_err());
        let e = i.set_real(&[vr::TRACK_PAD_STIFFNESS], &[-1.0]).unwrap_err();
        assert_eq!(e.status, Status::Error);
        assert!(
            e.message.contains("`track.pad.stiffness` = -1 N/m"),
            "{}",
            e.message
        );
        assert_eq!(
            i.v(vr::TRACK_PAD_STIFFNESS),
            140e6,
            "a refused set changes nothing"
        );
        let e = i.set_integer(&[vr::TRACK_SPANS], &[1]).unwrap_err();
        assert!(e.message.contains("`track.spans` = 1"), "{}", e.message);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 1e-4).unwrap();
        let mut p = [0.0];
        i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
        assert!((p[0] - 107.66e3).abs() < 2e3);
        assert_eq!(log.lock().unwrap().len(), 3, "each refusal logged once");
    }

    #[test]
    fn the_state_table_lists_every_function_once_in_enum_order() {
        for (k, (call, name, _)) in CALLS.iter().enumerate() {
            assert_eq!(*call as usize, k, "{name}");
            assert_eq!(call.name(), *name);
            assert_eq!(Call::from_name(name), Some(*call));
        }
        for p in ALL {
            assert_eq!(Phase::from_u8(*p as u8), Some(*p));
        }
        assert_eq!(Phase::from_u8(6), None);
    }

    #[test]
    fn terminate_and_status_follow_the_state_table() {
        let (mut i, log) = instance(Kind::TrackContact);
        let last = |log: &Arc<Mutex<Vec<String>>>| log.lock().unwrap().last().cloned().unwrap();
        for call in [Call::GetRealStatus, Call::GetBooleanStatus, Call::Terminate] {
            assert_eq!(i.check(call).unwrap_err().status, Status::Error);
            let m = last(&log);
            assert!(
                m.starts_with(&format!(
                    "{} is not allowed in state Instantiated",
                    call.name()
                )),
                "{m}"
            );
        }
        i.enter_initialization().unwrap();
        for call in [Call::GetRealStatus, Call::GetBooleanStatus] {
            assert!(i.check(call).is_err());
            assert!(last(&log).contains("in state Initialization"));
        }
        let e = i.terminate().unwrap_err();
        assert_eq!(
            e.message,
            "fmi2Terminate is not allowed in state Initialization; allowed in: StepComplete, StepFailed"
        );
        i.exit_initialization().unwrap();
        i.check(Call::GetRealStatus).unwrap();
        i.terminate().unwrap();
        assert_eq!(i.phase(), Phase::Terminated);
        let e = i.terminate().unwrap_err();
        assert!(
            e.message
                .starts_with("fmi2Terminate is not allowed in state Terminated"),
            "{}",
            e.message
        );
        assert!(e.message.contains("fmi2Reset"), "{}", e.message);
        i.check(Call::GetBooleanStatus).unwrap();
        i.reset().unwrap();
        assert_eq!(i.phase(), Phase::Instantiated);
        assert!(i.check(Call::GetRealStatus).is_err());
    }

    #[test]
    fn after_the_model_ended_the_run_steps_are_refused_and_outputs_readable() {
        let (mut i, log) = instance(Kind::CoupledSystem);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 0.01).unwrap();
        let e = i.do_step(0.01, 5.0).unwrap_err();
        assert_eq!(e.status, Status::Discard);
        assert_eq!(i.phase(), Phase::StepFailed);
        assert!(i.terminated_by_model());
        assert_eq!(i.last_successful_time(), 0.01);
        let n = log.lock().unwrap().len();
        for h in [1e-4, 5.0] {
            let e = i.do_step(0.01, h).unwrap_err();
            assert_eq!(e.status, Status::Error);
            assert!(
                e.message
                    .starts_with("fmi2DoStep is not allowed in state StepFailed; allowed in: StepComplete; the model ended the run at t = 0.01 s"),
                "{}",
                e.message
            );
            assert!(e.message.contains("use fmi2Reset"), "{}", e.message);
        }
        assert_eq!(log.lock().unwrap().len(), n + 2, "each refusal logged");
        // Inputs can no longer be set; outputs and status can be read.
        assert!(i.set_real(&[vr::SPEED], &[10.0]).is_err());
        let mut p = [0.0];
        i.get_real(&[vr::POSITION], &mut p).unwrap();
        // The track stands at its grid point nearest 0.01 s.
        let dt = i.published.step;
        assert!((p[0] - (1.37 + (0.01 / dt).round() * dt * 70.0 / 3.6)).abs() < 1e-9);
        i.check(Call::GetRealStatus).unwrap();
        i.check(Call::GetBooleanStatus).unwrap();
        // A state taken here restores the failed step.
        let s = i.get_state().unwrap();
        let b = i.serialize(&s).unwrap();
        i.terminate().unwrap();
        assert_eq!(i.phase(), Phase::Terminated);
        assert!(i.terminated_by_model());
        let d = i.deserialize(&b).unwrap();
        i.set_state(&d).unwrap();
        assert_eq!(i.phase(), Phase::StepFailed);
        assert!(i.do_step(0.01, 1e-4).is_err());
        i.reset().unwrap();
        assert!(!i.terminated_by_model());
        assert_eq!(i.phase(), Phase::Instantiated);
    }

    #[test]
    fn a_serialized_state_with_numbers_an_instance_cannot_hold_is_refused() {
        let (mut i, _) = instance(Kind::RollPlaneVehicle);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 1e-3).unwrap();
        let s = i.get_state().unwrap();
        let b = i.serialize(&s).unwrap();
        assert!(i.deserialize(&b).is_ok());
        let put = |at: usize, x: f64| {
            let mut c = b.clone();
            c[at..at + 8].copy_from_slice(&x.to_le_bytes());
            c
        };
        let guid = i.kind.table().guid.len();
        let time_at = MAGIC.len() + 8 + guid + 3;
        // time, start time, the reason's length (0), seven calculated parameters, the
        // value count
        let values_at = time_at + 8 * 10 + 8;
        for (at, x, why) in [
            (b.len() - 8, f64::NAN, "model state"),
            (b.len() - 8, f64::INFINITY, "model state"),
            (time_at, -1.0, "stored time"),
            (time_at + 8, f64::NAN, "start time NaN"),
            (time_at + 24, f64::NAN, "calculated parameter"),
            (values_at + 8 * vr::SPEED as usize, -5.0, "`speed` = -5"),
            (
                values_at + 8 * vr::GRAVITY as usize,
                f64::NAN,
                "`gravity` = NaN",
            ),
        ] {
            let e = i.deserialize(&put(at, x)).unwrap_err();
            assert!(e.message.contains(why), "{why}: {}", e.message);
        }
    }

    #[test]
    fn track_rotation_input_is_held_then_turns_at_speed_over_radius() {
        let (mut i, _) = instance(Kind::TrackContact);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let sim = |i: &Instance| match &i.model {
            Some(Model::Sim(s)) => (s.rotation(), s.time(), s.dt()),
            _ => unreachable!(),
        };
        i.set_real(&[vr::WHEEL_ROTATION], &[0.5]).unwrap();
        assert_eq!(sim(&i).0, 0.5);
        i.do_step(0.0, 1e-3).unwrap();
        // The track stops at its grid point nearest 1 ms and has turned the axle at
        // V / R_w from the angle given.
        let (rot, t, dt) = sim(&i);
        assert_eq!(t, (1e-3 / dt).round() * dt);
        assert!((t - 1e-3).abs() <= 0.5 * dt);
        assert!((rot - (0.5 + t * (70.0 / 3.6) / 0.475)).abs() < 1e-12);
        // A wheel height alone leaves the rotation turning.
        i.set_real(&[vr::WHEEL_LEFT_Z], &[-1.3e-3]).unwrap();
        assert_eq!(sim(&i).0, rot);
    }

    /// The time of the largest contact force on the left wheel over the first 60 ms and
    /// that force, for TrackContact at its defaults (wheels held at their static
    /// heights) stepped by `h`, with the wheel heights set again to the values they
    /// hold at every step from 0.01 s on when `set_heights`.
    fn first_impact(h: f64, set_heights: bool) -> (f64, f64) {
        let (mut i, _) = instance(Kind::TrackContact);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let mut z = [0.0; 2];
        i.get_real(&[vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z], &mut z)
            .unwrap();
        let (mut first, mut peak) = (0.0, 0.0f64);
        for k in 0..(0.06 / h).round() as usize {
            let t = k as f64 * h;
            if set_heights && t >= 0.01 {
                i.set_real(&[vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z], &z)
                    .unwrap();
            }
            let mut p = [0.0];
            i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
            if p[0] > peak {
                (first, peak) = (t, p[0]);
            }
            i.do_step(t, h).unwrap();
        }
        (first, peak)
    }

    #[test]
    fn setting_the_wheel_heights_alone_keeps_the_axle_turning() {
        // Issue 13's example: comm step 1e-4 s, wheel heights set from 0.01 s on. The
        // flat (90 degrees ahead at t = 0) passes the contact point after a quarter
        // turn, (pi / 2) R_w / V = 38.4 ms; with the rotation restarted by every height
        // set it never arrived (the impact moved 10 ms per restart).
        let alone = first_impact(1e-4, false);
        let with_heights = first_impact(1e-4, true);
        let quarter_turn = std::f64::consts::FRAC_PI_2 * 0.475 / (70.0 / 3.6);
        assert!((alone.0 - quarter_turn).abs() < 2.5e-3, "{alone:?}");
        assert!(alone.1 > 150e3, "{alone:?}");
        assert_eq!(alone, with_heights);
    }

    fn coupled(start: f64, params: &[(u32, f64)], integers: &[(u32, i32)]) -> Instance {
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.setup_experiment(start, None).unwrap();
        for &(r, x) in params {
            i.set_real(&[r], &[x]).unwrap();
        }
        for &(r, x) in integers {
            i.set_integer(&[r], &[x]).unwrap();
        }
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i
    }

    const FORCES: [u32; 4] = [
        vr::CONTACT_LEFT_FORCE,
        vr::CONTACT_RIGHT_FORCE,
        vr::WHEEL_LEFT_Z,
        vr::POSITION,
    ];

    #[test]
    fn a_later_start_time_is_the_same_run_shifted() {
        let mut a = coupled(0.0, &[], &[]);
        let mut b = coupled(0.2, &[], &[]);
        let h = 1e-4;
        for k in 0..500 {
            let (mut x, mut y) = ([0.0; 4], [0.0; 4]);
            a.get_real(&FORCES, &mut x).unwrap();
            b.get_real(&FORCES, &mut y).unwrap();
            assert_eq!(x, y, "step {k}");
            a.do_step(k as f64 * h, h).unwrap();
            b.do_step(0.2 + k as f64 * h, h).unwrap();
        }
        assert!((b.time() - 0.25).abs() < 1e-12);
    }

    #[test]
    fn a_master_clock_with_rounding_runs_whole_steps_at_the_seed_grid() {
        // Table 4.4 flat case on the seed grid (n = 2, dt = 45 us), stepped by
        // t_(i+1) - t_i with t_i = i dt as a master computes them: near 0.5 s these
        // differ from dt by a few 1e-12 relative. Every step must be one step of dt,
        // bit for bit the engine's fixed-step run, through 0.8 s (five impacts).
        let dt = 45e-6;
        let mut i = coupled(
            0.0,
            &[(vr::SOLVER_DT, dt)],
            &[(vr::TRACK_NODES_PER_SPAN, 2)],
        );
        let mut s = Scenario::table_4_4_flat();
        s.set_nodes_per_span(2);
        s.dt = dt;
        let mut sim = Simulation::new(&s).unwrap();
        let mut peak = 0.0f64;
        let mut uneven = 0;
        for k in 0..17_777u32 {
            let (t0, t1) = (f64::from(k) * dt, f64::from(k + 1) * dt);
            uneven += usize::from(t1 - t0 != dt);
            let mut p = [0.0; 2];
            i.get_real(&FORCES[..2], &mut p).unwrap();
            let m = sim.step().unwrap();
            assert_eq!(p, [m.contact[0].force, m.contact[1].force], "step {k}");
            peak = peak.max(p[0]);
            i.do_step(t0, t1 - t0).unwrap();
        }
        assert!(uneven > 1000, "the clock steps are not all equal to dt");
        // The seed-grid reference peak (docs/VALIDATION.md): 430.1 kN.
        assert!((peak - 430.1e3).abs() < 0.1e3, "{peak}");
    }

    #[test]
    fn communication_steps_of_any_size_keep_the_fixed_step_scheme() {
        // 1e5 communication steps cycling through sizes around the internal step, on a
        // track run at 0.97 of its critical step, through twelve flat impacts: the
        // track stays on its grid, so at every communication point the outputs are the
        // fixed-step run's at the nearest grid time (bit for bit), at most half a step
        // away from the master's time.
        let spans = 70;
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.set_integer(&[vr::TRACK_SPANS], &[spans]).unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let critical = i.published.critical_step;
        i.reset().unwrap();
        i.set_integer(&[vr::TRACK_SPANS], &[spans]).unwrap();
        i.set_real(&[vr::SOLVER_DT], &[0.97 * critical]).unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let dt = i.published.step;
        assert_eq!(dt, 0.97 * critical);
        let mut s = i.scenario();
        s.dt = dt;
        let mut sim = Simulation::new(&s).unwrap();
        let mut fixed = vec![sim.sample()];
        let sizes = [0.37, 1.0, 2.5, 0.81, 1.93, 0.5, 3.0, 1.0 + 1e-12];
        let (mut t, mut peak, mut impacts, mut above) = (0.0, 0.0f64, 0, false);
        for k in 0..100_000 {
            let h = sizes[k % sizes.len()] * dt;
            i.do_step(t, h).unwrap();
            t += h;
            let grid = (t / dt).round() as usize;
            while fixed.len() <= grid {
                sim.step().unwrap();
                fixed.push(sim.sample());
            }
            let mut p = [0.0; 4];
            i.get_real(&FORCES, &mut p).unwrap();
            let f = &fixed[grid];
            assert_eq!(
                p,
                [
                    f.contact[0].force,
                    f.contact[1].force,
                    f.wheel_z[0],
                    f.position
                ],
                "step {k}"
            );
            assert!((grid as f64 * dt - t).abs() <= 0.5 * dt * (1.0 + 1e-9));
            peak = peak.max(p[0]);
            if p[0] > 200e3 && !above {
                impacts += 1;
            }
            above = p[0] > 200e3;
        }
        assert!(impacts >= 10, "{impacts} impacts");
        assert!(peak < 400e3 && peak > 250e3, "{peak}");
    }

    #[test]
    fn steps_too_small_or_too_large_are_refused_or_harmless_and_never_hang() {
        // At t = 0 the least positive double moves the clock: no grid step is due,
        // outputs stay finite and equal.
        let mut c = coupled(0.0, &[], &[]);
        let mut before = [0.0; 4];
        c.get_real(&FORCES, &mut before).unwrap();
        c.do_step(0.0, 5e-324).unwrap();
        let mut after = [0.0; 4];
        c.get_real(&FORCES, &mut after).unwrap();
        assert_eq!(before, after);
        // Further on, t + h == t is refused.
        let mut t = 5e-324;
        for _ in 0..10 {
            c.do_step(t, 1e-3).unwrap();
            t += 1e-3;
        }
        let e = c.do_step(t, 5e-324).unwrap_err();
        assert!(
            e.message.contains("does not move the clock"),
            "{}",
            e.message
        );
        // Far too large: refused at once, naming the work.
        let start = std::time::Instant::now();
        let e = c.do_step(t, 1e9).unwrap_err();
        assert!(
            e.message.contains("the most one call may do"),
            "{}",
            e.message
        );
        let (mut v, _) = instance(Kind::RollPlaneVehicle);
        v.enter_initialization().unwrap();
        v.exit_initialization().unwrap();
        let e = v.do_step(0.0, 1e9).unwrap_err();
        assert!(
            e.message.contains("the most one call may do"),
            "{}",
            e.message
        );
        let (mut tc, _) = instance(Kind::TrackContact);
        tc.set_real(&[vr::SPEED], &[0.0]).unwrap();
        tc.enter_initialization().unwrap();
        tc.exit_initialization().unwrap();
        let e = tc.do_step(0.0, 1e9).unwrap_err();
        assert!(
            e.message.contains("the most one call may do"),
            "{}",
            e.message
        );
        assert!(start.elapsed().as_secs_f64() < 1.0);
        // The instances go on after a refused step.
        tc.do_step(0.0, 1e-3).unwrap();
        v.do_step(0.0, 1e-3).unwrap();
        // A vehicle step below 1e-3 of its step is carried over to the next call (it
        // would round the velocities away); the outputs stay as they were.
        let mut before = [0.0; 2];
        v.get_real(&[vr::WHEEL_LEFT_Z, vr::WHEEL_ROTATION], &mut before)
            .unwrap();
        v.do_step(1e-3, 1e-12).unwrap();
        let mut after = [0.0; 2];
        v.get_real(&[vr::WHEEL_LEFT_Z, vr::WHEEL_ROTATION], &mut after)
            .unwrap();
        assert_eq!(before, after);
        v.do_step(1e-3 + 1e-12, 1e-3).unwrap();
        // solver.dt far below the critical step is refused at initialisation.
        for kind in [
            Kind::TrackContact,
            Kind::RollPlaneVehicle,
            Kind::CoupledSystem,
        ] {
            let (mut i, log) = instance(kind);
            i.set_real(&[vr::SOLVER_DT], &[1e-12]).unwrap();
            i.enter_initialization().unwrap();
            let e = i.exit_initialization().unwrap_err();
            assert!(e.message.contains("`solver.dt` = 1e-12"), "{}", e.message);
            assert_eq!(log.lock().unwrap().len(), 1);
        }
    }

    #[test]
    fn parameter_ranges_follow_from_physics_and_match_the_engine() {
        for t in vars::FMUS {
            for v in t.vars {
                if v.causality != Causality::Parameter {
                    continue;
                }
                if let Some(r) = crate::limits::range(v.name) {
                    assert_eq!(
                        (v.min, v.max),
                        (r.min, r.max),
                        "{} in {}",
                        v.name,
                        t.model_identifier
                    );
                }
            }
        }
        let cases: [(Kind, u32, f64, &str); 5] = [
            (
                Kind::RollPlaneVehicle,
                vr::VEHICLE_PRIMARY_STIFFNESS,
                1e308,
                "vehicle.primary.stiffness",
            ),
            (
                Kind::CoupledSystem,
                vr::VEHICLE_BOLSTER_MASS,
                1e308,
                "vehicle.bolster.mass",
            ),
            (
                Kind::CoupledSystem,
                vr::VEHICLE_PRIMARY_DAMPING,
                1e300,
                "vehicle.primary.damping",
            ),
            (
                Kind::TrackContact,
                vr::TRACK_RAIL_MASS,
                1e-300,
                "track.rail.mass",
            ),
            (
                Kind::RollPlaneVehicle,
                vr::VEHICLE_SECONDARY_SPACING,
                5e-324,
                "vehicle.secondary.spacing",
            ),
        ];
        for (kind, r, x, name) in cases {
            let (mut i, _) = instance(kind);
            let e = i.set_real(&[r], &[x]).unwrap_err();
            assert!(e.message.contains(&format!("`{name}` =")), "{}", e.message);
            assert!(e.message.contains("out of range"), "{}", e.message);
        }
    }

    #[test]
    fn a_parameter_error_is_reported_once_at_exit_initialization() {
        let (mut i, log) = instance(Kind::TrackContact);
        i.set_real(&[vr::FLAT_LEFT_2_DEPTH], &[1e-3]).unwrap();
        i.enter_initialization().unwrap();
        let e = i.exit_initialization().unwrap_err();
        assert!(e.message.contains("flat.left[2]"), "{}", e.message);
        assert_eq!(log.lock().unwrap().len(), 1);
    }

    #[test]
    fn wheel_inputs_far_into_the_rail_stop_the_run_with_an_error() {
        let (mut i, log) = instance(Kind::TrackContact);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.set_real(&[vr::WHEEL_LEFT_Z], &[-0.02]).unwrap();
        let mut p = [0.0];
        let e = i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap_err();
        assert!(e.message.contains("`contact.left.force`"), "{}", e.message);
        let e = i.do_step(0.0, 1e-4).unwrap_err();
        assert_eq!(e.status, Status::Error);
        assert!(
            e.message.contains("contact.left.force (N)"),
            "{}",
            e.message
        );
        assert!(e.message.contains("t = 0 s"), "{}", e.message);
        assert!(e.message.contains("wheel inputs"), "{}", e.message);
        let e = i.do_step(0.0, 1e-4).unwrap_err();
        assert!(e.message.contains("the run stopped"), "{}", e.message);
        assert_eq!(log.lock().unwrap().len(), 3);
        // Reset gives a fresh run.
        i.reset().unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 1e-4).unwrap();
    }

    #[test]
    fn an_unreachable_stop_time_is_named_at_initialisation() {
        let (mut i, log) = instance(Kind::CoupledSystem);
        i.setup_experiment(0.0, Some(2.0)).unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let log = log.lock().unwrap();
        assert_eq!(log.len(), 1);
        // 30 spans of 0.685 m from 1.37 m at 70 km/h: the end at 0.986 s; 2 s needs
        // 1.37 + 38.9 m of track, 59 spans, plus the two kept clear of the end.
        assert!(
            log[0].contains("stopTime = 2 s cannot be reached"),
            "{}",
            log[0]
        );
        assert!(log[0].contains("t = 0.986"), "{}", log[0]);
        assert!(log[0].contains("track.spans >= 61"), "{}", log[0]);
    }

    #[test]
    fn the_communication_point_must_be_the_fmu_time_to_the_clock_rounding() {
        // At t = 1e9 s a tolerance relative to 1 + |t| let 0.5 s jumps and steps back
        // through with fmi2OK.
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.setup_experiment(1e9, None).unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        for t in [1e9 + 0.5, 1e9 - 0.4, 1e9 + 1e-4] {
            let e = i.do_step(t, 1e-4).unwrap_err();
            assert!(e.message.contains("but the FMU is at"), "{}", e.message);
        }
        // A few units in the last place are the master's rounding.
        i.do_step(1e9 + 2.0 * 1.2e-7, 1e-4).unwrap();
        assert_eq!(i.phase(), Phase::StepComplete);
    }

    #[test]
    fn contacts_and_suspensions_too_soft_to_carry_the_load_are_refused_at_initialisation() {
        let cases: [(Kind, u32, f64, &str); 4] = [
            (Kind::CoupledSystem, vr::CONTACT_CH, 1.0, "`contact.CH`"),
            (Kind::TrackContact, vr::CONTACT_KW, 1e6, "`contact.Kw`"),
            (
                Kind::CoupledSystem,
                vr::VEHICLE_PRIMARY_STIFFNESS,
                1e4,
                "`vehicle.primary.stiffness`",
            ),
            (
                Kind::RollPlaneVehicle,
                vr::VEHICLE_SECONDARY_STIFFNESS,
                1e4,
                "`vehicle.secondary.stiffness`",
            ),
        ];
        for (kind, r, x, name) in cases {
            let (mut i, log) = instance(kind);
            if r == vr::CONTACT_CH {
                i.set_integer(&[vr::CONTACT_MODEL], &[2]).unwrap();
            }
            i.set_real(&[r], &[x]).unwrap();
            i.enter_initialization().unwrap();
            let e = i.exit_initialization().unwrap_err();
            assert!(e.message.contains(name), "{}", e.message);
            assert_eq!(log.lock().unwrap().len(), 1);
        }
        // The longest chord flat would be 139 mm deep.
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.set_integer(&[vr::FLAT_LEFT_1_SHAPE], &[2]).unwrap();
        i.set_real(
            &[vr::FLAT_LEFT_1_DEPTH, vr::FLAT_LEFT_1_LENGTH],
            &[0.0, 0.746],
        )
        .unwrap();
        i.enter_initialization().unwrap();
        let e = i.exit_initialization().unwrap_err();
        assert!(e.message.contains("`flat.left[1].length`"), "{}", e.message);
    }

    #[test]
    fn a_state_saved_before_the_first_step_restores_in_a_fresh_instance() {
        for kind in [
            Kind::TrackContact,
            Kind::RollPlaneVehicle,
            Kind::CoupledSystem,
        ] {
            let (mut a, _) = instance(kind);
            a.enter_initialization().unwrap();
            a.exit_initialization().unwrap();
            let state = a.get_state().unwrap();
            let bytes = a.serialize(&state).unwrap();
            let (mut b, _) = instance(kind);
            let s = b.deserialize(&bytes).unwrap();
            b.set_state(&s).unwrap();
            for i in [&mut a, &mut b] {
                i.do_step(0.0, 1e-3).unwrap();
            }
            let (mut x, mut y) = ([0.0; 2], [0.0; 2]);
            let vrs = [vr::WHEEL_LEFT_Z, vr::CONTACT_LEFT_MAX_FORCE];
            a.get_real(&vrs, &mut x).unwrap();
            b.get_real(&vrs, &mut y).unwrap();
            assert_eq!(x, y, "{kind:?}");
        }
    }

    #[test]
    fn a_doctored_state_is_refused_and_leaves_the_instance_as_it_was() {
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 1e-3).unwrap();
        let state = i.get_state().unwrap();
        let b = i.serialize(&state).unwrap();
        let guid = i.kind.table().guid.len();
        let time_at = MAGIC.len() + 8 + guid + 3;
        let put = |at: usize, bytes: &[u8]| {
            let mut c = b.clone();
            c[at..at + bytes.len()].copy_from_slice(bytes);
            c
        };
        for (bytes, why) in [
            // the GUID's and the reason's lengths at their largest
            (put(MAGIC.len(), &u64::MAX.to_le_bytes()), "truncated"),
            (put(time_at + 16, &u64::MAX.to_le_bytes()), "truncated"),
            // solver.step (the fifth calculated parameter) and the clock
            (
                put(time_at + 24 + 4 * 8, &1e300f64.to_le_bytes()),
                "disagrees",
            ),
            (
                put(time_at, &0.5f64.to_le_bytes()),
                "disagrees with the model's clock",
            ),
        ] {
            let e = i.deserialize(&bytes).unwrap_err();
            assert!(e.message.contains(why), "{why}: {}", e.message);
        }
        assert_eq!(i.phase(), Phase::StepComplete);
        i.do_step(1e-3, 1e-3).unwrap();
    }

    #[test]
    fn a_coupled_run_beyond_the_bounds_fails_the_step_that_got_there() {
        // A contact 300 times stiffer than table 4.4's on a shear-soft rail: the first
        // impact passes 20 times the static load. The step that ends there returns
        // fmi2Error naming the force and not blaming inputs CoupledSystem has none of;
        // the stopped run's state serialises and restores as stopped.
        let (mut i, _) = instance(Kind::CoupledSystem);
        i.set_integer(&[vr::TRACK_SPANS], &[60]).unwrap();
        i.set_real(
            &[vr::CONTACT_KW, vr::CONTACT_CH, vr::TRACK_RAIL_KAG],
            &[1e13, 0.0, 1e7],
        )
        .unwrap();
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let h = 1e-3;
        let mut k = 0;
        let e = loop {
            match i.do_step(k as f64 * h, h) {
                Ok(()) => {
                    let mut p = [0.0];
                    i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
                    assert!(p[0] < 20.0 * 107.7e3);
                }
                Err(e) => break e,
            }
            k += 1;
            assert!(k < 100, "no impact beyond the bound");
        };
        assert!(
            e.message.contains("contact.left.force (N)"),
            "{}",
            e.message
        );
        assert!(!e.message.contains("wheel inputs"), "{}", e.message);
        assert_eq!(i.phase(), Phase::Error);
        let state = i.get_state().unwrap();
        let bytes = i.serialize(&state).unwrap();
        let (mut fresh, _) = instance(Kind::CoupledSystem);
        let restored = fresh.deserialize(&bytes).unwrap();
        fresh.set_state(&restored).unwrap();
        assert_eq!(fresh.phase(), Phase::Error);
        let mut p = [0.0];
        let e = fresh
            .get_real(&[vr::CONTACT_LEFT_FORCE], &mut p)
            .unwrap_err();
        assert!(e.message.contains("the run stopped"), "{}", e.message);
        fresh.reset().unwrap();
        fresh.enter_initialization().unwrap();
        fresh.exit_initialization().unwrap();
    }

    #[test]
    fn the_vehicle_follows_the_masters_clock_far_from_zero() {
        // At t = 1e9 s each t + 1e-3 rounds by up to 6e-8 s; summing the h given drifted
        // 1e-3 s from the clock over 2e4 calls.
        let (mut v, _) = instance(Kind::RollPlaneVehicle);
        v.setup_experiment(1e9, None).unwrap();
        v.enter_initialization().unwrap();
        v.exit_initialization().unwrap();
        let mut t = 1e9;
        for _ in 0..20_000 {
            let next = t + 1e-3;
            v.do_step(t, next - t).unwrap();
            t = next;
        }
        let mut rot = [0.0];
        v.get_real(&[vr::WHEEL_ROTATION], &mut rot).unwrap();
        let model_time = rot[0] * 0.475 / (70.0 / 3.6);
        let dt = v.published.step;
        assert!(
            (model_time - (t - 1e9)).abs() <= 1e-3 * dt + 1e-9,
            "{model_time} against {}",
            t - 1e9
        );
    }

    #[test]
    fn a_track_too_soft_to_carry_the_load_is_refused_naming_its_support() {
        let (mut i, log) = instance(Kind::TrackContact);
        i.set_real(&[vr::TRACK_BALLAST_STIFFNESS], &[0.0]).unwrap();
        i.enter_initialization().unwrap();
        let e = i.exit_initialization().unwrap_err();
        assert!(
            e.message.contains("`track.ballast.stiffness` = 0"),
            "{}",
            e.message
        );
        assert!(e.message.contains("rail deflection"), "{}", e.message);
        assert_eq!(log.lock().unwrap().len(), 1);
    }
}
