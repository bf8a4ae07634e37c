//! The C boundary: every FMI 2.0 co-simulation function, exported unmangled. Each one
//! checks its pointers, converts arguments and forwards to [`super::Instance`] inside
//! `catch_unwind`, so no panic crosses into the master. cbindgen writes the C header of
//! this file (`build.rs`); a test compiles it against the official `fmi2Functions.h`.

#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

use super::{Instance, Kind, Logger, Snapshot, Status};
use std::ffi::{CStr, CString, c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// `fmi2Component`: pointer to an instance.
pub type fmi2Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the master's pointer handed back to the logger.
pub type fmi2ComponentEnvironment = *mut c_void;
/// `fmi2FMUstate`: pointer to a saved state.
pub type fmi2FMUstate = *mut c_void;
/// `fmi2ValueReference`.
pub type fmi2ValueReference = c_uint;
/// `fmi2Real`.
pub type fmi2Real = f64;
/// `fmi2Integer`.
pub type fmi2Integer = c_int;
/// `fmi2Boolean`.
pub type fmi2Boolean = c_int;
/// `fmi2Char`.
pub type fmi2Char = c_char;
/// `fmi2String`.
pub type fmi2String = *const fmi2Char;
/// `fmi2Byte`.
pub type fmi2Byte = c_char;
/// `fmi2Status` (an enumeration in C, passed as int).
pub type fmi2Status = c_int;
/// `fmi2Type`: 0 Model Exchange, 1 Co-Simulation.
pub type fmi2Type = c_int;
/// `fmi2StatusKind`: 0 DoStepStatus, 1 PendingStatus, 2 LastSuccessfulTime, 3 Terminated.
pub type fmi2StatusKind = c_int;

/// `fmi2CallbackLogger`, variadic like the C declaration.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct fmi2CallbackFunctions {
    /// Logger.
    pub logger: fmi2CallbackLogger,
    /// Memory allocation (not used: `canNotUseMemoryManagementFunctions`).
    pub allocateMemory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// Memory release (not used).
    pub freeMemory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// Asynchronous step finished (not used).
    pub stepFinished: Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>,
    /// The master's environment pointer.
    pub componentEnvironment: fmi2ComponentEnvironment,
}

const OK: fmi2Status = Status::Ok as c_int;
const ERROR: fmi2Status = Status::Error as c_int;

/// The master's logger with what it needs; used by one instance at a time.
struct CLogger {
    logger: unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
    env: fmi2ComponentEnvironment,
    name: CString,
}

// The master owns the environment pointer and calls an instance from one thread at a
// time (FMI 2.0, section 2.1.4); the logger is only called during such calls.
unsafe impl Send for CLogger {}

impl CLogger {
    fn log(&self, status: Status, category: &str, message: &str) {
        let cat = CString::new(category.replace('\0', " ")).unwrap_or_default();
        // The message is the format string, with '%' doubled: masters that format it
        // (printf-style) and masters that print it as it is both show the text.
        let msg = CString::new(message.replace('\0', " ").replace('%', "%%")).unwrap_or_default();
        unsafe {
            (self.logger)(
                self.env,
                self.name.as_ptr(),
                status as c_int,
                cat.as_ptr(),
                msg.as_ptr(),
            )
        }
    }
}

fn c_str(s: fmi2String) -> Option<String> {
    if s.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
    }
}

/// Runs `f` on the instance behind `c`, catching panics.
fn with(
    c: fmi2Component,
    call: &str,
    f: impl FnOnce(&mut Instance) -> super::FmiResult,
) -> fmi2Status {
    if c.is_null() {
        return ERROR;
    }
    let inst = unsafe { &mut *(c as *mut Instance) };
    match catch_unwind(AssertUnwindSafe(|| f(inst))) {
        Ok(Ok(())) => OK,
        Ok(Err(r)) => r.status as c_int,
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            let _ = catch_unwind(AssertUnwindSafe(|| {
                inst.poison();
                inst.log(
                    Status::Error,
                    "logStatusError",
                    &format!("{call}: internal error ({what}); the instance was terminated, call fmi2Reset"),
                );
            }));
            ERROR
        }
    }
}

/// A slice from a C array, refusing a null pointer (also with a count of 0).
fn slice<'a, T>(
    inst: &mut Instance,
    call: &str,
    what: &str,
    p: *const T,
    n: usize,
) -> super::FmiResult<&'a [T]> {
    if p.is_null() {
        return inst.refuse(
            Status::Error,
            format!("{call}: argument `{what}` is a null pointer (count {n})"),
        );
    }
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

