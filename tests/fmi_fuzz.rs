//! Property test of the C boundary: random sequences of FMI 2.0 co-simulation calls,
//! valid and invalid, on all three FMUs with several instances alive at once, through
//! the exported `extern "C"` functions in this process.
//!
//! Asserted for every call: it returns within [`CALL_LIMIT`] (watchdog thread); no panic
//! escapes and none is caught inside (no "internal error" message); `fmi2GetReal`
//! never returns NaN or an infinity with fmi2OK; every fmi2Warning / fmi2Discard /
//! fmi2Error is logged with a message that names the function and gives a cause
//! (calls on a null `fmi2Component`, which has no logger, excepted); only the statuses
//! fmi2OK, fmi2Warning, fmi2Discard and fmi2Error are returned. For every sequence, a
//! reference instance driven by a fixed valid sequence between the random calls gives
//! bit-identical outputs to the same sequence run alone.
//!
//! `cargo test --release --test fmi_fuzz`; environment:
//! - `WHEELFLAT_FUZZ_SEED=<u64>`: base seed (default fixed; printed on failure);
//! - `WHEELFLAT_FUZZ_SCALE=<f64>`: number of sequences times this (10 to run longer,
//!   0.05 under valgrind);
//! - `WHEELFLAT_FUZZ_SEQUENCE=<n>`: run only sequence n (to replay a failure);
//! - `WHEELFLAT_FUZZ_TRACE=1`: print every call before it is made;
//! - `WHEELFLAT_FUZZ_STOP_AT=<n>`: print the variables of every instance before call
//!   n of the sequence, and stop;
//! - `WHEELFLAT_FUZZ_KNOWN_FAULTS=all` (or names: `SubnormalStep,TinySolverDt`): also
//!   generate the inputs of those [`KNOWN_ENGINE_FAULTS`].

mod common;

use common::{Log, callbacks};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::collections::VecDeque;
use std::ffi::{CString, c_int};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};
use wheelflat::fmu::Call;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{Causality, FMUS, FmuTable, N_VR, VarSpec, VarType};

/// Sequences per run (times `WHEELFLAT_FUZZ_SCALE`).
const SEQUENCES: usize = 3000;
/// Random calls per sequence.
const CALLS_PER_SEQUENCE: usize = 1000;
/// Fuzzed instances alive at once, at most (plus the reference instance).
const MAX_INSTANCES: usize = 4;
/// No call may take longer.
const CALL_LIMIT: Duration = Duration::from_secs(20);
/// Worker threads (sequences run in parallel).
const WORKERS: usize = 2;
/// Default base seed.
const SEED: u64 = 0x5EED_F1A7_2026;
/// Communication step of the reference instance (s).
const REF_H: f64 = 2e-5;

/// Engine faults being fixed outside the C layer: inputs that trigger them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fault {
    /// fmi2DoStep with a subnormal step (0 < h < 1e-300) returns fmi2OK and NaN outputs.
    SubnormalStep,
    /// fmi2DoStep with a huge step (h >= 1e3 s, e.g. 1e9) does not return when the run
    /// cannot end first (RollPlaneVehicle has no track end; `speed` = 0 on the track
    /// FMUs): h / dt substeps, unbounded.
    HugeStep,
    /// `solver.dt` far below the critical step (< 1e-9 s) makes every step take
    /// billions of substeps (fmi2DoStep does not return).
    TinySolverDt,
    /// Parameters of extreme magnitude (overflowing products, e.g. 1e300 stiffness or
    /// mass, 5e-324 masses) give NaN/inf outputs with fmi2OK, or a huge track
    /// (`track.spans` * `track.nodes_per_span` in the millions) takes minutes and GBs.
    ExtremeParameters,
    /// A serialized FMU state whose model state holds finite numbers of extreme
    /// magnitude (1e300, f64::MAX, 5e-324 in displacements, velocities, the step
    /// counter, ...) is accepted by fmi2DeSerializeFMUstate and then gives NaN/inf
    /// outputs with fmi2OK (non-finite numbers are refused).
    ExtremeState,
}

/// The engine faults the generator avoids (unless `WHEELFLAT_FUZZ_KNOWN_FAULTS=1`), with
/// what the fuzz test finds without the exclusion. Remove an entry when its fix is
/// merged.
const KNOWN_ENGINE_FAULTS: &[Fault] = &[];

/// `WHEELFLAT_FUZZ_TRACE=1`: every call printed before it is made.
fn trace_calls() -> bool {
    static ON: OnceLock<bool> = OnceLock::new();
    *ON.get_or_init(|| std::env::var("WHEELFLAT_FUZZ_TRACE").is_ok_and(|v| v == "1"))
}

/// Whether the generator avoids the inputs of `f`: it is listed in
/// [`KNOWN_ENGINE_FAULTS`] and not named in `WHEELFLAT_FUZZ_KNOWN_FAULTS` (`all`, or
/// names separated by commas: `SubnormalStep,TinySolverDt`).
fn avoided(f: Fault) -> bool {
    static WANTED: OnceLock<String> = OnceLock::new();
    let wanted =
        WANTED.get_or_init(|| std::env::var("WHEELFLAT_FUZZ_KNOWN_FAULTS").unwrap_or_default());
    let name = format!("{f:?}");
    let generated = wanted == "all" || wanted == "1" || wanted.split(',').any(|w| w.trim() == name);
    !generated && KNOWN_ENGINE_FAULTS.contains(&f)
}

// ------------------------------------------------------------------ generators

