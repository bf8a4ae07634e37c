//! The exported FMI 2.0 functions of values: `fmi2Get*` and `fmi2Set*` of Real,
//! Integer, Boolean and String variables (a source of the C header that cbindgen
//! writes, `build/c_header.rs`).

use super::component::*;
use super::types::*;
use crate::fmu::{Call, Status};

/// `fmi2GetReal`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetReal;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice_mut(i, call, "value", value, nvr)?;
        i.get_real(vr, value)?;
        i.log_call(|| format!("fmi2GetReal(vr={vr:?}) -> {value:?}"));
        Ok(())
    })
}

/// `fmi2GetInteger` (integers and enumerations).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    let call = Call::GetInteger;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice_mut(i, call, "value", value, nvr)?;
        i.get_integer(vr, value)?;
        i.log_call(|| format!("fmi2GetInteger(vr={vr:?}) -> {value:?}"));
        Ok(())
    })
}

/// `fmi2GetBoolean`: no Boolean variables.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    let call = Call::GetBoolean;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        slice_mut(i, call, "value", value, nvr)?;
        i.no_such_type(call.name(), vr)
    })
}

/// `fmi2GetString`: the String parameters; the strings stay valid until the next
/// `fmi2GetString` of this instance (or its freeing).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2String,
) -> fmi2Status {
    let call = Call::GetString;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let out = slice_mut(i, call, "value", value, nvr)?;
        let texts = i.get_string(vr)?;
        // The values hold no NUL: fmi2SetString took them from C strings.
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

/// `fmi2SetReal`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    let call = Call::SetReal;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        i.log_call(|| format!("fmi2SetReal(vr={vr:?}, value={value:?})"));
        i.set_real(vr, value)
    })
}

/// `fmi2SetInteger` (integers and enumerations).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    let call = Call::SetInteger;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        i.log_call(|| format!("fmi2SetInteger(vr={vr:?}, value={value:?})"));
        i.set_integer(vr, value)
    })
}

/// `fmi2SetBoolean`: no Boolean variables; values other than fmi2True/fmi2False are
/// refused first.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Boolean,
) -> fmi2Status {
    let call = Call::SetBoolean;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        for (k, &v) in value.iter().enumerate() {
            boolean(i, call, &format!("value[{k}]"), v)?;
        }
        i.no_such_type(call.name(), vr)
    })
}

/// `fmi2SetString`: the String parameters (UTF-8 text; a null string is refused).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2String,
) -> fmi2Status {
    let call = Call::SetString;
    with(c, call, |i| {
        let vr = slice(i, call, "vr", vr, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        let mut texts = Vec::with_capacity(nvr);
        for (k, &p) in value.iter().enumerate() {
            if p.is_null() {
                return i.refuse(
                    Status::Error,
                    format!("fmi2SetString: argument `value[{k}]` is a null pointer"),
                );
            }
            // SAFETY: a non-null fmi2String is a NUL-terminated C string (FMI 2.0).
            match unsafe { std::ffi::CStr::from_ptr(p) }.to_str() {
                Ok(t) => texts.push(t.to_string()),
                Err(_) => {
                    return i.refuse(
                        Status::Error,
                        format!("fmi2SetString: `value[{k}]` is not UTF-8 text"),
                    );
                }
            }
        }
        i.set_string(vr, &texts)
    })
}
