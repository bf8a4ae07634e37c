//! What the FMI 2.0 layer needs from a model: the binding of a concrete model
//! implements [`Model`], and [`super::Instance`] does the rest (state machine, value
//! access through the variable table, clock checks, FMU states, logging).

use crate::error::Error;
use crate::fmu::vars::{FmuTable, VarSpec};
use std::sync::Arc;

/// How a failed step leaves the run (FMI 2.0, section 4.2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepFault {
    /// The arguments were refused before anything moved: `fmi2Error`, the instance
    /// stays usable.
    Refused,
    /// The model ended the run (`fmi2Discard`, `fmi2Terminated` status true): outputs
    /// can still be read.
    Ended,
    /// The state is beyond what a physical run reaches: `fmi2Error`, the run can only
    /// be reset or restored from an FMU state.
    Stopped,
}

/// How many times worse a condition warned of must become to be warned of again
/// ([`Model::step_warning`]).
pub const WORSENED: f64 = 2.0;

/// A condition a successful step ends in, for `fmi2DoStep` to warn of
/// ([`Model::step_warning`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StepWarning {
    /// The kind: a short fixed name.
    pub kind: &'static str,
    /// What it is, with its numbers, and what to do.
    pub message: String,
    /// How bad it is, in the kind's own measure (> 0): warned of again once it reaches
    /// [`WORSENED`] times the severity last warned of.
    pub severity: f64,
}

impl StepWarning {
    /// A condition of one degree: warned of when it starts.
    pub fn once(kind: &'static str, message: String) -> Self {
        StepWarning {
            kind,
            message,
            severity: 1.0,
        }
    }

    /// A condition of severity `severity` (> 0, the kind's own measure).
    pub fn worse(kind: &'static str, severity: f64, message: String) -> Self {
        StepWarning {
            kind,
            message,
            severity,
        }
    }
}

