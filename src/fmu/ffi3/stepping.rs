//! The exported FMI 3.0 functions of stepping and derivatives: `fmi3DoStep`,
//! `fmi3GetOutputDerivatives`, `fmi3GetDirectionalDerivative` and
//! `fmi3GetAdjointDerivative`.

use super::component::*;
use super::types::*;
use crate::fmu::fmi3::Call3;
use crate::fmu::{FmiResult, Instance3};

/// `fmi3DoStep`: `terminateSimulation` when the model ended the run; `earlyReturn` (with
/// early return allowed) when it stopped where a wheel came into contact or lost it;
/// never an event. The out-arguments are written whenever the state table lets the step
/// be tried, whatever its status.
#[unsafe(no_mangle)]
#[allow(unused_variables)]
pub unsafe extern "C" fn fmi3DoStep(
    instance: fmi3Instance,
    currentCommunicationPoint: fmi3Float64,
    communicationStepSize: fmi3Float64,
    noSetFMUStatePriorToCurrentPoint: fmi3Boolean,
    eventHandlingNeeded: *mut fmi3Boolean,
    terminateSimulation: *mut fmi3Boolean,
    earlyReturn: *mut fmi3Boolean,
    lastSuccessfulTime: *mut fmi3Float64,
) -> fmi3Status {
    let call = Call3::DoStep;
    with(instance, call, |i| {
        i.log_call(|| {
            format!("fmi3DoStep(t={currentCommunicationPoint}, h={communicationStepSize})")
        });
        for (p, what) in [
            (eventHandlingNeeded, "eventHandlingNeeded"),
            (terminateSimulation, "terminateSimulation"),
            (earlyReturn, "earlyReturn"),
        ] {
            if p.is_null() {
                return null(i, call, what);
            }
        }
        if lastSuccessfulTime.is_null() {
            return null(i, call, "lastSuccessfulTime");
        }
        let (r, report) = i.do_step(currentCommunicationPoint, communicationStepSize);
        unsafe {
            *eventHandlingNeeded = false;
            *earlyReturn = report.early_return;
            *terminateSimulation = report.terminate;
            *lastSuccessfulTime = report.last_successful_time;
        }
        r
    })
}

/// `fmi3GetOutputDerivatives`: `orders[i]` applies to every element of the output
/// `valueReferences[i]`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetOutputDerivatives(
    instance: fmi3Instance,
    valueReferences: *const fmi3ValueReference,
    nValueReferences: usize,
    orders: *const fmi3Int32,
    values: *mut fmi3Float64,
    nValues: usize,
) -> fmi3Status {
    let call = Call3::GetOutputDerivatives;
    with(instance, call, |i| {
        let vr = slice(
            i,
            call,
            "valueReferences",
            valueReferences,
            nValueReferences,
        )?;
        let orders = slice(i, call, "orders", orders, nValueReferences)?;
        i.check_count(call, vr, nValues, "nValues")?;
        let out = slice_mut(i, call, "values", values, nValues)?;
        i.output_derivatives(vr, orders, out)
    })
}

#[allow(clippy::too_many_arguments)]
unsafe fn derivative(
    instance: fmi3Instance,
    call: Call3,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
    f: impl FnOnce(&mut Instance3, &[u32], &[u32], &[f64], &mut [f64]) -> FmiResult,
) -> fmi3Status {
    with(instance, call, |i| {
        let u = slice(i, call, "unknowns", unknowns, nUnknowns)?;
        let k = slice(i, call, "knowns", knowns, nKnowns)?;
        // The counts before the buffers: the seed has the knowns' values (the unknowns'
        // in the adjoint), the sensitivity the others'.
        let (by_seed, by_sensitivity) = match call {
            Call3::GetAdjointDerivative => (u, k),
            _ => (k, u),
        };
        i.check_count(call, by_seed, nSeed, "nSeed")?;
        i.check_count(call, by_sensitivity, nSensitivity, "nSensitivity")?;
        let s = slice(i, call, "seed", seed, nSeed)?;
        let out = slice_mut(i, call, "sensitivity", sensitivity, nSensitivity)?;
        f(i, u, k, s, out)
    })
}

/// `fmi3GetDirectionalDerivative` (where the FMU declares
/// `providesDirectionalDerivatives`): `sensitivity = J seed`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetDirectionalDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    let call = Call3::GetDirectionalDerivative;
    unsafe {
        derivative(
            instance,
            call,
            unknowns,
            nUnknowns,
            knowns,
            nKnowns,
            seed,
            nSeed,
            sensitivity,
            nSensitivity,
            |i, u, k, s, o| i.directional_derivative(u, k, s, o),
        )
    }
}

/// `fmi3GetAdjointDerivative` (where the FMU declares `providesAdjointDerivatives`):
/// `sensitivity = J^T seed`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi3GetAdjointDerivative(
    instance: fmi3Instance,
    unknowns: *const fmi3ValueReference,
    nUnknowns: usize,
    knowns: *const fmi3ValueReference,
    nKnowns: usize,
    seed: *const fmi3Float64,
    nSeed: usize,
    sensitivity: *mut fmi3Float64,
    nSensitivity: usize,
) -> fmi3Status {
    let call = Call3::GetAdjointDerivative;
    unsafe {
        derivative(
            instance,
            call,
            unknowns,
            nUnknowns,
            knowns,
            nKnowns,
            seed,
            nSeed,
            sensitivity,
            nSensitivity,
            |i, u, k, s, o| i.adjoint_derivative(u, k, s, o),
        )
    }
}
