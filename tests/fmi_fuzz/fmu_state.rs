//! The FMU-state calls (get, set, free, serialize, deserialize) and what each must do
//! with the state pointers: a pointer is used only by the instance that handed it out
//! and has not freed it.

use crate::world::World;
use rand::Rng;
use std::ffi::c_int;
use std::time::Duration;
use wheelflat::fmu::Call;
use wheelflat::fmu::ffi::*;

impl World {
    /// Makes FMU-state call `call` on instance `i` (component `c`, named `name`), with a
    /// null pointer argument if `null_ptr`; returns its status, description and duration.
    pub fn state_call(
        &mut self,
        call: Call,
        i: usize,
        c: fmi2Component,
        name: &str,
        null_ptr: bool,
    ) -> (c_int, String, Duration) {
        match call {
            Call::GetFMUstate => {
                let mut p = if self.rng.random_bool(0.7) {
                    std::ptr::null_mut()
                } else {
                    self.state_pointer(i)
                };
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    self,
                    name,
                    format!("fmi2GetFMUstate(*FMUstate = {before:p})"),
                    fmi2GetFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut p
                        }
                    )
                );
                if r.0 == 0 && !null_ptr {
                    if before.is_null() {
                        if p.is_null() {
                            self.fail(format!("{}: fmi2OK but no state", r.1));
                        }
                        self.freed_states.retain(|&q| q != p);
                        self.slots[i].states.push(p);
                    } else if p != before {
                        self.fail(format!("{}: the state pointer changed", r.1));
                    }
                }
                if !could_own && r.0 == 0 {
                    self.fail(format!("{}: a foreign pointer was accepted", r.1));
                }
                r
            }
            Call::SetFMUstate => {
                let p = self.state_pointer(i);
                let could_own = self.maybe_state(p);
                let r = run!(
                    self,
                    name,
                    format!("fmi2SetFMUstate({p:p})"),
                    fmi2SetFMUstate(c, p)
                );
                if r.0 == 0 {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was accepted", r.1));
                    }
                    self.refresh_time(i);
                }
                r
            }
            Call::FreeFMUstate => {
                let mut p = self.state_pointer(i);
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    self,
                    name,
                    format!("fmi2FreeFMUstate(*FMUstate = {before:p})"),
                    fmi2FreeFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut p
                        }
                    )
                );
                if r.0 == 0 && !null_ptr {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was freed", r.1));
                    }
                    if !p.is_null() {
                        self.fail(format!("{}: *FMUstate not set to NULL", r.1));
                    }
                    if !before.is_null() {
                        self.forget_state(before);
                    }
                } else if r.0 != 0 && p != before {
                    self.fail(format!("{}: refused, but *FMUstate changed", r.1));
                }
                r
            }
            Call::SerializedFMUstateSize => {
                let p = self.state_pointer(i);
                let mut size = 0usize;
                run!(
                    self,
                    name,
                    format!("fmi2SerializedFMUstateSize({p:p})"),
                    fmi2SerializedFMUstateSize(
                        c,
                        p,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut size
                        }
                    )
                )
            }
            Call::SerializeFMUstate => {
                let p = self.state_pointer(i);
                // The size as a master asks for it (not checked here).
                let mut size = 0usize;
                unsafe { fmi2SerializedFMUstateSize(c, p, &mut size) };
                let rng = &mut self.rng;
                let n = match rng.random_range(0..10) {
                    0 => size + 1,
                    1 => size.saturating_sub(1),
                    2 => rng.random_range(0..64),
                    _ => size,
                };
                let mut buf = vec![0 as fmi2Byte; n.max(1)];
                let r = run!(
                    self,
                    name,
                    format!("fmi2SerializeFMUstate({p:p}, size {n})"),
                    fmi2SerializeFMUstate(
                        c,
                        p,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            buf.as_mut_ptr()
                        },
                        n
                    )
                );
                if r.0 == 0 {
                    buf.truncate(n);
                    if self.blobs.len() < 16 {
                        self.blobs.push(buf);
                    } else {
                        let k = self.rng.random_range(0..16);
                        self.blobs[k] = buf;
                    }
                }
                r
            }
            Call::DeSerializeFMUstate => {
                let b = self.blob();
                let mut p = if self.rng.random_bool(0.7) {
                    std::ptr::null_mut()
                } else {
                    self.state_pointer(i)
                };
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    self,
                    name,
                    format!(
                        "fmi2DeSerializeFMUstate({} bytes, *FMUstate = {before:p})",
                        b.len()
                    ),
                    fmi2DeSerializeFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null()
                        } else {
                            b.as_ptr()
                        },
                        b.len(),
                        &mut p
                    )
                );
                if r.0 == 0 {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was overwritten", r.1));
                    }
                    if before.is_null() {
                        self.freed_states.retain(|&q| q != p);
                        self.slots[i].states.push(p);
                    } else if p != before {
                        self.fail(format!("{}: the state pointer changed", r.1));
                    }
                } else if p != before {
                    self.fail(format!("{}: refused, but *FMUstate changed", r.1));
                }
                r
            }
            _ => unreachable!("{} is not an FMU-state call", call.name()),
        }
    }
}
