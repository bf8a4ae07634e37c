//! The exported FMI 3.0 functions of FMU states: get, set, free, serialise and
//! deserialise; the work is the guard's, shared with FMI 2.0
//! ([`crate::fmu::ffi::guard::Inner`]).

use super::component::*;
use super::types::*;
use crate::fmu::fmi3::Call3;

/// `fmi3GetFMUState`: a new state, or the state of this instance that `*FMUState`
/// points to overwritten.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let call = Call3::GetFMUState;
    with_inner(instance, call, |x| x.get_fmu_state(call, FMUState))
}

/// `fmi3SetFMUState`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
) -> fmi3Status {
    let call = Call3::SetFMUState;
    with_inner(instance, call, |x| x.set_fmu_state(call, FMUState))
}

/// `fmi3FreeFMUState`: `*FMUState` NULL is a no-op.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3FreeFMUState(
    instance: fmi3Instance,
    FMUState: *mut fmi3FMUState,
) -> fmi3Status {
    let call = Call3::FreeFMUState;
    with_inner(instance, call, |x| x.free_fmu_state(call, FMUState))
}

/// `fmi3SerializedFMUStateSize`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializedFMUStateSize(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    size: *mut usize,
) -> fmi3Status {
    let call = Call3::SerializedFMUStateSize;
    with_inner(instance, call, |x| x.serialized_size(call, FMUState, size))
}

/// `fmi3SerializeFMUState`: a larger buffer than the state is padded with zeros.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SerializeFMUState(
    instance: fmi3Instance,
    FMUState: fmi3FMUState,
    serializedState: *mut fmi3Byte,
    size: usize,
) -> fmi3Status {
    let call = Call3::SerializeFMUState;
    with_inner(instance, call, |x| {
        x.serialize_into(call, FMUState, serializedState, size)
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
        x.deserialize_from(call, serializedState, size, FMUState)
    })
}