fn slice_mut<'a, T>(
    inst: &mut Instance,
    call: &str,
    what: &str,
    p: *mut T,
    n: usize,
) -> super::FmiResult<&'a mut [T]> {
    if p.is_null() {
        return inst.refuse(
            Status::Error,
            format!("{call}: argument `{what}` is a null pointer (count {n})"),
        );
    }
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

// ------------------------------------------------------------------ common functions

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
    with(c, "fmi2SetDebugLogging", |i| {
        let cats = if nCategories == 0 {
            Vec::new()
        } else {
            let s = slice(
                i,
                "fmi2SetDebugLogging",
                "categories",
                categories,
                nCategories,
            )?;
            let mut v = Vec::new();
            for &p in s {
                match c_str(p) {
                    Some(x) => v.push(x),
                    None => {
                        return i.refuse(
                            Status::Error,
                            "fmi2SetDebugLogging: a category is a null pointer".into(),
                        );
                    }
                }
            }
            v
        };
        i.set_debug_logging(loggingOn != 0, &cats)
    })
}

/// `fmi2Instantiate`: the GUID selects TrackContact, RollPlaneVehicle or CoupledSystem.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let cb = if functions.is_null() {
            None
        } else {
            let f = unsafe { &*functions };
            f.logger.map(|l| (l, f.componentEnvironment))
        };
        let name = c_str(instanceName).unwrap_or_default();
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
        if name.is_empty() {
            return fail("fmi2Instantiate: instanceName is null or empty".into());
        }
        if fmuType != 1 {
            return fail(format!(
                "fmi2Instantiate: fmuType = {fmuType}; these FMUs are Co-Simulation only (fmi2CoSimulation = 1)"
            ));
        }
        let guid = c_str(fmuGUID).unwrap_or_default();
        let Some(kind) = Kind::from_guid(&guid) else {
            return fail(format!(
                "fmi2Instantiate: GUID \"{guid}\" matches none of TrackContact ({}), RollPlaneVehicle ({}), CoupledSystem ({})",
                super::vars::TRACK_CONTACT.guid,
                super::vars::ROLL_PLANE_VEHICLE.guid,
                super::vars::COUPLED_SYSTEM.guid
            ));
        };
        let logger: Logger = match clog {
            Some(l) => Box::new(move |s, cat, m| l.log(s, cat, m)),
            None => Box::new(|_, _, _| {}),
        };
        let inst = Box::new(Instance::new(kind, &name, logger, loggingOn != 0));
        Box::into_raw(inst) as fmi2Component
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if !c.is_null() {
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(c as *mut Instance) })
        }));
    }
}

/// `fmi2SetupExperiment`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    _toleranceDefined: fmi2Boolean,
    _tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    with(c, "fmi2SetupExperiment", |i| {
        i.log_call(|| format!("fmi2SetupExperiment(startTime={startTime}, stopTime={stopTime})"));
        i.setup_experiment(startTime, (stopTimeDefined != 0).then_some(stopTime))
    })
}

/// `fmi2EnterInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2EnterInitializationMode", |i| {
        i.log_call(|| "fmi2EnterInitializationMode()".into());
        i.enter_initialization()
    })
}

/// `fmi2ExitInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2ExitInitializationMode", |i| {
        i.log_call(|| "fmi2ExitInitializationMode()".into());
        i.exit_initialization()
    })
}

/// `fmi2Terminate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Terminate", |i| {
        i.log_call(|| "fmi2Terminate()".into());
        i.terminate()
    })
}

/// `fmi2Reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    with(c, "fmi2Reset", |i| {
        i.log_call(|| "fmi2Reset()".into());
        i.reset()
    })
}

/// `fmi2GetReal`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    with(c, "fmi2GetReal", |i| {
        let vr = slice(i, "fmi2GetReal", "vr", vr, nvr)?;
        let value = slice_mut(i, "fmi2GetReal", "value", value, nvr)?;
        i.get_real(vr, value)?;
        i.log_call(|| format!("fmi2GetReal(vr={vr:?}) -> {value:?}"));
        Ok(())
    })
}

/// `fmi2GetInteger` (integers and enumerations).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    with(c, "fmi2GetInteger", |i| {
        let vr = slice(i, "fmi2GetInteger", "vr", vr, nvr)?;
        let value = slice_mut(i, "fmi2GetInteger", "value", value, nvr)?;
        i.get_integer(vr, value)?;
        i.log_call(|| format!("fmi2GetInteger(vr={vr:?}) -> {value:?}"));
        Ok(())
    })
}

