//! The FMU-state calls (get, set, free, serialize, deserialize) of either FMI version
//! (the same C signatures but for the byte type, [`StateApi`]) and what each must do
//! with the state pointers: a pointer is used only by the instance that handed it out
//! and has not freed it.

use crate::world::{Saved, Version, World};
use rand::Rng;
use std::ffi::{c_int, c_void};
use std::time::Duration;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::ffi3::*;

/// An FMU-state function.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StateOp {
    Get,
    Set,
    Free,
    Size,
    Serialize,
    Deserialize,
}

type State = *mut c_void;

/// One FMI version's FMU-state functions and their C names (in the order of
/// [`StateOp`]).
pub struct StateApi {
    pub names: [&'static str; 6],
    pub get: unsafe fn(State, *mut State) -> c_int,
    pub set: unsafe fn(State, State) -> c_int,
    pub free: unsafe fn(State, *mut State) -> c_int,
    pub size: unsafe fn(State, State, *mut usize) -> c_int,
    pub serialize: unsafe fn(State, State, *mut u8, usize) -> c_int,
    pub deserialize: unsafe fn(State, *const u8, usize, *mut State) -> c_int,
}

pub const FMI2_STATES: StateApi = StateApi {
    names: [
        "fmi2GetFMUstate",
        "fmi2SetFMUstate",
        "fmi2FreeFMUstate",
        "fmi2SerializedFMUstateSize",
        "fmi2SerializeFMUstate",
        "fmi2DeSerializeFMUstate",
    ],
    get: |c, p| unsafe { fmi2GetFMUstate(c, p) },
    set: |c, p| unsafe { fmi2SetFMUstate(c, p) },
    free: |c, p| unsafe { fmi2FreeFMUstate(c, p) },
    size: |c, p, n| unsafe { fmi2SerializedFMUstateSize(c, p, n) },
    serialize: |c, p, b, n| unsafe { fmi2SerializeFMUstate(c, p, b as *mut fmi2Byte, n) },
    deserialize: |c, b, n, p| unsafe { fmi2DeSerializeFMUstate(c, b as *const fmi2Byte, n, p) },
};

pub const FMI3_STATES: StateApi = StateApi {
    names: [
        "fmi3GetFMUState",
        "fmi3SetFMUState",
        "fmi3FreeFMUState",
        "fmi3SerializedFMUStateSize",
        "fmi3SerializeFMUState",
        "fmi3DeserializeFMUState",
    ],
    get: |c, p| unsafe { fmi3GetFMUState(c, p) },
    set: |c, p| unsafe { fmi3SetFMUState(c, p) },
    free: |c, p| unsafe { fmi3FreeFMUState(c, p) },
    size: |c, p, n| unsafe { fmi3SerializedFMUStateSize(c, p, n) },
    serialize: |c, p, b, n| unsafe { fmi3SerializeFMUState(c, p, b, n) },
    deserialize: |c, b, n, p| unsafe { fmi3DeserializeFMUState(c, b, n, p) },
};

impl World {
    /// Makes FMU-state call `op` on instance `i` (instance pointer `c`, which may be
    /// null, named `name`), with a null pointer argument if `null_ptr`; returns its
    /// status, description and duration.
    pub fn state_call(
        &mut self,
        op: StateOp,
        i: usize,
        c: State,
        name: &str,
        null_ptr: bool,
    ) -> (c_int, String, Duration) {
        let api = match self.slots[i].version {
            Version::Fmi2 => &FMI2_STATES,
            Version::Fmi3 => &FMI3_STATES,
        };
        let f = api.names[op as usize];
        match op {
            StateOp::Get => {
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
                    format!("{f}(*state = {before:p})"),
                    (api.get)(
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
                            self.fail(format!("{}: OK but no state", r.1));
                        }
                        self.freed_states.retain(|&q| q != p);
                        self.slots[i].states.push(p);
                    } else if p != before {
                        self.fail(format!("{}: the state pointer changed", r.1));
                    }
                    self.saved_as_now(i, p);
                }
                if !could_own && r.0 == 0 {
                    self.fail(format!("{}: a foreign pointer was accepted", r.1));
                }
                r
            }
            StateOp::Set => {
                let p = self.state_pointer(i);
                let could_own = self.maybe_state(p);
                let r = run!(self, name, format!("{f}({p:p})"), (api.set)(c, p));
                if r.0 == 0 {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was accepted", r.1));
                    }
                    match self.slots[i].version {
                        Version::Fmi2 => self.refresh_time(i),
                        Version::Fmi3 => self.restored(i, p),
                    }
                }
                r
            }
            StateOp::Free => {
                let mut p = self.state_pointer(i);
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    self,
                    name,
                    format!("{f}(*state = {before:p})"),
                    (api.free)(
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
                        self.fail(format!("{}: *state not set to NULL", r.1));
                    }
                    if !before.is_null() {
                        self.forget_state(before);
                    }
                } else if r.0 != 0 && p != before {
                    self.fail(format!("{}: refused, but *state changed", r.1));
                }
                r
            }
            StateOp::Size => {
                let p = self.state_pointer(i);
                let mut size = 0usize;
                run!(
                    self,
                    name,
                    format!("{f}({p:p})"),
                    (api.size)(
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
            StateOp::Serialize => {
                let p = self.state_pointer(i);
                // The size as a master asks for it (not checked here).
                let mut size = 0usize;
                unsafe { (api.size)(c, p, &mut size) };
                let rng = &mut self.rng;
                let n = match rng.random_range(0..10) {
                    0 => size + 1,
                    1 => size.saturating_sub(1),
                    2 => rng.random_range(0..64),
                    _ => size,
                };
                let mut buf = vec![0u8; n.max(1)];
                let r = run!(
                    self,
                    name,
                    format!("{f}({p:p}, size {n})"),
                    (api.serialize)(
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
            StateOp::Deserialize => {
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
                    format!("{f}({} bytes, *state = {before:p})", b.len()),
                    (api.deserialize)(
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
                    // Bytes of unknown origin: phase, time and wheelsets unknown.
                    self.saved.insert(
                        p as usize,
                        Saved {
                            phase: crate::calls::Mirror::Unknown,
                            t: 0.0,
                            wheelsets: None,
                        },
                    );
                } else if p != before {
                    self.fail(format!("{}: refused, but *state changed", r.1));
                }
                r
            }
        }
    }

    /// The state `p` of instance `i` now holds the instance as the test knows it.
    fn saved_as_now(&mut self, i: usize, p: State) {
        let s = &self.slots[i];
        self.saved.insert(
            p as usize,
            Saved {
                phase: s.phase,
                t: s.t,
                wheelsets: s.wheelsets,
            },
        );
    }
}
