//! The FMI 3.0 co-simulation state machine as one table: each function, the phases it
//! is allowed in (FMI 3.0, section 4.2.1 and figure 40, without Event Mode, which these
//! units do not have), and the FMI 2.0 function the layer below answers it with.

use crate::fmu::fmi2::{Call, Phase};

/// The phases of an FMI 3.0 co-simulation unit that these FMUs enter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase3 {
    /// After `fmi3InstantiateCoSimulation` or `fmi3Reset`.
    Instantiated,
    /// Between `fmi3EnterConfigurationMode` and `fmi3ExitConfigurationMode`: the
    /// structural parameter `wheelsets` may be set.
    ConfigurationMode,
    /// Between `fmi3EnterInitializationMode` and `fmi3ExitInitializationMode`.
    InitializationMode,
    /// Stepping.
    StepMode,
    /// After `fmi3DoStep` ended the run (`terminateSimulation` true, the wheel at the
    /// end of the track): outputs can be read and `fmi3Terminate` called.
    RunEnded,
    /// After `fmi3Terminate`.
    Terminated,
    /// After an error that stopped the run: `fmi3Reset`, `fmi3FreeInstance`, FMU
    /// states and reads for debugging.
    Error,
}

impl Phase3 {
    /// The FMI 3.0 phase of an instance whose FMI 2.0 layer is in `p` (`configuring`:
    /// between the configuration-mode calls).
    pub fn of(p: Phase, configuring: bool) -> Phase3 {
        match p {
            Phase::Instantiated if configuring => Phase3::ConfigurationMode,
            Phase::Instantiated => Phase3::Instantiated,
            Phase::Initialization => Phase3::InitializationMode,
            Phase::StepComplete => Phase3::StepMode,
            Phase::StepFailed => Phase3::RunEnded,
            Phase::Terminated => Phase3::Terminated,
            Phase::Error => Phase3::Error,
        }
    }
}

