//! FMU states (FMI 2.0, section 2.1.8): saved, restored, serialized and deserialized.
//! A serialized state holds the parameters, so it restores into a fresh instance: the
//! model is rebuilt from them and its dynamic state put back. A String parameter is
//! held with its content (a table file's text, as read when it was set): a state
//! restored or deserialized anywhere, after its file changed or where no file is,
//! continues the run it was taken from. The content is carried, not its hash, so that
//! a state moves to another process or machine (a cluster's worker) and restores there
//! without the file; tables are small next to the track's state (a 1,000-point profile
//! is about 20 kB).

use super::calls::{Call, Phase};
use super::instance::Instance;
use super::model::Model;
use super::status::{FmiResult, Status};
use crate::fmu::vars::{Causality, FmuTable, N_VR, VarType};
use std::sync::Arc;

/// Everything an FMU state holds: enough to continue bit-identically.
#[derive(Debug, Clone)]
pub struct Snapshot<M> {
    table: &'static FmuTable,
    phase: Phase,
    values: Vec<f64>,
    /// The String parameters, by value reference.
    strings: Vec<String>,
    /// Their contents ([`Model::read_string`]).
    contents: Vec<Arc<str>>,
    model: Option<M>,
    calculated: Vec<f64>,
    time: f64,
    start_time: f64,
    ended: bool,
    /// Why the run had stopped (phase `Error` after a value beyond the health bounds).
    failed: Option<String>,
}

/// The start of every serialized state.
pub(crate) const MAGIC: &[u8] = b"wheelflat-fmu-state-4\0";

impl<M: Model> Instance<M> {
    /// `fmi2GetFMUstate`.
    pub fn get_state(&mut self) -> FmiResult<Snapshot<M>> {
        let t = self.time;
        self.log_event(|| format!("state saved at t = {t} s"));
        Ok(Snapshot {
            table: self.table,
            phase: self.phase,
            values: self.values.clone(),
            strings: self.strings.clone(),
            contents: self.contents.clone(),
            model: self.model.clone(),
            calculated: self.calculated.clone(),
            time: self.time,
            start_time: self.start_time,
            ended: self.ended,
            failed: self.failed.clone(),
        })
    }

    /// `fmi2SetFMUstate`.
    pub fn set_state(&mut self, s: &Snapshot<M>) -> FmiResult {
        if !std::ptr::eq(s.table, self.table) {
            return self.refuse(
                Status::Error,
                format!(
                    "fmi2SetFMUstate: the state belongs to {}, this instance is {}",
                    s.table.model_identifier, self.table.model_identifier
                ),
            );
        }
        self.phase = s.phase;
        self.values.clone_from(&s.values);
        self.strings.clone_from(&s.strings);
        self.contents.clone_from(&s.contents);
        self.model.clone_from(&s.model);
        self.dirty = self.model.is_none();
        self.calculated.clone_from(&s.calculated);
        self.time = s.time;
        self.start_time = s.start_time;
        self.ended = s.ended;
        self.failed.clone_from(&s.failed);
        let t = self.time;
        self.log_event(|| format!("state restored at t = {t} s"));
        Ok(())
    }

