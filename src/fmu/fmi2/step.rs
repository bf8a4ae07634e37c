//! `fmi2DoStep` and the status functions: the master's clock, checked, and the model
//! advanced to it.

use super::calls::{Call, Phase};
use super::instance::Instance;
use super::model::{Model, StepError, StepFault};
use super::status::{FmiResult, Status};
use crate::error::num;

impl<M: Model> Instance<M> {
    /// `fmi2DoStep` from `t` (s) by `h` (s).
    ///
    /// The FMU's clock is the master's: it moves to `t + h` exactly, and the model
    /// advances to the model time `t + h - startTime` ([`Model::advance_to`], which
    /// rounds to its own grid within the clock's rounding).
    ///
    /// Refused before anything moves: `h` not finite and positive, `t + h == t`, `t`
    /// not the FMU's time (to 64 units in the last place), a step past `stopTime`, a
    /// step the model refuses as too much work for one call ([`StepError::TooMuchWork`]).
    /// A model error that ends the run gives `fmi2Discard` and the `fmi2Terminated`
    /// status; one that stops it ([`StepFault::Stopped`]) gives `fmi2Error`, and the run
    /// can then only be reset or restored from an FMU state.
    pub fn do_step(&mut self, t: f64, h: f64) -> FmiResult {
        self.step(t, h, false)
    }

    /// [`Instance::do_step`] that may end early, at an event of the model's own
    /// ([`Model::advance_to_event`]: a wheel coming into contact or losing it), for FMI
    /// 3.0's early return. Where it did, the FMU's clock is the model's time there
    /// ([`Instance::last_successful_time`], before `t + h`), where the next step starts,
    /// and the event is logged (`logEvents`).
    pub fn do_step_to_event(&mut self, t: f64, h: f64) -> FmiResult {
        self.step(t, h, true)
    }

    fn step(&mut self, t: f64, h: f64, early: bool) -> FmiResult {
        self.check(Call::DoStep)?;
        if !(h.is_finite() && h > 0.0) {
            return self.refuse(
                Status::Error,
                format!("fmi2DoStep: communicationStepSize = {h} s; allowed: finite and > 0 s"),
            );
        }
        // The master's clock may differ from `t + h` of the last call by its rounding.
        let tol = 64.0 * f64::EPSILON * t.abs().max(self.time.abs());
        if !t.is_finite() || (t - self.time).abs() > tol {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: currentCommunicationPoint = {t} s, but the FMU is at {} s \
                     (the end of the last step; allowed: that time to within {} s, the \
                     rounding of the clock)",
                    self.time,
                    num(tol)
                ),
            );
        }
        let end = t + h;
        if end == t {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: communicationStepSize = {h:e} s does not move the clock at t = {t} s \
                     (t + h == t in double precision); allowed: > {:e} s there",
                    f64::EPSILON * t.abs()
                ),
            );
        }
        if let Some(stop) = self.stop_time.filter(|s| end > s + 1e-9 * (1.0 + s.abs())) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2DoStep: t + h = {end} s is past stopTime = {stop} s of \
                     fmi2SetupExperiment; the last step must end at stopTime or before it (take \
                     floor((stopTime - startTime) / h) steps and a shorter last one), or give a \
                     later stopTime or none"
                ),
            );
        }
        // The rounding of the master's clock: a few units in the last place of the time.
        let clock = 16.0 * f64::EPSILON * t.abs().max(end.abs());
        // The model steps to the master's clock, not by the sum of the h it was given
        // (which drifts from the clock by its rounding, 1e-7 s per call at 1e9 s).
        let model_end = end - self.start_time;
        let r = match &mut self.model {
            Some(m) if early => m.advance_to_event(model_end, clock),
            Some(m) => m.advance_to(model_end, clock).map(|()| None),
            None => Err(StepError::Model(crate::Error::Unsupported(
                "stepping before initialisation".into(),
            ))),
        };
        let r = match r {
            Err(StepError::TooMuchWork(w)) => {
                return self.refuse(
                    Status::Error,
                    format!(
                        "fmi2DoStep: communicationStepSize = {h} s would take {w}; use shorter \
                         communication steps"
                    ),
                );
            }
            Err(StepError::Model(e)) => Err(e),
            Ok(x) => Ok(x),
        };
        let event = match r {
            Ok(x) => x,
            Err(e) => return self.step_failed(t, h, e),
        };
        // An early end: the model's time there, on its grid, is the FMU's clock.
        let end = match &event {
            Some((model_time, _)) => model_time + self.start_time,
            None => end,
        };
        if let Some((_, what)) = event.as_ref() {
            self.log_event(|| format!("returned early: {what}"));
        }
        self.time = end;
        // The step ended at stopTime (to the clock's rounding): a last step.
        let at_stop = self.stop_time.is_some_and(|s| (s - end).abs() <= clock);
        let warning = self
            .model
            .as_mut()
            .and_then(|m| m.step_warning(end, at_stop));
        let events = self.model.as_mut().map(|m| m.take_events());
        for e in events.into_iter().flatten() {
            self.log_event(|| e);
        }
        if let Some(w) = warning {
            // FMI 2.0.5 (2.1.3): fmi2Warning says "things are not quite right, but the
            // computation can continue", with the logger called (FMI 3.0: "a non-critical
            // problem was detected"). A condition is reported when it starts and when it
            // worsens WORSENED times; a step that ends in it unchanged has nothing new to
            // report and returns fmi2OK, logging nothing (a warning at every step stopped
            // C fmusim, PyFMI and OMSimulator, and flooded the others' logs).
            if !self.step_warned.fresh(w.kind, w.severity) {
                return Ok(());
            }
            let message = format!("fmi2DoStep: {}", w.message);
            self.warn(&message);
            return Err(super::status::Refusal {
                status: Status::Warning,
                message,
            });
        }
        Ok(())
    }

    /// A failed step: the run ended (`fmi2Discard`, the `fmi2Terminated` status) or
    /// stopped (`fmi2Error`, only a reset or an FMU state goes on), or the model refused
    /// its arguments (nothing moved).
    #[cold]
    fn step_failed<T>(&mut self, t: f64, h: f64, e: crate::Error) -> FmiResult<T> {
        match M::step_fault(&e) {
            StepFault::Ended => {
                self.ended = true;
                self.phase = Phase::StepFailed;
            }
            // The state may be partly advanced and beyond the health bounds.
            StepFault::Stopped => {
                self.failed = Some(e.to_string());
                self.phase = Phase::Error;
            }
            // Refused arguments: nothing moved.
            StepFault::Refused => {}
        }
        self.model_refusal(&format!("fmi2DoStep at t = {t} s, h = {h} s"), e)
    }

    /// `fmi2GetRealStatus(fmi2LastSuccessfulTime)`.
    pub fn last_successful_time(&self) -> f64 {
        self.time
    }

    /// `fmi2GetBooleanStatus(fmi2Terminated)`: the model ended the run.
    pub fn terminated_by_model(&self) -> bool {
        self.ended
    }
}
