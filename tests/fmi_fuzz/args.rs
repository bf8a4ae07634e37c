//! The arguments of the calls: sensible values near the start values and inside the
//! ranges, and garbage (values that break things, foreign value references, booleans
//! other than 0 and 1, state pointers that are not the instance's, corrupted
//! serialized states). Values, step sizes, state pointers and serialized states serve
//! both FMI versions; FMI 3.0's value references and counts are [`crate::fmi3_args`].

use crate::world::World;
use crate::{Fault, avoided};
use rand::Rng;
use rand::rngs::StdRng;
use std::ffi::c_int;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{Causality, FMUS, FmuTable, N_VR, VarSpec, VarType};

/// Values that break things.
pub const NASTY: [f64; 16] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    1e-300,
    1e-12,
    -1.0,
    1.0,
    1e9,
    1e300,
    -1e300,
    f64::MAX,
    f64::MIN,
];

pub fn nasty(rng: &mut StdRng) -> f64 {
    NASTY[rng.random_range(0..NASTY.len())]
}

/// Whether a value for variable `v` hits a known engine fault.
pub fn faulty_value(v: &VarSpec, x: f64) -> bool {
    if v.causality != Causality::Parameter || !x.is_finite() || x < v.min || x > v.max {
        // Refused by the range check anyway.
        return false;
    }
    if v.name == "solver.dt" {
        return x != 0.0 && x < 1e-9 && avoided(Fault::TinySolverDt);
    }
    if !avoided(Fault::ExtremeParameters) {
        return false;
    }
    match v.name {
        "track.spans" => x > 200.0,
        "track.nodes_per_span" => x > 40.0,
        // Far from the start value: masses, stiffnesses, lengths scaled by more than
        // 1e3 either way (or subnormal/huge where the start value is 0).
        _ if v.start != 0.0 => x != 0.0 && !(1e-3..=1e3).contains(&(x / v.start).abs()),
        _ => x != 0.0 && !(1e-30..=1e3).contains(&x.abs()),
    }
}

/// A value for `v`: sensible (near the start value, inside the range) or nasty.
pub fn value_for(rng: &mut StdRng, v: Option<&VarSpec>, valid: bool) -> f64 {
    let Some(v) = v else {
        return if valid { 0.0 } else { nasty(rng) };
    };
    for _ in 0..20 {
        let x = match rng.random_range(0..if valid { 6 } else { 10 }) {
            0..=5 => {
                let f = if rng.random_bool(0.5) {
                    1.0
                } else {
                    rng.random_range(0.8..1.25)
                };
                let base = if v.start.is_finite() && v.start != 0.0 {
                    v.start
                } else if v.max.is_finite() && v.min.is_finite() {
                    rng.random_range(v.min..=v.max)
                } else {
                    0.0
                };
                let x = (base * f).clamp(v.min, v.max);
                if v.ty == VarType::Real { x } else { x.round() }
            }
            6 => v.min,
            7 => v.max,
            8 if v.name == "solver.dt" => [1e-12, 1e-9, 1e-6, 1e-5, 2e-5][rng.random_range(0..5)],
            _ => nasty(rng),
        };
        if !faulty_value(v, x) {
            return x;
        }
    }
    v.start
}

/// A communication step size.
pub fn step_size(rng: &mut StdRng, valid: bool) -> f64 {
    loop {
        let h = match rng.random_range(0..if valid { 11 } else { 20 }) {
            0..=7 => 10f64.powf(rng.random_range(-6.0..-3.0)),
            8..=10 => 2e-5,
            11 => 10f64.powf(rng.random_range(-3.0..-1.3)),
            12 => 0.0,
            13 => -rng.random_range(1e-6..1e-3),
            14 => 5e-324,
            15 => 1e9,
            16 => 0.1,
            _ => nasty(rng),
        };
        let subnormal = h > 0.0 && h < 1e-300;
        if subnormal && avoided(Fault::SubnormalStep) {
            continue;
        }
        if h >= 1e3 && h.is_finite() && avoided(Fault::HugeStep) {
            continue;
        }
        return h;
    }
}

pub fn boolean(rng: &mut StdRng, valid: bool) -> c_int {
    if valid {
        return rng.random_range(0..2);
    }
    match rng.random_range(0..20) {
        0 => 2,
        1 => -1,
        2 => c_int::MAX,
        k => (k % 2) as c_int,
    }
}

