//! An initialised FMU instance through the exported C functions, for the benchmarks and
//! the profiling tools (`#[path]`-included by `benches/engine.rs` and `tools/*.rs`).

use std::ffi::CString;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::vr;

/// An instance of the FMU with `guid`, the Real parameters `reals` and the Integer
/// ones `integers` (value reference, value) set, initialised at t = 0 (no stop time),
/// and its `solver.step` (s). Panics on any refusal.
pub fn initialised(
    guid: &str,
    reals: &[(u32, f64)],
    integers: &[(u32, i32)],
) -> (fmi2Component, f64) {
    let cb = fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    };
    let guid = CString::new(guid).unwrap();
    let mut dt = 0.0;
    unsafe {
        let c = fmi2Instantiate(c"cost".as_ptr(), 1, guid.as_ptr(), c"".as_ptr(), &cb, 0, 0);
        assert!(!c.is_null());
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
        for (r, x) in reals {
            assert_eq!(fmi2SetReal(c, r, 1, x), 0);
        }
        for (r, x) in integers {
            assert_eq!(fmi2SetInteger(c, r, 1, x), 0);
        }
        assert_eq!(fmi2EnterInitializationMode(c), 0);
        assert_eq!(fmi2ExitInitializationMode(c), 0);
        assert_eq!(fmi2GetReal(c, &vr::SOLVER_STEP, 1, &mut dt), 0);
        (c, dt)
    }
}