/// `fmi2GetBoolean`: no Boolean variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2GetBoolean", |i| {
        let vr = slice(i, "fmi2GetBoolean", "vr", vr, nvr)?;
        slice_mut(i, "fmi2GetBoolean", "value", value, nvr)?;
        i.no_such_type("fmi2GetBoolean", vr)
    })
}

/// `fmi2GetString`: no String variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    with(c, "fmi2GetString", |i| {
        let vr = slice(i, "fmi2GetString", "vr", vr, nvr)?;
        slice_mut(i, "fmi2GetString", "value", value, nvr)?;
        i.no_such_type("fmi2GetString", vr)
    })
}

/// `fmi2SetReal`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    with(c, "fmi2SetReal", |i| {
        let vr = slice(i, "fmi2SetReal", "vr", vr, nvr)?;
        let value = slice(i, "fmi2SetReal", "value", value, nvr)?;
        i.log_call(|| format!("fmi2SetReal(vr={vr:?}, value={value:?})"));
        i.set_real(vr, value)
    })
}

/// `fmi2SetInteger` (integers and enumerations).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    with(c, "fmi2SetInteger", |i| {
        let vr = slice(i, "fmi2SetInteger", "vr", vr, nvr)?;
        let value = slice(i, "fmi2SetInteger", "value", value, nvr)?;
        i.log_call(|| format!("fmi2SetInteger(vr={vr:?}, value={value:?})"));
        i.set_integer(vr, value)
    })
}

/// `fmi2SetBoolean`: no Boolean variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2SetBoolean", |i| {
        let vr = slice(i, "fmi2SetBoolean", "vr", vr, nvr)?;
        slice(i, "fmi2SetBoolean", "value", value, nvr)?;
        i.no_such_type("fmi2SetBoolean", vr)
    })
}

/// `fmi2SetString`: no String variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    with(c, "fmi2SetString", |i| {
        let vr = slice(i, "fmi2SetString", "vr", vr, nvr)?;
        slice(i, "fmi2SetString", "value", value, nvr)?;
        i.no_such_type("fmi2SetString", vr)
    })
}

// ------------------------------------------------------------------ FMU states

/// `fmi2GetFMUstate`: a new state, or the one `*FMUstate` points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    with(c, "fmi2GetFMUstate", |i| {
        i.log_call(|| "fmi2GetFMUstate()".into());
        if FMUstate.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2GetFMUstate: argument `FMUstate` is a null pointer".into(),
            );
        }
        let s = i.get_state()?;
        let slot = unsafe { &mut *FMUstate };
        if slot.is_null() {
            *slot = Box::into_raw(Box::new(s)) as fmi2FMUstate;
        } else {
            unsafe { *(*slot as *mut Snapshot) = s };
        }
        Ok(())
    })
}

/// `fmi2SetFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    with(c, "fmi2SetFMUstate", |i| {
        i.log_call(|| "fmi2SetFMUstate()".into());
        if FMUstate.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2SetFMUstate: argument `FMUstate` is a null pointer".into(),
            );
        }
        let s = unsafe { &*(FMUstate as *const Snapshot) };
        i.set_state(s)
    })
}

/// `fmi2FreeFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    with(c, "fmi2FreeFMUstate", |i| {
        i.log_call(|| "fmi2FreeFMUstate()".into());
        if FMUstate.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2FreeFMUstate: argument `FMUstate` is a null pointer".into(),
            );
        }
        let slot = unsafe { &mut *FMUstate };
        if !slot.is_null() {
            drop(unsafe { Box::from_raw(*slot as *mut Snapshot) });
            *slot = std::ptr::null_mut();
        }
        Ok(())
    })
}

/// `fmi2SerializedFMUstateSize`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    with(c, "fmi2SerializedFMUstateSize", |i| {
        if FMUstate.is_null() || size.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2SerializedFMUstateSize: argument `FMUstate` or `size` is a null pointer"
                    .into(),
            );
        }
        let s = unsafe { &*(FMUstate as *const Snapshot) };
        let b = i.serialize(s)?;
        unsafe { *size = b.len() };
        Ok(())
    })
}