    /// `fmi2SerializeFMUstate`: magic, GUID, phase, clock, reason of a stopped run,
    /// calculated parameters, values, the String parameters that are set (value
    /// reference, length, UTF-8 bytes, then the same of their content), model state.
    pub fn serialize(&mut self, s: &Snapshot<M>) -> FmiResult<Vec<u8>> {
        let model = match s.model.as_ref().map(M::state_vector) {
            None => Vec::new(),
            Some(Ok(v)) => v,
            Some(Err(e)) => return self.model_refusal(Call::SerializeFMUstate.name(), e),
        };
        let mut b = Vec::new();
        b.extend_from_slice(MAGIC);
        let guid = s.table.guid.as_bytes();
        b.extend_from_slice(&(guid.len() as u64).to_le_bytes());
        b.extend_from_slice(guid);
        b.push(s.phase as u8);
        b.push(s.ended as u8);
        b.push(s.model.is_some() as u8);
        b.extend_from_slice(&s.time.to_le_bytes());
        b.extend_from_slice(&s.start_time.to_le_bytes());
        let failed = s.failed.as_deref().unwrap_or("").as_bytes();
        b.extend_from_slice(&(failed.len() as u64).to_le_bytes());
        b.extend_from_slice(failed);
        for x in &s.calculated {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b.extend_from_slice(&(s.values.len() as u64).to_le_bytes());
        for x in &s.values {
            b.extend_from_slice(&x.to_le_bytes());
        }
        let set: Vec<(usize, &String)> = s
            .strings
            .iter()
            .enumerate()
            .filter(|(_, t)| !t.is_empty())
            .collect();
        b.extend_from_slice(&(set.len() as u64).to_le_bytes());
        for (r, t) in set {
            b.extend_from_slice(&(r as u64).to_le_bytes());
            for t in [t.as_bytes(), s.contents[r].as_bytes()] {
                b.extend_from_slice(&(t.len() as u64).to_le_bytes());
                b.extend_from_slice(t);
            }
        }
        b.extend_from_slice(&(model.len() as u64).to_le_bytes());
        for x in &model {
            b.extend_from_slice(&x.to_le_bytes());
        }
        Ok(b)
    }

    /// `fmi2DeSerializeFMUstate`: rebuilds the model from the stored parameters, then
    /// puts the stored dynamic state into it.
    pub fn deserialize(&mut self, bytes: &[u8]) -> FmiResult<Snapshot<M>> {
        match self.decode(bytes) {
            Ok(s) => Ok(s),
            Err(m) => self.refuse(Status::Error, format!("fmi2DeSerializeFMUstate: {m}")),
        }
    }

    /// The numbers of a serialized state are what an instance can hold: a finite clock
    /// from 0 on, finite calculated values and model state, parameters and inputs
    /// inside their ranges (as fmi2SetReal would take them).
    fn check_stored(
        &self,
        (time, start_time): (f64, f64),
        calculated: &[f64],
        values: &[f64],
        state: &[f64],
    ) -> Result<(), String> {
        if !(time.is_finite() && start_time.is_finite() && time >= start_time) {
            return Err(format!(
                "stored time {time} s and start time {start_time} s are not finite with the \
                 time at or after the start"
            ));
        }
        if let Some(x) = calculated.iter().find(|x| !x.is_finite()) {
            return Err(format!("a stored calculated parameter is {x}"));
        }
        for v in self.table.vars {
            let x = values[v.vr as usize];
            // A String parameter's value is its text, stored apart (NaN here).
            let known = matches!(v.causality, Causality::Parameter | Causality::Input)
                && v.ty != VarType::String;
            if known && !(x.is_finite() && x >= v.min && x <= v.max) {
                return Err(format!(
                    "stored `{}` = {x} is out of range (finite, {} to {})",
                    v.name, v.min, v.max
                ));
            }
            // An Integer or an enumeration's code holds a whole number.
            if known && v.ty != VarType::Real && x.fract() != 0.0 {
                return Err(format!(
                    "stored `{}` = {x} is not a whole number (an {})",
                    v.name,
                    if v.ty == VarType::Integer {
                        "Integer"
                    } else {
                        "enumeration's code"
                    }
                ));
            }
        }
        if let Some(k) = state.iter().position(|x| !x.is_finite()) {
            return Err(format!("model state [{k}] = {} is not finite", state[k]));
        }
        Ok(())
    }

    fn decode(&mut self, bytes: &[u8]) -> Result<Snapshot<M>, String> {
        let mut r = Cursor { b: bytes, at: 0 };
        if r.take(MAGIC.len())? != MAGIC {
            return Err("not a wheelflat FMU state (bad magic)".into());
        }
        let n = r.u64()? as usize;
        let guid = r.take(n)?;
        if guid != self.table.guid.as_bytes() {
            return Err(format!(
                "the state was written by another FMU (GUID {}), not {} {}",
                String::from_utf8_lossy(guid),
                self.table.model_identifier,
                self.table.guid
            ));
        }
        let p = r.take(1)?[0];
        let phase = Phase::from_u8(p).ok_or_else(|| format!("bad phase {p}"))?;
        let ended = r.take(1)?[0] != 0;
        let has_model = r.take(1)?[0] != 0;
        // Stepping phases always have a model (only fmi2Reset and an internal error drop
        // it), and none has been built before initialisation.
        match (phase, has_model) {
            (Phase::StepComplete | Phase::StepFailed | Phase::Terminated, false) => {
                return Err(format!("a state in phase {phase:?} without a model"));
            }
            (Phase::Instantiated, true) => {
                return Err("a state in phase Instantiated with a model".into());
            }
            _ => {}
        }
        let time = r.f64()?;
        let start_time = r.f64()?;
        let n = r.u64()? as usize;
        let failed = std::str::from_utf8(r.take(n)?)
            .map_err(|_| "the stored reason for a stopped run is not UTF-8".to_string())?;
        let failed = (!failed.is_empty()).then(|| failed.to_string());
        if (phase == Phase::Error) != failed.is_some() {
            return Err("a stopped run's state without its reason, or the reverse".into());
        }
        let mut calculated = vec![0.0; M::CALCULATED];
        for x in &mut calculated {
            *x = r.f64()?;
        }
        let nv = r.u64()? as usize;
        if nv != N_VR {
            return Err(format!("{nv} values; this FMU has {N_VR}"));
        }
        let mut values = Vec::with_capacity(nv);
        for _ in 0..nv {
            values.push(r.f64()?);
        }
        let mut strings = vec![String::new(); N_VR];
        let mut contents: Vec<Arc<str>> = vec![Arc::from(""); N_VR];
        let ns = r.u64()? as usize;
        if ns > N_VR {
            return Err(format!("{ns} String values; this FMU has at most {N_VR}"));
        }
        for _ in 0..ns {
            let vr = r.u64()? as usize;
            let is_string = self
                .slot
                .get(vr)
                .copied()
                .flatten()
                .is_some_and(|i| self.table.vars[i].ty == VarType::String);
            if !is_string {
                return Err(format!(
                    "stored value reference {vr} is no String parameter"
                ));
            }
            let mut text = || -> Result<&str, String> {
                let len = r.u64()? as usize;
                std::str::from_utf8(r.take(len)?)
                    .map_err(|_| format!("stored String value of reference {vr} is not UTF-8"))
            };
            strings[vr] = text()?.to_string();
            contents[vr] = Arc::from(text()?);
        }
        let nm = r.u64()? as usize;
        if nm > bytes.len() / 8 {
            return Err(format!("model state length {nm} exceeds the data"));
        }
        let mut state = Vec::with_capacity(nm);
        for _ in 0..nm {
            state.push(r.f64()?);
        }
        // A buffer larger than the state (legal in fmi2SerializeFMUstate) is padded with
        // zeros there; anything else after the state is damage.
        if bytes[r.at..].iter().any(|&b| b != 0) {
            return Err(format!(
                "{} trailing bytes after the state that are not the zero padding of a larger \
                 buffer",
                bytes.len() - r.at
            ));
        }
        // A stopped run's model state is beyond the health bounds by definition, and
        // nothing can be read from it or stepped: it is restored as the stopped run
        // without a model (fmi2Reset or another state goes on from there).
        let stopped = phase == Phase::Error;
        let state = if stopped { Vec::new() } else { state };
        self.check_stored((time, start_time), &calculated, &values, &state)?;
        let model = if has_model && !stopped {
            // Build with the stored parameters, then overwrite the dynamic state.
            let mut m = M::build(self.table, &values, &contents)
                .map_err(|e| format!("stored parameters refused: {e}"))?;
            let again = m.calculated();
            if let Some(k) =
                (0..M::CALCULATED).find(|&k| again[k].to_bits() != calculated[k].to_bits())
            {
                return Err(format!(
                    "stored calculated parameter {k} = {} disagrees with the {} the stored \
                     parameters give",
                    calculated[k], again[k]
                ));
            }
            m.set_state_vector(&state).map_err(|e| e.to_string())?;
            // The model's clock must be the stored communication time's.
            let (model_time, slack) = m.model_time();
            let off = (start_time + model_time - time).abs();
            if off.is_nan() || off > slack + 1e-9 * (1.0 + time.abs()) {
                return Err(format!(
                    "stored time {time} s disagrees with the model's clock {} s",
                    start_time + model_time
                ));
            }
            Some(m)
        } else {
            None
        };
        Ok(Snapshot {
            table: self.table,
            phase,
            values,
            strings,
            contents,
            model,
            calculated,
            time,
            start_time,
            ended,
            failed,
        })
    }
}

/// Reads a serialized state front to back, refusing to read past its end.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

impl<'a> Cursor<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        if n > self.b.len() - self.at {
            return Err(format!(
                "truncated at byte {} ({n} bytes announced, {} left)",
                self.at,
                self.b.len() - self.at
            ));
        }
        let s = &self.b[self.at..self.at + n];
        self.at += n;
        Ok(s)
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(self.take(8)?.try_into().unwrap()))
    }
}
