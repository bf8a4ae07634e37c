//! Every FMI 2.0 co-simulation function, exported unmangled (the source of the C
//! header that cbindgen writes).

use super::binary::{kind_for_guid, kind_of_binary, loaded_binary};
use super::component::*;
use super::types::*;
use crate::fmu::{Call, Instance, Logger, Status};
use std::cell::UnsafeCell;
use std::collections::HashMap;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Arc;
use std::sync::atomic::AtomicUsize;

// ------------------------------------------------------------------ common functions

/// `fmi2GetTypesPlatform`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2SetDebugLogging`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    let call = Call::SetDebugLogging;
    with(c, call, |i| {
        let on = boolean(i, call, "loggingOn", loggingOn)?;
        let cats = if nCategories == 0 {
            Vec::new()
        } else {
            let s = slice(i, call, "categories", categories, nCategories)?;
            let mut v = Vec::new();
            for (k, &p) in s.iter().enumerate() {
                match c_str(p) {
                    Some(x) => v.push(x),
                    None => {
                        return i.refuse(
                            Status::Error,
                            format!("fmi2SetDebugLogging: categories[{k}] is a null pointer"),
                        );
                    }
                }
            }
            v
        };
        i.set_debug_logging(on, &cats)
    })
}

/// `fmi2Instantiate`: the GUID selects TrackContact, RollPlaneVehicle or CoupledSystem;
/// inside an FMU only that FMU's GUID ([`kind_for_guid`]).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    let r = catch_unwind(AssertUnwindSafe(|| {
        let cb = if functions.is_null() {
            None
        } else {
            let f = unsafe { &*functions };
            f.logger.map(|l| (l, f.componentEnvironment))
        };
        let name = instance_name(instanceName).unwrap_or_default();
        let clog = cb.map(|(l, env)| CLogger {
            logger: l,
            env,
            name: CString::new(name.replace('\0', " ")).unwrap_or_default(),
        });
        let fail = |m: String| {
            if let Some(l) = &clog {
                l.log(Status::Error, "logStatusError", &m);
            }
            std::ptr::null_mut()
        };
        if functions.is_null() {
            return std::ptr::null_mut();
        }
        if name.trim().is_empty() {
            return fail(format!(
                "fmi2Instantiate: instanceName {}; FMI 2.0 requires a non-empty name",
                if instanceName.is_null() {
                    "is null".to_string()
                } else {
                    format!("= {name:?}")
                }
            ));
        }
        for (what, v) in [("visible", visible), ("loggingOn", loggingOn)] {
            if v != 0 && v != 1 {
                return fail(bool_message(Call::Instantiate, what, v));
            }
        }
        if fmuType != 1 {
            return fail(format!(
                "fmi2Instantiate: fmuType = {fmuType}; these FMUs are Co-Simulation only (fmi2CoSimulation = 1)"
            ));
        }
        let guid = c_str(fmuGUID).unwrap_or_default();
        let binary = loaded_binary().as_deref().and_then(kind_of_binary);
        let kind = match kind_for_guid(binary, &guid) {
            Ok(k) => k,
            Err(m) => return fail(format!("fmi2Instantiate: {m}")),
        };
        let busy = Arc::new(AtomicUsize::new(0));
        let logger: Logger = match clog.clone() {
            Some(l) => {
                let busy = busy.clone();
                Box::new(move |s, cat, m| l.log_in_call(&busy, s, cat, m))
            }
            None => Box::new(|_, _, _| {}),
        };
        let comp = Box::new(Component {
            busy,
            logger: clog,
            inner: UnsafeCell::new(Inner {
                inst: Instance::new(kind.table(), &name, logger, loggingOn == 1),
                states: HashMap::new(),
            }),
        });
        Box::into_raw(comp) as fmi2Component
    }));
    r.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: the instance and every FMU state it handed out. Refused (and
/// logged) while another thread is in a call of the instance.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if enter(c, Call::FreeInstance).is_none() {
        return;
    }
    // The busy flag stays set: no call can start on the instance being freed.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        let mut comp = unsafe { Box::from_raw(c as *mut Component) };
        let inner = comp.inner.get_mut();
        let n = inner.states.len();
        inner
            .inst
            .log_call(|| format!("fmi2FreeInstance() ({n} FMU states freed with it)"));
        drop(comp)
    }));
}

/// `fmi2SetupExperiment`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    _tolerance: fmi2Real,
    startTime: fmi2Real,
    stopTimeDefined: fmi2Boolean,
    stopTime: fmi2Real,
) -> fmi2Status {
    let call = Call::SetupExperiment;
    with(c, call, |i| {
        boolean(i, call, "toleranceDefined", toleranceDefined)?;
        let stop_defined = boolean(i, call, "stopTimeDefined", stopTimeDefined)?;
        // A stop time the master did not define is not shown as one.
        i.log_call(|| match stop_defined {
            true => format!("fmi2SetupExperiment(startTime={startTime}, stopTime={stopTime})"),
            false => format!("fmi2SetupExperiment(startTime={startTime}, stopTime undefined)"),
        });
        i.setup_experiment(startTime, stop_defined.then_some(stopTime))
    })
}

/// `fmi2EnterInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, Call::EnterInitializationMode, |i| {
        i.log_call(|| "fmi2EnterInitializationMode()".into());
        i.enter_initialization()
    })
}

