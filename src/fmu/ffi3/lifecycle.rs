//! The exported FMI 3.0 functions of an instance's life cycle: version, debug logging,
//! instantiation and freeing, configuration, initialisation, termination and reset.

use super::component::*;
use super::types::*;
use crate::fmu::ffi::guard;
use crate::fmu::ffi::{kind_of_binary, loaded_binary};
use crate::fmu::fmi3::Call3;
use crate::fmu::{Instance3, Kind, Logger, Status};
use std::ffi::c_char;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

/// `fmi3GetVersion`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi3GetVersion() -> *const c_char {
    c"3.0".as_ptr()
}

/// `fmi3SetDebugLogging`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetDebugLogging(
    instance: fmi3Instance,
    loggingOn: fmi3Boolean,
    nCategories: usize,
    categories: *const fmi3String,
) -> fmi3Status {
    let call = Call3::SetDebugLogging;
    with(instance, call, |i| {
        let s = slice(i, call, "categories", categories, nCategories)?;
        let mut v = Vec::new();
        for (k, &p) in s.iter().enumerate() {
            match c_str(p) {
                Some(x) => v.push(x),
                None => {
                    return i.refuse(
                        Status::Error,
                        format!("fmi3SetDebugLogging: categories[{k}] is a null pointer"),
                    );
                }
            }
        }
        i.set_debug_logging(loggingOn, &v)
    })
}

/// The FMU an instantiation token instantiates in this binary: only its own FMU's
/// token inside an FMU (whose library is named after it), any of them otherwise.
pub fn kind_for_token(binary: Option<Kind>, token: &str) -> Result<Kind, String> {
    let found = Kind::ALL.into_iter().find(|k| k.table3().token == token);
    match (binary, found) {
        (None, Some(k)) => Ok(k),
        (Some(b), Some(k)) if b == k => Ok(k),
        (Some(b), Some(k)) => Err(format!(
            "instantiationToken \"{token}\" belongs to {}, but this binary is {} (token {}): \
             instantiate {} from its own FMU",
            k.table().model_identifier,
            b.table().model_identifier,
            b.table3().token,
            k.table().model_identifier
        )),
        (Some(b), None) => Err(format!(
            "instantiationToken \"{token}\" matches none of the wheelflat FMI 3.0 FMUs; this \
             binary is {} (token {}){}",
            b.table().model_identifier,
            b.table3().token,
            if Kind::from_guid(token).is_some() {
                " - it is an FMI 2.0 GUID: instantiate the FMI 2.0 FMU with fmi2Instantiate"
            } else {
                ""
            }
        )),
        (None, None) => Err(format!(
            "instantiationToken \"{token}\" matches none of {}",
            Kind::ALL
                .map(|k| format!("{} ({})", k.table().model_identifier, k.table3().token))
                .join(", ")
        )),
    }
}

