//! What both C boundaries (FMI 2.0 here, FMI 3.0 in `ffi3/`) put around an instance:
//! the busy flag that refuses a second thread, the FMU states it handed out, the
//! wrapper every exported function runs in (claim the instance, check the state table,
//! catch panics) and the conversion of C arrays. Each boundary implements [`Guarded`]
//! for its instance and [`MasterLog`] for its master's logger.

use crate::fmu::{FmiResult, Snapshot, Status};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ffi::{CStr, c_char, c_int, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// An instance of one FMI version, as its C boundary drives it.
pub(crate) trait Guarded {
    /// The functions of its state table.
    type Call: Copy + PartialEq;
    /// The standard's name, in messages (`FMI 2.0`).
    const STANDARD: &'static str;
    /// Its reset function (`fmi2Reset`).
    const RESET: &'static str;
    /// Whether a null array pointer with a count of 0 is taken as empty (FMI 3.0) or
    /// refused (FMI 2.0, as before).
    const NULL_EMPTY_OK: bool;
    /// The function recorded in a busy flag: 0 is idle, else 1 + its index.
    fn call_of_flag(flag: usize) -> Option<Self::Call>;
    /// The busy flag of `call`.
    fn flag_of(call: Self::Call) -> usize;
    /// The C name of `call`.
    fn call_name(call: Self::Call) -> &'static str;
    /// The state table's check of `call` before it runs.
    fn check_call(&mut self, call: Self::Call) -> FmiResult;
    /// Logs and returns a refusal.
    fn refuse_with(&mut self, status: Status, message: String) -> FmiResult;
    /// Sends a message to the logger.
    fn log_message(&mut self, status: Status, category: &str, message: &str);
    /// After an internal error: the instance can only be reset.
    fn poison_instance(&mut self);
    /// The instance's name.
    fn instance_name(&self) -> &str;
    /// The FMU-state argument's name (`FMUstate`, `FMUState`).
    const STATE: &'static str;
    /// The function that tells a serialized state's size.
    const SIZE_CALL: &'static str;
    /// Its current FMU state.
    fn get_state(&mut self) -> FmiResult<Snapshot>;
    /// Restores `s`.
    fn set_state(&mut self, s: &Snapshot) -> FmiResult;
    /// `s` serialized.
    fn serialize(&mut self, s: &Snapshot) -> FmiResult<Vec<u8>>;
    /// The state `bytes` hold.
    fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot>;
}

/// The master's logger of a boundary.
pub(crate) trait MasterLog {
    /// Logs `message` of `status` in `category`.
    fn log(&self, status: Status, category: &str, message: &str);
}

/// What an instance pointer points to: the instance behind a busy flag.
///
/// The FMI standards forbid calling one instance from two threads at once; a master
/// that does gets an error for the second call, which touches nothing but the flag and
/// the copy of the logger here. (Freeing racing with another call is refused the same
/// way; a call made after the instance was freed cannot be detected.)
pub(crate) struct Component<I, L> {
    /// 0 when idle, else 1 + the index of the function running. Shared with the
    /// instance's logger, which names that function.
    pub(crate) busy: Arc<AtomicUsize>,
    /// The master's logger, for refusals that must not touch the instance.
    pub(crate) logger: Option<L>,
    pub(crate) inner: UnsafeCell<Inner<I>>,
}

/// The instance and the FMU states it handed out.
pub(crate) struct Inner<I> {
    pub(crate) inst: I,
    /// Every FMU state handed out and not freed, by address. A state pointer is used
    /// only when it is a key here; the rest are freed with the instance.
    pub(crate) states: HashMap<usize, Box<Snapshot>>,
}

impl<I: Guarded> Inner<I> {
    /// Puts `s` into the state `old` of this instance (already checked by
    /// [`Inner::state`]), or into a new state whose address goes to `slot`.
    pub(crate) fn store(&mut self, old: Option<usize>, s: Snapshot, slot: &mut *mut c_void) {
        match old.and_then(|key| self.states.get_mut(&key)) {
            Some(b) => **b = s,
            None => {
                let b = Box::new(s);
                let p = &*b as *const Snapshot as *mut c_void;
                self.states.insert(p as usize, b);
                *slot = p;
            }
        }
    }

    /// The state behind `p` when this instance handed it out and has not freed it;
    /// `p` itself is never dereferenced.
    pub(crate) fn state(&mut self, call: I::Call, what: &str, p: *mut c_void) -> FmiResult<usize> {
        let key = p as usize;
        if self.states.contains_key(&key) {
            return Ok(key);
        }
        let live = self.states.len();
        let message = format!(
            "{}: argument `{what}` = {p:p} is not an FMU state of this instance (\"{}\", {live} \
             live states): it belongs to another instance, was already freed, or is not an \
             FMU state; it was not used",
            I::call_name(call),
            self.inst.instance_name()
        );
        self.inst.refuse_with(Status::Error, message).map(|()| 0)
    }
}

// The FMU-state functions of both standards. Each instance owns the states it hands out:
// a state pointer is looked up among them before use and never dereferenced otherwise,
// so a state of another instance, a freed one or a foreign pointer is refused; freeing
// the instance frees the states left.
impl<I: Guarded> Inner<I> {
    /// Get: a new state, or the state of this instance that `*slot` points to
    /// overwritten.
    pub(crate) fn get_fmu_state(&mut self, call: I::Call, slot: *mut *mut c_void) -> FmiResult {
        if slot.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        let slot = unsafe { &mut *slot };
        let old = match slot.is_null() {
            true => None,
            false => Some(self.state(call, &format!("*{}", I::STATE), *slot)?),
        };
        let s = self.inst.get_state()?;
        self.store(old, s, slot);
        Ok(())
    }

    /// Set.
    pub(crate) fn set_fmu_state(&mut self, call: I::Call, p: *mut c_void) -> FmiResult {
        if p.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        let key = self.state(call, I::STATE, p)?;
        self.inst.set_state(&self.states[&key])
    }

    /// Free: `*slot` NULL is a no-op.
    pub(crate) fn free_fmu_state(&mut self, call: I::Call, slot: *mut *mut c_void) -> FmiResult {
        if slot.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        let slot = unsafe { &mut *slot };
        if !slot.is_null() {
            let key = self.state(call, &format!("*{}", I::STATE), *slot)?;
            self.states.remove(&key);
            *slot = std::ptr::null_mut();
        }
        Ok(())
    }

    /// The serialized size of the state `p`, into `*size`.
    pub(crate) fn serialized_size(
        &mut self,
        call: I::Call,
        p: *mut c_void,
        size: *mut usize,
    ) -> FmiResult {
        if p.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        if size.is_null() {
            return null(&mut self.inst, call, "size");
        }
        let key = self.state(call, I::STATE, p)?;
        let b = self.inst.serialize(&self.states[&key])?;
        unsafe { *size = b.len() };
        Ok(())
    }

    /// The state `p` serialized into `out` (`size` bytes): a larger buffer is legal, the
    /// state then zeros (which deserialization takes as padding).
    pub(crate) fn serialize_into(
        &mut self,
        call: I::Call,
        p: *mut c_void,
        out: *mut u8,
        size: usize,
    ) -> FmiResult {
        if p.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        let key = self.state(call, I::STATE, p)?;
        let out = slice_mut(&mut self.inst, call, "serializedState", out, size)?;
        let b = self.inst.serialize(&self.states[&key])?;
        if b.len() > size {
            return self.inst.refuse_with(
                Status::Error,
                format!(
                    "{}: size = {size} bytes; allowed: at least {} (from {})",
                    I::call_name(call),
                    b.len(),
                    I::SIZE_CALL
                ),
            );
        }
        for (o, x) in out
            .iter_mut()
            .zip(b.into_iter().chain(std::iter::repeat(0)))
        {
            *o = x;
        }
        Ok(())
    }

    /// Deserialize `size` bytes at `bytes`: a new state, or the state of this instance
    /// that `*slot` points to overwritten.
    pub(crate) fn deserialize_from(
        &mut self,
        call: I::Call,
        bytes: *const u8,
        size: usize,
        slot: *mut *mut c_void,
    ) -> FmiResult {
        if slot.is_null() {
            return null(&mut self.inst, call, I::STATE);
        }
        let slot = unsafe { &mut *slot };
        let old = match slot.is_null() {
            true => None,
            false => Some(self.state(call, &format!("*{}", I::STATE), *slot)?),
        };
        let bytes = slice(&mut self.inst, call, "serializedState", bytes, size)?.to_vec();
        let s = self.inst.deserialize(&bytes)?;
        self.store(old, s, slot);
        Ok(())
    }
}

/// A new instance for the master: `inst` behind the busy flag `busy` (which its logger
/// shares), with the master's logger `logger` and no FMU states yet.
pub(crate) fn boxed<I, L>(busy: Arc<AtomicUsize>, logger: Option<L>, inst: I) -> *mut c_void {
    let comp = Box::new(Component {
        busy,
        logger,
        inner: UnsafeCell::new(Inner {
            inst,
            states: HashMap::new(),
        }),
    });
    Box::into_raw(comp) as *mut c_void
}

/// Frees the instance behind `c` and every FMU state it handed out (`call`, the free
/// function); refused (and logged) while another thread is in a call of it.
pub(crate) fn free<I: Guarded, L: MasterLog>(c: *mut c_void, call: I::Call) {
    if enter::<I, L>(c, call).is_none() {
        return;
    }
    // The busy flag stays set: no call can start on the instance being freed.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let mut comp = unsafe { Box::from_raw(c as *mut Component<I, L>) };
        let inner = comp.inner.get_mut();
        let n = inner.states.len();
        let m = format!("{}() ({n} FMU states freed with it)", I::call_name(call));
        inner.inst.log_message(Status::Ok, "logCalls", &m);
        drop(comp)
    }));
}

