//! What an `fmi2Component` points to: the instance behind a busy flag with the FMU
//! states it handed out, the master's logger, and the wrappers every exported function
//! runs in (claim the instance, check the state table, catch panics).

use super::types::*;
use crate::fmu::{CALLS, Call, FmiResult, Instance, Snapshot, Status};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ffi::{CStr, CString, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

pub(super) const OK: fmi2Status = Status::Ok as c_int;
pub(super) const ERROR: fmi2Status = Status::Error as c_int;

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
        match running(busy.load(Ordering::Relaxed)) {
            Some(call) if !message.contains(call.name()) => {
                self.log(status, category, &format!("{}: {message}", call.name()))
            }
            _ => self.log(status, category, message),
        }
    }
}

/// The function recorded in a busy flag: 0 is idle, else 1 + its index in [`CALLS`].
pub(super) fn running(flag: usize) -> Option<Call> {
    CALLS.get(flag.wrapping_sub(1)).map(|c| c.0)
}

/// What an `fmi2Component` points to: the instance behind a busy flag.
///
/// FMI 2.0 forbids calling one instance from two threads at once; a master that does
/// gets `fmi2Error` for the second call, which touches nothing but the flag and the
/// copy of the logger here. (`fmi2FreeInstance` racing with another call is refused
/// the same way; a call made after `fmi2FreeInstance` returned cannot be detected.)
pub(super) struct Component {
    /// 0 when idle, else 1 + the index in [`CALLS`] of the function running. Shared with
    /// the instance's logger, which names that function.
    pub(super) busy: Arc<AtomicUsize>,
    /// The master's logger, for refusals that must not touch the instance.
    pub(super) logger: Option<CLogger>,
    pub(super) inner: UnsafeCell<Inner>,
}

/// The instance and the FMU states it handed out.
pub(super) struct Inner {
    pub(super) inst: Instance,
    /// Every FMU state handed out and not freed, by address. A state pointer is used
    /// only when it is a key here; the rest are freed with the instance.
    pub(super) states: HashMap<usize, Box<Snapshot>>,
}

impl Inner {
    /// Puts `s` into the state `old` of this instance (already checked by
    /// [`Inner::state`]), or into a new state whose address goes to `slot`.
    pub(super) fn store(&mut self, old: Option<usize>, s: Snapshot, slot: &mut fmi2FMUstate) {
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
    pub(super) fn state(&mut self, call: Call, what: &str, p: fmi2FMUstate) -> FmiResult<usize> {
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
#[inline]
pub(super) fn enter<'a>(c: fmi2Component, call: Call) -> Option<&'a Component> {
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
#[inline]
pub(super) fn with_inner(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Inner) -> FmiResult,
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
#[inline]
pub(super) fn with(
    c: fmi2Component,
    call: Call,
    f: impl FnOnce(&mut Instance) -> FmiResult,
) -> fmi2Status {
    with_inner(c, call, |x| f(&mut x.inst))
}

pub(super) fn c_str(s: fmi2String) -> Option<String> {
    if s.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
    }
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

/// A slice from a C array, refusing a null pointer (also with a count of 0).
pub(super) fn slice<'a, T>(
    inst: &mut Instance,
    call: Call,
    what: &str,
    p: *const T,
    n: usize,
) -> FmiResult<&'a [T]> {
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A mutable slice from a C array; see [`slice`].
pub(super) fn slice_mut<'a, T>(
    inst: &mut Instance,
    call: Call,
    what: &str,
    p: *mut T,
    n: usize,
) -> FmiResult<&'a mut [T]> {
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

/// Refuses a null array pointer `p` (with `n` values announced).
fn non_null<T>(inst: &mut Instance, call: Call, what: &str, p: *const T, n: usize) -> FmiResult {
    if p.is_null() {
        return inst.refuse(
            Status::Error,
            format!(
                "{}: argument `{what}` is a null pointer (count {n})",
                call.name()
            ),
        );
    }
    Ok(())
}

/// A null pointer argument refused.
pub(super) fn null(inst: &mut Instance, call: Call, what: &str) -> FmiResult {
    inst.refuse(
        Status::Error,
        format!("{}: argument `{what}` is a null pointer", call.name()),
    )
}
