//! The call generator of FMI 3.0: every exported FMI 3.0 function by its C name, the
//! weights of a random pick, and the calls a well-behaved master makes in each phase
//! (the FMI 2.0 generator is [`crate::calls`]).

use crate::calls::{Mirror, pick};
use rand::rngs::StdRng;

/// The FMI 3.0 functions, in the order of [`F3S`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum F3 {
    GetVersion,
    SetDebugLogging,
    InstantiateCoSimulation,
    InstantiateModelExchange,
    InstantiateScheduledExecution,
    FreeInstance,
    EnterConfigurationMode,
    ExitConfigurationMode,
    EnterInitializationMode,
    ExitInitializationMode,
    Terminate,
    Reset,
    GetFloat64,
    SetFloat64,
    GetInt32,
    SetInt32,
    GetInt64,
    SetInt64,
    GetUInt64,
    SetUInt64,
    GetString,
    SetString,
    GetFloat32,
    SetFloat32,
    GetInt8,
    SetInt8,
    GetUInt8,
    SetUInt8,
    GetInt16,
    SetInt16,
    GetUInt16,
    SetUInt16,
    GetUInt32,
    SetUInt32,
    GetBoolean,
    SetBoolean,
    GetBinary,
    SetBinary,
    GetFMUState,
    SetFMUState,
    FreeFMUState,
    SerializedFMUStateSize,
    SerializeFMUState,
    DeserializeFMUState,
    GetDirectionalDerivative,
    GetAdjointDerivative,
    GetOutputDerivatives,
    DoStep,
    EnterEventMode,
    EnterStepMode,
    EvaluateDiscreteStates,
    UpdateDiscreteStates,
    GetNumberOfVariableDependencies,
    GetVariableDependencies,
    GetClock,
    SetClock,
    GetIntervalDecimal,
    GetIntervalFraction,
    GetShiftDecimal,
    GetShiftFraction,
    SetIntervalDecimal,
    SetIntervalFraction,
    SetShiftDecimal,
    SetShiftFraction,
    EnterContinuousTimeMode,
    CompletedIntegratorStep,
    SetTime,
    SetContinuousStates,
    GetContinuousStateDerivatives,
    GetEventIndicators,
    GetContinuousStates,
    GetNominalsOfContinuousStates,
    GetNumberOfEventIndicators,
    GetNumberOfContinuousStates,
    ActivateModelPartition,
}

