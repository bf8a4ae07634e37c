//! What an `fmi3Instance` points to: the instance behind a busy flag with the FMU
//! states it handed out, the master's logger, and the wrapper every exported function
//! runs in (claim the instance, catch panics).

use super::types::*;
use crate::fmu::fmi3::{CALLS3, Call3};
use crate::fmu::{FmiResult, Instance3, Snapshot, Status};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ffi::{CStr, CString, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

pub(super) const ERROR: fmi3Status = Status::Error as c_int;

/// The master's logger with its environment.
#[derive(Clone)]
pub(super) struct CLogger {
    pub(super) logger:
        unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String),
    pub(super) env: fmi3InstanceEnvironment,
}

// The master owns the environment pointer; the logger is only called during calls of
// the instance, from the thread that makes the call.
unsafe impl Send for CLogger {}

impl CLogger {
    pub(super) fn log(&self, status: Status, category: &str, message: &str) {
        let cat = CString::new(category.replace('\0', " ")).unwrap_or_default();
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        unsafe { (self.logger)(self.env, status as c_int, cat.as_ptr(), msg.as_ptr()) }
    }

    /// Logs with the running function's name in front when the message does not name
    /// it: every message says which call it answers.
    pub(super) fn log_in_call(&self, busy: &AtomicUsize, status: Status, cat: &str, m: &str) {
        match running(busy.load(Ordering::Relaxed)) {
            Some(call)
                if !m.contains(call.name())
                    && !matches!(call, Call3::GetOther | Call3::SetOther) =>
            {
                self.log(status, cat, &format!("{}: {m}", call.name()))
            }
            _ => self.log(status, cat, m),
        }
    }
}

/// The function recorded in a busy flag: 0 is idle, else 1 + its index in [`CALLS3`].
pub(super) fn running(flag: usize) -> Option<Call3> {
    CALLS3.get(flag.wrapping_sub(1)).map(|c| c.0)
}

/// What an `fmi3Instance` points to: the instance behind a busy flag (FMI 3.0 forbids
/// calling one instance from two threads at once: the second call gets `fmi3Error`).
pub(super) struct Component {
    pub(super) busy: Arc<AtomicUsize>,
    pub(super) logger: Option<CLogger>,
    pub(super) inner: UnsafeCell<Inner>,
}

/// The instance and the FMU states it handed out.
pub(super) struct Inner {
    pub(super) inst: Instance3,
    /// Every FMU state handed out and not freed, by address.
    pub(super) states: HashMap<usize, Box<Snapshot>>,
}

impl Inner {
    /// Puts `s` into the state `old` of this instance, or into a new state whose address
    /// goes to `slot`.
    pub(super) fn store(&mut self, old: Option<usize>, s: Snapshot, slot: &mut fmi3FMUState) {
        match old.and_then(|key| self.states.get_mut(&key)) {
            Some(b) => **b = s,
            None => {
                let b = Box::new(s);
                let p = &*b as *const Snapshot as fmi3FMUState;
                self.states.insert(p as usize, b);
                *slot = p;
            }
        }
    }

    /// The state behind `p` when this instance handed it out and has not freed it.
    pub(super) fn state(&mut self, call: Call3, what: &str, p: fmi3FMUState) -> FmiResult<usize> {
        let key = p as usize;
        if self.states.contains_key(&key) {
            return Ok(key);
        }
        let live = self.states.len();
        self.inst.refuse(
            Status::Error,
            format!(
                "{}: argument `{what}` = {p:p} is not an FMU state of this instance ({live} \
                 live states): it belongs to another instance, was already freed, or is not \
                 an FMU state; it was not used",
                call.name()
            ),
        )
    }
}

/// Claims the instance behind `c` for `call`, or refuses (busy: logged).
pub(super) fn enter<'a>(c: fmi3Instance, call: Call3) -> Option<&'a Component> {
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
            if let Some(l) = &comp.logger {
                l.log(
                    Status::Error,
                    "logStatusError",
                    &format!(
                        "{0}: instance busy: {0} called while {other} is running on another \
                         thread; the call was refused and the instance left as it was (FMI \
                         3.0: one call at a time per instance)",
                        call.name()
                    ),
                );
            }
            None
        }
    }
}

/// Runs `f` on the instance behind `c` as `call`, catching panics.
pub(super) fn with_inner(
    c: fmi3Instance,
    call: Call3,
    f: impl FnOnce(&mut Inner) -> FmiResult,
) -> fmi3Status {
    let Some(comp) = enter(c, call) else {
        return ERROR;
    };
    let inner = unsafe { &mut *comp.inner.get() };
    let r = catch_unwind(AssertUnwindSafe(|| {
        // A family's function checks under its own name (Instance3::no_such_type).
        if !matches!(call, Call3::GetOther | Call3::SetOther) {
            inner.inst.check(call)?;
        }
        f(inner)
    }));
    let status = match r {
        Ok(Ok(())) => Status::Ok as c_int,
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
                        "{}: internal error ({what}); the instance was stopped, call fmi3Reset",
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
pub(super) fn with(
    c: fmi3Instance,
    call: Call3,
    f: impl FnOnce(&mut Instance3) -> FmiResult,
) -> fmi3Status {
    with_inner(c, call, |x| f(&mut x.inst))
}

pub(super) fn c_str(s: fmi3String) -> Option<String> {
    if s.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
    }
}

/// A slice from a C array: a null pointer is refused unless the count is 0.
pub(super) fn slice<'a, T>(
    inst: &mut Instance3,
    call: Call3,
    what: &str,
    p: *const T,
    n: usize,
) -> FmiResult<&'a [T]> {
    if n == 0 {
        return Ok(&[]);
    }
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A mutable slice from a C array; see [`slice`].
pub(super) fn slice_mut<'a, T>(
    inst: &mut Instance3,
    call: Call3,
    what: &str,
    p: *mut T,
    n: usize,
) -> FmiResult<&'a mut [T]> {
    if n == 0 {
        return Ok(&mut []);
    }
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

fn non_null<T>(inst: &mut Instance3, call: Call3, what: &str, p: *const T, n: usize) -> FmiResult {
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
pub(super) fn null(inst: &mut Instance3, call: Call3, what: &str) -> FmiResult {
    inst.refuse(
        Status::Error,
        format!("{}: argument `{what}` is a null pointer", call.name()),
    )
}
