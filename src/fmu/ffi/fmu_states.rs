//! The exported FMI 2.0 functions of FMU states: get, set, free, serialise and
//! deserialise (a source of the C header that cbindgen writes, `build/c_header.rs`); the
//! work is the guard's, shared with FMI 3.0 ([`super::guard::Inner`]).

use super::component::*;
use super::types::*;
use crate::fmu::Call;

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
        x.get_fmu_state(call, FMUstate)
    })
}

/// `fmi2SetFMUstate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, FMUstate: fmi2FMUstate) -> fmi2Status {
    let call = Call::SetFMUstate;
    with_inner(c, call, |x| {
        x.inst.log_call(|| "fmi2SetFMUstate()".into());
        x.set_fmu_state(call, FMUstate)
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
        x.free_fmu_state(call, FMUstate)
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
    with_inner(c, call, |x| x.serialized_size(call, FMUstate, size))
}

/// `fmi2SerializeFMUstate`: a larger buffer than the state is padded with zeros.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    FMUstate: fmi2FMUstate,
    serializedState: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    let call = Call::SerializeFMUstate;
    with_inner(c, call, |x| {
        x.serialize_into(call, FMUstate, serializedState.cast(), size)
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
        x.deserialize_from(call, serializedState.cast(), size, FMUstate)
    })
}
