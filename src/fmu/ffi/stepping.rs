//! The exported FMI 2.0 functions of stepping: `fmi2DoStep`, `fmi2CancelStep` and
//! the status functions (a source of the C header that cbindgen writes,
//! `build/c_header.rs`).

use super::component::*;
use super::types::*;
use crate::fmu::{Call, Status};

/// A function refused in every state: [`Instance::check`](crate::fmu::Instance::check)
/// gives the reason from the table.
fn unsupported(c: fmi2Component, call: Call) -> fmi2Status {
    with(c, call, |_| Ok(()))
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
