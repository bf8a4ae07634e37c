//! The FMI 3.0 side of the C boundary's guard ([`crate::fmu::ffi::guard`], shared with FMI
//! 2.0): what an `fmi3Instance` points to, the master's logger (FMI 3.0's), and the
//! wrappers every exported function runs in (claim the instance, check the state table,
//! catch panics).

use super::types::*;
use crate::fmu::ffi::guard::{self, Guarded, MasterLog};
pub(super) use crate::fmu::ffi::guard::{MasterLog as _, c_str, null, slice, slice_mut};
use crate::fmu::fmi3::{CALLS3, Call3};
use crate::fmu::{FmiResult, Instance3, Snapshot, Status};
use std::ffi::{CString, c_int};
use std::sync::atomic::AtomicUsize;

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

impl MasterLog for CLogger {
    fn log(&self, status: Status, category: &str, message: &str) {
        let cat = CString::new(category.replace('\0', " ")).unwrap_or_default();
        let msg = CString::new(message.replace('\0', " ")).unwrap_or_default();
        unsafe { (self.logger)(self.env, status as c_int, cat.as_ptr(), msg.as_ptr()) }
    }
}

impl CLogger {
    /// Logs with the running function's name in front when the message does not name
    /// it (the gets and sets of the absent types name themselves): every message says
    /// which call it answers.
    pub(super) fn log_in_call(&self, busy: &AtomicUsize, status: Status, cat: &str, m: &str) {
        guard::log_in_call::<Instance3>(self, busy, status, cat, m, |call| {
            matches!(call, Call3::GetOther | Call3::SetOther)
        })
    }
}

impl Guarded for Instance3 {
    type Call = Call3;
    const STANDARD: &'static str = "FMI 3.0";
    const RESET: &'static str = "fmi3Reset";
    const NULL_EMPTY_OK: bool = true;
    fn call_of_flag(flag: usize) -> Option<Call3> {
        CALLS3.get(flag.wrapping_sub(1)).map(|c| c.0)
    }
    fn flag_of(call: Call3) -> usize {
        call as usize + 1
    }
    fn call_name(call: Call3) -> &'static str {
        call.name()
    }
    fn check_call(&mut self, call: Call3) -> FmiResult {
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
    const STATE: &'static str = "FMUState";
    const SIZE_CALL: &'static str = "fmi3SerializedFMUStateSize";
    fn get_state(&mut self) -> FmiResult<Snapshot> {
        Instance3::get_state(self)
    }
    fn set_state(&mut self, s: &Snapshot) -> FmiResult {
        Instance3::set_state(self, s)
    }
    fn serialize(&mut self, s: &Snapshot) -> FmiResult<Vec<u8>> {
        Instance3::serialize(self, s)
    }
    fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot> {
        Instance3::deserialize(self, bytes)
    }
    fn instance_name(&self) -> &str {
        self.fmi2().name()
    }
}

/// The instance and the FMU states it handed out.
pub(super) type Inner = guard::Inner<Instance3>;

/// Runs `f` on the instance behind `c` as `call`, after its state check (the gets and
/// sets of the absent types check under their own names), catching panics.
pub(super) fn with_inner(
    c: fmi3Instance,
    call: Call3,
    f: impl FnOnce(&mut Inner) -> FmiResult,
) -> fmi3Status {
    let check = !matches!(call, Call3::GetOther | Call3::SetOther);
    guard::with_inner::<Instance3, CLogger>(c, call, check, f)
}

/// Runs `f` on the instance behind `c`; see [`with_inner`].
pub(super) fn with(
    c: fmi3Instance,
    call: Call3,
    f: impl FnOnce(&mut Instance3) -> FmiResult,
) -> fmi3Status {
    with_inner(c, call, |x| f(&mut x.inst))
}
