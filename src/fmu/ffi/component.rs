//! The FMI 2.0 side of the C boundary's guard ([`super::guard`]): what an
//! `fmi2Component` points to, the master's logger (FMI 2.0's, variadic, with the instance
//! name), the wrappers every exported function runs in, and `fmi2Boolean` arguments.

use super::guard::{self, Guarded, MasterLog};
pub(super) use super::guard::{c_str, slice, slice_mut};
use super::types::*;
use crate::fmu::{CALLS, Call, FmiResult, Instance, Snapshot, Status};
use std::ffi::{CStr, CString, c_int};
use std::sync::atomic::AtomicUsize;

/// The master's logger with what it needs.
#[derive(Clone)]
pub(super) struct CLogger {
    pub(super) logger: unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
    pub(super) env: fmi2ComponentEnvironment,
    pub(super) name: CString,
}

// The master owns the environment pointer; the logger is only called during calls of
// the instance (FMI 2.0, section 2.1.4), from the thread that makes the call.
unsafe impl Send for CLogger {}

impl CLogger {
    pub(super) fn log(&self, status: Status, category: &str, message: &str) {
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
    pub(super) fn log_in_call(
        &self,
        busy: &AtomicUsize,
        status: Status,
        category: &str,
        message: &str,
    ) {
        guard::log_in_call::<Instance>(self, busy, status, category, message, |_| false)
    }
}

/// The function recorded in a busy flag: 0 is idle, else 1 + its index in [`CALLS`].
pub(super) fn running(flag: usize) -> Option<Call> {
    CALLS.get(flag.wrapping_sub(1)).map(|c| c.0)
}

impl MasterLog for CLogger {
    fn log(&self, status: Status, category: &str, message: &str) {
        CLogger::log(self, status, category, message)
    }
}

impl Guarded for Instance {
    type Call = Call;
    const STANDARD: &'static str = "FMI 2.0";
    const RESET: &'static str = "fmi2Reset";
    const NULL_EMPTY_OK: bool = false;
    fn call_of_flag(flag: usize) -> Option<Call> {
        running(flag)
    }
    fn flag_of(call: Call) -> usize {
        call as usize + 1
    }
    fn call_name(call: Call) -> &'static str {
        call.name()
    }
    fn check_call(&mut self, call: Call) -> FmiResult {
        self.check(call)
    }
    fn refuse_with(&mut self, status: Status, message: String) -> FmiResult {
        self.refuse(status, message)
    }
    fn log_message(&mut self, status: Status, category: &str, message: &str) {
        self.log(status, category, message)
    }
    fn poison_instance(&mut self) {
        self.poison()
    }
    const STATE: &'static str = "FMUstate";
    const SIZE_CALL: &'static str = "fmi2SerializedFMUstateSize";
    fn get_state(&mut self) -> FmiResult<Snapshot> {
        Instance::get_state(self)
    }
    fn set_state(&mut self, s: &Snapshot) -> FmiResult {
        Instance::set_state(self, s)
    }
    fn serialize(&mut self, s: &Snapshot) -> FmiResult<Vec<u8>> {
        Instance::serialize(self, s)
    }
    fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot> {
        Instance::deserialize(self, bytes)
    }
    fn instance_name(&self) -> &str {
        self.name()
    }
}

/// The instance and the FMU states it handed out.
pub(super) type Inner = guard::Inner<Instance>;

/// Runs `f` on the instance behind `c` after the state check of `call`, catching
/// panics.
#[inline]
pub(super) fn with_inner(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Inner) -> FmiResult,
) -> fmi2Status {
    guard::with_inner::<Instance, CLogger>(c, call, true, f)
}

/// Runs `f` on the instance behind `c`; see [`with_inner`].
#[inline]
pub(super) fn with(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Instance) -> FmiResult,
) -> fmi2Status {
    with_inner(c, call, |x| f(&mut x.inst))
}

/// The instance name as given: UTF-8 as it is, other bytes escaped (`\xff`) so that a
/// log shows the name the master gave; `None` for a null pointer.
pub(super) fn instance_name(s: fmi2String) -> Option<String> {
    if s.is_null() {
        return None;
    }
    let bytes = unsafe { CStr::from_ptr(s) }.to_bytes();
    Some(match std::str::from_utf8(bytes) {
        Ok(text) => text.to_string(),
        Err(_) => bytes.escape_ascii().to_string(),
    })
}

/// An `fmi2Boolean` argument: fmi2True (1) or fmi2False (0), nothing else.
pub(super) fn boolean(
    inst: &mut Instance,
    call: Call,
    what: &str,
    v: fmi2Boolean,
) -> FmiResult<bool> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => inst.refuse(Status::Error, bool_message(call, what, v)),
    }
}

pub(super) fn bool_message(call: Call, what: &str, v: fmi2Boolean) -> String {
    format!(
        "{}: argument `{what}` = {v} is not an fmi2Boolean; allowed: fmi2True (1) or fmi2False (0)",
        call.name()
    )
}
