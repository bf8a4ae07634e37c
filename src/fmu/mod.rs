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
use crate::cosim::{VehicleUnit, VehicleUnitParams};
use crate::error::Error;
use crate::params::{Scenario, TrackSpec, VehicleSpec};
use crate::profile::{FlatShape, FlatSpec};
use crate::solver::{Sample, Simulation, VehicleState};
use crate::track::{RailEnds, RailSection, TrackParams};
use crate::vehicle::RollPlaneParams;
use vars::{Causality, FmuTable, N_VR, VarSpec, VarType, vr};

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

/// Everything an FMU state holds: enough to continue bit-identically.
#[derive(Debug, Clone)]
pub struct Snapshot {
    kind: Kind,
    phase: Phase,
    values: Vec<f64>,
    model: Option<Model>,
    published: Published,
    time: f64,
    ended: bool,
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
    time: f64,
    stop_time: Option<f64>,
    /// The model ended the run (wheel at the track end): `fmi2Terminated` status.
    ended: bool,
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

/// Value references of the flats `[side][k]`: length, depth, angle, shape.
const FLAT_VRS: [[[u32; 4]; 4]; 2] = [
    [
        [
            vr::FLAT_LEFT_1_LENGTH,
            vr::FLAT_LEFT_1_DEPTH,
            vr::FLAT_LEFT_1_ANGLE,
            vr::FLAT_LEFT_1_SHAPE,
        ],
        [
            vr::FLAT_LEFT_2_LENGTH,
            vr::FLAT_LEFT_2_DEPTH,
            vr::FLAT_LEFT_2_ANGLE,
            vr::FLAT_LEFT_2_SHAPE,
        ],
        [
            vr::FLAT_LEFT_3_LENGTH,
            vr::FLAT_LEFT_3_DEPTH,
            vr::FLAT_LEFT_3_ANGLE,
            vr::FLAT_LEFT_3_SHAPE,
        ],
        [
            vr::FLAT_LEFT_4_LENGTH,
            vr::FLAT_LEFT_4_DEPTH,
            vr::FLAT_LEFT_4_ANGLE,
            vr::FLAT_LEFT_4_SHAPE,
        ],
    ],
    [
        [
            vr::FLAT_RIGHT_1_LENGTH,
            vr::FLAT_RIGHT_1_DEPTH,
            vr::FLAT_RIGHT_1_ANGLE,
            vr::FLAT_RIGHT_1_SHAPE,
        ],
        [
            vr::FLAT_RIGHT_2_LENGTH,
            vr::FLAT_RIGHT_2_DEPTH,
            vr::FLAT_RIGHT_2_ANGLE,
            vr::FLAT_RIGHT_2_SHAPE,
        ],
        [
            vr::FLAT_RIGHT_3_LENGTH,
            vr::FLAT_RIGHT_3_DEPTH,
            vr::FLAT_RIGHT_3_ANGLE,
            vr::FLAT_RIGHT_3_SHAPE,
        ],
        [
            vr::FLAT_RIGHT_4_LENGTH,
            vr::FLAT_RIGHT_4_DEPTH,
            vr::FLAT_RIGHT_4_ANGLE,
            vr::FLAT_RIGHT_4_SHAPE,
        ],
    ],
];

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
            stop_time: None,
            ended: false,
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
            Phase::Error => "; an internal error stopped the instance: call fmi2Reset".into(),
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

