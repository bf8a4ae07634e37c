//! The arguments of the FMI 3.0 calls: value references of FMI 3.0 variables (scalars
//! and arrays sized by `wheelsets`, the independent variable `time`, unknown ones, ones
//! of another type), the number of values they have and wrong ones, values per type
//! (each array element's from its FMI 2.0 variable, [`crate::args::value_for`]),
//! `wheelsets`, tolerances, start and stop times, instantiation tokens.

use crate::args::{faulty_value, nasty, value_for};
use rand::Rng;
use rand::rngs::StdRng;
use std::sync::OnceLock;
use wheelflat::fmu::vars::{FMI3_FMUS, Fmu3Table, N_VR, Type3, Var3Spec, VarSpec};

/// The value reference of the independent variable `time`.
pub const TIME_VR: u32 = N_VR as u32;

/// Per value reference, the index of its variable in an FMU's FMI 3.0 table and in its
/// FMI 2.0 table (the tables' own look-ups search them).
type Index = (Vec<Option<u16>>, Vec<Option<u16>>);

fn index(table: &'static Fmu3Table) -> &'static Index {
    static INDEX: OnceLock<Vec<Index>> = OnceLock::new();
    let all = INDEX.get_or_init(|| {
        FMI3_FMUS
            .iter()
            .map(|t| {
                let (mut a, mut b) = (vec![None; N_VR], vec![None; N_VR]);
                for (k, v) in t.vars.iter().enumerate() {
                    a[v.vr as usize] = Some(k as u16);
                }
                for (k, v) in t.fmi2.vars.iter().enumerate() {
                    b[v.vr as usize] = Some(k as u16);
                }
                (a, b)
            })
            .collect()
    });
    let k = FMI3_FMUS
        .iter()
        .position(|t| std::ptr::eq(*t, table))
        .expect("an FMU's FMI 3.0 table");
    &all[k]
}

/// The FMI 3.0 variable of value reference `vr` of `table` ([`Fmu3Table::var`]).
pub fn var3(table: &'static Fmu3Table, vr: u32) -> Option<&'static Var3Spec> {
    let k = (*index(table).0.get(vr as usize)?)?;
    Some(&table.vars[k as usize])
}

/// The FMI 2.0 variable of value reference `vr` of `table`'s FMU.
pub fn var2(table: &'static Fmu3Table, vr: u32) -> Option<&'static VarSpec> {
    let k = (*index(table).1.get(vr as usize)?)?;
    Some(&table.fmi2.vars[k as usize])
}

/// The variable `wheelsets` of `table`: the structural parameter or the constant.
pub fn wheelsets_var(table: &'static Fmu3Table) -> Option<&'static Var3Spec> {
    table
        .vars
        .iter()
        .find(|v| matches!(v.ty, Type3::Wheelsets | Type3::Constant))
}

/// The structural parameter `wheelsets` of `table`, if it has one.
pub fn structural(table: &'static Fmu3Table) -> Option<&'static Var3Spec> {
    wheelsets_var(table).filter(|v| v.ty == Type3::Wheelsets)
}

/// The wheelsets of a new instance of `table`: the structural parameter's start value
/// or the constant.
pub fn start_wheelsets(table: &'static Fmu3Table) -> usize {
    match wheelsets_var(table) {
        Some(v) if v.ty == Type3::Constant => v.constant as usize,
        Some(v) => var2(table, v.vr).map_or(1, |s| s.start as usize),
        None => 1,
    }
}

/// The number of values of `vrs` with `wheelsets` wheelsets: an array's elements in
/// use, one for a scalar, `time` or a reference the FMU does not have.
pub fn values_of(table: &'static Fmu3Table, vrs: &[u32], wheelsets: usize) -> usize {
    element_specs(table, vrs, wheelsets).len()
}

/// The FMI 2.0 variable of each value of `vrs` with `wheelsets` wheelsets (an array's
/// elements in use, the leading wheelset's first); `None` for `time` and for a
/// reference the FMU does not have.
pub fn element_specs(
    table: &'static Fmu3Table,
    vrs: &[u32],
    wheelsets: usize,
) -> Vec<Option<&'static VarSpec>> {
    let mut out = Vec::new();
    for &r in vrs {
        match var3(table, r) {
            Some(v) if v.array => {
                let n = wheelsets.min(v.elements.len());
                out.extend(v.elements[..n].iter().map(|&e| var2(table, e)));
            }
            Some(v) => out.push(var2(table, v.elements[0])),
            None => out.push(None),
        }
    }
    out
}

/// The name of value `k` of `vrs` (for messages).
pub fn value_name(table: &'static Fmu3Table, vrs: &[u32], wheelsets: usize, k: usize) -> String {
    let mut at = 0;
    for &r in vrs {
        let n = match var3(table, r) {
            Some(v) if v.array => wheelsets.min(v.elements.len()),
            _ => 1,
        };
        if k < at + n {
            return match var3(table, r) {
                Some(v) if v.array => format!("{}[{}]", v.name, k - at + 1),
                Some(v) => v.name.to_string(),
                None if r == TIME_VR => "time".into(),
                None => format!("vr {r}"),
            };
        }
        at += n;
    }
    "?".into()
}

/// Value references for a call on variables of `types`: mostly this FMU's variables of
/// those types (for a set, valid: parameters and inputs); `time` for a get of Float64;
/// some (invalid) of another type, unknown (past `time`, `u32::MAX`, an FMI 2.0
/// element's or another FMU's), `time` where nothing sets it.
pub fn refs3(
    rng: &mut StdRng,
    table: &'static Fmu3Table,
    types: &[Type3],
    get: bool,
    valid: bool,
) -> Vec<u32> {
    let n = match rng.random_range(0..10) {
        0 if !valid => 0,
        0..=6 => 1,
        _ => rng.random_range(2..6),
    };
    (0..n)
        .map(|_| match rng.random_range(if valid { 3 } else { 0 }..24) {
            0 => TIME_VR + rng.random_range(1..5),
            1 => u32::MAX,
            2 => rng.random_range(0..TIME_VR),
            3 if get && types.contains(&Type3::Float64) => TIME_VR,
            4 if !valid => TIME_VR,
            _ => {
                let pool: Vec<&Var3Spec> = table
                    .vars
                    .iter()
                    .filter(|v| {
                        let settable = get
                            || matches!(v.causality, "parameter" | "input" | "structuralParameter");
                        (types.contains(&v.ty) && (settable || !valid))
                            || (!valid && rng.random_bool(0.05))
                    })
                    .collect();
                if pool.is_empty() {
                    TIME_VR + 7
                } else {
                    pool[rng.random_range(0..pool.len())].vr
                }
            }
        })
        .collect()
}

/// Value references of `table`'s Float64 variables of causality `causality` (valid),
/// or of any Float64 variable or none (invalid): the unknowns and knowns of the
/// derivatives.
pub fn float64_of(
    rng: &mut StdRng,
    table: &'static Fmu3Table,
    causality: &str,
    valid: bool,
) -> Vec<u32> {
    let pool: Vec<u32> = table
        .vars
        .iter()
        .filter(|v| v.ty == Type3::Float64 && (v.causality == causality || !valid))
        .map(|v| v.vr)
        .collect();
    let n = match rng.random_range(0..8) {
        0 if !valid => 0,
        0..=4 => 1,
        _ => rng.random_range(2..4),
    };
    if pool.is_empty() {
        return vec![TIME_VR + 1; n];
    }
    (0..n)
        .map(|_| pool[rng.random_range(0..pool.len())])
        .collect()
}

/// `nValues` for `right` values: right, or (invalid, sometimes) one more, one less, none
/// or far more.
pub fn n_values(rng: &mut StdRng, right: usize, valid: bool) -> usize {
    if valid || rng.random_bool(0.85) {
        return right;
    }
    match rng.random_range(0..4) {
        0 => right + 1,
        1 => right.saturating_sub(1),
        2 => 0,
        _ => 2 * right + 3,
    }
}

/// A Float64 value for the element of FMI 2.0 variable `v` ([`value_for`]).
pub fn float64(rng: &mut StdRng, v: Option<&VarSpec>, valid: bool) -> f64 {
    value_for(rng, v, valid)
}

/// An Int32 value for `v`: near its start, or (invalid) the extremes.
pub fn int32(rng: &mut StdRng, v: Option<&VarSpec>, valid: bool) -> i32 {
    let x = value_for(rng, v, valid);
    if !valid && rng.random_ratio(1, 10) {
        return [i32::MIN, i32::MAX, -1, 0][rng.random_range(0..4)];
    }
    let x = x as i32;
    match v {
        Some(v) if faulty_value(v, x as f64) => v.start as i32,
        _ => x,
    }
}

/// An Int64 value for the Enumeration `v`: an item's code, or (invalid) beyond them and
/// beyond 32 bits.
pub fn int64(rng: &mut StdRng, v: Option<&VarSpec>, valid: bool) -> i64 {
    if !valid && rng.random_ratio(1, 8) {
        return [i64::MIN, i64::MAX, 1 << 32, -1, 1 << 31][rng.random_range(0..5)];
    }
    value_for(rng, v, valid) as i64
}

/// A value of `wheelsets` (range 1 to `max`): valid, or 0, `max + 1`, huge.
pub fn wheelsets_value(rng: &mut StdRng, max: u64, valid: bool) -> u64 {
    if valid || rng.random_bool(0.5) {
        return rng.random_range(1..=max);
    }
    [
        0,
        max + 1,
        u64::MAX,
        1 << 32,
        (1 << 32) + 2,
        i32::MAX as u64 + 1,
        1 << 63,
    ][rng.random_range(0..7)]
}

/// `(toleranceDefined, tolerance)`: undefined or positive, or (invalid) 0, negative,
/// NaN, infinite.
pub fn tolerance(rng: &mut StdRng, valid: bool) -> (bool, f64) {
    let defined = rng.random_bool(0.5);
    if valid || rng.random_bool(0.5) {
        return (defined, [1e-6, 1e-4, 1e-10][rng.random_range(0..3)]);
    }
    (
        true,
        [0.0, -1.0, f64::NAN, f64::INFINITY, -1e-6, 5e-324][rng.random_range(0..6)],
    )
}

/// `(startTime, stopTimeDefined, stopTime)`: a start at 0 or later with no stop or a
/// later one; (invalid) a stop before the start, non-finite or huge times.
pub fn experiment(rng: &mut StdRng, valid: bool) -> (f64, bool, f64) {
    let start = if rng.random_bool(0.8) {
        0.0
    } else if valid || rng.random_bool(0.5) {
        rng.random_range(0.0..1.0)
    } else {
        nasty(rng)
    };
    match rng.random_range(0..if valid { 4 } else { 6 }) {
        0 | 1 => (start, false, 0.0),
        2 => (start, true, start + rng.random_range(0.001..2.0)),
        3 => (start, true, start + 1.0),
        4 => (start, true, start - rng.random_range(1e-6..1.0)),
        _ => (start, true, nasty(rng)),
    }
}

/// An instantiation token other than `table`'s: empty, garbage, the FMI 2.0 GUID.
pub fn bad_token(rng: &mut StdRng, table: &'static Fmu3Table) -> String {
    match rng.random_range(0..4) {
        0 => String::new(),
        1 => "{0}".into(),
        2 => "garbage".into(),
        _ => table.fmi2.guid.into(),
    }
}
