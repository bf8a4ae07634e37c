//! The FMI co-simulation units: [`fmi2`], a model-independent FMI 2.0 layer (state
//! machine, value access through the variable table, clock, FMU states, logging), and
//! [`fmi3`], the FMI 3.0 layer over it (its state machine, arrays of wheelsets,
//! Configuration Mode, early return); [`binding`], this project's models behind them,
//! one for each FMU listed in [`Kind`]; [`ffi`] and [`ffi3`], the thin C boundaries that
//! only convert pointers, catch panics and forward (one guard, `ffi/guard.rs`, serves
//! both); and [`vars`], the variable table generated from
//! `modelDescription/variables.xml`.
//!
//! The FMUs of both versions share one shared library; `fmi2Instantiate` picks the model
//! from the GUID and `fmi3InstantiateCoSimulation` from the instantiation token, each of
//! which identifies exactly one of them.

pub mod binding;
pub mod ffi;
pub mod ffi3;
pub mod fmi2;
pub mod fmi3;
#[cfg(test)]
mod tests;
pub mod vars;

pub use binding::{END_ZONE_SPANS, FmuModel, Kind};
pub use fmi2::{
    Allowed, CALLS, Call, FmiResult, LOG_CATEGORIES, Logger, Phase, Refusal, Status, StepFault,
};

/// An instance of one of this project's FMUs.
pub type Instance = fmi2::Instance<FmuModel>;
/// An FMI 3.0 instance of one of this project's FMUs.
pub type Instance3 = fmi3::Instance3<FmuModel>;
/// An FMU state of one of this project's FMUs.
pub type Snapshot = fmi2::Snapshot<FmuModel>;
