//! Value access through the variable table: every reference, type, causality, phase
//! and range is checked against the FMU's table before anything is read or stored.

use super::calls::{Call, Phase};
use super::instance::Instance;
use super::model::Model;
use super::status::{FmiResult, Status};
use crate::error::num;
use crate::fmu::vars::{Causality, VarSpec, VarType};

impl<M: Model> Instance<M> {
    fn spec(&mut self, call: &str, r: u32) -> FmiResult<&'static VarSpec> {
        match self.slot.get(r as usize).copied().flatten() {
            Some(i) => Ok(&self.table.vars[i]),
            None => self.refuse(
                Status::Error,
                format!(
                    "{call}: unknown value reference {r} for {}",
                    self.table.model_identifier
                ),
            ),
        }
    }

    /// The spec of a value reference already checked by [`Instance::spec`].
    fn known_spec(&self, r: u32) -> &'static VarSpec {
        &self.table.vars[self.slot[r as usize].unwrap_or_default()]
    }

    #[inline(always)]
    fn check_type(&mut self, call: &str, s: &VarSpec, real: bool) -> FmiResult {
        let fits = match s.ty {
            VarType::Real => real,
            VarType::Integer | VarType::Enumeration => !real,
            VarType::String => false,
        };
        if fits {
            Ok(())
        } else {
            self.wrong_type(call, s)
        }
    }

    #[cold]
    #[inline(never)]
    fn wrong_type(&mut self, call: &str, s: &VarSpec) -> FmiResult {
        self.refuse(
            Status::Error,
            format!(
                "{call}: variable `{}` (value reference {}) is of type {}",
                s.name,
                s.vr,
                match s.ty {
                    VarType::Real => "Real",
                    // Written as Integer in the model descriptions.
                    VarType::Integer | VarType::Enumeration => "Integer",
                    VarType::String => "String",
                }
            ),
        )
    }

    /// Reads variables into `out` (Real or Integer/Enumeration by `real`). Outputs and
    /// calculated parameters come from the model, checked: a non-finite value stops the
    /// run, and so does a value the model's [`Model::check_output`] refuses with
    /// `stops_run`.
    /// Refuses outputs (values or derivatives, for `call`) after the run stopped: an
    /// internal error, or a value beyond the health bounds.
    pub(super) fn outputs_available(&mut self, call: &str) -> FmiResult {
        if self.phase == Phase::Error && self.failed.is_none() {
            return self.refuse(
                Status::Error,
                format!(
                    "{call}: no outputs: an internal error stopped the instance; call fmi2Reset"
                ),
            );
        }
        if let Some(why) = &self.failed {
            let m = format!(
                "{call}: no outputs: the run stopped at t = {} s ({why}); call fmi2Reset or \
                 fmi2SetFMUstate",
                self.time
            );
            return self.refuse(Status::Error, m);
        }
        Ok(())
    }

    fn get(&mut self, call: Call, vrs: &[u32], out: &mut [f64], real: bool) -> FmiResult {
        self.check(call)?;
        let call = call.name();
        let mut needs_model = false;
        for &r in vrs {
            let s = self.spec(call, r)?;
            self.check_type(call, s, real)?;
            needs_model |= matches!(
                s.causality,
                Causality::Output | Causality::CalculatedParameter
            );
        }
        if needs_model {
            self.outputs_available(call)?;
            self.ensure_model()?;
        }
        let outputs = match &self.model {
            Some(m) if needs_model => Some(m.outputs()),
            _ => None,
        };
        for (o, &r) in out.iter_mut().zip(vrs) {
            let s = self.known_spec(r);
            let computed = !matches!(s.causality, Causality::Parameter | Causality::Input);
            let model = self.model.as_ref().filter(|_| computed);
            *o = match (model, &outputs) {
                (Some(m), Some(x)) => m.output(x, s.vr),
                _ if computed => f64::NAN,
                _ => self.values[s.vr as usize],
            };
            if !o.is_finite() {
                let (name, x) = (s.name, *o);
                let why = format!("`{name}` = {x} at t = {} s is not finite", self.time);
                self.failed = Some(why.clone());
                self.phase = Phase::Error;
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: {why}; the run cannot go on: call fmi2Reset or fmi2SetFMUstate"
                    ),
                );
            }
            let Some(m) = model else { continue };
            if let Err(f) = m.check_output(s, *o, self.time) {
                if f.stops_run {
                    self.failed = Some(f.message.clone());
                    self.phase = Phase::Error;
                }
                return self.refuse(Status::Error, format!("{call}: {}", f.message));
            }
        }
        Ok(())
    }

    /// Why input `s` is not used in the FMU's configuration (its table's `usedWhen`
    /// does not hold), in words; `None` when it is used.
    pub(super) fn unused_input(&self, s: &VarSpec) -> Option<String> {
        let w = s.used_when?;
        let now = self.values[w.selector as usize];
        (now != w.value).then(|| {
            let selector = self
                .table
                .vars
                .iter()
                .find(|v| v.vr == w.selector)
                .map_or("the selector", |v| v.name);
            format!(
                "`{}` is an input of {} only, but {selector} = {} here ({}), where it \
                 would be ignored: connect the inputs of the {selector} in use, or set \
                 {selector} to match the coupling",
                s.name,
                w.text,
                num(now),
                w.items
            )
        })
    }

    /// Whether `x` written to reference `r` (by `real`: a Real) is an input of the
    /// configuration not in use at its declared start value, after initialisation: a
    /// master that writes every input's start (fmpy's `apply_start_values`, an SSP's
    /// connectors) changes nothing by it, and it is passed over (issue 38, N7).
    fn unused_at_start(&self, r: u32, x: f64, real: bool) -> bool {
        let Some(s) = (self.slot.get(r as usize).copied().flatten()).map(|i| &self.table.vars[i])
        else {
            return false;
        };
        s.causality == Causality::Input
            && (s.ty == VarType::Real) == real
            && s.ty != VarType::String
            && x == s.start
            && !matches!(self.phase, Phase::Instantiated | Phase::Initialization)
            && self.unused_input(s).is_some()
    }

    /// Writes variables (Real or Integer/Enumeration by `real`): every value is checked
    /// before any is stored, so a refused call changes nothing. An input of the
    /// configuration not in use, written at its start value, is passed over
    /// ([`Instance::unused_at_start`]).
    fn set(&mut self, call: Call, vrs: &[u32], vals: &[f64], real: bool) -> FmiResult {
        self.check(call)?;
        if (vrs.iter().zip(vals)).any(|(&r, &x)| self.unused_at_start(r, x, real)) {
            let (vrs, vals): (Vec<u32>, Vec<f64>) = (vrs.iter().zip(vals))
                .filter(|&(&r, &x)| !self.unused_at_start(r, x, real))
                .unzip();
            return self.set(call, &vrs, &vals, real);
        }
        let call = call.name();
        let (mut inputs, mut parameters) = (false, false);
        for (&r, &x) in vrs.iter().zip(vals) {
            let s = self.spec(call, r)?;
            self.check_type(call, s, real)?;
            match s.causality {
                Causality::Parameter => parameters = true,
                _ => inputs = true,
            }
            let settable = matches!(
                (s.causality, self.phase),
                (Causality::Input, _)
                    | (
                        Causality::Parameter,
                        Phase::Instantiated | Phase::Initialization
                    )
            );
            if !settable {
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: variable `{}` ({:?}) cannot be set in state {:?}{}",
                        s.name,
                        s.causality,
                        self.phase,
                        if s.causality == Causality::Parameter {
                            "; parameters are fixed after initialisation (use fmi2Reset)"
                        } else {
                            ""
                        }
                    ),
                );
            }
            // An input of another configuration: refused once the configuration is
            // fixed (after initialisation); before, the selector may still change, and
            // fmi2ExitInitializationMode checks what was set.
            if !matches!(self.phase, Phase::Instantiated | Phase::Initialization)
                && let Some(why) = self.unused_input(s)
            {
                return self.refuse(Status::Error, format!("{call}: {why}"));
            }
            if !x.is_finite() || x < s.min || x > s.max {
                let unit = if s.unit.is_empty() {
                    String::new()
                } else {
                    format!(" {}", s.unit)
                };
                return self.refuse(
                    Status::Error,
                    format!(
                        "{call}: `{}` = {}{unit} is out of range; allowed: finite, {} <= {} <= {}{unit}",
                        s.name,
                        num(x),
                        num(s.min),
                        s.name,
                        num(s.max)
                    ),
                );
            }
            if s.causality == Causality::Parameter
                && let Err(e) = M::check_real(s, x)
            {
                return self.refuse(Status::Error, format!("{call}: {e}"));
            }
        }
        // A set call that changed a parameter rebuilds the model (with every input)
        // before it is next used; otherwise every reference of the call is an input,
        // and the model takes them all or none (the values it refused are restored).
        let sync = inputs && self.model.is_some() && !self.dirty && !parameters;
        let mut kept = [0.0; 8];
        let kept_many: Vec<f64>;
        let before: &[f64] = if !sync {
            &[]
        } else if vrs.len() <= kept.len() {
            for (k, &r) in kept.iter_mut().zip(vrs) {
                *k = self.values[r as usize];
            }
            &kept[..vrs.len()]
        } else {
            kept_many = vrs.iter().map(|&r| self.values[r as usize]).collect();
            &kept_many
        };
        for (&r, &x) in vrs.iter().zip(vals) {
            self.values[r as usize] = x;
        }
        if inputs && !parameters {
            for &r in vrs {
                self.given[r as usize] = true;
            }
        } else if inputs {
            for &r in vrs {
                if let Some(i) = self.slot[r as usize]
                    && self.table.vars[i].causality == Causality::Input
                {
                    self.given[r as usize] = true;
                }
            }
        }
        self.dirty |= parameters;
        if sync && let Err(e) = self.sync_inputs(vrs) {
            for (&r, &x) in vrs.iter().zip(before) {
                self.values[r as usize] = x;
            }
            return Err(e);
        }
        Ok(())
    }

    /// `fmi2GetReal`.
    pub fn get_real(&mut self, vrs: &[u32], out: &mut [f64]) -> FmiResult {
        self.get(Call::GetReal, vrs, out, true)
    }

    /// `fmi2GetInteger` (integers and enumerations).
    pub fn get_integer(&mut self, vrs: &[u32], out: &mut [i32]) -> FmiResult {
        let mut tmp = vec![0.0; vrs.len()];
        self.get(Call::GetInteger, vrs, &mut tmp, false)?;
        for (o, t) in out.iter_mut().zip(tmp) {
            *o = t as i32;
        }
        Ok(())
    }

    /// `fmi2SetReal`.
    pub fn set_real(&mut self, vrs: &[u32], vals: &[f64]) -> FmiResult {
        self.set(Call::SetReal, vrs, vals, true)
    }

    /// `fmi2SetInteger` (integers and enumerations).
    pub fn set_integer(&mut self, vrs: &[u32], vals: &[i32]) -> FmiResult {
        let tmp: Vec<f64> = vals.iter().map(|&x| x as f64).collect();
        self.set(Call::SetInteger, vrs, &tmp, false)
    }

    /// Boolean and String access for an FMU without such variables: any value
    /// reference is unknown (an empty request succeeds).
    /// `fmi2SetString`: String parameters, in the phases parameters are set; each
    /// value read and checked by the model ([`Model::read_string`]) before any is
    /// stored; the instance keeps what was set and its content (a file's text, read
    /// once here: setting the same path again reads the file again).
    pub fn set_string(&mut self, vrs: &[u32], vals: &[String]) -> FmiResult {
        let call = Call::SetString;
        self.check(call)?;
        let name = call.name();
        let mut contents = Vec::with_capacity(vrs.len());
        for (&r, v) in vrs.iter().zip(vals) {
            let s = self.string_spec(name, r)?;
            if !matches!(self.phase, Phase::Instantiated | Phase::Initialization) {
                return self.refuse(
                    Status::Error,
                    format!(
                        "{name}: variable `{}` (Parameter) cannot be set in state {:?}; \
                         parameters are fixed after initialisation (use fmi2Reset)",
                        s.name, self.phase
                    ),
                );
            }
            match M::read_string(s, v) {
                Ok(c) => contents.push(c),
                Err(e) => return self.refuse(Status::Error, format!("{name}: {e}")),
            }
        }
        for ((&r, v), c) in vrs.iter().zip(vals).zip(contents) {
            self.log_call(|| {
                format!(
                    "{name}(vr={r}, value={:?})",
                    v.chars().take(200).collect::<String>()
                )
            });
            if self.strings[r as usize] != *v || self.contents[r as usize] != c {
                self.strings[r as usize] = v.clone();
                self.contents[r as usize] = c;
                self.dirty = true;
            }
        }
        Ok(())
    }

    /// The spec of String variable `r`; another type is refused.
    fn string_spec(&mut self, call: &str, r: u32) -> FmiResult<&'static VarSpec> {
        let s = self.spec(call, r)?;
        if s.ty != VarType::String {
            return self.refuse(
                Status::Error,
                format!(
                    "{call}: variable `{}` (value reference {}) is not of type String",
                    s.name, s.vr
                ),
            );
        }
        Ok(s)
    }

    /// `fmi2GetString`: the String parameters' values.
    pub fn get_string(&mut self, vrs: &[u32]) -> FmiResult<Vec<String>> {
        let call = Call::GetString;
        self.check(call)?;
        let name = call.name();
        let mut out = Vec::with_capacity(vrs.len());
        for &r in vrs {
            self.string_spec(name, r)?;
            out.push(self.strings[r as usize].clone());
        }
        Ok(out)
    }

    pub fn no_such_type(&mut self, call: &str, vrs: &[u32]) -> FmiResult {
        match vrs.first() {
            None => Ok(()),
            Some(r) => self.refuse(
                Status::Error,
                format!(
                    "{call}: unknown value reference {r}: {} has no variables of this type",
                    self.table.model_identifier
                ),
            ),
        }
    }
}
