//! One FMU instance: its phase in the state machine, its values, its clock and its
//! logging. Value access is in `values.rs`, stepping in `step.rs`, FMU states in
//! `states.rs`.

use super::calls::{Allowed, Call, Phase};
use super::model::{Model, StepFault};
use super::status::{FmiResult, LOG_CATEGORIES, Logger, Refusal, Status};
use crate::error::Error;
use crate::fmu::vars::{FmuTable, N_VR};
use std::sync::Arc;

/// One FMU instance of the model `M`.
pub struct Instance<M: Model> {
    pub(super) table: &'static FmuTable,
    name: String,
    /// Index into the FMU's variable list for each value reference.
    pub(super) slot: Vec<Option<usize>>,
    /// Current values of parameters and inputs, by value reference.
    pub(super) values: Vec<f64>,
    /// Current values of the String parameters, by value reference (empty for every
    /// other reference).
    pub(super) strings: Vec<String>,
    /// Their contents, as [`Model::read_string`] read them when they were set (a table
    /// file's text for its path): what the model is built from.
    pub(super) contents: Vec<Arc<str>>,
    /// The C strings of the last `fmi2GetString`, alive until the next call.
    pub(super) string_buffers: Vec<std::ffi::CString>,
    pub(super) phase: Phase,
    pub(super) model: Option<M>,
    /// Parameters changed since the model was built.
    pub(super) dirty: bool,
    /// The inputs the master has set since instantiation or reset, by value reference:
    /// a model is built with these; the others take [`Model::input_at_rest`].
    pub(super) given: Vec<bool>,
    /// The calculated parameters of the last model built ([`Model::calculated`]).
    pub(super) calculated: Vec<f64>,
    /// Communication time (s): the master's clock, as its `fmi2DoStep` calls carry it.
    pub(super) time: f64,
    /// `startTime` of `fmi2SetupExperiment` (s): the model's own clock starts at 0 there.
    pub(super) start_time: f64,
    pub(super) stop_time: Option<f64>,
    /// The model ended the run: `fmi2Terminated` status.
    pub(super) ended: bool,
    /// Why the run cannot go on (a value beyond the health bounds): `fmi2DoStep` and
    /// outputs are refused until `fmi2Reset` or `fmi2SetFMUstate`.
    pub(super) failed: Option<String>,
    /// The kinds of step warning ([`Model::step_warning`]) warned of in this run, with
    /// the severity last warned of, until `fmi2Reset` (FMU states leave them as they
    /// are).
    pub(super) step_warned: super::model::Warned,
    logger: Logger,
    logging_on: bool,
    categories: [bool; 4],
}

impl<M: Model> std::fmt::Debug for Instance<M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance")
            .field("model", &self.table.model_identifier)
            .field("name", &self.name)
            .field("phase", &self.phase)
            .field("time", &self.time)
            .finish()
    }
}

impl<M: Model> Instance<M> {
    /// A new instance of the FMU `table` with its start values, logging through
    /// `logger` (errors and warnings always, the other categories when `logging_on`).
    pub fn new(table: &'static FmuTable, name: &str, logger: Logger, logging_on: bool) -> Self {
        let mut slot = vec![None; N_VR];
        let mut values = vec![f64::NAN; N_VR];
        for (i, v) in table.vars.iter().enumerate() {
            slot[v.vr as usize] = Some(i);
            values[v.vr as usize] = v.start;
        }
        Instance {
            table,
            name: name.to_string(),
            slot,
            values,
            strings: vec![String::new(); N_VR],
            contents: vec![Arc::from(""); N_VR],
            string_buffers: Vec::new(),
            phase: Phase::Instantiated,
            model: None,
            dirty: true,
            given: vec![false; N_VR],
            calculated: vec![0.0; M::CALCULATED],
            time: 0.0,
            start_time: 0.0,
            stop_time: None,
            ended: false,
            failed: None,
            step_warned: super::model::Warned::default(),
            logger,
            logging_on,
            categories: [true; 4],
        }
    }

