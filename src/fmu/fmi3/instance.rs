//! One FMI 3.0 co-simulation instance: the FMI 2.0 layer's [`Instance`] (values,
//! ranges, clock, model, FMU states) behind the FMI 3.0 state table ([`CALLS3`]), its
//! types and its arrays. An array's value reference stands for its elements, the FMI
//! 2.0 variables of the wheelsets in use; `wheelsets` is set in Configuration Mode.

use super::calls::{Allowed3, CALLS3, Call3, Phase3};
use super::messages::translate;
use crate::fmu::fmi2::{FmiResult, Instance, Logger, Model, Refusal, Snapshot, Status};
use crate::fmu::vars::{Fmu3Table, N_VR, Type3, Var3Spec};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The value reference of the independent variable `time`: the first after the
/// table's (build/fmi3.rs).
const TIME_VR: u32 = N_VR as u32;
/// Its stand-in among the FMI 2.0 value references of [`Instance3::elements`].
const TIME: u32 = u32::MAX;

/// `r` of the FMI 2.0 layer with its refusal's message in FMI 3.0 terms (the logger's
/// copy is translated on its way).
fn fmi3<T>(table: &'static Fmu3Table, running: &AtomicUsize, r: FmiResult<T>) -> FmiResult<T> {
    r.map_err(|e| Refusal {
        status: e.status,
        message: translate(
            &e.message,
            CALLS3
                .get(running.load(Ordering::Relaxed).wrapping_sub(1))
                .map(|c| c.0),
            table,
        ),
    })
}

/// What `fmi3DoStep` reports besides its status.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepReport {
    /// `terminateSimulation`: the model ended the run (the wheel reached the end of the
    /// track).
    pub terminate: bool,
    /// `lastSuccessfulTime` (s).
    pub last_successful_time: f64,
    /// `earlyReturn`: the step ended before `t + h`, at `lastSuccessfulTime`, where a
    /// wheel came into contact or lost it (only with early return allowed).
    pub early_return: bool,
}

/// One FMI 3.0 instance of the model `M`.
pub struct Instance3<M: Model> {
    inner: Instance<M>,
    table: &'static Fmu3Table,
    /// Index into `table.vars` by value reference.
    slot: Vec<Option<u16>>,
    /// Between `fmi3EnterConfigurationMode` and `fmi3ExitConfigurationMode`.
    configuring: bool,
    /// `earlyReturnAllowed` of the instantiation: `fmi3DoStep` returns at a change of
    /// contact.
    early_return: bool,
    /// 1 + the index in [`CALLS3`] of the call running (0: none), for the logger's
    /// translation of the FMI 2.0 layer's messages.
    running: Arc<AtomicUsize>,
}

impl<M: Model> std::fmt::Debug for Instance3<M> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Instance3")
            .field("inner", &self.inner)
            .field("configuring", &self.configuring)
            .finish()
    }
}

impl<M: Model> Instance3<M> {
    /// A new instance of the FMU `table` with its start values, logging through `logger`
    /// (errors and warnings always, the other categories when `logging_on`) in FMI 3.0
    /// terms.
    pub fn new(
        table: &'static Fmu3Table,
        name: &str,
        mut logger: Logger,
        logging_on: bool,
    ) -> Self {
        let running = Arc::new(AtomicUsize::new(0));
        let r = running.clone();
        let translating: Logger = Box::new(move |status, category, message| {
            let call = CALLS3
                .get(r.load(Ordering::Relaxed).wrapping_sub(1))
                .map(|c| c.0);
            logger(status, category, &translate(message, call, table))
        });
        let mut slot = vec![None; N_VR];
        for (i, v) in table.vars.iter().enumerate() {
            slot[v.vr as usize] = Some(i as u16);
        }
        Instance3 {
            inner: Instance::new(table.fmi2, name, translating, logging_on),
            table,
            slot,
            configuring: false,
            early_return: false,
            running,
        }
    }