/// `fmi3InstantiateCoSimulation`: the token selects the FMU ([`kind_for_token`]). Event
/// Mode and intermediate variables are refused (NULL, with the reason logged); with
/// `earlyReturnAllowed` a track-carrying FMU returns early where a wheel comes into
/// contact or loses it.
#[unsafe(no_mangle)]
#[allow(unused_variables)]
pub unsafe extern "C" fn fmi3InstantiateCoSimulation(
    instanceName: fmi3String,
    instantiationToken: fmi3String,
    resourcePath: fmi3String,
    visible: fmi3Boolean,
    loggingOn: fmi3Boolean,
    eventModeUsed: fmi3Boolean,
    earlyReturnAllowed: fmi3Boolean,
    requiredIntermediateVariables: *const fmi3ValueReference,
    nRequiredIntermediateVariables: usize,
    instanceEnvironment: fmi3InstanceEnvironment,
    logMessage: fmi3LogMessageCallback,
    intermediateUpdate: fmi3IntermediateUpdateCallback,
) -> fmi3Instance {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let clog = logMessage.map(|l| CLogger {
            logger: l,
            env: instanceEnvironment,
        });
        let fail = |m: String| {
            if let Some(l) = &clog {
                l.log(Status::Error, "logStatusError", &m);
            }
            std::ptr::null_mut()
        };
        let name = c_str(instanceName).unwrap_or_default();
        if name.trim().is_empty() {
            return fail(format!(
                "fmi3InstantiateCoSimulation: instanceName {}; FMI 3.0 requires a non-empty name",
                if instanceName.is_null() {
                    "is null".to_string()
                } else {
                    format!("= {name:?}")
                }
            ));
        }
        if eventModeUsed {
            return fail(
                "fmi3InstantiateCoSimulation: eventModeUsed = true; these units have no Event \
                 Mode (hasEventMode is false): instantiate with eventModeUsed = false"
                    .into(),
            );
        }
        if nRequiredIntermediateVariables > 0 {
            return fail(format!(
                "fmi3InstantiateCoSimulation: nRequiredIntermediateVariables = \
                 {nRequiredIntermediateVariables}; these units provide no intermediate update \
                 (providesIntermediateUpdate is false): allowed 0"
            ));
        }
        let Some(token) = c_str(instantiationToken) else {
            return fail(
                "fmi3InstantiateCoSimulation: instantiationToken is a null pointer; give the \
                 model description's instantiationToken"
                    .into(),
            );
        };
        let binary = loaded_binary().as_deref().and_then(kind_of_binary);
        let kind = match kind_for_token(binary, &token) {
            Ok(k) => k,
            Err(m) => return fail(format!("fmi3InstantiateCoSimulation: {m}")),
        };
        let busy = Arc::new(AtomicUsize::new(0));
        let logger: Logger = match clog.clone() {
            Some(l) => {
                let busy = busy.clone();
                Box::new(move |s, cat, m| l.log_in_call(&busy, s, cat, m))
            }
            None => Box::new(|_, _, _| {}),
        };
        let mut inst = Instance3::new(kind.table3(), &name, logger, loggingOn);
        inst.allow_early_return(earlyReturnAllowed);
        guard::boxed(busy, clog, inst)
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi3FreeInstance`: the instance and every FMU state it handed out.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeInstance(instance: fmi3Instance) {
    guard::free::<Instance3, CLogger>(instance, Call3::FreeInstance)
}

/// `fmi3EnterConfigurationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    with(instance, Call3::EnterConfigurationMode, |i| {
        i.enter_configuration()
    })
}

/// `fmi3ExitConfigurationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitConfigurationMode(instance: fmi3Instance) -> fmi3Status {
    with(instance, Call3::ExitConfigurationMode, |i| {
        i.exit_configuration()
    })
}

/// `fmi3EnterInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3EnterInitializationMode(
    instance: fmi3Instance,
    toleranceDefined: fmi3Boolean,
    tolerance: fmi3Float64,
    startTime: fmi3Float64,
    stopTimeDefined: fmi3Boolean,
    stopTime: fmi3Float64,
) -> fmi3Status {
    with(instance, Call3::EnterInitializationMode, |i| {
        i.log_call(|| match stopTimeDefined {
            true => {
                format!("fmi3EnterInitializationMode(startTime={startTime}, stopTime={stopTime})")
            }
            false => {
                format!("fmi3EnterInitializationMode(startTime={startTime}, stopTime undefined)")
            }
        });
        i.enter_initialization(
            toleranceDefined.then_some(tolerance),
            startTime,
            stopTimeDefined.then_some(stopTime),
        )
    })
}

/// `fmi3ExitInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3ExitInitializationMode(instance: fmi3Instance) -> fmi3Status {
    with(instance, Call3::ExitInitializationMode, |i| {
        i.exit_initialization()
    })
}

/// `fmi3Terminate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Terminate(instance: fmi3Instance) -> fmi3Status {
    with(instance, Call3::Terminate, |i| i.terminate())
}

/// `fmi3Reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3Reset(instance: fmi3Instance) -> fmi3Status {
    with(instance, Call3::Reset, |i| i.reset())
}
