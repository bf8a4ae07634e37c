//! The exported FMI 2.0 functions of an instance's life cycle: the common functions
//! (types platform, version, debug logging), instantiation and freeing, the experiment's
//! set-up, initialisation, termination and reset (a source of the C header that
//! cbindgen writes, `build/c_header.rs`).

use super::binary::{kind_for_guid, kind_of_binary, loaded_binary};
use super::component::*;
use super::guard;
use super::types::*;
use crate::fmu::{Call, Instance, Logger, Status};
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

/// `fmi2GetTypesPlatform`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2SetDebugLogging`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    let call = Call::SetDebugLogging;
    with(c, call, |i| {
        let on = boolean(i, call, "loggingOn", loggingOn)?;
        let cats = if nCategories == 0 {
            Vec::new()
        } else {
            let s = slice(i, call, "categories", categories, nCategories)?;
            let mut v = Vec::new();
            for (k, &p) in s.iter().enumerate() {
                match c_str(p) {
                    Some(x) => v.push(x),
                    None => {
                        return i.refuse(
                            Status::Error,
                            format!("fmi2SetDebugLogging: categories[{k}] is a null pointer"),
                        );
                    }
                }
            }
            v
        };
        i.set_debug_logging(on, &cats)
    })
}

/// `fmi2Instantiate`: the GUID selects TrackContact, RollPlaneVehicle or CoupledSystem;
/// inside an FMU only that FMU's GUID ([`kind_for_guid`]).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let cb = if functions.is_null() {
            None
        } else {
            let f = unsafe { &*functions };
            f.logger.map(|l| (l, f.componentEnvironment))
        };
        let name = instance_name(instanceName).unwrap_or_default();
        let clog = cb.map(|(l, env)| CLogger {
            logger: l,
            env,
            name: CString::new(name.replace('\0', " ")).unwrap_or_default(),
        });
        let fail = |m: String| {
            if let Some(l) = &clog {
                l.log(Status::Error, "logStatusError", &m);
            }
            std::ptr::null_mut()
        };
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        if name.trim().is_empty() {
            return fail(format!(
                "fmi2Instantiate: instanceName {}; FMI 2.0 requires a non-empty name",
                if instanceName.is_null() {
                    "is null".to_string()
                } else {
                    format!("= {name:?}")
                }
            ));
        }
        for (what, v) in [("visible", visible), ("loggingOn", loggingOn)] {
            if v != 0 && v != 1 {
                return fail(bool_message(Call::Instantiate, what, v));
            }
        }
        if fmuType != 1 {
            return fail(format!(
                "fmi2Instantiate: fmuType = {fmuType}; these FMUs are Co-Simulation only (fmi2CoSimulation = 1)"
            ));
        }
        let guid = c_str(fmuGUID).unwrap_or_default();
        let binary = loaded_binary().as_deref().and_then(kind_of_binary);
        let kind = match kind_for_guid(binary, &guid) {
            Ok(k) => k,
            Err(m) => return fail(format!("fmi2Instantiate: {m}")),
        };
        let busy = Arc::new(AtomicUsize::new(0));
        let logger: Logger = match clog.clone() {
            Some(l) => {
                let busy = busy.clone();
                Box::new(move |s, cat, m| l.log_in_call(&busy, s, cat, m))
            }
            None => Box::new(|_, _, _| {}),
        };
        let inst = Instance::new(kind.table(), &name, logger, loggingOn == 1);
        guard::boxed(busy, clog, inst)
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: the instance and every FMU state it handed out. Refused (and
/// logged) while another thread is in a call of the instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    guard::free::<Instance, CLogger>(c, Call::FreeInstance)
}

/// `fmi2SetupExperiment`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    _tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    let call = Call::SetupExperiment;
    with(c, call, |i| {
        boolean(i, call, "toleranceDefined", toleranceDefined)?;
        let stop_defined = boolean(i, call, "stopTimeDefined", stopTimeDefined)?;
        // A stop time the master did not define is not shown as one.
        i.log_call(|| match stop_defined {
            true => format!("fmi2SetupExperiment(startTime={startTime}, stopTime={stopTime})"),
            false => format!("fmi2SetupExperiment(startTime={startTime}, stopTime undefined)"),
        });
        i.setup_experiment(startTime, stop_defined.then_some(stopTime))
    })
}

/// `fmi2EnterInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, Call::EnterInitializationMode, |i| {
        i.log_call(|| "fmi2EnterInitializationMode()".into());
        i.enter_initialization()
    })
}

/// `fmi2ExitInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, Call::ExitInitializationMode, |i| {
        i.log_call(|| "fmi2ExitInitializationMode()".into());
        i.exit_initialization()
    })
}

/// `fmi2Terminate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with(c, Call::Terminate, |i| {
        i.log_call(|| "fmi2Terminate()".into());
        i.terminate()
    })
}

/// `fmi2Reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    with(c, Call::Reset, |i| {
        i.log_call(|| "fmi2Reset()".into());
        i.reset()
    })
}