    /// `earlyReturnAllowed`: from now on `fmi3DoStep` of a track-carrying FMU returns
    /// after the internal step at whose end a wheel came into contact (an impact) or lost
    /// it, so that a master sees it at its time ([`Model::advance_to_event`]); the
    /// vehicles' FMUs, which see forces and not contact, never return early.
    pub fn allow_early_return(&mut self, allowed: bool) {
        self.early_return = allowed;
    }

    /// The FMU's FMI 3.0 table.
    pub fn table(&self) -> &'static Fmu3Table {
        self.table
    }
    /// The FMI 2.0 layer's instance (values, model, clock).
    pub fn fmi2(&self) -> &Instance<M> {
        &self.inner
    }
    /// The phase in the FMI 3.0 state machine.
    pub fn phase(&self) -> Phase3 {
        Phase3::of(self.inner.phase(), self.configuring)
    }

    /// Logs and returns a refusal.
    pub fn refuse<T>(&mut self, status: Status, message: String) -> FmiResult<T> {
        fmi3(
            self.table,
            &self.running,
            self.inner.refuse(status, message),
        )
    }
    /// Sends a message to the logger ([`Instance::log`]).
    pub fn log(&mut self, status: Status, category: &str, message: &str) {
        self.inner.log(status, category, message)
    }
    /// Logs a call (category `logCalls`) when enabled.
    pub fn log_call(&mut self, what: impl FnOnce() -> String) {
        self.inner.log_call(what)
    }
    /// After an internal error: drop the model and require `fmi3Reset`.
    pub fn poison(&mut self) {
        self.configuring = false;
        self.inner.poison()
    }

    /// Records `call` as running and refuses it unless [`CALLS3`] allows it in the
    /// current phase; the message names the function, the phase and where it is allowed.
    pub fn check(&mut self, call: Call3) -> FmiResult {
        self.check_as(call, call.name())
    }

    /// [`Instance3::check`] of `call` for the function `name` of its family (the gets
    /// and sets of the types no variable has).
    pub fn check_as(&mut self, call: Call3, name: &str) -> FmiResult {
        self.running.store(call as usize + 1, Ordering::Relaxed);
        let phase = self.phase();
        match call.allowed() {
            Allowed3::NoInstance => Ok(()),
            Allowed3::In(p) if p.contains(&phase) => Ok(()),
            Allowed3::In(p) => {
                let names: Vec<String> = p.iter().map(|x| format!("{x:?}")).collect();
                let why = match phase {
                    Phase3::RunEnded => {
                        "; the model ended the run (terminateSimulation, the wheel reached the \
                         end of the track): outputs can still be read and fmi3Terminate \
                         called; use fmi3Reset to run again"
                    }
                    Phase3::Error => "; the run stopped: call fmi3Reset or fmi3SetFMUState",
                    Phase3::Terminated => "; use fmi3Reset to run again",
                    _ => "",
                };
                self.refuse(
                    Status::Error,
                    format!(
                        "{name} is not allowed in state {phase:?}; allowed in: {}{why}",
                        names.join(", ")
                    ),
                )
            }
            Allowed3::Unsupported(why) => {
                self.refuse(Status::Error, format!("{name} is not supported: {why}"))
            }
        }
    }

    // ------------------------------------------------------------ life cycle

    /// `fmi3SetDebugLogging`.
    pub fn set_debug_logging(&mut self, on: bool, categories: &[String]) -> FmiResult {
        fmi3(
            self.table,
            &self.running,
            self.inner.set_debug_logging(on, categories),
        )
    }

    /// `fmi3EnterConfigurationMode`: `wheelsets` may be set until
    /// `fmi3ExitConfigurationMode`.
    pub fn enter_configuration(&mut self) -> FmiResult {
        self.check(Call3::EnterConfigurationMode)?;
        if !self.table.vars.iter().any(|v| v.ty == Type3::Wheelsets) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi3EnterConfigurationMode: {} has no structural parameter (its \
                     wheelsets is a constant)",
                    self.table.fmi2.model_identifier
                ),
            );
        }
        self.configuring = true;
        Ok(())
    }

    /// `fmi3ExitConfigurationMode`.
    pub fn exit_configuration(&mut self) -> FmiResult {
        self.check(Call3::ExitConfigurationMode)?;
        self.configuring = false;
        Ok(())
    }

    /// `fmi3EnterInitializationMode`: the experiment's start and stop time (s), then
    /// Initialization Mode. The tolerance is not used (the engine steps on its fixed
    /// grid), but must be positive and finite when given.
    pub fn enter_initialization(
        &mut self,
        tolerance: Option<f64>,
        start: f64,
        stop: Option<f64>,
    ) -> FmiResult {
        self.check(Call3::EnterInitializationMode)?;
        if let Some(t) = tolerance.filter(|t| !(t.is_finite() && *t > 0.0)) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi3EnterInitializationMode: tolerance = {t}; allowed: finite and > 0 \
                     (or toleranceDefined = false)"
                ),
            );
        }
        fmi3(
            self.table,
            &self.running,
            self.inner.setup_experiment(start, stop),
        )?;
        fmi3(self.table, &self.running, self.inner.enter_initialization())
    }

    /// `fmi3ExitInitializationMode`: builds the model; the instance is then in Step
    /// Mode (there is no Event Mode).
    pub fn exit_initialization(&mut self) -> FmiResult {
        self.check(Call3::ExitInitializationMode)?;
        fmi3(self.table, &self.running, self.inner.exit_initialization())
    }

    /// `fmi3Terminate`.
    pub fn terminate(&mut self) -> FmiResult {
        self.check(Call3::Terminate)?;
        fmi3(self.table, &self.running, self.inner.terminate())
    }

    /// `fmi3Reset`: back to the state after instantiation, start values restored
    /// (`wheelsets` among them).
    pub fn reset(&mut self) -> FmiResult {
        self.check(Call3::Reset)?;
        self.configuring = false;
        fmi3(self.table, &self.running, self.inner.reset())
    }

    // ------------------------------------------------------------ values

    /// The number of wheelsets in use: the size of every array.
    pub fn wheelsets(&self) -> usize {
        self.table
            .vars
            .iter()
            .find_map(|v| match v.ty {
                Type3::Constant => Some(v.constant as usize),
                Type3::Wheelsets => Some(self.inner.value(v.vr) as usize),
                _ => None,
            })
            .unwrap_or(1)
    }

    fn var(&mut self, call: Call3, vr: u32) -> FmiResult<&'static Var3Spec> {
        match self.slot.get(vr as usize).copied().flatten() {
            Some(i) => Ok(&self.table.vars[i as usize]),
            None => self.refuse(
                Status::Error,
                format!(
                    "{}: unknown value reference {vr} for {}",
                    call.name(),
                    self.table.fmi2.model_identifier
                ),
            ),
        }
    }

    /// The FMI 2.0 value references of the values of the variables `vrs`, each of one
    /// of the types `types`: a scalar's, or an array's elements in use. Refuses an
    /// unknown reference, a variable of another type and a count of values `n_values`
    /// that is not theirs.
    pub fn elements(
        &mut self,
        call: Call3,
        vrs: &[u32],
        types: &[Type3],
        n_values: usize,
    ) -> FmiResult<Vec<u32>> {
        self.elements_counted(call, vrs, types, n_values, "nValues")
    }

    /// Refuses `n_values` (the argument `count`) unless it is the number of values of
    /// the variables `vrs` now: the C boundary asks before it takes a buffer of that
    /// length from the master.
    pub fn check_count(
        &mut self,
        call: Call3,
        vrs: &[u32],
        n_values: usize,
        count: &str,
    ) -> FmiResult {
        const ANY: [Type3; 6] = [
            Type3::Float64,
            Type3::Int32,
            Type3::Enumeration,
            Type3::String,
            Type3::Wheelsets,
            Type3::Constant,
        ];
        self.elements_counted(call, vrs, &ANY, n_values, count)
            .map(|_| ())
    }

    /// [`Instance3::elements`] whose count is the argument `count` (`nSeed`, say).
    fn elements_counted(
        &mut self,
        call: Call3,
        vrs: &[u32],
        types: &[Type3],
        n_values: usize,
        count: &str,
    ) -> FmiResult<Vec<u32>> {
        let n = self.wheelsets();
        // Not the master's count (which may be any size_t): what the references need.
        let mut out = Vec::with_capacity(n_values.min(4 * vrs.len()));
        for &r in vrs {
            if r == TIME_VR {
                // The independent variable: read only (fmi3GetFloat64).
                if call != Call3::GetFloat64 {
                    return self.refuse(
                        Status::Error,
                        format!(
                            "{}: value reference {r} is the independent variable time, which \
                             fmi3GetFloat64 reads and nothing sets",
                            call.name()
                        ),
                    );
                }
                out.push(TIME);
                continue;
            }
            let v = self.var(call, r)?;
            if !types.contains(&v.ty) {
                let ty = match v.ty {
                    Type3::Float64 => "Float64",
                    Type3::Int32 => "Int32",
                    Type3::Enumeration => "an Enumeration (fmi3GetInt64, fmi3SetInt64)",
                    Type3::String => "String",
                    Type3::Wheelsets | Type3::Constant => "UInt64",
                };
                return self.refuse(
                    Status::Error,
                    format!(
                        "{}: variable `{}` (value reference {r}) is of type {ty}",
                        call.name(),
                        v.name
                    ),
                );
            }
            out.extend_from_slice(&v.elements[..Self::in_use(v, n)]);
        }
        if out.len() != n_values {
            return self.refuse(
                Status::Error,
                format!(
                    "{}: {count} = {n_values}, but the {} variables given have {} values (each \
                     array one per wheelset: wheelsets = {n})",
                    call.name(),
                    vrs.len(),
                    out.len()
                ),
            );
        }
        Ok(out)
    }

    /// Instantiated or Configuration Mode: the values are the parameters' and inputs'.
    fn before_initialization(&self) -> bool {
        matches!(
            self.phase(),
            Phase3::Instantiated | Phase3::ConfigurationMode
        )
    }

    /// The values of the FMI 2.0 variables `e` in Instantiated (FMI 3.0, 2.3.2): a
    /// parameter's or an input's start or the value set; any other variable is refused
    /// (known from Initialization Mode on).
    fn start_values<T>(
        &mut self,
        call: Call3,
        e: &[u32],
        out: &mut [T],
        of: impl Fn(f64) -> T,
    ) -> FmiResult {
        use crate::fmu::vars::Causality;
        for (o, &r) in out.iter_mut().zip(e) {
            let spec = self
                .table
                .fmi2
                .var(r)
                .expect("an element of the FMU's table");
            if !matches!(spec.causality, Causality::Parameter | Causality::Input) {
                return self.refuse(
                    Status::Error,
                    format!(
                        "{}: `{}` is computed by the FMU: it can be read from \
                         fmi3EnterInitializationMode on (in Instantiated only parameters and \
                         inputs have values)",
                        call.name(),
                        spec.name
                    ),
                );
            }
            *o = of(self.inner.value(r));
        }
        Ok(())
    }

    /// `fmi3GetFloat64`.
    pub fn get_float64(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        let call = Call3::GetFloat64;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Float64], out.len())?;
        if e.contains(&TIME) {
            // The time where it is asked for, the variables' values around it.
            let values: Vec<u32> = e.iter().copied().filter(|&r| r != TIME).collect();
            let mut got = vec![0.0; values.len()];
            self.get_float64_elements(call, &values, &mut got)?;
            let mut got = got.into_iter();
            for (o, &r) in out.iter_mut().zip(&e) {
                *o = match r {
                    TIME => self.inner.time(),
                    _ => got.next().unwrap_or(f64::NAN),
                };
            }
            return Ok(());
        }
        self.get_float64_elements(call, &e, out)
    }

    fn get_float64_elements(&mut self, call: Call3, e: &[u32], out: &mut [f64]) -> FmiResult {
        if self.before_initialization() {
            return self.start_values(call, e, out, |x| x);
        }
        if e.is_empty() {
            return Ok(());
        }
        fmi3(self.table, &self.running, self.inner.get_real(e, out))
    }

    /// `fmi3SetFloat64`.
    pub fn set_float64(&mut self, vrs: &[u32], values: &[f64]) -> FmiResult {
        let call = Call3::SetFloat64;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Float64], values.len())?;
        fmi3(self.table, &self.running, self.inner.set_real(&e, values))
    }

    /// `fmi3GetInt32`.
    pub fn get_int32(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        let call = Call3::GetInt32;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Int32], out.len())?;
        if self.before_initialization() {
            return self.start_values(call, &e, out, |x| x as i32);
        }
        fmi3(self.table, &self.running, self.inner.get_integer(&e, out))
    }

    /// `fmi3SetInt32`.
    pub fn set_int32(&mut self, vrs: &[u32], values: &[i32]) -> FmiResult {
        let call = Call3::SetInt32;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Int32], values.len())?;
        fmi3(
            self.table,
            &self.running,
            self.inner.set_integer(&e, values),
        )
    }

    /// `fmi3GetInt64`: the Enumerations.
    pub fn get_int64(&mut self, vrs: &[u32], out: &mut [i64]) -> FmiResult {
        let call = Call3::GetInt64;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Enumeration], out.len())?;
        if self.before_initialization() {
            return self.start_values(call, &e, out, |x| x as i64);
        }
        let mut v = vec![0; e.len()];
        fmi3(
            self.table,
            &self.running,
            self.inner.get_integer(&e, &mut v),
        )?;
        for (o, x) in out.iter_mut().zip(v) {
            *o = x.into();
        }
        Ok(())
    }

    /// `fmi3SetInt64`: the Enumerations; a value beyond the items' codes is refused
    /// naming the items.
    pub fn set_int64(&mut self, vrs: &[u32], values: &[i64]) -> FmiResult {
        let call = Call3::SetInt64;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Enumeration], values.len())?;
        let v = self.narrow(call, &e, values)?;
        fmi3(self.table, &self.running, self.inner.set_integer(&e, &v))
    }

    /// `values` for the FMI 2.0 variables `e` as the 32-bit integers they are: a value
    /// beyond 32 bits is refused as it was given, naming the variable's range.
    fn narrow<T: Copy + TryInto<i32> + std::fmt::Display>(
        &mut self,
        call: Call3,
        e: &[u32],
        values: &[T],
    ) -> FmiResult<Vec<i32>> {
        let mut out = Vec::with_capacity(values.len());
        for (&r, &x) in e.iter().zip(values) {
            match x.try_into() {
                Ok(v) => out.push(v),
                Err(_) => {
                    let spec = self
                        .table
                        .fmi2
                        .var(r)
                        .expect("an element of the FMU's table");
                    return self.refuse(
                        Status::Error,
                        format!(
                            "{}: `{}` = {x} is out of range; allowed: {} to {}",
                            call.name(),
                            spec.name,
                            spec.min,
                            spec.max
                        ),
                    );
                }
            }
        }
        Ok(out)
    }

    /// `fmi3GetUInt64`: `wheelsets`.
    pub fn get_uint64(&mut self, vrs: &[u32], out: &mut [u64]) -> FmiResult {
        let call = Call3::GetUInt64;
        self.check(call)?;
        self.elements(call, vrs, &[Type3::Wheelsets, Type3::Constant], out.len())?;
        let n = self.wheelsets() as u64;
        out.iter_mut().for_each(|o| *o = n);
        Ok(())
    }

    /// `fmi3SetUInt64`: `wheelsets`, in Configuration Mode, within its range.
    pub fn set_uint64(&mut self, vrs: &[u32], values: &[u64]) -> FmiResult {
        let call = Call3::SetUInt64;
        if let Some(c) = (self.table.vars.iter())
            .find(|v| v.ty == Type3::Constant)
            .filter(|_| !vrs.is_empty())
        {
            self.running.store(call as usize + 1, Ordering::Relaxed);
            return self.refuse(
                Status::Error,
                format!(
                    "fmi3SetUInt64: {} has no structural parameter: `{}` is a constant ({}), \
                     its number of wheelsets",
                    self.table.fmi2.model_identifier, c.name, c.constant
                ),
            );
        }
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Wheelsets], values.len())?;
        let v = self.narrow(call, &e, values)?;
        fmi3(self.table, &self.running, self.inner.set_integer(&e, &v))
    }

    /// `fmi3GetString`.
    pub fn get_string(&mut self, vrs: &[u32], n_values: usize) -> FmiResult<Vec<String>> {
        let call = Call3::GetString;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::String], n_values)?;
        if self.before_initialization() {
            self.start_values(call, &e, &mut vec![0.0; e.len()], |x| x)?;
            return Ok(e
                .iter()
                .map(|&r| self.inner.string(r).to_string())
                .collect());
        }
        fmi3(self.table, &self.running, self.inner.get_string(&e))
    }

    /// Keeps the C strings `fmi3GetString` handed out until the next call.
    pub fn keep_string_buffers(&mut self, buffers: Vec<std::ffi::CString>) {
        self.inner.keep_string_buffers(buffers)
    }

    /// `fmi3SetString`.
    pub fn set_string(&mut self, vrs: &[u32], values: &[String]) -> FmiResult {
        let call = Call3::SetString;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::String], values.len())?;
        fmi3(self.table, &self.running, self.inner.set_string(&e, values))
    }

    /// A get or set of a type no variable has (`fmi3GetBoolean`, ...): any value
    /// reference is refused, an empty request succeeds.
    pub fn no_such_type(&mut self, name: &str, get: bool, vrs: &[u32]) -> FmiResult {
        let call = if get {
            Call3::GetOther
        } else {
            Call3::SetOther
        };
        self.check_as(call, name)?;
        match vrs.first() {
            None => Ok(()),
            Some(&r) => {
                let what = match self.slot.get(r as usize).copied().flatten() {
                    Some(i) => format!(
                        "variable `{}` is of another type",
                        self.table.vars[i as usize].name
                    ),
                    None => format!("unknown value reference {r}"),
                };
                self.refuse(
                    Status::Error,
                    format!(
                        "{name}: {what}; {} has no variable of this type (Float64, Int32, \
                         Enumeration as Int64, UInt64 wheelsets and String)",
                        self.table.fmi2.model_identifier
                    ),
                )
            }
        }
    }

    // ------------------------------------------------------------ stepping

    /// `fmi3DoStep` from `t` (s) by `h` (s): the FMI 2.0 layer's step, whose checks of
    /// the master's clock and warnings it keeps.
    pub fn do_step(&mut self, t: f64, h: f64) -> (FmiResult, StepReport) {
        let r = self.check(Call3::DoStep).and_then(|()| {
            let r = match self.early_return {
                true => self.inner.do_step_to_event(t, h),
                false => self.inner.do_step(t, h),
            };
            fmi3(self.table, &self.running, r)
        });
        // A step taken (with or without a warning) that ended before the master's
        // t + h (which the FMU's clock is after a whole step) returned early.
        let taken = match &r {
            Ok(()) => true,
            Err(e) => e.status == Status::Warning,
        };
        let last_successful_time = self.inner.last_successful_time();
        let report = StepReport {
            terminate: self.inner.terminated_by_model(),
            last_successful_time,
            early_return: taken && self.early_return && last_successful_time != t + h,
        };
        (r, report)
    }

    // ------------------------------------------------------------ FMU states

    /// `fmi3GetFMUState`.
    pub fn get_state(&mut self) -> FmiResult<Snapshot<M>> {
        self.check(Call3::GetFMUState)?;
        fmi3(self.table, &self.running, self.inner.get_state())
    }
    /// `fmi3SetFMUState`.
    pub fn set_state(&mut self, s: &Snapshot<M>) -> FmiResult {
        self.check(Call3::SetFMUState)?;
        self.configuring = false;
        fmi3(self.table, &self.running, self.inner.set_state(s))
    }
    /// `fmi3SerializeFMUState`'s bytes of `s`.
    pub fn serialize(&mut self, s: &Snapshot<M>) -> FmiResult<Vec<u8>> {
        fmi3(self.table, &self.running, self.inner.serialize(s))
    }
    /// `fmi3DeserializeFMUState`.
    pub fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot<M>> {
        self.check(Call3::DeserializeFMUState)?;
        fmi3(self.table, &self.running, self.inner.deserialize(bytes))
    }

    // ------------------------------------------------------------ derivatives

    /// `fmi3GetDirectionalDerivative`: `sensitivity = J seed`, `J` the partial
    /// derivatives of the elements of the outputs `unknowns` with respect to those of
    /// the inputs `knowns`.
    pub fn directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        sensitivity: &mut [f64],
    ) -> FmiResult {
        let call = Call3::GetDirectionalDerivative;
        self.check(call)?;
        let u = self.elements(call, unknowns, &[Type3::Float64], sensitivity.len())?;
        let k = self.elements(call, knowns, &[Type3::Float64], seed.len())?;
        self.inner
            .get_directional_derivative(&u, &k, seed, sensitivity)
    }

    /// `fmi3GetAdjointDerivative`: `sensitivity = J^T seed` (FMI 3.0, 2.2.11), from the
    /// columns of `J`, one directional derivative per known element.
    pub fn adjoint_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        sensitivity: &mut [f64],
    ) -> FmiResult {
        let call = Call3::GetAdjointDerivative;
        self.check(call)?;
        let f = &[Type3::Float64];
        let u = self.elements_counted(call, unknowns, f, seed.len(), "nSeed")?;
        let k = self.elements_counted(call, knowns, f, sensitivity.len(), "nSensitivity")?;
        if let Some(x) = seed.iter().find(|x| !x.is_finite()) {
            return self.refuse(
                Status::Error,
                format!("{}: seed value {x}; allowed: finite", call.name()),
            );
        }
        let mut column = vec![0.0; u.len()];
        let mut result = vec![0.0; k.len()];
        for (s, &kj) in result.iter_mut().zip(&k) {
            let r = self
                .inner
                .get_directional_derivative(&u, &[kj], &[1.0], &mut column);
            fmi3(self.table, &self.running, r)?;
            *s = column.iter().zip(seed).map(|(j, w)| j * w).sum();
        }
        if let Some(x) = result.iter().find(|x| !x.is_finite()) {
            return self.refuse(
                Status::Error,
                format!(
                    "{}: a sensitivity is {x}: the seed times the partial derivatives \
                     overflows; scale the seed down",
                    call.name()
                ),
            );
        }
        sensitivity.copy_from_slice(&result);
        Ok(())
    }

    /// `fmi3GetOutputDerivatives`: the derivatives of order `orders[i]` of every element
    /// of the output `vrs[i]`.
    pub fn output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        out: &mut [f64],
    ) -> FmiResult {
        let call = Call3::GetOutputDerivatives;
        self.check(call)?;
        let e = self.elements(call, vrs, &[Type3::Float64], out.len())?;
        let orders: Vec<i32> = self.expand_per_element(vrs, orders);
        fmi3(
            self.table,
            &self.running,
            self.inner.get_real_output_derivatives(&e, &orders, out),
        )
    }

    /// `per_variable[i]` repeated for each element in use of the variable `vrs[i]`.
    fn expand_per_element<T: Copy>(&self, vrs: &[u32], per_variable: &[T]) -> Vec<T> {
        let n = self.wheelsets();
        let mut out = Vec::new();
        for (&r, &x) in vrs.iter().zip(per_variable) {
            let k = (self.slot.get(r as usize).copied().flatten())
                .map_or(1, |i| Self::in_use(&self.table.vars[i as usize], n));
            out.extend(std::iter::repeat_n(x, k));
        }
        out
    }

    /// How many of the variable `v`'s values there are with `n` wheelsets: an array's
    /// elements in use, one for a scalar.
    fn in_use(v: &Var3Spec, n: usize) -> usize {
        if v.array { n.min(v.elements.len()) } else { 1 }
    }
}