/// Values that break things.
const NASTY: [f64; 16] = [
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

fn nasty(rng: &mut StdRng) -> f64 {
    NASTY[rng.random_range(0..NASTY.len())]
}

/// Whether a value for variable `v` hits a known engine fault.
fn faulty_value(v: &VarSpec, x: f64) -> bool {
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
fn value_for(rng: &mut StdRng, v: Option<&VarSpec>, valid: bool) -> f64 {
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
fn step_size(rng: &mut StdRng, valid: bool) -> f64 {
    loop {
        let h = match rng.random_range(0..if valid { 11 } else { 20 }) {
            0..=7 => 10f64.powf(rng.random_range(-6.0..-3.0)),
            8..=10 => 2e-5,
            11 => 10f64.powf(rng.random_range(-3.0..-1.3)),
            12 => 0.0,
            13 => -rng.random_range(1e-6..1e-3),
            14 => 5e-324,
            15 => 1e9,
            16 => 1.0,
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

fn boolean(rng: &mut StdRng, valid: bool) -> c_int {
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
fn refs(rng: &mut StdRng, table: &FmuTable, want: Option<VarType>, valid: bool) -> Vec<u32> {
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

fn spec(table: &FmuTable, r: u32) -> Option<&'static VarSpec> {
    FMUS.iter()
        .find(|t| t.model_identifier == table.model_identifier)
        .and_then(|t| t.vars.iter().find(|v| v.vr == r))
}

// ------------------------------------------------------------------ the world

struct Slot {
    c: fmi2Component,
    log: Box<Log>,
    table: &'static FmuTable,
    name: String,
    /// Communication time as far as the test knows.
    t: f64,
    /// States handed out and not freed.
    states: Vec<fmi2FMUstate>,
    /// The phase as far as the test knows.
    phase: Mirror,
}

/// The phase of an instance as the test follows it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mirror {
    Instantiated,
    Initialization,
    Stepping,
    Ended,
    Terminated,
    Unknown,
}

/// A call a well-behaved master would make next (with valid arguments).
fn next_valid_call(rng: &mut StdRng, phase: Mirror) -> Call {
    let pick = |rng: &mut StdRng, w: &[(Call, u32)]| {
        let total: u32 = w.iter().map(|x| x.1).sum();
        let mut x = rng.random_range(0..total);
        for &(c, n) in w {
            if x < n {
                return c;
            }
            x -= n;
        }
        unreachable!()
    };
    match phase {
        Mirror::Instantiated => pick(
            rng,
            &[
                (Call::SetReal, 2),
                (Call::SetInteger, 1),
                (Call::SetupExperiment, 2),
                (Call::EnterInitializationMode, 5),
            ],
        ),
        Mirror::Initialization => pick(
            rng,
            &[
                (Call::SetReal, 2),
                (Call::GetReal, 2),
                (Call::ExitInitializationMode, 6),
            ],
        ),
        Mirror::Stepping => pick(
            rng,
            &[
                (Call::DoStep, 60),
                (Call::GetReal, 15),
                (Call::SetReal, 10),
                (Call::GetFMUstate, 4),
                (Call::SetFMUstate, 4),
                (Call::SerializeFMUstate, 2),
                (Call::DeSerializeFMUstate, 2),
                (Call::GetRealStatus, 2),
                (Call::Terminate, 1),
            ],
        ),
        Mirror::Ended => pick(
            rng,
            &[
                (Call::GetReal, 3),
                (Call::GetBooleanStatus, 1),
                (Call::DoStep, 1),
                (Call::Terminate, 3),
                (Call::Reset, 3),
            ],
        ),
        Mirror::Terminated => pick(rng, &[(Call::GetReal, 1), (Call::Reset, 4)]),
        Mirror::Unknown => pick(
            rng,
            &[
                (Call::EnterInitializationMode, 1),
                (Call::ExitInitializationMode, 1),
                (Call::Reset, 1),
            ],
        ),
    }
}

/// What the watchdog sees of a worker: the call running and since when.
type Beat = Arc<Mutex<Option<(String, Instant)>>>;

struct World {
    rng: StdRng,
    seed: u64,
    sequence: usize,
    slots: Vec<Slot>,
    freed_states: Vec<fmi2FMUstate>,
    blobs: Vec<Vec<fmi2Byte>>,
    foreign: Box<[u64; 4]>,
    trace: VecDeque<String>,
    beat: Beat,
    calls: usize,
    serial: usize,
    /// The call being made is a well-behaved one (valid arguments).
    valid: bool,
}

/// Statistics of a run.
struct Stats {
    calls: AtomicUsize,
    ok: AtomicUsize,
    refused: AtomicUsize,
    slowest_us: AtomicUsize,
    /// Per function (index of [`Call`]): calls, fmi2OK.
    per_call: [[AtomicUsize; 2]; 34],
}

impl Stats {
    fn count(&self, call: Call, status: c_int) {
        self.calls.fetch_add(1, Ordering::Relaxed);
        self.per_call[call as usize][0].fetch_add(1, Ordering::Relaxed);
        if status == 0 {
            self.per_call[call as usize][1].fetch_add(1, Ordering::Relaxed);
            self.ok.fetch_add(1, Ordering::Relaxed);
        } else {
            self.refused.fetch_add(1, Ordering::Relaxed);
        }
    }
}

impl Default for Stats {
    fn default() -> Stats {
        Stats {
            calls: AtomicUsize::new(0),
            ok: AtomicUsize::new(0),
            refused: AtomicUsize::new(0),
            slowest_us: AtomicUsize::new(0),
            per_call: std::array::from_fn(|_| [AtomicUsize::new(0), AtomicUsize::new(0)]),
        }
    }
}

impl World {
    fn fail(&self, what: String) -> ! {
        let trace: Vec<&str> = self.trace.iter().map(|s| s.as_str()).collect();
        panic!(
            "{what}\n  seed {} sequence {} (replay: WHEELFLAT_FUZZ_SEED={} \
             WHEELFLAT_FUZZ_SEQUENCE={})\n  last calls:\n    {}",
            self.seed,
            self.sequence,
            self.seed,
            self.sequence,
            trace.join("\n    ")
        )
    }

    fn instantiate(&mut self, valid: bool) -> Option<usize> {
        let k = self.rng.random_range(0..3);
        let table = FMUS[k];
        let log = Box::<Log>::default();
        let cb = callbacks(&log);
        self.serial += 1;
        let name = format!("fuzz{}", self.serial);
        let rng = &mut self.rng;
        let guid = if valid || rng.random_bool(0.8) {
            table.guid.to_string()
        } else {
            ["", "{0}", "garbage"][rng.random_range(0..3)].to_string()
        };
        let (visible, logging_on) = if valid {
            (0, rng.random_range(0..2))
        } else {
            (boolean(rng, false), boolean(rng, false))
        };
        let fmu_type = if valid || rng.random_bool(0.9) { 1 } else { 0 };
        let no_name = !valid && rng.random_bool(0.05);
        let no_functions = !valid && rng.random_bool(0.05);
        let cname = CString::new(name.clone()).unwrap();
        let cguid = CString::new(guid.clone()).unwrap();
        let desc = format!(
            "fmi2Instantiate({name}, type {fmu_type}, {}, visible {visible}, loggingOn {logging_on}{}{})",
            table.model_identifier,
            if no_name { ", null name" } else { "" },
            if no_functions { ", null functions" } else { "" }
        );
        let (c, _) = self.timed(desc, || unsafe {
            fmi2Instantiate(
                if no_name {
                    std::ptr::null()
                } else {
                    cname.as_ptr()
                },
                fmu_type,
                cguid.as_ptr(),
                c"file:///nowhere".as_ptr(),
                if no_functions { std::ptr::null() } else { &cb },
                visible,
                logging_on,
            )
        });
        let refused = c.is_null();
        if valid && refused {
            self.fail(format!("a valid fmi2Instantiate failed: {}", log.text()));
        }
        if refused {
            if !no_functions {
                self.check_messages(&log, 0, "fmi2Instantiate", Status::Error as c_int);
            }
            return None;
        }
        self.slots.push(Slot {
            c,
            log,
            table,
            name,
            t: 0.0,
            states: Vec::new(),
            phase: Mirror::Instantiated,
        });
        Some(self.slots.len() - 1)
    }

    /// Runs `f` under the watchdog and records the call.
    fn timed<T>(&mut self, desc: String, f: impl FnOnce() -> T) -> (T, Duration) {
        if self.trace.len() == 16 {
            self.trace.pop_front();
        }
        let mut short = desc.clone();
        if short.len() > 200 {
            let mut k = 200;
            while !short.is_char_boundary(k) {
                k -= 1;
            }
            short.truncate(k);
            short.push_str(" ...");
        }
        if trace_calls() {
            eprintln!("[{} {}] {short}", self.sequence, self.calls);
        }
        self.trace.push_back(short);
        *self.beat.lock().unwrap() = Some((
            format!("sequence {}, call {}: {desc}", self.sequence, self.calls),
            Instant::now(),
        ));
        let t0 = Instant::now();
        let r = f();
        let d = t0.elapsed();
        *self.beat.lock().unwrap() = None;
        self.calls += 1;
        (r, d)
    }

    /// The messages logged since `from` must include one of status >= Warning that
    /// names `call` and says why; none may report an internal error.
    fn check_messages(&self, log: &Log, from: usize, call: &str, status: c_int) {
        let recs = log.since(from);
        for r in &recs {
            if r.message.contains("internal error") {
                self.fail(format!("{call}: a panic was caught: {}", r.message));
            }
        }
        if status == 0 {
            return;
        }
        let named = recs.iter().any(|r| {
            r.status >= 1
                && r.message.contains(call)
                && r.message.len() > call.len() + 12
                && r.category.starts_with("logStatus")
        });
        if !named {
            self.fail(format!(
                "{call} returned {status} without a message naming it and the cause; logged: {:?}",
                recs
            ));
        }
    }

    /// Any state pointer: this instance's, another's, a freed one, a foreign one, null.
    fn state_pointer(&mut self, i: usize) -> fmi2FMUstate {
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

    /// Whether any instance may still own `p` (a pointer never handed out must be
    /// refused).
    fn maybe_state(&self, p: fmi2FMUstate) -> bool {
        self.slots.iter().any(|s| s.states.contains(&p)) || self.freed_states.contains(&p)
    }

    fn forget_state(&mut self, p: fmi2FMUstate) {
        for s in &mut self.slots {
            s.states.retain(|&q| q != p);
        }
        self.freed_states.push(p);
    }

    /// The serialized bytes handed to fmi2DeSerializeFMUstate.
    fn blob(&mut self) -> Vec<fmi2Byte> {
        let rng = &mut self.rng;
        if self.blobs.is_empty() || rng.random_bool(0.1) {
            let n = rng.random_range(0..300);
            return (0..n).map(|_| rng.random::<u8>() as fmi2Byte).collect();
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
                b[k] = b[k].wrapping_add(rng.random_range(1..=255u8) as fmi2Byte);
            }
            2 => b.extend_from_slice(&[0, 1, 2]),
            3 if b.len() > 40 => {
                // A number of the body (clock, calculated values, variables, model
                // state, or a length) replaced, on the grid of 8-byte fields after the
                // GUID and the three flag bytes.
                let guid_len = u64::from_le_bytes(std::array::from_fn(|k| b[22 + k] as u8));
                let first = 22 + 8 + guid_len as usize + 3;
                if first + 8 <= b.len() {
                    let j = rng.random_range(0..(b.len() - first) / 8);
                    let x = if avoided(Fault::ExtremeState) {
                        NASTY[rng.random_range(0..3)]
                    } else {
                        NASTY[rng.random_range(0..NASTY.len())]
                    };
                    let at = first + 8 * j;
                    for (o, v) in b[at..at + 8].iter_mut().zip(x.to_le_bytes()) {
                        *o = v as fmi2Byte;
                    }
                }
            }
            _ => {}
        }
        b
    }

    /// One random call.
    fn one(&mut self, stats: &Stats) {
        if std::env::var("WHEELFLAT_FUZZ_STOP_AT")
            .ok()
            .and_then(|s| s.parse::<usize>().ok())
            == Some(self.calls)
        {
            self.dump();
        }
        if self.slots.is_empty() {
            self.instantiate(true);
            return;
        }
        let i = self.rng.random_range(0..self.slots.len());
        self.valid = self.rng.random_bool(0.5);
        let call = if self.valid {
            next_valid_call(&mut self.rng, self.slots[i].phase)
        } else {
            pick_call(&mut self.rng)
        };
        if call == Call::Instantiate {
            if self.slots.len() < MAX_INSTANCES {
                let made = self.instantiate(false).is_some();
                stats.count(call, if made { 0 } else { 3 });
            }
            return;
        }
        if call == Call::FreeInstance {
            if self.slots.len() > 1 {
                let s = self.slots.remove(i);
                let from = s.log.len();
                self.timed(format!("{}: fmi2FreeInstance()", s.name), || unsafe {
                    fmi2FreeInstance(s.c)
                });
                self.check_messages(&s.log, from, "fmi2FreeInstance", 0);
                for p in s.states {
                    self.freed_states.push(p);
                }
                stats.count(call, 0);
            }
            return;
        }
        let null_component = !self.valid
            && self.rng.random_ratio(1, 100)
            && !matches!(call, Call::GetTypesPlatform | Call::GetVersion);
        let c = if null_component {
            std::ptr::null_mut()
        } else {
            self.slots[i].c
        };
        let table = self.slots[i].table;
        let name = self.slots[i].name.clone();
        let from = self.slots[i].log.len();
        let (status, desc, d) = self.dispatch(call, i, c, table, &name);
        if !null_component {
            self.follow(i, call, status);
        }
        stats.count(call, status);
        stats
            .slowest_us
            .fetch_max(d.as_micros() as usize, Ordering::Relaxed);
        if !(0..=3).contains(&status) {
            self.fail(format!("{desc} returned status {status}"));
        }
        if null_component {
            if status != 3 {
                self.fail(format!("{desc} on a null component returned {status}"));
            }
            return;
        }
        let log: *const Log = &*self.slots[i].log;
        self.check_messages(unsafe { &*log }, from, call.name(), status);
    }

    /// Makes the call; returns its status, description and duration.
    fn dispatch(
        &mut self,
        call: Call,
        i: usize,
        c: fmi2Component,
        table: &'static FmuTable,
        name: &str,
    ) -> (c_int, String, Duration) {
        let rng = &mut self.rng;
        let valid = self.valid;
        let null_ptr = !valid && rng.random_ratio(1, 25);
        macro_rules! run {
            ($desc:expr, $body:expr) => {{
                let desc = format!("{name}: {}", $desc);
                let (s, d) = self.timed(desc.clone(), || unsafe { $body });
                (s, desc, d)
            }};
        }
        match call {
            Call::GetTypesPlatform | Call::GetVersion => {
                let (p, d) = self.timed(format!("{name}: {}()", call.name()), || {
                    if call == Call::GetTypesPlatform {
                        fmi2GetTypesPlatform()
                    } else {
                        fmi2GetVersion()
                    }
                });
                assert!(!p.is_null());
                (0, call.name().into(), d)
            }
            Call::SetDebugLogging => {
                let on = boolean(rng, valid);
                let names = [
                    c"logStatusError",
                    c"logStatusWarning",
                    c"logCalls",
                    c"logEvents",
                    c"noSuchCategory",
                ];
                let n = rng.random_range(0..4);
                let mut cats: Vec<fmi2String> = (0..n)
                    .map(|_| names[rng.random_range(0..names.len())].as_ptr())
                    .collect();
                if null_ptr && n > 0 {
                    cats[0] = std::ptr::null();
                }
                let nulled = rng.random_ratio(1, 30);
                run!(
                    format!("fmi2SetDebugLogging({on}, {n} categories)"),
                    fmi2SetDebugLogging(
                        c,
                        on,
                        n,
                        if nulled {
                            std::ptr::null()
                        } else {
                            cats.as_ptr()
                        }
                    )
                )
            }
            Call::SetupExperiment => {
                let (td, sd) = (boolean(rng, valid), boolean(rng, valid));
                let start = if valid || rng.random_bool(0.9) {
                    0.0
                } else {
                    nasty(rng)
                };
                let stop = match rng.random_range(0..4) {
                    0 if !valid => nasty(rng),
                    0 | 1 => rng.random_range(0.001..2.0),
                    _ => 1.0,
                };
                run!(
                    format!("fmi2SetupExperiment({td}, 1e-6, {start:?}, {sd}, {stop:?})"),
                    fmi2SetupExperiment(c, td, 1e-6, start, sd, stop)
                )
            }
            Call::EnterInitializationMode => {
                run!(
                    "fmi2EnterInitializationMode()",
                    fmi2EnterInitializationMode(c)
                )
            }
            Call::ExitInitializationMode => {
                run!(
                    "fmi2ExitInitializationMode()",
                    fmi2ExitInitializationMode(c)
                )
            }
            Call::Terminate => run!("fmi2Terminate()", fmi2Terminate(c)),
            Call::Reset => {
                let r = run!("fmi2Reset()", fmi2Reset(c));
                if r.0 == 0 {
                    self.slots[i].t = 0.0;
                }
                r
            }
            Call::GetReal | Call::GetInteger | Call::GetBoolean | Call::GetString => {
                let vrs = if call == Call::GetReal && rng.random_bool(0.2) {
                    table
                        .vars
                        .iter()
                        .filter(|v| v.ty == VarType::Real)
                        .map(|v| v.vr)
                        .collect()
                } else {
                    refs(
                        rng,
                        table,
                        Some(if call == Call::GetReal {
                            VarType::Real
                        } else {
                            VarType::Integer
                        }),
                        valid,
                    )
                };
                let n = vrs.len();
                let vp = if null_ptr {
                    std::ptr::null()
                } else {
                    vrs.as_ptr()
                };
                let null_out = !valid && rng.random_ratio(1, 25);
                let desc = format!("{}(vr={vrs:?})", call.name());
                match call {
                    Call::GetReal => {
                        let mut out = vec![0.0f64; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        let r = run!(desc, fmi2GetReal(c, vp, n, op));
                        if r.0 == 0
                            && let Some(k) = out.iter().position(|x| !x.is_finite())
                        {
                            let v = spec(table, vrs[k]).map_or("?", |v| v.name);
                            self.fail(format!(
                                "{}: fmi2GetReal returned fmi2OK with `{v}` = {}",
                                r.1, out[k]
                            ));
                        }
                        r
                    }
                    Call::GetInteger => {
                        let mut out = vec![0 as c_int; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(desc, fmi2GetInteger(c, vp, n, op))
                    }
                    Call::GetBoolean => {
                        let mut out = vec![0 as c_int; n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(desc, fmi2GetBoolean(c, vp, n, op))
                    }
                    _ => {
                        let mut out = vec![std::ptr::null::<i8>(); n];
                        let op = if null_out {
                            std::ptr::null_mut()
                        } else {
                            out.as_mut_ptr()
                        };
                        run!(desc, fmi2GetString(c, vp, n, op))
                    }
                }
            }
            Call::SetReal | Call::SetInteger | Call::SetBoolean | Call::SetString => {
                let want = if call == Call::SetReal {
                    VarType::Real
                } else {
                    VarType::Integer
                };
                let vrs = refs(rng, table, Some(want), valid);
                let n = vrs.len();
                let vp = if null_ptr {
                    std::ptr::null()
                } else {
                    vrs.as_ptr()
                };
                let null_in = !valid && rng.random_ratio(1, 25);
                let vals: Vec<f64> = vrs
                    .iter()
                    .map(|&r| value_for(rng, spec(table, r), valid))
                    .collect();
                match call {
                    Call::SetReal => {
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            vals.as_ptr()
                        };
                        run!(
                            format!("fmi2SetReal(vr={vrs:?}, value={vals:?})"),
                            fmi2SetReal(c, vp, n, ip)
                        )
                    }
                    Call::SetInteger => {
                        let ints: Vec<c_int> = vals
                            .iter()
                            .map(|&x| {
                                if !valid && rng.random_ratio(1, 10) {
                                    [c_int::MIN, c_int::MAX, -1, 0][rng.random_range(0..4)]
                                } else {
                                    x as c_int
                                }
                            })
                            .collect();
                        // Integer parameters go through the same fault filter.
                        let ints: Vec<c_int> = ints
                            .iter()
                            .zip(&vrs)
                            .map(|(&x, &r)| match spec(table, r) {
                                Some(v) if faulty_value(v, x as f64) => v.start as c_int,
                                _ => x,
                            })
                            .collect();
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            ints.as_ptr()
                        };
                        run!(
                            format!("fmi2SetInteger(vr={vrs:?}, value={ints:?})"),
                            fmi2SetInteger(c, vp, n, ip)
                        )
                    }
                    Call::SetBoolean => {
                        let bools: Vec<c_int> = (0..n).map(|_| boolean(rng, valid)).collect();
                        let ip = if null_in {
                            std::ptr::null()
                        } else {
                            bools.as_ptr()
                        };
                        run!(
                            format!("fmi2SetBoolean(vr={vrs:?}, value={bools:?})"),
                            fmi2SetBoolean(c, vp, n, ip)
                        )
                    }
                    _ => {
                        let strs: Vec<fmi2String> = (0..n)
                            .map(|k| {
                                if k == 0 && null_in {
                                    std::ptr::null()
                                } else {
                                    c"text".as_ptr()
                                }
                            })
                            .collect();
                        run!(
                            format!("fmi2SetString(vr={vrs:?})"),
                            fmi2SetString(c, vp, n, strs.as_ptr())
                        )
                    }
                }
            }
            Call::GetFMUstate => {
                let mut p = if rng.random_bool(0.7) {
                    std::ptr::null_mut()
                } else {
                    self.state_pointer(i)
                };
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    format!("fmi2GetFMUstate(*FMUstate = {before:p})"),
                    fmi2GetFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut p
                        }
                    )
                );
                if r.0 == 0 && !null_ptr {
                    if before.is_null() {
                        if p.is_null() {
                            self.fail(format!("{}: fmi2OK but no state", r.1));
                        }
                        self.freed_states.retain(|&q| q != p);
                        self.slots[i].states.push(p);
                    } else if p != before {
                        self.fail(format!("{}: the state pointer changed", r.1));
                    }
                }
                if !could_own && r.0 == 0 {
                    self.fail(format!("{}: a foreign pointer was accepted", r.1));
                }
                r
            }
            Call::SetFMUstate => {
                let p = self.state_pointer(i);
                let could_own = self.maybe_state(p);
                let r = run!(format!("fmi2SetFMUstate({p:p})"), fmi2SetFMUstate(c, p));
                if r.0 == 0 {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was accepted", r.1));
                    }
                    self.refresh_time(i);
                }
                r
            }
            Call::FreeFMUstate => {
                let mut p = self.state_pointer(i);
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    format!("fmi2FreeFMUstate(*FMUstate = {before:p})"),
                    fmi2FreeFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut p
                        }
                    )
                );
                if r.0 == 0 && !null_ptr {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was freed", r.1));
                    }
                    if !p.is_null() {
                        self.fail(format!("{}: *FMUstate not set to NULL", r.1));
                    }
                    if !before.is_null() {
                        self.forget_state(before);
                    }
                } else if r.0 != 0 && p != before {
                    self.fail(format!("{}: refused, but *FMUstate changed", r.1));
                }
                r
            }
            Call::SerializedFMUstateSize => {
                let p = self.state_pointer(i);
                let mut size = 0usize;
                run!(
                    format!("fmi2SerializedFMUstateSize({p:p})"),
                    fmi2SerializedFMUstateSize(
                        c,
                        p,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut size
                        }
                    )
                )
            }
            Call::SerializeFMUstate => {
                let p = self.state_pointer(i);
                // The size as a master asks for it (not checked here).
                let mut size = 0usize;
                unsafe { fmi2SerializedFMUstateSize(c, p, &mut size) };
                let rng = &mut self.rng;
                let n = match rng.random_range(0..10) {
                    0 => size + 1,
                    1 => size.saturating_sub(1),
                    2 => rng.random_range(0..64),
                    _ => size,
                };
                let mut buf = vec![0 as fmi2Byte; n.max(1)];
                let r = run!(
                    format!("fmi2SerializeFMUstate({p:p}, size {n})"),
                    fmi2SerializeFMUstate(
                        c,
                        p,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            buf.as_mut_ptr()
                        },
                        n
                    )
                );
                if r.0 == 0 {
                    buf.truncate(n);
                    if self.blobs.len() < 16 {
                        self.blobs.push(buf);
                    } else {
                        let k = self.rng.random_range(0..16);
                        self.blobs[k] = buf;
                    }
                }
                r
            }
            Call::DeSerializeFMUstate => {
                let b = self.blob();
                let mut p = if self.rng.random_bool(0.7) {
                    std::ptr::null_mut()
                } else {
                    self.state_pointer(i)
                };
                let before = p;
                let could_own = before.is_null() || self.maybe_state(before);
                let r = run!(
                    format!(
                        "fmi2DeSerializeFMUstate({} bytes, *FMUstate = {before:p})",
                        b.len()
                    ),
                    fmi2DeSerializeFMUstate(
                        c,
                        if null_ptr {
                            std::ptr::null()
                        } else {
                            b.as_ptr()
                        },
                        b.len(),
                        &mut p
                    )
                );
                if r.0 == 0 {
                    if !could_own {
                        self.fail(format!("{}: a foreign pointer was overwritten", r.1));
                    }
                    if before.is_null() {
                        self.freed_states.retain(|&q| q != p);
                        self.slots[i].states.push(p);
                    } else if p != before {
                        self.fail(format!("{}: the state pointer changed", r.1));
                    }
                } else if p != before {
                    self.fail(format!("{}: refused, but *FMUstate changed", r.1));
                }
                r
            }
            Call::GetDirectionalDerivative => {
                let v = [0u32];
                let mut o = [0.0];
                run!(
                    "fmi2GetDirectionalDerivative()",
                    fmi2GetDirectionalDerivative(
                        c,
                        v.as_ptr(),
                        1,
                        v.as_ptr(),
                        1,
                        o.as_ptr(),
                        o.as_mut_ptr()
                    )
                )
            }
            Call::SetRealInputDerivatives => {
                let v = [0u32];
                let ord = [1];
                let x = [0.0];
                run!(
                    "fmi2SetRealInputDerivatives()",
                    fmi2SetRealInputDerivatives(c, v.as_ptr(), 1, ord.as_ptr(), x.as_ptr())
                )
            }
            Call::GetRealOutputDerivatives => {
                let v = [0u32];
                let ord = [1];
                let mut x = [0.0];
                run!(
                    "fmi2GetRealOutputDerivatives()",
                    fmi2GetRealOutputDerivatives(c, v.as_ptr(), 1, ord.as_ptr(), x.as_mut_ptr())
                )
            }
            Call::DoStep => {
                let t = if valid || rng.random_bool(0.85) {
                    self.slots[i].t
                } else {
                    nasty(rng)
                };
                let h = step_size(rng, valid);
                let b = if rng.random_bool(0.9) {
                    rng.random_range(0..2)
                } else {
                    boolean(rng, valid)
                };
                let r = run!(
                    format!("fmi2DoStep(t={t:?}, h={h:?}, noSet={b})"),
                    fmi2DoStep(c, t, h, b)
                );
                if r.0 == 0 {
                    self.slots[i].t = t + h;
                }
                r
            }
            Call::CancelStep => run!("fmi2CancelStep()", fmi2CancelStep(c)),
            Call::GetStatus => {
                let mut s = 0;
                run!("fmi2GetStatus(0)", fmi2GetStatus(c, 0, &mut s))
            }
            Call::GetRealStatus => {
                let k = rng.random_range(0..5);
                let mut x = 0.0;
                run!(
                    format!("fmi2GetRealStatus({k})"),
                    fmi2GetRealStatus(
                        c,
                        k,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut x
                        }
                    )
                )
            }
            Call::GetIntegerStatus => {
                let mut x = 0;
                run!(
                    "fmi2GetIntegerStatus(0)",
                    fmi2GetIntegerStatus(c, 0, &mut x)
                )
            }
            Call::GetBooleanStatus => {
                let k = rng.random_range(0..5);
                let mut x = 0;
                let r = run!(
                    format!("fmi2GetBooleanStatus({k})"),
                    fmi2GetBooleanStatus(
                        c,
                        k,
                        if null_ptr {
                            std::ptr::null_mut()
                        } else {
                            &mut x
                        }
                    )
                );
                if r.0 == 0 && x != 0 && x != 1 {
                    self.fail(format!("{}: not an fmi2Boolean: {x}", r.1));
                }
                r
            }
            Call::GetStringStatus => {
                let mut x: fmi2String = std::ptr::null();
                run!("fmi2GetStringStatus(0)", fmi2GetStringStatus(c, 0, &mut x))
            }
            Call::Instantiate | Call::FreeInstance => unreachable!(),
        }
    }

    /// Prints every Real variable of every instance and stops (`WHEELFLAT_FUZZ_STOP_AT`).
    fn dump(&self) -> ! {
        for s in &self.slots {
            let vars: Vec<&VarSpec> = s
                .table
                .vars
                .iter()
                .filter(|v| v.ty == VarType::Real)
                .collect();
            let vrs: Vec<u32> = vars.iter().map(|v| v.vr).collect();
            let mut x = vec![0.0; vrs.len()];
            let st = unsafe { fmi2GetReal(s.c, vrs.as_ptr(), vrs.len(), x.as_mut_ptr()) };
            eprintln!(
                "{} ({}), fmi2GetReal -> {st}: {}",
                s.name,
                s.table.model_identifier,
                s.log.last()
            );
            for (v, x) in vars.iter().zip(&x) {
                eprintln!("    {} = {x:?}", v.name);
            }
        }
        self.fail(format!("stopped before call {}", self.calls));
    }

    /// After a state was set: the communication time and phase from the instance.
    fn refresh_time(&mut self, i: usize) {
        let (mut t, mut ended) = (0.0, 0);
        let c = self.slots[i].c;
        let s = unsafe { fmi2GetRealStatus(c, 2, &mut t) };
        let e = unsafe { fmi2GetBooleanStatus(c, 3, &mut ended) };
        let slot = &mut self.slots[i];
        slot.t = if s == 0 { t } else { 0.0 };
        slot.phase = match (s, e, ended) {
            (0, 0, 1) => Mirror::Ended,
            (0, 0, _) => Mirror::Stepping,
            _ => Mirror::Unknown,
        };
    }

    /// Follows the phase of instance `i` after `call` returned `status`.
    fn follow(&mut self, i: usize, call: Call, status: c_int) {
        let p = &mut self.slots[i].phase;
        *p = match (call, status) {
            (Call::EnterInitializationMode, 0) => Mirror::Initialization,
            (Call::ExitInitializationMode, 0) => Mirror::Stepping,
            (Call::Terminate, 0) => Mirror::Terminated,
            (Call::Reset, 0) => Mirror::Instantiated,
            (Call::DoStep, 2) => Mirror::Ended,
            _ => *p,
        };
    }

    fn free_all(&mut self) {
        for s in self.slots.drain(..) {
            unsafe { fmi2FreeInstance(s.c) };
        }
    }
}