    /// The state check of `call` by its C name, for callers that still pass their own
    /// list: `allowed` must be the table's entry (checked in debug builds); a refusal
    /// comes from [`Instance::check`], with the table's message. New code calls
    /// [`Instance::check`] with the [`Call`].
    #[inline]
    fn require(&mut self, call: &str, allowed: &[Phase]) -> FmiResult {
        debug_assert!(
            Call::from_name(call)
                .is_some_and(|c| matches!(c.allowed(), Allowed::In(p) if p == allowed)),
            "{call}: the phases {allowed:?} are not the table's"
        );
        if allowed.contains(&self.phase()) {
            return Ok(());
        }
        match Call::from_name(call) {
            Some(c) => self.refuse_call(c),
            None => self.refuse(
                Status::Error,
                format!("{call}: not an FMI 2.0 co-simulation function"),
            ),
        }
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> FmiResult {
        self.require("fmi2SetupExperiment", &[Phase::Instantiated])?;
        if start != 0.0 || !start.is_finite() {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetupExperiment: startTime = {start} s; allowed: 0 s (the model starts in \
                     static equilibrium at start_position)"
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
        Ok(())
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
        self.stop_time = None;
        self.ended = false;
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
                        shape: if self.v(f[3]) == 2.0 {
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
            contact_model: if self.v(vr::CONTACT_MODEL) == 2.0 {
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
                let critical_step = match &s.track {
                    TrackSpec::Discrete(t) => t.critical_time_step().0,
                    TrackSpec::Lumped(_) => f64::NAN,
                };
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
                    self.sync_inputs()?;
                }
                Err(e) => {
                    self.model = None;
                    return self.engine_refusal("parameters refused", e);
                }
            }
        }
        Ok(())
    }

    /// Pushes the input values into the model. Called when inputs are set (and when
    /// the model is built), not at every step: the track turns the axle on at
    /// `V / R_w` from the last rotation it was given.
    fn sync_inputs(&mut self) -> FmiResult {
        let r = match (&mut self.model, self.kind) {
            (Some(Model::Sim(sim)), Kind::TrackContact) => sim.set_wheel_inputs(
                [
                    self.values[vr::WHEEL_LEFT_Z as usize],
                    self.values[vr::WHEEL_RIGHT_Z as usize],
                ],
                self.values[vr::WHEEL_ROTATION as usize],
            ),
            (Some(Model::Vehicle(u)), _) => u.set_forces([
                self.values[vr::CONTACT_LEFT_FORCE as usize],
                self.values[vr::CONTACT_RIGHT_FORCE as usize],
            ]),
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
    fn get(&mut self, call: &str, vrs: &[u32], out: &mut [f64], real: bool) -> FmiResult {
        self.require(call, READ)?;
        let mut needs_model = false;
        for &r in vrs {
            let s = self.spec(call, r)?;
            self.check_type(call, s, real)?;
            needs_model |= matches!(
                s.causality,
                Causality::Output | Causality::CalculatedParameter
            );
        }
        if needs_model {
            self.ensure_model()?;
        }
        let sample = match &self.model {
            Some(Model::Sim(sim)) if needs_model => Some(sim.sample()),
            _ => None,
        };
        for (o, &r) in out.iter_mut().zip(vrs) {
            let s = self.known_spec(r);
            *o = match s.causality {
                Causality::Parameter | Causality::Input => self.values[s.vr as usize],
                _ => self.computed(s.vr, sample.as_ref()),
            };
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
    fn set(&mut self, call: &str, vrs: &[u32], vals: &[f64], real: bool) -> FmiResult {
        self.require(
            call,
            &[
                Phase::Instantiated,
                Phase::Initialization,
                Phase::StepComplete,
            ],
        )?;
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
                        "{call}: `{}` = {x}{unit} is out of range; allowed: finite, {} <= {} <= {}{unit}",
                        s.name, s.min, s.name, s.max
                    ),
                );
            }
        }
        let mut inputs_changed = false;
        for (&r, &x) in vrs.iter().zip(vals) {
            let s = self.known_spec(r);
            self.values[s.vr as usize] = x;
            if s.causality == Causality::Parameter {
                self.dirty = true;
            } else {
                inputs_changed = true;
            }
        }
        if inputs_changed && self.model.is_some() && !self.dirty {
            self.sync_inputs()?;
        }
        Ok(())
    }

    /// `fmi2GetReal`.
    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        self.get("fmi2GetReal", vrs, out, true)
    }

