//! The C boundary: every FMI 2.0 co-simulation function, exported unmangled. Each one
//! claims the instance (a busy flag refuses a second thread), checks the state table
//! ([`super::CALLS`]), its pointers and arguments, and forwards to [`super::Instance`]
//! inside `catch_unwind`, so no panic crosses into the master. FMU states are owned by
//! the instance that handed them out. cbindgen writes the C header of this file
//! (`build.rs`); a test compiles it against the official `fmi2Functions.h`.

#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

use super::{CALLS, Call, Instance, Kind, Logger, Snapshot, Status};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ffi::{CStr, CString, c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `fmi2Component`: pointer to an instance (behind its busy flag).
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

/// The master's logger with what it needs.
#[derive(Clone)]
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

// The master owns the environment pointer; the logger is only called during calls of
// the instance (FMI 2.0, section 2.1.4), from the thread that makes the call.
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

    /// Logs a message of the instance during the call recorded in `busy`, with the
    /// function's name in front when the message does not name it: every message says
    /// which call it answers.
    fn log_in_call(&self, busy: &AtomicUsize, status: Status, category: &str, message: &str) {
        match running(busy.load(Ordering::Relaxed)) {
            Some(call) if !message.contains(call.name()) => {
                self.log(status, category, &format!("{}: {message}", call.name()))
            }
            _ => self.log(status, category, message),
        }
    }
}

/// The function recorded in a busy flag: 0 is idle, else 1 + its index in [`CALLS`].
fn running(flag: usize) -> Option<Call> {
    CALLS.get(flag.wrapping_sub(1)).map(|c| c.0)
}

/// What an `fmi2Component` points to: the instance behind a busy flag.
///
/// FMI 2.0 forbids calling one instance from two threads at once; a master that does
/// gets `fmi2Error` for the second call, which touches nothing but the flag and the
/// copy of the logger here. (`fmi2FreeInstance` racing with another call is refused
/// the same way; a call made after `fmi2FreeInstance` returned cannot be detected.)
struct Component {
    /// 0 when idle, else 1 + the index in [`CALLS`] of the function running. Shared with
    /// the instance's logger, which names that function.
    busy: Arc<AtomicUsize>,
    /// The master's logger, for refusals that must not touch the instance.
    logger: Option<CLogger>,
    inner: UnsafeCell<Inner>,
}

/// The instance and the FMU states it handed out.
struct Inner {
    inst: Instance,
    /// Every FMU state handed out and not freed, by address. A state pointer is used
    /// only when it is a key here; the rest are freed with the instance.
    states: HashMap<usize, Box<Snapshot>>,
}

impl Inner {
    /// Puts `s` into the state `old` of this instance (already checked by
    /// [`Inner::state`]), or into a new state whose address goes to `slot`.
    fn store(&mut self, old: Option<usize>, s: Snapshot, slot: &mut fmi2FMUstate) {
        match old.and_then(|key| self.states.get_mut(&key)) {
            Some(b) => **b = s,
            None => {
                let b = Box::new(s);
                let p = &*b as *const Snapshot as fmi2FMUstate;
                self.states.insert(p as usize, b);
                *slot = p;
            }
        }
    }

    /// The state behind `p` when this instance handed it out and has not freed it;
    /// `p` itself is never dereferenced.
    fn state(&mut self, call: Call, what: &str, p: fmi2FMUstate) -> super::FmiResult<usize> {
        let key = p as usize;
        if self.states.contains_key(&key) {
            return Ok(key);
        }
        let live = self.states.len();
        self.inst.refuse(
            Status::Error,
            format!(
                "{}: argument `{what}` = {p:p} is not an FMU state of this instance \
                 (\"{}\", {live} live states): it belongs to another instance, was already \
                 freed, or is not an FMU state; it was not used",
                call.name(),
                self.inst.name()
            ),
        )
    }
}

