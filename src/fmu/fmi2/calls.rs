//! The FMI 2.0 co-simulation state machine as one table: each function and the phases
//! it is allowed in (FMI 2.0, section 4.2.4).

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
    pub(crate) fn from_u8(p: u8) -> Option<Phase> {
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
pub(crate) const ALL: &[Phase] = &[Ins, Ini, Stc, Stf, Ter, Err_];
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
/// every call ([`super::Instance::check`]).
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
    // Where the FMU declares the capability (checked by the instance).
    (Call::GetDirectionalDerivative, "fmi2GetDirectionalDerivative", Allowed::In(&[Ini, Stc, Stf, Ter, Err_])),
    (Call::SetRealInputDerivatives, "fmi2SetRealInputDerivatives", Allowed::In(&[Ini, Stc])),
    (Call::GetRealOutputDerivatives, "fmi2GetRealOutputDerivatives", Allowed::In(&[Stc, Stf, Ter, Err_])),
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