/// Claims the instance behind `c` for `call`, or refuses (busy: logged).
pub(crate) fn enter<'a, I: Guarded, L: MasterLog>(
    c: *mut c_void,
    call: I::Call,
) -> Option<&'a Component<I, L>> {
    if c.is_null() {
        return None;
    }
    let comp = unsafe { &*(c as *const Component<I, L>) };
    match comp
        .busy
        .compare_exchange(0, I::flag_of(call), Ordering::Acquire, Ordering::Acquire)
    {
        Ok(_) => Some(comp),
        Err(other) => {
            let other = I::call_of_flag(other).map_or("another function", I::call_name);
            let name = I::call_name(call);
            let what = if name.ends_with("FreeInstance") {
                "the instance was not freed"
            } else {
                "the call was refused and the instance left as it was"
            };
            if let Some(l) = &comp.logger {
                l.log(
                    Status::Error,
                    "logStatusError",
                    &format!(
                        "{name}: instance busy: {name} called while {other} is running on \
                         another thread; {what} ({}: one call at a time per instance)",
                        I::STANDARD
                    ),
                );
            }
            None
        }
    }
}

/// Runs `f` on the instance behind `c` after the state check of `call` (`check`),
/// catching panics: a panic stops the instance, which then only resets.
pub(crate) fn with_inner<I: Guarded, L: MasterLog>(
    c: *mut c_void,
    call: I::Call,
    check: bool,
    f: impl FnOnce(&mut Inner<I>) -> FmiResult,
) -> c_int {
    let Some(comp) = enter::<I, L>(c, call) else {
        return Status::Error as c_int;
    };
    // The busy flag is ours: no other thread touches the instance until it is cleared.
    let inner = unsafe { &mut *comp.inner.get() };
    let r = catch_unwind(AssertUnwindSafe(|| {
        if check {
            inner.inst.check_call(call)?;
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
                inner.inst.poison_instance();
                inner.inst.log_message(
                    Status::Error,
                    "logStatusError",
                    &format!(
                        "{}: internal error ({what}); the instance was stopped, call {}",
                        I::call_name(call),
                        I::RESET
                    ),
                );
            }));
            Status::Error as c_int
        }
    };
    comp.busy.store(0, Ordering::Release);
    status
}