    /// `fmi2GetInteger` (integers and enumerations).
    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        let mut tmp = vec![0.0; vrs.len()];
        self.get("fmi2GetInteger", vrs, &mut tmp, false)?;
        for (o, t) in out.iter_mut().zip(tmp) {
            *o = t as i32;
        }
        Ok(())
    }

    /// `fmi2SetReal`.
    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> FmiResult {
        self.set("fmi2SetReal", vrs, vals, true)
    }

    /// `fmi2SetInteger` (integers and enumerations).
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> FmiResult {
        let tmp: Vec<f64> = vals.iter().map(|&x| x as f64).collect();
        self.set("fmi2SetInteger", vrs, &tmp, false)
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
    pub fn do_step(&mut self, t: f64, h: f64) -> FmiResult {
        self.require("fmi2DoStep", &[Phase::StepComplete])?;
        if !(h.is_finite() && h > 0.0) {
            return self.refuse(
                Status::Error,
                format!("fmi2DoStep: communicationStepSize = {h} s; allowed: finite and > 0 s"),
            );
        }
        let tol = 1e-9 * (1.0 + self.time.abs());
        if !t.is_finite() || (t - self.time).abs() > tol {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: currentCommunicationPoint = {t} s, but the FMU is at {} s",
                    self.time
                ),
            );
        }
        if let Some(stop) = self
            .stop_time
            .filter(|s| t + h > s + 1e-9 * (1.0 + s.abs()))
        {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: t + h = {} s is past stopTime = {stop} s of fmi2SetupExperiment",
                    t + h
                ),
            );
        }
        let r = match &mut self.model {
            Some(Model::Sim(sim)) => sim.advance(h),
            Some(Model::Vehicle(u)) => u.advance(h),
            None => Err(Error::Unsupported("stepping before initialisation".into())),
        };
        if let Err(e) = r {
            if matches!(e, Error::OffTrack { .. }) {
                self.ended = true;
            }
            return self.engine_refusal(&format!("fmi2DoStep at t = {t} s, h = {h} s"), e);
        }
        self.time = t + h;
        Ok(())
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
            ended: self.ended,
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
        self.ended = s.ended;
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
        for x in [
            s.published.static_load[0],
            s.published.static_load[1],
            s.published.static_wheel_z[0],
            s.published.static_wheel_z[1],
            s.published.step,
            s.published.critical_step,
            s.published.kw_used,
        ] {
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
        time: f64,
        pubs: &[f64],
        values: &[f64],
        state: &[f64],
    ) -> std::result::Result<(), String> {
        if !(time.is_finite() && time >= 0.0) {
            return Err(format!("stored time {time} s is not finite and >= 0"));
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
        self.check_stored(time, &pubs, &values, &state)?;
        let model = if has_model {
            // Build with the stored parameters on a scratch instance, then overwrite
            // the dynamic state.
            let saved = std::mem::replace(&mut self.values, values.clone());
            let built = self.build();
            self.values = saved;
            let (mut m, _) = built.map_err(|e| format!("stored parameters refused: {e}"))?;
            match &mut m {
                Model::Vehicle(u) => u.set_state_vector(&state),
                Model::Sim(sim) => sim.set_state_vector(&state),
            }
            .map_err(|e| e.to_string())?;
            Some(m)
        } else {
            None
        };
        Ok(Snapshot {
            kind: self.kind,
            phase,
            values,
            model,
            published: Published {
                static_load: [pubs[0], pubs[1]],
                static_wheel_z: [pubs[2], pubs[3]],
                step: pubs[4],
                critical_step: pubs[5],
                kw_used: pubs[6],
            },
            time,
            ended,
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

const MAGIC: &[u8] = b"wheelflat-fmu-state-1\0";

struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> std::result::Result<&'a [u8], String> {
        if self.at + n > self.b.len() {
            return Err(format!("truncated at byte {}", self.at));
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
    fn every_variable_is_documented() {
        let doc = include_str!("../../docs/VARIABLES.md");
        for t in vars::FMUS {
            for v in t.vars {
                assert!(
                    doc.contains(&format!("| `{}` |", v.name)),
                    "{} undocumented",
                    v.name
                );
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
        assert!((p[0] - (1.37 + 0.01 * 70.0 / 3.6)).abs() < 1e-9);
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
        let values_at = time_at + 8 * 8 + 8;
        for (at, x, why) in [
            (b.len() - 8, f64::NAN, "model state"),
            (b.len() - 8, f64::INFINITY, "model state"),
            (time_at, -1.0, "stored time"),
            (time_at + 8, f64::NAN, "calculated parameter"),
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
            Some(Model::Sim(s)) => s.rotation(),
            _ => unreachable!(),
        };
        i.set_real(&[vr::WHEEL_ROTATION], &[0.5]).unwrap();
        assert_eq!(sim(&i), 0.5);
        i.do_step(0.0, 1e-3).unwrap();
        let expected = 0.5 + 1e-3 * (70.0 / 3.6) / 0.475;
        assert!((sim(&i) - expected).abs() < 1e-12);
    }
}
