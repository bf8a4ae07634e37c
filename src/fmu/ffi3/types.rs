//! The C types of FMI 3.0 (`fmi3PlatformTypes.h`, `fmi3FunctionTypes.h`).

use std::ffi::{c_char, c_int, c_void};

/// `fmi3Instance`.
pub type fmi3Instance = *mut c_void;
/// `fmi3InstanceEnvironment`.
pub type fmi3InstanceEnvironment = *mut c_void;
/// `fmi3FMUState`.
pub type fmi3FMUState = *mut c_void;
/// `fmi3ValueReference`.
pub type fmi3ValueReference = u32;
/// `fmi3Float32`.
pub type fmi3Float32 = f32;
/// `fmi3Float64`.
pub type fmi3Float64 = f64;
/// `fmi3Int8`.
pub type fmi3Int8 = i8;
/// `fmi3UInt8`.
pub type fmi3UInt8 = u8;
/// `fmi3Int16`.
pub type fmi3Int16 = i16;
/// `fmi3UInt16`.
pub type fmi3UInt16 = u16;
/// `fmi3Int32`.
pub type fmi3Int32 = i32;
/// `fmi3UInt32`.
pub type fmi3UInt32 = u32;
/// `fmi3Int64`.
pub type fmi3Int64 = i64;
/// `fmi3UInt64`.
pub type fmi3UInt64 = u64;
/// `fmi3Boolean` (C `bool`).
pub type fmi3Boolean = bool;
/// `fmi3Clock` (C `bool`).
pub type fmi3Clock = bool;
/// `fmi3Byte`.
pub type fmi3Byte = u8;
/// `fmi3Binary`.
pub type fmi3Binary = *const fmi3Byte;
/// `fmi3String`.
pub type fmi3String = *const c_char;
/// `fmi3Status`: `fmi3OK` 0 to `fmi3Fatal` 4.
pub type fmi3Status = c_int;
/// `fmi3DependencyKind` (a C enum).
pub type fmi3DependencyKind = c_int;
/// `fmi3IntervalQualifier` (a C enum).
pub type fmi3IntervalQualifier = c_int;
/// `fmi3LogMessageCallback`.
pub type fmi3LogMessageCallback =
    Option<unsafe extern "C" fn(fmi3InstanceEnvironment, fmi3Status, fmi3String, fmi3String)>;
/// `fmi3IntermediateUpdateCallback` (never called: these units provide no intermediate
/// update).
pub type fmi3IntermediateUpdateCallback = *const c_void;
/// `fmi3ClockUpdateCallback` (never called: Scheduled Execution is refused).
pub type fmi3ClockUpdateCallback = *const c_void;
/// `fmi3LockPreemptionCallback` (never called).
pub type fmi3LockPreemptionCallback = *const c_void;
/// `fmi3UnlockPreemptionCallback` (never called).
pub type fmi3UnlockPreemptionCallback = *const c_void;
