//! The C types of FMI 2.0 (`fmi2TypesPlatform.h`, `fmi2FunctionTypes.h`).

use std::ffi::{c_char, c_int, c_uint, c_void};

/// `fmi2Component`: pointer to an instance (behind its busy flag).
pub type fmi2Component = *mut c_void;
/// `fmi2ComponentEnvironment`: the master's pointer handed back to the logger.
pub type fmi2ComponentEnvironment = *mut c_void;
/// `fmi2FMUstate`: pointer to a saved state.
pub type fmi2FMUstate = *mut c_void;
/// `fmi2ValueReference`.
pub type fmi2ValueReference = c_uint;
/// `fmi2Real`.
pub type fmi2Real = f64;
/// `fmi2Integer`.
pub type fmi2Integer = c_int;
/// `fmi2Boolean`.
pub type fmi2Boolean = c_int;
/// `fmi2Char`.
pub type fmi2Char = c_char;
/// `fmi2String`.
pub type fmi2String = *const fmi2Char;
/// `fmi2Byte`.
pub type fmi2Byte = c_char;
/// `fmi2Status` (an enumeration in C, passed as int).
pub type fmi2Status = c_int;
/// `fmi2Type`: 0 Model Exchange, 1 Co-Simulation.
pub type fmi2Type = c_int;
/// `fmi2StatusKind`: 0 DoStepStatus, 1 PendingStatus, 2 LastSuccessfulTime, 3 Terminated.
pub type fmi2StatusKind = c_int;

/// `fmi2CallbackLogger`, variadic like the C declaration.
pub type fmi2CallbackLogger = Option<
    unsafe extern "C" fn(
        fmi2ComponentEnvironment,
        fmi2String,
        fmi2Status,
        fmi2String,
        fmi2String,
        ...
    ),
>;

/// `fmi2CallbackFunctions`.
#[repr(C)]
pub struct fmi2CallbackFunctions {
    /// Logger.
    pub logger: fmi2CallbackLogger,
    /// Memory allocation (not used: `canNotUseMemoryManagementFunctions`).
    pub allocateMemory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// Memory release (not used).
    pub freeMemory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// Asynchronous step finished (not used).
    pub stepFinished: Option<unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2Status)>,
    /// The master's environment pointer.
    pub componentEnvironment: fmi2ComponentEnvironment,
}