/// Claims the instance behind `c` for `call`, or refuses (busy: logged).
fn enter<'a>(c: fmi2Component, call: Call) -> Option<&'a Component> {
    if c.is_null() {
        return None;
    }
    let comp = unsafe { &*(c as *const Component) };
    match comp
        .busy
        .compare_exchange(0, call as usize + 1, Ordering::Acquire, Ordering::Acquire)
    {
        Ok(_) => Some(comp),
        Err(other) => {
            let other = running(other).map_or("another function", |o| o.name());
            let freeing = if call == Call::FreeInstance {
                "; the instance was not freed"
            } else {
                "; the call was refused and the instance left as it was"
            };
            if let Some(l) = &comp.logger {
                l.log(
                    Status::Error,
                    "logStatusError",
                    &format!(
                        "{0}: instance busy: {0} called while {other} is running on another \
                         thread{freeing} (FMI 2.0: one call at a time per instance)",
                        call.name()
                    ),
                );
            }
            None
        }
    }
}

/// Runs `f` on the instance behind `c` after the state check of `call`, catching
/// panics.
fn with_inner(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Inner) -> super::FmiResult,
) -> fmi2Status {
    let Some(comp) = enter(c, call) else {
        return ERROR;
    };
    // The busy flag is ours: no other thread touches the instance until it is cleared.
    let inner = unsafe { &mut *comp.inner.get() };
    let r = catch_unwind(AssertUnwindSafe(|| {
        inner.inst.check(call)?;
        f(inner)
    }));
    let status = match r {
        Ok(Ok(())) => OK,
        Ok(Err(r)) => r.status as c_int,
        Err(p) => {
            let what = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            let _ = catch_unwind(AssertUnwindSafe(|| {
                inner.inst.poison();
                inner.inst.log(
                    Status::Error,
                    "logStatusError",
                    &format!(
                        "{}: internal error ({what}); the instance was stopped, call fmi2Reset",
                        call.name()
                    ),
                );
            }));
            ERROR
        }
    };
    comp.busy.store(0, Ordering::Release);
    status
}

/// Runs `f` on the instance behind `c`; see [`with_inner`].
fn with(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Instance) -> super::FmiResult,
) -> fmi2Status {
    with_inner(c, call, |x| f(&mut x.inst))
}

fn c_str(s: fmi2String) -> Option<String> {
    if s.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
    }
}

/// An `fmi2Boolean` argument: fmi2True (1) or fmi2False (0), nothing else.
fn boolean(inst: &mut Instance, call: Call, what: &str, v: fmi2Boolean) -> super::FmiResult<bool> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => inst.refuse(Status::Error, bool_message(call, what, v)),
    }
}

fn bool_message(call: Call, what: &str, v: fmi2Boolean) -> String {
    format!(
        "{}: argument `{what}` = {v} is not an fmi2Boolean; allowed: fmi2True (1) or fmi2False (0)",
        call.name()
    )
}

/// A slice from a C array, refusing a null pointer (also with a count of 0).
fn slice<'a, T>(
    inst: &mut Instance,
    call: Call,
    what: &str,
    p: *const T,
    n: usize,
) -> super::FmiResult<&'a [T]> {
    if p.is_null() {
        return inst.refuse(
            Status::Error,
            format!(
                "{}: argument `{what}` is a null pointer (count {n})",
                call.name()
            ),
        );
    }
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

fn slice_mut<'a, T>(
    inst: &mut Instance,
    call: Call,
    what: &str,
    p: *mut T,
    n: usize,
) -> super::FmiResult<&'a mut [T]> {
    if p.is_null() {
        return inst.refuse(
            Status::Error,
            format!(
                "{}: argument `{what}` is a null pointer (count {n})",
                call.name()
            ),
        );
    }
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// A null pointer argument refused.
fn null(inst: &mut Instance, call: Call, what: &str) -> super::FmiResult {
    inst.refuse(
        Status::Error,
        format!("{}: argument `{what}` is a null pointer", call.name()),
    )
}

// ------------------------------------------------------------------ which binary

