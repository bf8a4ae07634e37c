//! The exported FMI 2.0 functions of FMU states: get, set, free, serialise and
//! deserialise (a source of the C header that cbindgen writes, `build/c_header.rs`).

use super::component::*;
use super::types::*;
use crate::fmu::{Call, Status};

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
        if b.len() > size {
            return inst.refuse(
                Status::Error,
                format!(
                    "fmi2SerializeFMUstate: size = {size} bytes; allowed: at least {} (from \
                     fmi2SerializedFMUstateSize)",
                    b.len()
                ),
            );
        }
        // A larger buffer is legal: the state, then zeros (which fmi2DeSerializeFMUstate
        // takes as padding).
        let padded = b.into_iter().chain(std::iter::repeat(0));
        for (o, x) in out.iter_mut().zip(padded) {
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