/// The function of a random call, weighted towards the ones that do something.
fn pick_call(rng: &mut StdRng) -> Call {
    const W: [(Call, u32); 34] = [
        (Call::GetTypesPlatform, 1),
        (Call::GetVersion, 1),
        (Call::SetDebugLogging, 2),
        (Call::Instantiate, 3),
        (Call::FreeInstance, 2),
        (Call::SetupExperiment, 4),
        (Call::EnterInitializationMode, 6),
        (Call::ExitInitializationMode, 6),
        (Call::Terminate, 3),
        (Call::Reset, 3),
        (Call::GetReal, 12),
        (Call::GetInteger, 3),
        (Call::GetBoolean, 1),
        (Call::GetString, 1),
        (Call::SetReal, 10),
        (Call::SetInteger, 4),
        (Call::SetBoolean, 1),
        (Call::SetString, 1),
        (Call::GetFMUstate, 4),
        (Call::SetFMUstate, 4),
        (Call::FreeFMUstate, 3),
        (Call::SerializedFMUstateSize, 2),
        (Call::SerializeFMUstate, 3),
        (Call::DeSerializeFMUstate, 3),
        (Call::GetDirectionalDerivative, 1),
        (Call::SetRealInputDerivatives, 1),
        (Call::GetRealOutputDerivatives, 1),
        (Call::DoStep, 18),
        (Call::CancelStep, 1),
        (Call::GetStatus, 1),
        (Call::GetRealStatus, 2),
        (Call::GetIntegerStatus, 1),
        (Call::GetBooleanStatus, 2),
        (Call::GetStringStatus, 1),
    ];
    let total: u32 = W.iter().map(|w| w.1).sum();
    let mut x = rng.random_range(0..total);
    for (c, w) in W {
        if x < w {
            return c;
        }
        x -= w;
    }
    unreachable!()
}