/// `fmi2ExitInitializationMode`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    with(c, Call::ExitInitializationMode, |i| {
        i.log_call(|| "fmi2ExitInitializationMode()".into());
        i.exit_initialization()
    })
}

/// `fmi2Terminate`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    with(c, Call::Terminate, |i| {
        i.log_call(|| "fmi2Terminate()".into());
        i.terminate()
    })
}

/// `fmi2Reset`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    with(c, Call::Reset, |i| {
        i.log_call(|| "fmi2Reset()".into());
        i.reset()
    })
}

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

// ------------------------------------------------------------------ FMU states
//
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

/// `fmi2GetDirectionalDerivative`: `dvUnknown = J dvKnown`, `J` the partial
/// derivatives of the outputs `vUnknown_ref` with respect to the inputs `vKnown_ref`
/// (TrackContact: the exact contact stiffness, `providesDirectionalDerivative="true"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetDirectionalDerivative;
    with(c, call, |i| {
        i.check_declared(call)?;
        let unknowns = slice(i, call, "vUnknown_ref", vUnknown_ref, nUnknown)?;
        let knowns = slice(i, call, "vKnown_ref", vKnown_ref, nKnown)?;
        let seed = slice(i, call, "dvKnown", dvKnown, nKnown)?;
        let out = slice_mut(i, call, "dvUnknown", dvUnknown, nUnknown)?;
        i.get_directional_derivative(unknowns, knowns, seed, out)?;
        i.log_call(|| {
            format!("fmi2GetDirectionalDerivative(unknowns={unknowns:?}, knowns={knowns:?}, seed={seed:?}) -> {out:?}")
        });
        Ok(())
    })
}

/// A function refused in every state: [`Instance::check`] gives the reason from the
/// table.
fn unsupported(c: fmi2Component, call: Call) -> fmi2Status {
    with(c, call, |_| Ok(()))
}

// ------------------------------------------------------------------ co-simulation

/// `fmi2SetRealInputDerivatives`: the inputs' time derivatives at the current
/// communication point (TrackContact: the wheel heights to order 2, the axle angle to
/// order 1; `canInterpolateInputs="true"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    let call = Call::SetRealInputDerivatives;
    with(c, call, |i| {
        i.check_declared(call)?;
        let vr = slice(i, call, "vr", vr, nvr)?;
        let order = slice(i, call, "order", order, nvr)?;
        let value = slice(i, call, "value", value, nvr)?;
        i.log_call(|| {
            format!("fmi2SetRealInputDerivatives(vr={vr:?}, order={order:?}, value={value:?})")
        });
        i.set_real_input_derivatives(vr, order, value)
    })
}

/// `fmi2GetRealOutputDerivatives`: the outputs' time derivatives (RollPlaneVehicle and
/// HalfCarBogie: the wheel and side-frame velocities, the axle's rate;
/// `maxOutputDerivativeOrder="1"`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetRealOutputDerivatives;
    with(c, call, |i| {
        i.check_declared(call)?;
        let vr = slice(i, call, "vr", vr, nvr)?;
        let order = slice(i, call, "order", order, nvr)?;
        let value = slice_mut(i, call, "value", value, nvr)?;
        i.get_real_output_derivatives(vr, order, value)?;
        i.log_call(|| {
            format!("fmi2GetRealOutputDerivatives(vr={vr:?}, order={order:?}) -> {value:?}")
        });
        Ok(())
    })
}

/// `fmi2DoStep`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    let call = Call::DoStep;
    with(c, call, |i| {
        i.log_call(|| {
            format!("fmi2DoStep(t={currentCommunicationPoint}, h={communicationStepSize})")
        });
        boolean(
            i,
            call,
            "noSetFMUStatePriorToCurrentPoint",
            noSetFMUStatePriorToCurrentPoint,
        )?;
        i.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

/// `fmi2CancelStep`: steps are synchronous, there is nothing to cancel.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    unsupported(c, Call::CancelStep)
}

/// `fmi2GetStatus`: steps are synchronous, no status to ask for.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    unsupported(c, Call::GetStatus)
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    let call = Call::GetRealStatus;
    with(c, call, |i| {
        let v = slice_mut(i, call, "value", value, 1)?;
        if s != 2 {
            return i.refuse(
                Status::Error,
                format!("fmi2GetRealStatus: status kind {s}; allowed: fmi2LastSuccessfulTime (2)"),
            );
        }
        v[0] = i.last_successful_time();
        Ok(())
    })
}

/// `fmi2GetIntegerStatus`: no integer status.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    unsupported(c, Call::GetIntegerStatus)
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` (the wheel reached the end of the track).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    let call = Call::GetBooleanStatus;
    with(c, call, |i| {
        let v = slice_mut(i, call, "value", value, 1)?;
        if s != 3 {
            return i.refuse(
                Status::Error,
                format!("fmi2GetBooleanStatus: status kind {s}; allowed: fmi2Terminated (3)"),
            );
        }
        v[0] = i.terminated_by_model() as fmi2Boolean;
        Ok(())
    })
}

/// `fmi2GetStringStatus`: no string status.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    _s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    unsupported(c, Call::GetStringStatus)
}
