//! The exported FMI 3.0 functions of values: `fmi3Get*` and `fmi3Set*` of Float64,
//! Int32, Int64 (the Enumerations), UInt64 (`wheelsets`) and String variables, and of
//! the types no variable has (every value reference refused). An array's value
//! reference gives as many values as `wheelsets`.

use super::component::*;
use super::types::*;
use crate::fmu::fmi3::Call3;
use crate::fmu::{FmiResult, Instance3};

/// A get of `call`: the value references and the values' buffer, then `get`.
unsafe fn get<T: std::fmt::Debug>(
    c: fmi3Instance,
    call: Call3,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *mut T,
    n: usize,
    get: impl FnOnce(&mut Instance3, &[u32], &mut [T]) -> FmiResult,
) -> fmi3Status {
    with(c, call, |i| {
        let vr = slice(i, call, "valueReferences", vr, nvr)?;
        let values = slice_mut(i, call, "values", values, n)?;
        get(i, vr, values)?;
        i.log_call(|| format!("{}(vr={vr:?}) -> {values:?}", call.name()));
        Ok(())
    })
}

/// A set of `call`: the value references and the values, then `set`.
unsafe fn set<T: std::fmt::Debug>(
    c: fmi3Instance,
    call: Call3,
    vr: *const fmi3ValueReference,
    nvr: usize,
    values: *const T,
    n: usize,
    set: impl FnOnce(&mut Instance3, &[u32], &[T]) -> FmiResult,
) -> fmi3Status {
    with(c, call, |i| {
        let vr = slice(i, call, "valueReferences", vr, nvr)?;
        let values = slice(i, call, "values", values, n)?;
        i.log_call(|| format!("{}(vr={vr:?}, values={values:?})", call.name()));
        set(i, vr, values)
    })
}

macro_rules! typed {
    ($get:ident, $set:ident, $t:ty, $call_get:ident, $call_set:ident, $g:ident, $s:ident) => {
        #[doc = concat!("`", stringify!($get), "`.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(
            c: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            values: *mut $t,
            nValues: usize,
        ) -> fmi3Status {
            unsafe {
                get(
                    c,
                    Call3::$call_get,
                    valueReferences,
                    nValueReferences,
                    values,
                    nValues,
                    |i, v, o| i.$g(v, o),
                )
            }
        }

        #[doc = concat!("`", stringify!($set), "`.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(
            c: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            values: *const $t,
            nValues: usize,
        ) -> fmi3Status {
            unsafe {
                set(
                    c,
                    Call3::$call_set,
                    valueReferences,
                    nValueReferences,
                    values,
                    nValues,
                    |i, v, x| i.$s(v, x),
                )
            }
        }
    };
}

typed!(
    fmi3GetFloat64,
    fmi3SetFloat64,
    fmi3Float64,
    GetFloat64,
    SetFloat64,
    get_float64,
    set_float64
);
typed!(
    fmi3GetInt32,
    fmi3SetInt32,
    fmi3Int32,
    GetInt32,
    SetInt32,
    get_int32,
    set_int32
);
typed!(
    fmi3GetInt64,
    fmi3SetInt64,
    fmi3Int64,
    GetInt64,
    SetInt64,
    get_int64,
    set_int64
);
typed!(
    fmi3GetUInt64,
    fmi3SetUInt64,
    fmi3UInt64,
    GetUInt64,
    SetUInt64,
    get_uint64,
    set_uint64
);

/// Gets and sets of the types no variable has: an empty request succeeds, any value
/// reference is refused naming it.
macro_rules! absent {
    ($get:ident, $set:ident, $t:ty) => {
        #[doc = concat!("`", stringify!($get), "`: no variable has this type.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $get(
            c: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *mut $t,
            _nValues: usize,
        ) -> fmi3Status {
            let call = Call3::GetOther;
            with(c, call, |i| {
                let vr = slice(
                    i,
                    call,
                    "valueReferences",
                    valueReferences,
                    nValueReferences,
                )?;
                i.no_such_type(stringify!($get), true, vr)
            })
        }

        #[doc = concat!("`", stringify!($set), "`: no variable has this type.")]
        #[unsafe(no_mangle)]
        pub unsafe extern "C" fn $set(
            c: fmi3Instance,
            valueReferences: *const fmi3ValueReference,
            nValueReferences: usize,
            _values: *const $t,
            _nValues: usize,
        ) -> fmi3Status {
            let call = Call3::SetOther;
            with(c, call, |i| {
                let vr = slice(
                    i,
                    call,
                    "valueReferences",
                    valueReferences,
                    nValueReferences,
                )?;
                i.no_such_type(stringify!($set), false, vr)
            })
        }
    };
}

absent!(fmi3GetFloat32, fmi3SetFloat32, f32);
absent!(fmi3GetInt8, fmi3SetInt8, i8);
absent!(fmi3GetUInt8, fmi3SetUInt8, u8);
absent!(fmi3GetInt16, fmi3SetInt16, i16);
absent!(fmi3GetUInt16, fmi3SetUInt16, u16);
absent!(fmi3GetUInt32, fmi3SetUInt32, u32);
absent!(fmi3GetBoolean, fmi3SetBoolean, fmi3Boolean);

/// `fmi3GetBinary`: no variable has this type.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetBinary(
    c: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *mut usize,
    _values: *mut *const fmi3Byte,
    _nValues: usize,
) -> fmi3Status {
    let call = Call3::GetOther;
    with(c, call, |i| {
        let vr = slice(
            i,
            call,
            "valueReferences",
            valueReferences,
            nValueReferences,
        )?;
        i.no_such_type("fmi3GetBinary", true, vr)
    })
}

/// `fmi3SetBinary`: no variable has this type.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetBinary(
    c: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    _valueSizes: *const usize,
    _values: *const *const fmi3Byte,
    _nValues: usize,
) -> fmi3Status {
    let call = Call3::SetOther;
    with(c, call, |i| {
        let vr = slice(
            i,
            call,
            "valueReferences",
            valueReferences,
            nValueReferences,
        )?;
        i.no_such_type("fmi3SetBinary", false, vr)
    })
}

/// `fmi3GetString`: the strings stay valid until the next `fmi3GetString` of this
/// instance (or its freeing).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetString(
    c: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *mut fmi3String,
    nValues: usize,
) -> fmi3Status {
    let call = Call3::GetString;
    with(c, call, |i| {
        let vr = slice(
            i,
            call,
            "valueReferences",
            valueReferences,
            nValueReferences,
        )?;
        let out = slice_mut(i, call, "values", values, nValues)?;
        let texts = i.get_string(vr, nValues)?;
        let buffers: Vec<std::ffi::CString> = texts
            .into_iter()
            .map(|t| std::ffi::CString::new(t).unwrap_or_default())
            .collect();
        for (slot, b) in out.iter_mut().zip(&buffers) {
            *slot = b.as_ptr();
        }
        i.keep_string_buffers(buffers);
        Ok(())
    })
}

/// `fmi3SetString`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3SetString(
    c: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    values: *const fmi3String,
    nValues: usize,
) -> fmi3Status {
    let call = Call3::SetString;
    with(c, call, |i| {
        let vr = slice(
            i,
            call,
            "valueReferences",
            valueReferences,
            nValueReferences,
        )?;
        let ps = slice(i, call, "values", values, nValues)?;
        let mut texts = Vec::with_capacity(ps.len());
        for (k, &p) in ps.iter().enumerate() {
            match c_str(p) {
                Some(t) => texts.push(t),
                None => return null(i, call, &format!("values[{k}]")),
            }
        }
        i.set_string(vr, &texts)
    })
}