/// Where an FMI 3.0 function may be called.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Allowed3 {
    /// Not called on an instance.
    NoInstance,
    /// In these phases.
    In(&'static [Phase3]),
    /// Never: refused in every phase, for this reason.
    Unsupported(&'static str),
}

use Phase3::{
    ConfigurationMode as Cnf, Error as Err_, InitializationMode as Ini, Instantiated as Ins,
    RunEnded as End, StepMode as Stp, Terminated as Ter,
};

const ALL: &[Phase3] = &[Ins, Cnf, Ini, Stp, End, Ter, Err_];
/// Where values can be read: in Instantiated and Configuration Mode the parameters' and
/// inputs' start values (or the values set; FMI 3.0 2.3.2, and the Reference-FMUs read in
/// Configuration Mode too), from Initialization Mode on every variable.
const READ: &[Phase3] = &[Ins, Cnf, Ini, Stp, End, Ter, Err_];
const WRITE: &[Phase3] = &[Ins, Ini, Stp];
const DERIVATIVES: &[Phase3] = &[Ini, Stp, End, Ter, Err_];
const NO_EVENTS: &str = "these units have no Event Mode (hasEventMode is false): instantiate \
     with eventModeUsed = false";
const NO_CLOCKS: &str = "these units have no clocks";
const CO_SIMULATION: &str = "these FMUs are co-simulation units only";
const NO_TYPE: &str = "";

/// The FMI 3.0 functions, in the order of [`CALLS3`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[allow(missing_docs)]
pub enum Call3 {
    GetVersion,
    SetDebugLogging,
    InstantiateModelExchange,
    InstantiateCoSimulation,
    InstantiateScheduledExecution,
    FreeInstance,
    EnterInitializationMode,
    ExitInitializationMode,
    EnterEventMode,
    Terminate,
    Reset,
    GetFloat64,
    GetInt32,
    GetInt64,
    GetUInt64,
    GetString,
    SetFloat64,
    SetInt32,
    SetInt64,
    SetUInt64,
    SetString,
    /// Every other type's get (Float32, Int8 to UInt32, Boolean, Binary): no variable
    /// has it.
    GetOther,
    /// Every other type's set.
    SetOther,
    GetNumberOfVariableDependencies,
    GetVariableDependencies,
    GetFMUState,
    SetFMUState,
    FreeFMUState,
    SerializedFMUStateSize,
    SerializeFMUState,
    DeserializeFMUState,
    GetDirectionalDerivative,
    GetAdjointDerivative,
    EnterConfigurationMode,
    ExitConfigurationMode,
    Clocks,
    EvaluateDiscreteStates,
    UpdateDiscreteStates,
    ModelExchange,
    EnterStepMode,
    GetOutputDerivatives,
    DoStep,
    ActivateModelPartition,
}

/// The one table of the FMI 3.0 state machine: each function, its C name (the type's
/// for a family), where it is allowed, and the FMI 2.0 function of the layer below that
/// answers it (whose name the messages of that layer carry).
#[rustfmt::skip]
pub const CALLS3: [(Call3, &str, Allowed3, Option<Call>); 43] = [
    (Call3::GetVersion, "fmi3GetVersion", Allowed3::NoInstance, None),
    (Call3::SetDebugLogging, "fmi3SetDebugLogging", Allowed3::In(ALL), Some(Call::SetDebugLogging)),
    (Call3::InstantiateModelExchange, "fmi3InstantiateModelExchange", Allowed3::Unsupported(CO_SIMULATION), None),
    (Call3::InstantiateCoSimulation, "fmi3InstantiateCoSimulation", Allowed3::NoInstance, Some(Call::Instantiate)),
    (Call3::InstantiateScheduledExecution, "fmi3InstantiateScheduledExecution", Allowed3::Unsupported(CO_SIMULATION), None),
    (Call3::FreeInstance, "fmi3FreeInstance", Allowed3::In(ALL), Some(Call::FreeInstance)),
    (Call3::EnterInitializationMode, "fmi3EnterInitializationMode", Allowed3::In(&[Ins]), Some(Call::SetupExperiment)),
    (Call3::ExitInitializationMode, "fmi3ExitInitializationMode", Allowed3::In(&[Ini]), Some(Call::ExitInitializationMode)),
    (Call3::EnterEventMode, "fmi3EnterEventMode", Allowed3::Unsupported(NO_EVENTS), None),
    (Call3::Terminate, "fmi3Terminate", Allowed3::In(&[Stp, End]), Some(Call::Terminate)),
    (Call3::Reset, "fmi3Reset", Allowed3::In(ALL), Some(Call::Reset)),
    (Call3::GetFloat64, "fmi3GetFloat64", Allowed3::In(READ), Some(Call::GetReal)),
    (Call3::GetInt32, "fmi3GetInt32", Allowed3::In(READ), Some(Call::GetInteger)),
    (Call3::GetInt64, "fmi3GetInt64", Allowed3::In(READ), Some(Call::GetInteger)),
    (Call3::GetUInt64, "fmi3GetUInt64", Allowed3::In(READ), Some(Call::GetInteger)),
    (Call3::GetString, "fmi3GetString", Allowed3::In(READ), Some(Call::GetString)),
    (Call3::SetFloat64, "fmi3SetFloat64", Allowed3::In(WRITE), Some(Call::SetReal)),
    (Call3::SetInt32, "fmi3SetInt32", Allowed3::In(WRITE), Some(Call::SetInteger)),
    (Call3::SetInt64, "fmi3SetInt64", Allowed3::In(WRITE), Some(Call::SetInteger)),
    (Call3::SetUInt64, "fmi3SetUInt64", Allowed3::In(&[Cnf]), Some(Call::SetInteger)),
    (Call3::SetString, "fmi3SetString", Allowed3::In(WRITE), Some(Call::SetString)),
    (Call3::GetOther, "fmi3Get", Allowed3::In(READ), None),
    (Call3::SetOther, "fmi3Set", Allowed3::In(WRITE), None),
    (Call3::GetNumberOfVariableDependencies, "fmi3GetNumberOfVariableDependencies", Allowed3::Unsupported("the dependencies are in the model description's ModelStructure (providesPerElementDependencies is false)"), None),
    (Call3::GetVariableDependencies, "fmi3GetVariableDependencies", Allowed3::Unsupported("the dependencies are in the model description's ModelStructure (providesPerElementDependencies is false)"), None),
    (Call3::GetFMUState, "fmi3GetFMUState", Allowed3::In(ALL), Some(Call::GetFMUstate)),
    (Call3::SetFMUState, "fmi3SetFMUState", Allowed3::In(ALL), Some(Call::SetFMUstate)),
    (Call3::FreeFMUState, "fmi3FreeFMUState", Allowed3::In(ALL), Some(Call::FreeFMUstate)),
    (Call3::SerializedFMUStateSize, "fmi3SerializedFMUStateSize", Allowed3::In(ALL), Some(Call::SerializedFMUstateSize)),
    (Call3::SerializeFMUState, "fmi3SerializeFMUState", Allowed3::In(ALL), Some(Call::SerializeFMUstate)),
    (Call3::DeserializeFMUState, "fmi3DeserializeFMUState", Allowed3::In(ALL), Some(Call::DeSerializeFMUstate)),
    (Call3::GetDirectionalDerivative, "fmi3GetDirectionalDerivative", Allowed3::In(DERIVATIVES), Some(Call::GetDirectionalDerivative)),
    (Call3::GetAdjointDerivative, "fmi3GetAdjointDerivative", Allowed3::In(DERIVATIVES), Some(Call::GetDirectionalDerivative)),
    (Call3::EnterConfigurationMode, "fmi3EnterConfigurationMode", Allowed3::In(&[Ins]), None),
    (Call3::ExitConfigurationMode, "fmi3ExitConfigurationMode", Allowed3::In(&[Cnf]), None),
    (Call3::Clocks, "the clock functions", Allowed3::Unsupported(NO_CLOCKS), None),
    (Call3::EvaluateDiscreteStates, "fmi3EvaluateDiscreteStates", Allowed3::Unsupported(NO_EVENTS), None),
    (Call3::UpdateDiscreteStates, "fmi3UpdateDiscreteStates", Allowed3::Unsupported(NO_EVENTS), None),
    (Call3::ModelExchange, "the Model Exchange functions", Allowed3::Unsupported(CO_SIMULATION), None),
    (Call3::EnterStepMode, "fmi3EnterStepMode", Allowed3::Unsupported(NO_EVENTS), None),
    (Call3::GetOutputDerivatives, "fmi3GetOutputDerivatives", Allowed3::In(&[Stp, End, Ter, Err_]), Some(Call::GetRealOutputDerivatives)),
    (Call3::DoStep, "fmi3DoStep", Allowed3::In(&[Stp]), Some(Call::DoStep)),
    (Call3::ActivateModelPartition, "fmi3ActivateModelPartition", Allowed3::Unsupported(CO_SIMULATION), None),
];

impl Call3 {
    /// The C name (`fmi3DoStep`).
    pub fn name(self) -> &'static str {
        CALLS3[self as usize].1
    }
    /// Where it may be called.
    pub fn allowed(self) -> Allowed3 {
        CALLS3[self as usize].2
    }
    /// The FMI 2.0 function of the layer below that answers it.
    pub fn fmi2(self) -> Option<Call> {
        CALLS3[self as usize].3
    }
}

/// The FMI 3.0 name of the FMI 2.0 function `fmi2` in a message: `running`'s own name
/// when it answers through `fmi2`, else the first FMI 3.0 function that does.
pub fn fmi3_name(fmi2: Call, running: Option<Call3>) -> &'static str {
    if let Some(r) = running.filter(|r| r.fmi2() == Some(fmi2)) {
        return r.name();
    }
    match fmi2 {
        Call::EnterInitializationMode => "fmi3EnterInitializationMode",
        _ => CALLS3
            .iter()
            .find(|c| c.3 == Some(fmi2) && !c.1.ends_with("fmi3Get") && !c.1.ends_with("fmi3Set"))
            .map_or(NO_TYPE, |c| c.1),
    }
}