/// Status values of the C layer.
#[allow(dead_code)]
enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
}

// ------------------------------------------------------------------ reference instance

/// An instance driven by a fixed valid sequence: one step of `REF_H` and all Real
/// outputs read, per call of [`Reference::advance`].
struct Reference {
    c: fmi2Component,
    _log: Box<Log>,
    outs: Vec<u32>,
    k: usize,
    record: Vec<Vec<u64>>,
}

impl Reference {
    fn new(table: &'static FmuTable) -> Reference {
        let log = Box::<Log>::default();
        let cb = callbacks(&log);
        let guid = CString::new(table.guid).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                c"reference".as_ptr(),
                1,
                guid.as_ptr(),
                c"".as_ptr(),
                &cb,
                0,
                0,
            )
        };
        assert!(!c.is_null());
        unsafe {
            assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), 0);
            assert_eq!(fmi2EnterInitializationMode(c), 0);
            assert_eq!(fmi2ExitInitializationMode(c), 0);
        }
        let outs = table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
            .map(|v| v.vr)
            .collect();
        Reference {
            c,
            _log: log,
            outs,
            k: 0,
            record: Vec::new(),
        }
    }

    fn advance(&mut self) {
        let t = self.k as f64 * REF_H;
        let mut v = vec![0.0; self.outs.len()];
        unsafe {
            assert_eq!(
                fmi2DoStep(self.c, t, REF_H, 1),
                0,
                "reference step {}",
                self.k
            );
            assert_eq!(
                fmi2GetReal(self.c, self.outs.as_ptr(), self.outs.len(), v.as_mut_ptr()),
                0
            );
        }
        self.record.push(v.iter().map(|x| x.to_bits()).collect());
        self.k += 1;
    }
}