/// The FMU a binary belongs to, from its file name: FMI 2.0 names the shared library
/// `binaries/<platform>/<modelIdentifier>.<ext>`, so the stem is the model identifier.
/// `None` for any other name (the development library `libwheelflat.so`, a test
/// executable that links the crate).
pub fn kind_of_binary(path: &str) -> Option<Kind> {
    let stem = std::path::Path::new(path).file_stem()?.to_str()?;
    [
        Kind::TrackContact,
        Kind::RollPlaneVehicle,
        Kind::CoupledSystem,
    ]
    .into_iter()
    .find(|k| k.table().model_identifier == stem)
}

/// Path of the loaded object that holds this code (the FMU's shared library, or the
/// executable that links the crate), from the dynamic loader.
///
/// Asked at every `fmi2Instantiate` rather than cached: a cached copy would outlive an
/// unloaded library (a leak per `dlopen`/`dlclose`).
pub fn loaded_binary() -> Option<String> {
    #[cfg(unix)]
    {
        let mut info: libc::Dl_info = unsafe { std::mem::zeroed() };
        let addr = fmi2Instantiate as *const c_void;
        if unsafe { libc::dladdr(addr, &mut info) } != 0 && !info.dli_fname.is_null() {
            return c_str(info.dli_fname);
        }
        None
    }
    #[cfg(not(unix))]
    {
        None
    }
}

/// The FMU a GUID instantiates in a binary of `binary` (see [`kind_of_binary`]): only
/// its own GUID when the binary is one FMU's, any of the three otherwise.
pub fn kind_for_guid(binary: Option<Kind>, guid: &str) -> Result<Kind, String> {
    let found = Kind::from_guid(guid);
    match (binary, found) {
        (None, Some(k)) => Ok(k),
        (Some(b), Some(k)) if b == k => Ok(k),
        (Some(b), Some(k)) => Err(format!(
            "GUID \"{guid}\" belongs to {}, but this binary is {} (GUID {}): instantiate {} \
             from its own FMU",
            k.table().model_identifier,
            b.table().model_identifier,
            b.table().guid,
            k.table().model_identifier
        )),
        (Some(b), None) => Err(format!(
            "GUID \"{guid}\" matches none of the wheelflat FMUs; this binary is {} (GUID {})",
            b.table().model_identifier,
            b.table().guid
        )),
        (None, None) => Err(format!(
            "GUID \"{guid}\" matches none of TrackContact ({}), RollPlaneVehicle ({}), \
             CoupledSystem ({})",
            super::vars::TRACK_CONTACT.guid,
            super::vars::ROLL_PLANE_VEHICLE.guid,
            super::vars::COUPLED_SYSTEM.guid
        )),
    }
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
        let comp = Box::new(Component {
            busy,
            logger: clog,
            inner: UnsafeCell::new(Inner {
                inst: Instance::new(kind, &name, logger, loggingOn == 1),
                states: HashMap::new(),
            }),
        });
        Box::into_raw(comp) as fmi2Component
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: the instance and every FMU state it handed out. Refused (and
/// logged) while another thread is in a call of the instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if enter(c, Call::FreeInstance).is_none() {
        return;
    }
    // The busy flag stays set: no call can start on the instance being freed.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let mut comp = unsafe { Box::from_raw(c as *mut Component) };
        let inner = comp.inner.get_mut();
        let n = inner.states.len();
        inner
            .inst
            .log_call(|| format!("fmi2FreeInstance() ({n} FMU states freed with it)"));
        drop(comp)
    }));
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
        i.log_call(|| format!("fmi2SetupExperiment(startTime={startTime}, stopTime={stopTime})"));
        boolean(i, call, "toleranceDefined", toleranceDefined)?;
        let stop_defined = boolean(i, call, "stopTimeDefined", stopTimeDefined)?;
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