/// Logs `message` through `log` during the call recorded in `busy`, with the function's
/// name in front when the message does not name it (`named(call)`: the message names
/// it already, or the call stands for a family whose functions name themselves).
pub(crate) fn log_in_call<I: Guarded>(
    log: &impl MasterLog,
    busy: &AtomicUsize,
    status: Status,
    category: &str,
    message: &str,
    names_itself: impl Fn(I::Call) -> bool,
) {
    match I::call_of_flag(busy.load(Ordering::Relaxed)) {
        Some(call) if !message.contains(I::call_name(call)) && !names_itself(call) => log.log(
            status,
            category,
            &format!("{}: {message}", I::call_name(call)),
        ),
        _ => log.log(status, category, message),
    }
}

/// A C string, `None` for a null pointer (invalid UTF-8 replaced).
pub(crate) fn c_str(s: *const c_char) -> Option<String> {
    if s.is_null() {
        None
    } else {
        Some(unsafe { CStr::from_ptr(s) }.to_string_lossy().into_owned())
    }
}

/// A slice from a C array: a null pointer is refused (with a count of 0 too, unless
/// [`Guarded::NULL_EMPTY_OK`]).
pub(crate) fn slice<'a, I: Guarded, T>(
    inst: &mut I,
    call: I::Call,
    what: &str,
    p: *const T,
    n: usize,
) -> FmiResult<&'a [T]> {
    if n == 0 && I::NULL_EMPTY_OK {
        return Ok(&[]);
    }
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts(p, n) })
}

/// A mutable slice from a C array; see [`slice`].
pub(crate) fn slice_mut<'a, I: Guarded, T>(
    inst: &mut I,
    call: I::Call,
    what: &str,
    p: *mut T,
    n: usize,
) -> FmiResult<&'a mut [T]> {
    if n == 0 && I::NULL_EMPTY_OK {
        return Ok(&mut []);
    }
    non_null(inst, call, what, p, n)?;
    Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
}

fn non_null<I: Guarded, T>(
    inst: &mut I,
    call: I::Call,
    what: &str,
    p: *const T,
    n: usize,
) -> FmiResult {
    if p.is_null() {
        return inst.refuse_with(
            Status::Error,
            format!(
                "{}: argument `{what}` is a null pointer (count {n})",
                I::call_name(call)
            ),
        );
    }
    Ok(())
}

/// A null pointer argument refused.
pub(crate) fn null<I: Guarded>(inst: &mut I, call: I::Call, what: &str) -> FmiResult {
    inst.refuse_with(
        Status::Error,
        format!(
            "{}: argument `{what}` is a null pointer",
            I::call_name(call)
        ),
    )
}
