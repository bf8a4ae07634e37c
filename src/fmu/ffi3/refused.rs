//! The exported FMI 3.0 functions these co-simulation units do not support (Model
//! Exchange, Scheduled Execution, Event Mode, clocks, per-element dependencies): each
//! is refused with `fmi3Error` and its reason from the state table, logged.

use super::component::*;
use super::types::*;
use crate::fmu::Status;
use crate::fmu::fmi3::{Allowed3, Call3};
use std::ffi::c_void;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::Ordering;

/// Refuses the function `name` of the family `call` on the instance behind `c`.
fn unsupported(c: fmi3Instance, call: Call3, name: &str) -> fmi3Status {
    let Some(comp) = enter(c, call) else {
        return ERROR;
    };
    let inner = unsafe { &mut *comp.inner.get() };
    let why = match call.allowed() {
        Allowed3::Unsupported(why) => why,
        _ => "",
    };
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let _ = inner
            .inst
            .refuse::<()>(Status::Error, format!("{name} is not supported: {why}"));
    }));
    comp.busy.store(0, Ordering::Release);
    ERROR
}

macro_rules! refused {
    ($name:ident, $call:ident $(, $t:ty)*) => {
        #[doc = concat!("`", stringify!($name), "`: not supported (refused with the reason).")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $name(c: fmi3Instance $(, _: $t)*) -> fmi3Status {
            unsupported(c, Call3::$call, stringify!($name))
        }
    };
}

type Vrs = *const fmi3ValueReference;
type Out<T> = *mut T;

refused!(fmi3EnterEventMode, EnterEventMode);
refused!(fmi3EnterStepMode, EnterStepMode);
refused!(fmi3EvaluateDiscreteStates, EvaluateDiscreteStates);
refused!(
    fmi3UpdateDiscreteStates,
    UpdateDiscreteStates,
    Out<bool>,
    Out<bool>,
    Out<bool>,
    Out<bool>,
    Out<bool>,
    Out<f64>
);
refused!(
    fmi3GetNumberOfVariableDependencies,
    GetNumberOfVariableDependencies,
    fmi3ValueReference,
    Out<usize>
);
refused!(
    fmi3GetVariableDependencies,
    GetVariableDependencies,
    fmi3ValueReference,
    Out<usize>,
    Out<u32>,
    Out<usize>,
    Out<i32>,
    usize
);
refused!(fmi3GetClock, Clocks, Vrs, usize, Out<bool>);
refused!(fmi3SetClock, Clocks, Vrs, usize, *const bool);
refused!(
    fmi3GetIntervalDecimal,
    Clocks,
    Vrs,
    usize,
    Out<f64>,
    Out<i32>
);
refused!(
    fmi3GetIntervalFraction,
    Clocks,
    Vrs,
    usize,
    Out<u64>,
    Out<u64>,
    Out<i32>
);
refused!(fmi3GetShiftDecimal, Clocks, Vrs, usize, Out<f64>);
refused!(fmi3GetShiftFraction, Clocks, Vrs, usize, Out<u64>, Out<u64>);
refused!(fmi3SetIntervalDecimal, Clocks, Vrs, usize, *const f64);
refused!(
    fmi3SetIntervalFraction,
    Clocks,
    Vrs,
    usize,
    *const u64,
    *const u64
);
refused!(fmi3SetShiftDecimal, Clocks, Vrs, usize, *const f64);
refused!(
    fmi3SetShiftFraction,
    Clocks,
    Vrs,
    usize,
    *const u64,
    *const u64
);
refused!(fmi3EnterContinuousTimeMode, ModelExchange);
refused!(
    fmi3CompletedIntegratorStep,
    ModelExchange,
    bool,
    Out<bool>,
    Out<bool>
);
refused!(fmi3SetTime, ModelExchange, f64);
refused!(fmi3SetContinuousStates, ModelExchange, *const f64, usize);
refused!(
    fmi3GetContinuousStateDerivatives,
    ModelExchange,
    Out<f64>,
    usize
);
refused!(fmi3GetEventIndicators, ModelExchange, Out<f64>, usize);
refused!(fmi3GetContinuousStates, ModelExchange, Out<f64>, usize);
refused!(
    fmi3GetNominalsOfContinuousStates,
    ModelExchange,
    Out<f64>,
    usize
);
refused!(fmi3GetNumberOfEventIndicators, ModelExchange, Out<usize>);
refused!(fmi3GetNumberOfContinuousStates, ModelExchange, Out<usize>);
refused!(
    fmi3ActivateModelPartition,
    ActivateModelPartition,
    fmi3ValueReference,
    f64
);

/// Logs through a logger given at an instantiation refused before there is an instance.
fn refuse_instantiation(
    log: fmi3LogMessageCallback,
    env: fmi3InstanceEnvironment,
    name: &str,
) -> fmi3Instance {
    if let Some(l) = log {
        let m = format!(
            "{name}: these FMUs are co-simulation units only: use fmi3InstantiateCoSimulation"
        );
        let _ = catch_unwind(AssertUnwindSafe(|| {
            CLogger { logger: l, env }.log(Status::Error, "logStatusError", &m)
        }));
    }
    std::ptr::null_mut()
}

/// `fmi3InstantiateModelExchange`: refused (NULL); these are co-simulation units.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateModelExchange(
    _: fmi3String,
    _: fmi3String,
    _: fmi3String,
    _: fmi3Boolean,
    _: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
) -> fmi3Instance {
    refuse_instantiation(
        logMessage,
        instanceEnvironment,
        "fmi3InstantiateModelExchange",
    )
}

/// `fmi3InstantiateScheduledExecution`: refused (NULL); these are co-simulation units.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3InstantiateScheduledExecution(
    _: fmi3String,
    _: fmi3String,
    _: fmi3String,
    _: fmi3Boolean,
    _: fmi3Boolean,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    _: *const c_void,
    _: *const c_void,
    _: *const c_void,
) -> fmi3Instance {
    refuse_instantiation(
        logMessage,
        instanceEnvironment,
        "fmi3InstantiateScheduledExecution",
    )
}
