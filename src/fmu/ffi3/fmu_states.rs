//! The exported FMI 3.0 functions of FMU states: get, set, free, serialise and
//! deserialise. Each instance owns the states it hands out: a state pointer is looked
//! up there before use and never dereferenced otherwise.

use super::component::*;
use super::types::*;
use crate::fmu::Status;
use crate::fmu::fmi3::Call3;

/// `fmi3GetFMUState`: a new state, or the state of this instance that `*FMUState`
/// points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let call = Call3::GetFMUState;
    with_inner(instance, call, |x| {
        if FMUState.is_null() {
            return null(&mut x.inst, call, "FMUState");
        }
        let slot = unsafe { &mut *FMUState };
        let old = match slot.is_null() {
            true => None,
            false => Some(x.state(call, "*FMUState", *slot)?),
        };
        let s = x.inst.get_state()?;
        x.store(old, s, slot);
        Ok(())
    })
}

/// `fmi3SetFMUState`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    let call = Call3::SetFMUState;
    with_inner(instance, call, |x| {
        if FMUState.is_null() {
            return null(&mut x.inst, call, "FMUState");
        }
        let key = x.state(call, "FMUState", FMUState)?;
        let Inner { inst, states } = x;
        inst.set_state(&states[&key])
    })
}

/// `fmi3FreeFMUState`: `*FMUState` NULL is a no-op.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let call = Call3::FreeFMUState;
    with_inner(instance, call, |x| {
        if FMUState.is_null() {
            return null(&mut x.inst, call, "FMUState");
        }
        let slot = unsafe { &mut *FMUState };
        if !slot.is_null() {
            let key = x.state(call, "*FMUState", *slot)?;
            x.states.remove(&key);
            *slot = std::ptr::null_mut();
        }
        Ok(())
    })
}

/// `fmi3SerializedFMUStateSize`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    let call = Call3::SerializedFMUStateSize;
    with_inner(instance, call, |x| {
        if size.is_null() {
            return null(&mut x.inst, call, "size");
        }
        let key = x.state(call, "FMUState", FMUState)?;
        let Inner { inst, states } = x;
        let b = inst.serialize(&states[&key])?;
        unsafe { *size = b.len() };
        Ok(())
    })
}

/// `fmi3SerializeFMUState`: a larger buffer is padded with zeros (which
/// `fmi3DeserializeFMUState` takes as padding).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    let call = Call3::SerializeFMUState;
    with_inner(instance, call, |x| {
        let key = x.state(call, "FMUState", FMUState)?;
        let out = slice_mut(&mut x.inst, call, "serializedState", serializedState, size)?;
        let Inner { inst, states } = x;
        let b = inst.serialize(&states[&key])?;
        if b.len() > size {
            return inst.refuse(
                Status::Error,
                format!(
                    "fmi3SerializeFMUState: size = {size} bytes; allowed: at least {} (from \
                     fmi3SerializedFMUStateSize)",
                    b.len()
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
    })
}

/// `fmi3DeserializeFMUState`: a new state, or the state of this instance that
/// `*FMUState` points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3DeserializeFMUState(
    instance: fmi3Instance,
    serializedState: *const fmi3Byte,
    size: usize,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let call = Call3::DeserializeFMUState;
    with_inner(instance, call, |x| {
        if FMUState.is_null() {
            return null(&mut x.inst, call, "FMUState");
        }
        let slot = unsafe { &mut *FMUState };
        let old = match slot.is_null() {
            true => None,
            false => Some(x.state(call, "*FMUState", *slot)?),
        };
        let bytes = slice(&mut x.inst, call, "serializedState", serializedState, size)?.to_vec();
        let s = x.inst.deserialize(&bytes)?;
        x.store(old, s, slot);
        Ok(())
    })
}
