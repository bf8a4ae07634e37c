//! The oracle of every call: the status is one FMI 2.0 defines, a call on a null
//! component is refused, and the messages logged name the function and the cause
//! without reporting a caught panic.

use crate::common::Log;
use crate::world::{Status, World};
use std::ffi::c_int;
use wheelflat::fmu::Call;

impl World {
    /// The messages logged since `from` must include one of status >= Warning that
    /// names `call` and says why; none may report an internal error.
    pub fn check_messages(&self, log: &Log, from: usize, call: &str, status: c_int) {
        let recs = log.since(from);
        for r in &recs {
            if r.message.contains("internal error") {
                self.fail(format!("{call}: a panic was caught: {}", r.message));
            }
        }
        if status == 0 {
            return;
        }
        let named = recs.iter().any(|r| {
            r.status >= 1
                && r.message.contains(call)
                && r.message.len() > call.len() + 12
                && r.category.starts_with("logStatus")
        });
        if !named {
            self.fail(format!(
                "{call} returned {status} without a message naming it and the cause; logged: {:?}",
                recs
            ));
        }
    }

    /// Checks call `call` on instance `i` (`desc`), which returned `status`: a status
    /// of FMI 2.0, `fmi2Error` on a null component, and the messages logged since
    /// `from` ([`World::check_messages`]).
    pub fn check_call(
        &self,
        i: usize,
        call: Call,
        desc: &str,
        status: c_int,
        null_component: bool,
        from: usize,
    ) {
        if !(0..=3).contains(&status) {
            self.fail(format!("{desc} returned status {status}"));
        }
        if null_component {
            if status != Status::Error as c_int {
                self.fail(format!("{desc} on a null component returned {status}"));
            }
            return;
        }
        self.check_messages(&self.slots[i].log, from, call.name(), status);
    }
}