/// The conditions warned of in a run and the severity each was last warned of at: a
/// condition is warned of when it starts and when it reaches [`WORSENED`] times that
/// severity ([`Model::step_warning`]).
#[derive(Debug, Clone, Default)]
pub struct Warned(Vec<(&'static str, f64)>);

impl Warned {
    /// Whether the condition `kind` at `severity` is to be warned of (new, or worse by
    /// [`WORSENED`] than last warned of); if so, it is recorded as warned of.
    pub fn fresh(&mut self, kind: &'static str, severity: f64) -> bool {
        match self.0.iter_mut().find(|(k, _)| *k == kind) {
            Some((_, s)) if severity < WORSENED * *s => false,
            Some((_, s)) => {
                *s = severity;
                true
            }
            None => {
                self.0.push((kind, severity));
                true
            }
        }
    }

    /// Forgets every condition (a new run).
    pub fn clear(&mut self) {
        self.0.clear();
    }
}

/// Why `fmi2DoStep` did not complete.
#[derive(Debug)]
pub enum StepError {
    /// The step would do more work than one call may; nothing moved. What it would
    /// take, with the numbers.
    TooMuchWork(String),
    /// The model's error.
    Model(Error),
}

impl From<Error> for StepError {
    fn from(e: Error) -> Self {
        StepError::Model(e)
    }
}

/// A value an output must not take, found when it is read.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputFault {
    /// Why, naming the variable, the value and the bound.
    pub message: String,
    /// The run cannot go on (the value is the model's own state, not the result of the
    /// inputs a master may still change).
    pub stops_run: bool,
}

/// A model behind the FMI 2.0 co-simulation layer.
///
/// Values are passed by value reference: `values[vr]` holds the current value of every
/// parameter and input of the FMU (NaN for the others). Times are the model's own,
/// counted from `startTime` of `fmi2SetupExperiment`.
pub trait Model: Clone + Sized {
    /// Number of calculated parameters FMU states store.
    const CALCULATED: usize;

    /// Builds the model of the FMU `table` from the parameter and input values, solving
    /// its initial state.
    ///
    /// Errors: any parameter the model refuses, named with its value and allowed range.
    /// `contents[vr]` holds the String parameters' contents as
    /// [`Model::read_string`] gave them when they were set (empty for the others).
    fn build(
        table: &'static FmuTable,
        values: &[f64],
        contents: &[Arc<str>],
    ) -> Result<Self, Error>;
    /// Reads and checks the value of the String parameter `spec` when it is set (the
    /// earliest call that can know it is bad): its content, what the model will be
    /// built from. A value that names a file gives the file's text, read here once:
    /// the instance keeps the content, FMU states and their serialized form carry it,
    /// so that nothing built later reads the file again (issue 38). The default: the
    /// value itself.
    ///
    /// Errors: a value the model refuses, named with the variable.
    fn read_string(_spec: &VarSpec, value: &str) -> Result<Arc<str>, Error> {
        Ok(Arc::from(value))
    }
    /// Checks the value of the Real parameter `spec` when it is set, beyond the range
    /// of its variable (which the layer checks first): the earliest call that can know
    /// it is bad.
    ///
    /// Errors: a value the model refuses, named with the variable.
    fn check_real(_spec: &VarSpec, _value: f64) -> Result<(), Error> {
        Ok(())
    }

    /// The calculated parameters (fixed by [`Model::build`]), in the order FMU states
    /// store them; [`Model::CALCULATED`] values.
    fn calculated(&self) -> Vec<f64>;

    /// Hands the model the inputs `changed` (value references) from `values`.
    fn set_inputs(&mut self, values: &[f64], changed: &[u32]) -> Result<(), Error>;

    /// The value the model built itself for input `vr`, which the master has not set:
    /// where the model's own initial state puts it (a wheel height at rest in static
    /// equilibrium, say). `None` takes the input's start value. The layer reports it
    /// as the input's value.
    fn input_at_rest(&self, _vr: u32) -> Option<f64> {
        None
    }

    /// What the outputs of one read are computed from (evaluated once per read call).
    type Outputs;

    /// The state the outputs of a read are computed from.
    fn outputs(&self) -> Self::Outputs;

    /// The value of the output or calculated parameter `vr`.
    fn output(&self, outputs: &Self::Outputs, vr: u32) -> f64;

    /// Checks a finite output value against the bounds of a physical run.
    fn check_output(&self, spec: &VarSpec, value: f64, time: f64) -> Result<(), OutputFault>;

    /// A warning at the end of initialisation (for instance a `stopTime` the model cannot
    /// reach), given the experiment's `startTime` and `stopTime` (s).
    fn initialised_warning(&self, start: f64, stop: Option<f64>) -> Option<String>;

    /// Advances to the model time `end` (s), within the master clock's rounding `clock`
    /// (s), with the inputs held.
    ///
    /// Errors: [`StepError::TooMuchWork`] before anything moves when the step would do
    /// more work than one call may; the model's errors.
    fn advance_to(&mut self, end: f64, clock: f64) -> Result<(), StepError>;

    /// [`Model::advance_to`] that may stop early, at an event of the model's own (a wheel
    /// coming into contact or losing it): the model time it stopped at (s, on its own
    /// grid, before `end`) and the event in words; `None` where it reached `end`. For
    /// FMI 3.0's early return (`earlyReturnAllowed`). The default never stops early.
    ///
    /// Errors: as [`Model::advance_to`].
    fn advance_to_event(
        &mut self,
        end: f64,
        clock: f64,
    ) -> Result<Option<(f64, String)>, StepError> {
        self.advance_to(end, clock).map(|()| None)
    }

    /// How an error of [`Model::advance_to`] leaves the run.
    fn step_fault(e: &Error) -> StepFault;

    /// A warning about the state after a successful step at the communication time
    /// `time` (s); `at_stop`: the step ended at the experiment's stop time.
    /// `fmi2DoStep` returns `fmi2Warning` with its message when the condition starts
    /// (the first time of its kind in a run, until `fmi2Reset`) and when it has
    /// worsened [`WORSENED`] times since it was last warned of; at the steps between,
    /// while it holds, `fmi2OK` and nothing logged.
    fn step_warning(&mut self, time: f64, at_stop: bool) -> Option<StepWarning>;

    /// What the model did of its own accord in the last step that a user may want to
    /// know (logged in the category `logEvents` when debug logging is on; no status).
    fn take_events(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// Everything that determines the continuation, for serialized FMU states.
    fn state_vector(&self) -> Result<Vec<f64>, Error>;

    /// Restores [`Model::state_vector`] into a model built from the same parameters.
    fn set_state_vector(&mut self, v: &[f64]) -> Result<(), Error>;

    /// The model's time since `startTime` (s) and how far it may lie from the
    /// communication time (s): the model steps on its own grid.
    fn model_time(&self) -> (f64, f64);

    /// Takes over from `old`, the model this one replaces after a parameter changed
    /// (in initialization mode), what the master gave it besides the values the layer
    /// keeps: the inputs' derivatives. Called after the inputs are handed over.
    fn carry_inputs_from(&mut self, _old: &Self) {}

    /// Sets the time derivative of order `order` (>= 1) of the Real input `vr` at the
    /// current time (`fmi2SetRealInputDerivatives`; the FMU declares
    /// `canInterpolateInputs`).
    ///
    /// Errors: an input or order the model does not interpolate, a value out of range.
    fn set_input_derivative(&mut self, vr: u32, _order: i32, _value: f64) -> Result<(), Error> {
        Err(Error::Unsupported(format!(
            "input derivatives of value reference {vr}"
        )))
    }

    /// The time derivative of order `order` (>= 1) of the output `vr` at the current
    /// time (`fmi2GetRealOutputDerivatives`, up to the FMU's
    /// `maxOutputDerivativeOrder`).
    ///
    /// Errors: an output the model has no derivative of.
    fn output_derivative(&self, vr: u32, _order: i32) -> Result<f64, Error> {
        Err(Error::Unsupported(format!(
            "output derivatives of value reference {vr}"
        )))
    }

    /// The partial derivative of the output `unknown` with respect to the input
    /// `known` at the current state (`fmi2GetDirectionalDerivative`, where the FMU
    /// declares `providesDirectionalDerivative`).
    ///
    /// Errors: a pair the model has no derivative of.
    fn partial_derivative(&self, unknown: u32, known: u32) -> Result<f64, Error> {
        Err(Error::Unsupported(format!(
            "the derivative of value reference {unknown} with respect to {known}"
        )))
    }
}