impl Drop for Reference {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}

/// The reference sequence of each FMU run alone.
fn alone() -> &'static [Vec<Vec<u64>>; 3] {
    static ALONE: OnceLock<[Vec<Vec<u64>>; 3]> = OnceLock::new();
    ALONE.get_or_init(|| {
        [0, 1, 2].map(|k| {
            let mut r = Reference::new(FMUS[k]);
            for _ in 0..CALLS_PER_SEQUENCE {
                r.advance();
            }
            std::mem::take(&mut r.record)
        })
    })
}

// ------------------------------------------------------------------ driver

fn run_sequence(seed: u64, sequence: usize, beat: Beat, stats: &Stats) {
    let mut w = World {
        rng: StdRng::seed_from_u64(seed ^ (sequence as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)),
        seed,
        sequence,
        slots: Vec::new(),
        freed_states: Vec::new(),
        blobs: Vec::new(),
        foreign: Box::new([0; 4]),
        trace: VecDeque::new(),
        beat,
        calls: 0,
        serial: 0,
        valid: false,
    };
    let kind = sequence % 3;
    let mut reference = Reference::new(FMUS[kind]);
    // A few instances to start with.
    for _ in 0..w.rng.random_range(1..=3) {
        w.instantiate(true);
    }
    for _ in 0..CALLS_PER_SEQUENCE {
        w.one(stats);
        reference.advance();
    }
    w.free_all();
    if w.foreign.iter().any(|&x| x != 0) {
        w.fail("a foreign pointer's memory was written".into());
    }
    let expected = &alone()[kind];
    if let Some(k) = (0..expected.len()).find(|&k| reference.record[k] != expected[k]) {
        w.fail(format!(
            "the reference {} instance differs from its run alone at step {k}",
            FMUS[kind].model_identifier
        ));
    }
}

