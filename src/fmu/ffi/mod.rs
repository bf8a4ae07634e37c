//! The C boundary: every FMI 2.0 co-simulation function, exported unmangled. Each one
//! claims the instance (a busy flag refuses a second thread), checks the state table
//! ([`crate::fmu::CALLS`]), its pointers and arguments, and forwards to
//! [`crate::fmu::Instance`] inside `catch_unwind`, so no panic crosses into the
//! master. FMU states are owned by the instance that handed them out. The exported
//! functions are in one file per concern (`lifecycle.rs`, `values.rs`, `fmu_states.rs`,
//! `derivatives.rs`, `stepping.rs`); cbindgen writes the C header from them
//! (`build/c_header.rs`); a test compiles it against the official `fmi2Functions.h`.

#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

mod binary;
mod component;
mod derivatives;
mod fmu_states;
pub(crate) mod guard;
mod lifecycle;
mod stepping;
#[cfg(test)]
mod tests;
mod types;
mod values;

pub use binary::{kind_for_guid, kind_of_binary, loaded_binary};
pub use derivatives::*;
pub use fmu_states::*;
pub use lifecycle::*;
pub use stepping::*;
pub use types::*;
pub use values::*;