/// Every FMI 3.0 function: its C name and its weight in a random pick (the refused
/// ones of Model Exchange, Scheduled Execution, Event Mode and clocks, and the types no
/// variable has, 1 each: together as often as `fmi3DoStep`).
#[rustfmt::skip]
pub const F3S: [(F3, &str, u32); 75] = [
    (F3::GetVersion, "fmi3GetVersion", 1),
    (F3::SetDebugLogging, "fmi3SetDebugLogging", 2),
    (F3::InstantiateCoSimulation, "fmi3InstantiateCoSimulation", 3),
    (F3::InstantiateModelExchange, "fmi3InstantiateModelExchange", 1),
    (F3::InstantiateScheduledExecution, "fmi3InstantiateScheduledExecution", 1),
    (F3::FreeInstance, "fmi3FreeInstance", 2),
    (F3::EnterConfigurationMode, "fmi3EnterConfigurationMode", 4),
    (F3::ExitConfigurationMode, "fmi3ExitConfigurationMode", 4),
    (F3::EnterInitializationMode, "fmi3EnterInitializationMode", 6),
    (F3::ExitInitializationMode, "fmi3ExitInitializationMode", 6),
    (F3::Terminate, "fmi3Terminate", 3),
    (F3::Reset, "fmi3Reset", 3),
    (F3::GetFloat64, "fmi3GetFloat64", 12),
    (F3::SetFloat64, "fmi3SetFloat64", 10),
    (F3::GetInt32, "fmi3GetInt32", 2),
    (F3::SetInt32, "fmi3SetInt32", 2),
    (F3::GetInt64, "fmi3GetInt64", 2),
    (F3::SetInt64, "fmi3SetInt64", 3),
    (F3::GetUInt64, "fmi3GetUInt64", 3),
    (F3::SetUInt64, "fmi3SetUInt64", 6),
    (F3::GetString, "fmi3GetString", 2),
    (F3::SetString, "fmi3SetString", 2),
    (F3::GetFloat32, "fmi3GetFloat32", 1),
    (F3::SetFloat32, "fmi3SetFloat32", 1),
    (F3::GetInt8, "fmi3GetInt8", 1),
    (F3::SetInt8, "fmi3SetInt8", 1),
    (F3::GetUInt8, "fmi3GetUInt8", 1),
    (F3::SetUInt8, "fmi3SetUInt8", 1),
    (F3::GetInt16, "fmi3GetInt16", 1),
    (F3::SetInt16, "fmi3SetInt16", 1),
    (F3::GetUInt16, "fmi3GetUInt16", 1),
    (F3::SetUInt16, "fmi3SetUInt16", 1),
    (F3::GetUInt32, "fmi3GetUInt32", 1),
    (F3::SetUInt32, "fmi3SetUInt32", 1),
    (F3::GetBoolean, "fmi3GetBoolean", 1),
    (F3::SetBoolean, "fmi3SetBoolean", 1),
    (F3::GetBinary, "fmi3GetBinary", 1),
    (F3::SetBinary, "fmi3SetBinary", 1),
    (F3::GetFMUState, "fmi3GetFMUState", 4),
    (F3::SetFMUState, "fmi3SetFMUState", 4),
    (F3::FreeFMUState, "fmi3FreeFMUState", 3),
    (F3::SerializedFMUStateSize, "fmi3SerializedFMUStateSize", 2),
    (F3::SerializeFMUState, "fmi3SerializeFMUState", 3),
    (F3::DeserializeFMUState, "fmi3DeserializeFMUState", 3),
    (F3::GetDirectionalDerivative, "fmi3GetDirectionalDerivative", 2),
    (F3::GetAdjointDerivative, "fmi3GetAdjointDerivative", 2),
    (F3::GetOutputDerivatives, "fmi3GetOutputDerivatives", 2),
    (F3::DoStep, "fmi3DoStep", 18),
    (F3::EnterEventMode, "fmi3EnterEventMode", 1),
    (F3::EnterStepMode, "fmi3EnterStepMode", 1),
    (F3::EvaluateDiscreteStates, "fmi3EvaluateDiscreteStates", 1),
    (F3::UpdateDiscreteStates, "fmi3UpdateDiscreteStates", 1),
    (F3::GetNumberOfVariableDependencies, "fmi3GetNumberOfVariableDependencies", 1),
    (F3::GetVariableDependencies, "fmi3GetVariableDependencies", 1),
    (F3::GetClock, "fmi3GetClock", 1),
    (F3::SetClock, "fmi3SetClock", 1),
    (F3::GetIntervalDecimal, "fmi3GetIntervalDecimal", 1),
    (F3::GetIntervalFraction, "fmi3GetIntervalFraction", 1),
    (F3::GetShiftDecimal, "fmi3GetShiftDecimal", 1),
    (F3::GetShiftFraction, "fmi3GetShiftFraction", 1),
    (F3::SetIntervalDecimal, "fmi3SetIntervalDecimal", 1),
    (F3::SetIntervalFraction, "fmi3SetIntervalFraction", 1),
    (F3::SetShiftDecimal, "fmi3SetShiftDecimal", 1),
    (F3::SetShiftFraction, "fmi3SetShiftFraction", 1),
    (F3::EnterContinuousTimeMode, "fmi3EnterContinuousTimeMode", 1),
    (F3::CompletedIntegratorStep, "fmi3CompletedIntegratorStep", 1),
    (F3::SetTime, "fmi3SetTime", 1),
    (F3::SetContinuousStates, "fmi3SetContinuousStates", 1),
    (F3::GetContinuousStateDerivatives, "fmi3GetContinuousStateDerivatives", 1),
    (F3::GetEventIndicators, "fmi3GetEventIndicators", 1),
    (F3::GetContinuousStates, "fmi3GetContinuousStates", 1),
    (F3::GetNominalsOfContinuousStates, "fmi3GetNominalsOfContinuousStates", 1),
    (F3::GetNumberOfEventIndicators, "fmi3GetNumberOfEventIndicators", 1),
    (F3::GetNumberOfContinuousStates, "fmi3GetNumberOfContinuousStates", 1),
    (F3::ActivateModelPartition, "fmi3ActivateModelPartition", 1),
];