    /// The FMU's variable table.
    pub fn table(&self) -> &'static FmuTable {
        self.table
    }
    /// Instance name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// State-machine phase. A step that ended the run (`ended`) leaves the instance in
    /// [`Phase::StepFailed`] even where the stepping code left the phase at
    /// `StepComplete`.
    pub fn phase(&self) -> Phase {
        match self.phase {
            Phase::StepComplete if self.ended => Phase::StepFailed,
            p => p,
        }
    }
    /// Communication time (s).
    pub fn time(&self) -> f64 {
        self.time
    }
    /// The current value of a parameter or input (NaN for any other value reference).
    pub fn value(&self, vr: u32) -> f64 {
        self.values.get(vr as usize).copied().unwrap_or(f64::NAN)
    }
    /// Keeps the C strings `fmi2GetString` handed out until the next call.
    pub fn keep_string_buffers(&mut self, buffers: Vec<std::ffi::CString>) {
        self.string_buffers = buffers;
    }
    /// The value of a String parameter (empty for any other value reference).
    pub fn string(&self, vr: u32) -> &str {
        self.strings.get(vr as usize).map_or("", |s| s.as_str())
    }
    /// The values of the parameters and inputs, by value reference.
    pub fn values(&self) -> &[f64] {
        &self.values
    }
    /// The model, once built.
    pub fn model(&self) -> Option<&M> {
        self.model.as_ref()
    }

    // ---------------------------------------------------------------- logging

    /// Sends a message to the logger: errors and warnings always, the other
    /// categories when debug logging is on and the category is selected.
    pub fn log(&mut self, status: Status, category: &str, message: &str) {
        let idx = LOG_CATEGORIES.iter().position(|c| *c == category);
        let always = status >= Status::Warning;
        let on = self.logging_on && idx.is_none_or(|i| self.categories[i]);
        if always || on {
            (self.logger)(status, category, message);
        }
    }

    /// Logs a call (category `logCalls`) when enabled.
    pub fn log_call(&mut self, what: impl FnOnce() -> String) {
        if self.logging_on && self.categories[2] {
            let m = what();
            (self.logger)(Status::Ok, "logCalls", &m);
        }
    }

    pub(super) fn log_event(&mut self, what: impl FnOnce() -> String) {
        if self.logging_on && self.categories[3] {
            let m = what();
            (self.logger)(Status::Ok, "logEvents", &m);
        }
    }

    /// Logs a warning.
    pub(super) fn warn(&mut self, message: &str) {
        self.log(Status::Warning, "logStatusWarning", message);
    }

    /// Logs and returns a refusal.
    pub fn refuse<T>(&mut self, status: Status, message: String) -> FmiResult<T> {
        let cat = if status >= Status::Error {
            "logStatusError"
        } else {
            "logStatusWarning"
        };
        self.log(status, cat, &message);
        Err(Refusal { status, message })
    }

    /// Refuses with the model's error `e`, after `context`: `fmi2Discard` when the
    /// error ends the run, `fmi2Error` otherwise.
    pub(super) fn model_refusal<T>(&mut self, context: &str, e: Error) -> FmiResult<T> {
        let status = match M::step_fault(&e) {
            StepFault::Ended => Status::Discard,
            _ => Status::Error,
        };
        self.refuse(status, format!("{context}: {e}"))
    }

    /// `fmi2SetDebugLogging`: on/off, and the categories to log (all when empty).
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> FmiResult {
        let mut sel = [categories.is_empty(); 4];
        for c in categories {
            match LOG_CATEGORIES.iter().position(|x| x == c) {
                Some(i) => sel[i] = true,
                None => {
                    return self.refuse(
                        Status::Error,
                        format!(
                            "fmi2SetDebugLogging: unknown log category \"{c}\"; the categories are {}",
                            LOG_CATEGORIES.join(", ")
                        ),
                    );
                }
            }
        }
        self.logging_on = on;
        self.categories = sel;
        Ok(())
    }

    // ---------------------------------------------------------------- state machine

    /// Refuses `call` unless the table [`super::CALLS`] allows it in the current phase
    /// (or refuses it as unsupported). The message names the function, the phase, where
    /// the function is allowed and, after a failed step or an internal error, why the
    /// instance is there.
    #[inline]
    pub fn check(&mut self, call: Call) -> FmiResult {
        match call.allowed() {
            Allowed::NoInstance => Ok(()),
            Allowed::In(phases) if phases.contains(&self.phase()) => Ok(()),
            _ => self.refuse_call(call),
        }
    }

    #[cold]
    #[inline(never)]
    fn refuse_call(&mut self, call: Call) -> FmiResult {
        let phases = match call.allowed() {
            Allowed::Unsupported(why) => {
                return self.refuse(
                    Status::Error,
                    format!("{} is not supported: {why}", call.name()),
                );
            }
            Allowed::In(p) => p,
            Allowed::NoInstance => return Ok(()),
        };
        let phase = self.phase();
        let names: Vec<String> = phases.iter().map(|p| format!("{p:?}")).collect();
        let why = match phase {
            Phase::StepFailed if self.ended => format!(
                "; the model ended the run at t = {} s (the wheel reached the end of the \
                 track; fmi2Terminated status is true): outputs can still be read and \
                 fmi2Terminate called; use fmi2Reset to run again",
                self.time
            ),
            Phase::StepFailed => {
                "; a step failed: outputs can still be read and fmi2Terminate called; use \
                 fmi2Reset to run again"
                    .to_string()
            }
            Phase::Error => match &self.failed {
                Some(f) => format!(
                    "; the run stopped at t = {} s: {f}; call fmi2Reset or fmi2SetFMUstate",
                    self.time
                ),
                None => "; an internal error stopped the instance: call fmi2Reset".into(),
            },
            Phase::Terminated => "; use fmi2Reset to run again".into(),
            _ => String::new(),
        };
        self.refuse(
            Status::Error,
            format!(
                "{} is not allowed in state {phase:?}; allowed in: {}{why}",
                call.name(),
                names.join(", ")
            ),
        )
    }

    /// `fmi2SetupExperiment`.
    pub fn setup_experiment(&mut self, start: f64, stop: Option<f64>) -> FmiResult {
        self.check(Call::SetupExperiment)?;
        if !start.is_finite() {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetupExperiment: startTime = {start} s; allowed: any finite time (the \
                     model starts in static equilibrium at start_position then)"
                ),
            );
        }
        if let Some(t) = stop.filter(|t| !(t.is_finite() && *t >= start)) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetupExperiment: stopTime = {t} s; allowed: finite and >= startTime \
                     ({start} s)"
                ),
            );
        }
        self.stop_time = stop;
        self.start_time = start;
        self.time = start;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> FmiResult {
        self.check(Call::EnterInitializationMode)?;
        self.phase = Phase::Initialization;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: builds the model if parameters changed.
    pub fn exit_initialization(&mut self) -> FmiResult {
        self.check(Call::ExitInitializationMode)?;
        // Inputs set for another configuration than the one now fixed; written at their
        // start value they change nothing (issue 38, N7: a master may write every
        // input's start).
        let misused = self
            .table
            .vars
            .iter()
            .filter(|v| self.given[v.vr as usize] && self.values[v.vr as usize] != v.start)
            .find_map(|v| self.unused_input(v));
        if let Some(why) = misused {
            return self.refuse(Status::Error, format!("fmi2ExitInitializationMode: {why}"));
        }
        self.ensure_model()?;
        self.phase = Phase::StepComplete;
        self.log_event(|| "initialised in static equilibrium".into());
        let warning = self
            .model
            .as_ref()
            .and_then(|m| m.initialised_warning(self.start_time, self.stop_time));
        if let Some(w) = warning {
            // Initialised: the warning is the status, nothing was refused.
            let message = format!("fmi2ExitInitializationMode: {w}");
            self.warn(&message);
            return Err(Refusal {
                status: Status::Warning,
                message,
            });
        }
        Ok(())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> FmiResult {
        self.check(Call::Terminate)?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    /// `fmi2Reset`: back to the state after instantiation, start values restored.
    pub fn reset(&mut self) -> FmiResult {
        for v in self.table.vars {
            self.values[v.vr as usize] = v.start;
        }
        self.strings.iter_mut().for_each(String::clear);
        self.contents.iter_mut().for_each(|c| *c = Arc::from(""));
        self.phase = Phase::Instantiated;
        self.model = None;
        self.dirty = true;
        self.given.iter_mut().for_each(|g| *g = false);
        self.time = 0.0;
        self.start_time = 0.0;
        self.stop_time = None;
        self.ended = false;
        self.failed = None;
        self.step_warned.clear();
        self.calculated = vec![0.0; M::CALCULATED];
        Ok(())
    }

    /// After an internal error: drop the model and require `fmi2Reset`.
    pub fn poison(&mut self) {
        self.model = None;
        self.dirty = true;
        self.phase = Phase::Error;
    }

    // ---------------------------------------------------------------- model

    /// Builds the model if there is none or parameters changed, and hands it the
    /// current inputs.
    pub(super) fn ensure_model(&mut self) -> FmiResult {
        if self.model.is_none() || self.dirty {
            let old = self.model.take();
            match M::build(self.table, &self.values, &self.contents) {
                Ok(m) => {
                    self.calculated = m.calculated();
                    self.model = Some(m);
                    self.dirty = false;
                    self.log_event(|| "model built: static equilibrium solved".into());
                    // The inputs the master gave go to the model; the others report
                    // where the model put them.
                    let (given, at_rest): (Vec<u32>, Vec<u32>) =
                        self.table.inputs().partition(|&r| self.given[r as usize]);
                    // An input of the configuration not in use keeps its start.
                    let at_rest: Vec<u32> = (at_rest.into_iter())
                        .filter(|&r| {
                            let i = self.slot[r as usize].expect("an input of the table");
                            self.unused_input(&self.table.vars[i]).is_none()
                        })
                        .collect();
                    if let Some(m) = &self.model {
                        for r in at_rest {
                            if let Some(x) = m.input_at_rest(r) {
                                self.values[r as usize] = x;
                            }
                        }
                    }
                    self.sync_inputs(&given)?;
                    if let (Some(m), Some(old)) = (&mut self.model, &old) {
                        m.carry_inputs_from(old);
                    }
                }
                Err(e) => {
                    self.model = None;
                    return self.model_refusal("parameters refused", e);
                }
            }
        }
        Ok(())
    }

    /// Pushes the input values `changed` into the model. Called with the inputs a set
    /// call changed, and with all of them when the model is built; not at every step.
    pub(super) fn sync_inputs(&mut self, changed: &[u32]) -> FmiResult {
        let r = match &mut self.model {
            Some(m) => m.set_inputs(&self.values, changed),
            None => Ok(()),
        };
        match r {
            Ok(()) => Ok(()),
            Err(e) => self.model_refusal("inputs refused", e),
        }
    }
}