#[test]
fn random_call_sequences_keep_the_fmi_contract() {
    let seed = std::env::var("WHEELFLAT_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(SEED);
    let scale: f64 = std::env::var("WHEELFLAT_FUZZ_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let only: Option<usize> = std::env::var("WHEELFLAT_FUZZ_SEQUENCE")
        .ok()
        .and_then(|s| s.parse().ok());
    let n = ((SEQUENCES as f64 * scale).round() as usize).max(1);
    let sequences: Vec<usize> = match only {
        Some(s) => vec![s],
        None => (0..n).collect(),
    };
    let excluded: Vec<Fault> = KNOWN_ENGINE_FAULTS
        .iter()
        .copied()
        .filter(|&f| avoided(f))
        .collect();
    eprintln!(
        "fmi_fuzz: seed {seed}, {} sequences of {CALLS_PER_SEQUENCE} calls, known engine \
         faults avoided: {excluded:?}",
        sequences.len()
    );
    let t0 = Instant::now();
    alone();
    let stats = Arc::new(Stats::default());
    let next = Arc::new(AtomicUsize::new(0));
    let sequences = Arc::new(sequences);
    let failed = Arc::new(AtomicBool::new(false));
    let mut beats = Vec::new();
    let mut workers = Vec::new();
    for _ in 0..WORKERS.min(sequences.len()) {
        let beat: Beat = Arc::new(Mutex::new(None));
        beats.push(beat.clone());
        let (stats, next, sequences, failed) = (
            stats.clone(),
            next.clone(),
            sequences.clone(),
            failed.clone(),
        );
        workers.push(std::thread::spawn(move || {
            loop {
                if failed.load(Ordering::Relaxed) {
                    return;
                }
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(&s) = sequences.get(k) else { return };
                let r = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    run_sequence(seed, s, beat.clone(), &stats)
                }));
                if let Err(p) = r {
                    failed.store(true, Ordering::Relaxed);
                    std::panic::resume_unwind(p);
                }
            }
        }));
    }
    // Watchdog.
    while workers.iter().any(|w| !w.is_finished()) {
        std::thread::sleep(Duration::from_millis(50));
        for b in &beats {
            if let Some((desc, since)) = b.lock().unwrap().as_ref()
                && since.elapsed() > CALL_LIMIT
            {
                panic!(
                    "a call did not return within {CALL_LIMIT:?}: {desc} (seed {seed}; replay \
                     with WHEELFLAT_FUZZ_SEED={seed} WHEELFLAT_FUZZ_SEQUENCE=<the sequence> \
                     WHEELFLAT_FUZZ_TRACE=1)"
                );
            }
        }
    }
    for w in workers {
        if let Err(p) = w.join() {
            std::panic::resume_unwind(p);
        }
    }
    eprintln!(
        "fmi_fuzz: {} calls ({} fmi2OK, {} refused), slowest {:.1} ms, {:.1} s",
        stats.calls.load(Ordering::Relaxed),
        stats.ok.load(Ordering::Relaxed),
        stats.refused.load(Ordering::Relaxed),
        stats.slowest_us.load(Ordering::Relaxed) as f64 / 1e3,
        t0.elapsed().as_secs_f64()
    );
    let per: Vec<String> = wheelflat::fmu::CALLS
        .iter()
        .map(|(c, name, _)| {
            let [n, ok] = &stats.per_call[*c as usize];
            format!(
                "{name} {}/{}",
                ok.load(Ordering::Relaxed),
                n.load(Ordering::Relaxed)
            )
        })
        .collect();
    eprintln!("fmi_fuzz: fmi2OK/calls: {}", per.join(", "));
}
