//! The exported FMI 2.0 functions of derivatives: directional derivatives, the inputs'
//! and the outputs' time derivatives (a source of the C header that cbindgen writes,
//! `build/c_header.rs`).

use super::component::*;
use super::types::*;
use crate::fmu::Call;

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

/// `fmi2GetRealOutputDerivatives`: the outputs' time derivatives (RollPlaneVehicle,
/// HalfCarBogie and Wagon: the wheel and side-frame velocities, the axle's rate;
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
