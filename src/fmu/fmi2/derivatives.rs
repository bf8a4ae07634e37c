//! Input and output derivatives and directional derivatives (FMI 2.0, sections
//! 4.2.1 and 2.1.9): `fmi2SetRealInputDerivatives`, `fmi2GetRealOutputDerivatives` and
//! `fmi2GetDirectionalDerivative`, each refused where the FMU does not declare the
//! capability, and for value references that are not the FMU's Real inputs or outputs.

use super::calls::Call;
use super::instance::Instance;
use super::model::Model;
use super::status::{FmiResult, Status};
use crate::fmu::vars::{Causality, VarType};

impl<M: Model> Instance<M> {
    /// The variable `vr` when it is one of this FMU's Real variables of causality
    /// `causality`; a refusal naming it otherwise.
    fn real_of(&mut self, call: Call, vr: u32, causality: Causality) -> FmiResult<()> {
        let spec = self
            .slot
            .get(vr as usize)
            .copied()
            .flatten()
            .map(|i| &self.table.vars[i]);
        match spec {
            Some(s) if s.causality == causality && s.ty == VarType::Real => Ok(()),
            Some(s) => self.refuse(
                Status::Error,
                format!(
                    "{}: `{}` (value reference {vr}) is not a Real {} of {}",
                    call.name(),
                    s.name,
                    if causality == Causality::Input {
                        "input"
                    } else {
                        "output"
                    },
                    self.table.model_identifier
                ),
            ),
            None => self.refuse(
                Status::Error,
                format!(
                    "{}: value reference {vr} is not a variable of {}",
                    call.name(),
                    self.table.model_identifier
                ),
            ),
        }
    }

    /// The state table's check of a derivative function `call`, then whether this FMU
    /// declares it: the C boundary asks this before it reads the arguments.
    pub fn check_declared(&mut self, call: Call) -> FmiResult {
        self.check(call)?;
        match call {
            Call::SetRealInputDerivatives if !self.table.can_interpolate_inputs => self
                .not_declared(
                    call,
                    "canInterpolateInputs is false; inputs are held over a step",
                ),
            Call::GetRealOutputDerivatives if self.table.max_output_derivative_order == 0 => {
                self.not_declared(call, "maxOutputDerivativeOrder is 0")
            }
            Call::GetDirectionalDerivative if !self.table.provides_directional_derivative => {
                self.not_declared(call, "providesDirectionalDerivative is false")
            }
            _ => Ok(()),
        }
    }

    /// A refusal of `call`, which this FMU does not declare (`what`).
    fn not_declared(&mut self, call: Call, what: &str) -> FmiResult {
        self.refuse(
            Status::Error,
            format!(
                "{} is not supported by {}: {what}",
                call.name(),
                self.table.model_identifier
            ),
        )
    }

    /// `fmi2SetRealInputDerivatives`: the derivatives `values` of orders `orders` of the
    /// inputs `vrs` at the current communication point; they shape the inputs over the
    /// following steps until an input is set again at a later point. All or none are
    /// taken. In initialization mode the model is built first (as a read builds it), so
    /// they are checked at once; a parameter set later rebuilds the model with them.
    pub fn set_real_input_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        values: &[f64],
    ) -> FmiResult {
        let call = Call::SetRealInputDerivatives;
        self.check_declared(call)?;
        for &r in vrs {
            self.real_of(call, r, Causality::Input)?;
        }
        if let Some(&o) = orders.iter().find(|&&o| o < 1) {
            return self.refuse(
                Status::Error,
                format!("{}: order {o}; allowed: 1 or more", call.name()),
            );
        }
        self.ensure_model()?;
        let saved = self.model.clone();
        for ((&r, &o), &x) in vrs.iter().zip(orders).zip(values) {
            let result = match &mut self.model {
                Some(m) => m.set_input_derivative(r, o, x),
                None => Ok(()),
            };
            if let Err(e) = result {
                self.model = saved;
                return self.model_refusal("input derivatives refused", e);
            }
        }
        Ok(())
    }

    /// `fmi2GetRealOutputDerivatives`: the derivatives of orders `orders` (1 up to
    /// `maxOutputDerivativeOrder`) of the outputs `vrs` at the current time.
    pub fn get_real_output_derivatives(
        &mut self,
        vrs: &[u32],
        orders: &[i32],
        out: &mut [f64],
    ) -> FmiResult {
        let call = Call::GetRealOutputDerivatives;
        self.check_declared(call)?;
        let max = self.table.max_output_derivative_order;
        for (&r, &o) in vrs.iter().zip(orders) {
            self.real_of(call, r, Causality::Output)?;
            if o < 1 || o as u32 > max {
                return self.refuse(
                    Status::Error,
                    format!(
                        "{}: order {o}; allowed: 1 to {max} (maxOutputDerivativeOrder)",
                        call.name()
                    ),
                );
            }
        }
        self.outputs_available(call.name())?;
        let Some(m) = &self.model else {
            return self.refuse(Status::Error, format!("{}: no model", call.name()));
        };
        let got: Result<Vec<f64>, _> = vrs
            .iter()
            .zip(orders)
            .map(|(&r, &o)| m.output_derivative(r, o))
            .collect();
        match got {
            Ok(v) => {
                out[..v.len()].copy_from_slice(&v);
                Ok(())
            }
            Err(e) => self.model_refusal("output derivatives", e),
        }
    }

    /// `fmi2GetDirectionalDerivative`: `sensitivity = J seed`, `J` the partial
    /// derivatives of the outputs `unknowns` with respect to the inputs `knowns` at the
    /// current state.
    pub fn get_directional_derivative(
        &mut self,
        unknowns: &[u32],
        knowns: &[u32],
        seed: &[f64],
        sensitivity: &mut [f64],
    ) -> FmiResult {
        let call = Call::GetDirectionalDerivative;
        self.check_declared(call)?;
        for &r in unknowns {
            self.real_of(call, r, Causality::Output)?;
        }
        for &r in knowns {
            self.real_of(call, r, Causality::Input)?;
        }
        if let Some((_, &x)) = knowns.iter().zip(seed).find(|(_, x)| !x.is_finite()) {
            return self.refuse(
                Status::Error,
                format!("{}: seed value {x}; allowed: finite", call.name()),
            );
        }
        self.ensure_model()?;
        let Some(m) = &self.model else {
            return self.refuse(Status::Error, format!("{}: no model", call.name()));
        };
        let mut result = vec![0.0; unknowns.len()];
        for (s, &u) in result.iter_mut().zip(unknowns) {
            for (&k, &x) in knowns.iter().zip(seed) {
                match m.partial_derivative(u, k) {
                    Ok(d) => *s += d * x,
                    Err(e) => return self.model_refusal("directional derivative", e),
                }
            }
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
        sensitivity[..result.len()].copy_from_slice(&result);
        Ok(())
    }
}