/// `fmi2SerializeFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    with(c, "fmi2SerializeFMUstate", |i| {
        if FMUstate.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2SerializeFMUstate: argument `FMUstate` is a null pointer".into(),
            );
        }
        let out = slice_mut(
            i,
            "fmi2SerializeFMUstate",
            "serializedState",
            serializedState,
            size,
        )?;
        let s = unsafe { &*(FMUstate as *const Snapshot) };
        let b = i.serialize(s)?;
        if b.len() != size {
            return i.refuse(
                Status::Error,
                format!(
                    "fmi2SerializeFMUstate: size = {size} bytes; allowed: {} (from fmi2SerializedFMUstateSize)",
                    b.len()
                ),
            );
        }
        for (o, x) in out.iter_mut().zip(b) {
            *o = x as fmi2Byte;
        }
        Ok(())
    })
}

/// `fmi2DeSerializeFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    with(c, "fmi2DeSerializeFMUstate", |i| {
        if FMUstate.is_null() {
            return i.refuse(
                Status::Error,
                "fmi2DeSerializeFMUstate: argument `FMUstate` is a null pointer".into(),
            );
        }
        let bytes = slice(
            i,
            "fmi2DeSerializeFMUstate",
            "serializedState",
            serializedState,
            size,
        )?;
        let bytes: Vec<u8> = bytes.iter().map(|&b| b as u8).collect();
        let s = i.deserialize(&bytes)?;
        let slot = unsafe { &mut *FMUstate };
        if !slot.is_null() {
            drop(unsafe { Box::from_raw(*slot as *mut Snapshot) });
        }
        *slot = Box::into_raw(Box::new(s)) as fmi2FMUstate;
        Ok(())
    })
}

/// `fmi2GetDirectionalDerivative`: not provided (`providesDirectionalDerivative="false"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    _vUnknown_ref: *const fmi2ValueReference,
    _nUnknown: usize,
    _vKnown_ref: *const fmi2ValueReference,
    _nKnown: usize,
    _dvKnown: *const fmi2Real,
    _dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2GetDirectionalDerivative",
        "providesDirectionalDerivative is false",
    )
}

fn unsupported(c: fmi2Component, call: &str, why: &str) -> fmi2Status {
    with(c, call, |i| {
        i.refuse(Status::Error, format!("{call} is not supported: {why}"))
    })
}

// ------------------------------------------------------------------ co-simulation

/// `fmi2SetRealInputDerivatives`: not supported (`canInterpolateInputs="false"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *const fmi2Real,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2SetRealInputDerivatives",
        "canInterpolateInputs is false; inputs are held over a step",
    )
}

/// `fmi2GetRealOutputDerivatives`: not supported (`maxOutputDerivativeOrder="0"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    _vr: *const fmi2ValueReference,
    _nvr: usize,
    _order: *const fmi2Integer,
    _value: *mut fmi2Real,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2GetRealOutputDerivatives",
        "maxOutputDerivativeOrder is 0",
    )
}

/// `fmi2DoStep`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2DoStep", |i| {
        i.log_call(|| {
            format!("fmi2DoStep(t={currentCommunicationPoint}, h={communicationStepSize})")
        });
        i.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// `fmi2CancelStep`: steps are synchronous, there is nothing to cancel.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    unsupported(
        c,
        "fmi2CancelStep",
        "fmi2DoStep is synchronous and never returns fmi2Pending",
    )
}

/// `fmi2GetStatus`: steps are synchronous, no status to ask for.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2GetStatus",
        "fmi2DoStep is synchronous and never returns fmi2Pending",
    )
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    with(c, "fmi2GetRealStatus", |i| {
        let v = slice_mut(i, "fmi2GetRealStatus", "value", value, 1)?;
        if s != 2 {
            return i.refuse(
                Status::Error,
                format!("fmi2GetRealStatus: status kind {s}; allowed: fmi2LastSuccessfulTime (2)"),
            );
        }
        v[0] = i.last_successful_time();
        Ok(())
    })
}

/// `fmi2GetIntegerStatus`: no integer status.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2GetIntegerStatus",
        "FMI 2.0 defines no integer status",
    )
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (the wheel reached the end of the track).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    with(c, "fmi2GetBooleanStatus", |i| {
        let v = slice_mut(i, "fmi2GetBooleanStatus", "value", value, 1)?;
        if s != 3 {
            return i.refuse(
                Status::Error,
                format!("fmi2GetBooleanStatus: status kind {s}; allowed: fmi2Terminated (3)"),
            );
        }
        v[0] = i.terminated_by_model() as fmi2Boolean;
        Ok(())
    })
}

/// `fmi2GetStringStatus`: no string status.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    unsupported(
        c,
        "fmi2GetStringStatus",
        "fmi2PendingStatus never applies: steps are synchronous",
    )
}