/// `fmi2GetReal`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetReal;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice_mut(i, call, "value", value, nvr)?;
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
    let call = Call::GetInteger;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice_mut(i, call, "value", value, nvr)?;
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
    let call = Call::GetBoolean;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        slice_mut(i, call, "value", value, nvr)?;
        i.no_such_type(call.name(), vr)
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
    let call = Call::GetString;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        slice_mut(i, call, "value", value, nvr)?;
        i.no_such_type(call.name(), vr)
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
    let call = Call::SetReal;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
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
    let call = Call::SetInteger;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        i.log_call(|| format!("fmi2SetInteger(vr={vr:?}, value={value:?})"));
        i.set_integer(vr, value)
    })
}

/// `fmi2SetBoolean`: no Boolean variables; values other than fmi2True/fmi2False are
/// refused first.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    let call = Call::SetBoolean;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        for (k, &v) in value.iter().enumerate() {
            boolean(i, call, &format!("value[{k}]"), v)?;
        }
        i.no_such_type(call.name(), vr)
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
    let call = Call::SetString;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        slice(i, call, "value", value, nvr)?;
        i.no_such_type(call.name(), vr)
    })
}

// ------------------------------------------------------------------ FMU states
//
// Each instance owns the states it hands out ([`Inner::states`]): a state pointer is
// looked up there before use and never dereferenced otherwise, so a state of another
// instance, a freed one or a foreign pointer is refused; fmi2FreeInstance frees the
// states left.

/// `fmi2GetFMUstate`: a new state, or the state of this instance that `*FMUstate`
/// points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    let call = Call::GetFMUstate;
    with_inner(c, call, |x| {
        x.inst.log_call(|| "fmi2GetFMUstate()".into());
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        let slot = unsafe { &mut *FMUstate };
        let old = if slot.is_null() {
            None
        } else {
            Some(x.state(call, "*FMUstate", *slot)?)
        };
        let s = x.inst.get_state()?;
        x.store(old, s, slot);
        Ok(())
    })
}

/// `fmi2SetFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    let call = Call::SetFMUstate;
    with_inner(c, call, |x| {
        x.inst.log_call(|| "fmi2SetFMUstate()".into());
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        let key = x.state(call, "FMUstate", FMUstate)?;
        let Inner { inst, states } = x;
        inst.set_state(&states[&key])
    })
}

