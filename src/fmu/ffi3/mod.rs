//! The FMI 3.0 C boundary: every FMI 3.0 function, exported unmangled from the same
//! library as the FMI 2.0 ones ([`super::ffi`]). Each one claims the instance (a busy
//! flag refuses a second thread), converts its pointers and arguments, and forwards to
//! [`crate::fmu::Instance3`] inside `catch_unwind`, so no panic crosses into the
//! master; the instance checks the FMI 3.0 state table ([`crate::fmu::fmi3::CALLS3`]).
//! The functions of Model Exchange, Scheduled Execution, Event Mode and clocks are
//! exported (an importer may look every function up) and refused with the reason.

#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

mod component;
mod fmu_states;
mod lifecycle;
mod refused;
mod stepping;
#[cfg(test)]
mod tests;
mod types;
mod values;

pub use fmu_states::*;
pub use lifecycle::*;
pub use refused::*;
pub use stepping::*;
pub use types::*;
pub use values::*;