impl F3 {
    /// The C name (`fmi3DoStep`).
    pub fn name(self) -> &'static str {
        F3S[self as usize].1
    }

    /// A function these units refuse whatever the arguments and the phase (Model
    /// Exchange, Scheduled Execution, Event Mode, clocks, per-element dependencies).
    pub fn unsupported(self) -> bool {
        self as usize >= F3::EnterEventMode as usize
            || matches!(
                self,
                F3::InstantiateModelExchange | F3::InstantiateScheduledExecution
            )
    }

    /// A get or set of a type no variable has.
    pub fn absent_type(self) -> bool {
        (F3::GetFloat32 as usize..=F3::SetBinary as usize).contains(&(self as usize))
    }
}

/// A random FMI 3.0 function ([`F3S`]'s weights).
pub fn pick_call3(rng: &mut StdRng) -> F3 {
    static W: std::sync::OnceLock<Vec<(F3, u32)>> = std::sync::OnceLock::new();
    pick(
        rng,
        W.get_or_init(|| F3S.iter().map(|f| (f.0, f.2)).collect()),
    )
}

/// A call a well-behaved master would make next on an FMI 3.0 instance in `phase`
/// (with valid arguments); `structural`: the FMU has the structural parameter
/// `wheelsets`.
pub fn next_valid_call3(rng: &mut StdRng, phase: Mirror, structural: bool) -> F3 {
    let configure = if structural { 2 } else { 0 };
    match phase {
        Mirror::Instantiated => pick(
            rng,
            &[
                (F3::SetFloat64, 2),
                (F3::SetInt64, 1),
                (F3::GetFloat64, 1),
                (F3::GetUInt64, 1),
                (F3::EnterConfigurationMode, configure),
                (F3::EnterInitializationMode, 5),
            ],
        ),
        Mirror::Configuration => pick(rng, &[(F3::SetUInt64, 4), (F3::ExitConfigurationMode, 4)]),
        Mirror::Initialization => pick(
            rng,
            &[
                (F3::SetFloat64, 2),
                (F3::GetFloat64, 2),
                (F3::ExitInitializationMode, 6),
                // After a refused exit (parameters the model refuses).
                (F3::Reset, 1),
            ],
        ),
        Mirror::Stepping => pick(
            rng,
            &[
                (F3::DoStep, 60),
                (F3::GetFloat64, 15),
                (F3::SetFloat64, 10),
                (F3::GetInt64, 1),
                (F3::GetInt32, 1),
                (F3::GetString, 1),
                (F3::GetUInt64, 1),
                (F3::GetFMUState, 4),
                (F3::SetFMUState, 4),
                (F3::SerializeFMUState, 2),
                (F3::DeserializeFMUState, 2),
                (F3::GetDirectionalDerivative, 1),
                (F3::GetAdjointDerivative, 1),
                (F3::GetOutputDerivatives, 1),
                (F3::Terminate, 1),
            ],
        ),
        Mirror::Ended => pick(
            rng,
            &[
                (F3::GetFloat64, 3),
                (F3::DoStep, 1),
                (F3::Terminate, 3),
                (F3::Reset, 3),
            ],
        ),
        Mirror::Terminated => pick(rng, &[(F3::GetFloat64, 1), (F3::Reset, 4)]),
        Mirror::Unknown => pick(
            rng,
            &[
                (F3::EnterInitializationMode, 1),
                (F3::ExitInitializationMode, 1),
                (F3::Reset, 1),
            ],
        ),
    }
}