/// `fmi2FreeFMUstate`: `*FMUstate` NULL is a no-op.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    let call = Call::FreeFMUstate;
    with_inner(c, call, |x| {
        x.inst.log_call(|| "fmi2FreeFMUstate()".into());
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        let slot = unsafe { &mut *FMUstate };
        if !slot.is_null() {
            let key = x.state(call, "*FMUstate", *slot)?;
            x.states.remove(&key);
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
    let call = Call::SerializedFMUstateSize;
    with_inner(c, call, |x| {
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        if size.is_null() {
            return null(&mut x.inst, call, "size");
        }
        let key = x.state(call, "FMUstate", FMUstate)?;
        let Inner { inst, states } = x;
        let b = inst.serialize(&states[&key])?;
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
    let call = Call::SerializeFMUstate;
    with_inner(c, call, |x| {
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        let key = x.state(call, "FMUstate", FMUstate)?;
        let out = slice_mut(&mut x.inst, call, "serializedState", serializedState, size)?;
        let Inner { inst, states } = x;
        let b = inst.serialize(&states[&key])?;
        if b.len() != size {
            return inst.refuse(
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

/// `fmi2DeSerializeFMUstate`: a new state, or the state of this instance that
/// `*FMUstate` points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    serializedState: *const fmi2Byte,
    size: usize,
    FMUstate: *mut fmi2FMUstate,
) -> fmi2Status {
    let call = Call::DeSerializeFMUstate;
    with_inner(c, call, |x| {
        if FMUstate.is_null() {
            return null(&mut x.inst, call, "FMUstate");
        }
        let slot = unsafe { &mut *FMUstate };
        let old = if slot.is_null() {
            None
        } else {
            Some(x.state(call, "*FMUstate", *slot)?)
        };
        let bytes = slice(&mut x.inst, call, "serializedState", serializedState, size)?;
        let bytes: Vec<u8> = bytes.iter().map(|&b| b as u8).collect();
        let s = x.inst.deserialize(&bytes)?;
        x.store(old, s, slot);
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
    unsupported(c, Call::GetDirectionalDerivative)
}

/// A function refused in every state: [`Instance::check`] gives the reason from the
/// table.
fn unsupported(c: fmi2Component, call: Call) -> fmi2Status {
    with(c, call, |_| Ok(()))
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
    unsupported(c, Call::SetRealInputDerivatives)
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
    unsupported(c, Call::GetRealOutputDerivatives)
}

/// `fmi2DoStep`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let call = Call::DoStep;
    with(c, call, |i| {
        i.log_call(|| {
            format!("fmi2DoStep(t={currentCommunicationPoint}, h={communicationStepSize})")
        });
        boolean(
            i,
            call,
            "noSetFMUStatePriorToCurrentPoint",
            noSetFMUStatePriorToCurrentPoint,
        )?;
        i.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// `fmi2CancelStep`: steps are synchronous, there is nothing to cancel.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    unsupported(c, Call::CancelStep)
}

/// `fmi2GetStatus`: steps are synchronous, no status to ask for.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    unsupported(c, Call::GetStatus)
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetRealStatus;
    with(c, call, |i| {
        let v = slice_mut(i, call, "value", value, 1)?;
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
    unsupported(c, Call::GetIntegerStatus)
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (the wheel reached the end of the track).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    let call = Call::GetBooleanStatus;
    with(c, call, |i| {
        let v = slice_mut(i, call, "value", value, 1)?;
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
    unsupported(c, Call::GetStringStatus)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_stem_of_the_binary_is_the_model_identifier() {
        for (path, kind) in [
            (
                "/tmp/x/binaries/linux64/TrackContact.so",
                Some(Kind::TrackContact),
            ),
            ("RollPlaneVehicle.so", Some(Kind::RollPlaneVehicle)),
            (
                "C:/fmu/binaries/win64/CoupledSystem.dll",
                Some(Kind::CoupledSystem),
            ),
            (
                "binaries/darwin64/CoupledSystem.dylib",
                Some(Kind::CoupledSystem),
            ),
            ("/work/target/release/libwheelflat.so", None),
            ("/work/target/release/deps/fmi_fuzz-0123abcd", None),
            ("binaries/linux64/trackcontact.so", None),
            ("binaries/linux64/TrackContact2.so", None),
            ("", None),
        ] {
            assert_eq!(kind_of_binary(path), kind, "{path}");
        }
    }

    #[test]
    fn a_binary_of_one_fmu_instantiates_only_its_guid() {
        use super::super::vars::{COUPLED_SYSTEM, ROLL_PLANE_VEHICLE, TRACK_CONTACT};
        let kinds = [
            (Kind::TrackContact, TRACK_CONTACT.guid),
            (Kind::RollPlaneVehicle, ROLL_PLANE_VEHICLE.guid),
            (Kind::CoupledSystem, COUPLED_SYSTEM.guid),
        ];
        for (k, g) in kinds {
            // The development library (or a test executable): every GUID.
            assert_eq!(kind_for_guid(None, g), Ok(k));
            for (b, _) in kinds {
                let r = kind_for_guid(Some(b), g);
                if b == k {
                    assert_eq!(r, Ok(k));
                } else {
                    let m = r.unwrap_err();
                    let want = format!(
                        "belongs to {}, but this binary is {}",
                        k.table().model_identifier,
                        b.table().model_identifier
                    );
                    assert!(m.contains(&want), "{m}");
                }
            }
        }
        let m = kind_for_guid(Some(Kind::TrackContact), "{0}").unwrap_err();
        assert!(
            m.contains("matches none of") && m.contains("this binary is TrackContact"),
            "{m}"
        );
        assert!(
            kind_for_guid(None, "")
                .unwrap_err()
                .contains("matches none of")
        );
        // Tests link the crate into their own executable: not an FMU binary.
        let exe = loaded_binary().expect("dladdr names the executable");
        assert_eq!(kind_of_binary(&exe), None, "{exe}");
    }
}