/// Value references: mostly this FMU's (of any type), some of the others or outside
/// the table.
pub fn refs(rng: &mut StdRng, table: &FmuTable, want: Option<VarType>, valid: bool) -> Vec<u32> {
    let n = match rng.random_range(0..10) {
        0 if !valid => 0,
        0..=6 => 1,
        _ => rng.random_range(2..8),
    };
    (0..n)
        .map(|_| match rng.random_range(if valid { 3 } else { 0 }..20) {
            0 => N_VR as u32 + rng.random_range(0..5),
            1 => u32::MAX,
            2 => rng.random_range(0..N_VR as u32),
            _ => {
                let pool: Vec<&VarSpec> = table
                    .vars
                    .iter()
                    .filter(|v| {
                        want.is_none_or(|t| {
                            (t == VarType::Real) == (v.ty == VarType::Real)
                                || (!valid && rng.random_bool(0.1))
                        })
                    })
                    .collect();
                if pool.is_empty() {
                    0
                } else {
                    pool[rng.random_range(0..pool.len())].vr
                }
            }
        })
        .collect()
}

pub fn spec(table: &FmuTable, r: u32) -> Option<&'static VarSpec> {
    FMUS.iter()
        .find(|t| t.model_identifier == table.model_identifier)
        .and_then(|t| (*t).var(r))
}

impl World {
    /// Any state pointer: this instance's, another's, a freed one, a foreign one, null.
    pub fn state_pointer(&mut self, i: usize) -> fmi2FMUstate {
        let rng = &mut self.rng;
        let own = &self.slots[i].states;
        match rng.random_range(0..20) {
            0..=11 if !own.is_empty() => own[rng.random_range(0..own.len())],
            12 | 13 => {
                let j = rng.random_range(0..self.slots.len());
                let o = &self.slots[j].states;
                if o.is_empty() {
                    std::ptr::null_mut()
                } else {
                    o[rng.random_range(0..o.len())]
                }
            }
            14 | 15 if !self.freed_states.is_empty() => {
                self.freed_states[rng.random_range(0..self.freed_states.len())]
            }
            16 => 8 as fmi2FMUstate,
            17 => usize::MAX as fmi2FMUstate,
            18 => self.foreign.as_mut_ptr() as fmi2FMUstate,
            _ => std::ptr::null_mut(),
        }
    }

    /// The serialized bytes handed to fmi2DeSerializeFMUstate or
    /// fmi3DeserializeFMUState (both versions serialize the FMI 2.0 layer's state).
    pub fn blob(&mut self) -> Vec<u8> {
        let rng = &mut self.rng;
        if self.blobs.is_empty() || rng.random_bool(0.1) {
            let n = rng.random_range(0..300);
            return (0..n).map(|_| rng.random::<u8>()).collect();
        }
        let mut b = self.blobs[rng.random_range(0..self.blobs.len())].clone();
        match rng.random_range(0..8) {
            0 => {
                let n = rng.random_range(0..b.len());
                b.truncate(n);
            }
            1 => {
                // A header byte (magic, GUID, phase, flags, lengths).
                let k = rng.random_range(0..b.len().min(120));
                b[k] = b[k].wrapping_add(rng.random_range(1..=255u8));
            }
            2 => b.extend_from_slice(&[0, 1, 2]),
            3 if b.len() > 40 => {
                // A number of the body (clock, calculated values, variables, model
                // state, or a length) replaced, on the grid of 8-byte fields after the
                // GUID and the three flag bytes.
                let guid_len = u64::from_le_bytes(std::array::from_fn(|k| b[22 + k]));
                let first = 22 + 8 + guid_len as usize + 3;
                if first + 8 <= b.len() {
                    let j = rng.random_range(0..(b.len() - first) / 8);
                    let x = if avoided(Fault::ExtremeState) {
                        NASTY[rng.random_range(0..3)]
                    } else {
                        NASTY[rng.random_range(0..NASTY.len())]
                    };
                    let at = first + 8 * j;
                    b[at..at + 8].copy_from_slice(&x.to_le_bytes());
                }
            }
            _ => {}
        }
        b
    }
}
