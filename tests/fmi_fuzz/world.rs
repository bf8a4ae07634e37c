//! The instances of one sequence as the test follows them (FMI 2.0 and FMI 3.0 ones
//! side by side), and one random call on one of them.

use crate::args::boolean;
use crate::calls::{Mirror, next_valid_call, pick_call};
use crate::common::{Log, callbacks};
use crate::stats::Stats;
use crate::{MAX_INSTANCES, trace_calls};
use rand::Rng;
use rand::rngs::StdRng;
use std::collections::{HashMap, VecDeque};
use std::ffi::{CString, c_int, c_void};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use wheelflat::fmu::Call;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::ffi3::fmi3FreeInstance;
use wheelflat::fmu::vars::{FMI3_FMUS, FMUS, Fmu3Table, FmuTable, VarSpec, VarType};

/// The FMI version an instance was made with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Version {
    Fmi2,
    Fmi3,
}

pub struct Slot {
    /// The `fmi2Component` or `fmi3Instance`.
    pub c: *mut c_void,
    pub version: Version,
    pub log: Box<Log>,
    /// The instance has a logger (an FMI 3.0 instance may be made without one: nothing
    /// can be checked of its messages).
    pub logged: bool,
    pub table: &'static FmuTable,
    /// The same FMU's FMI 3.0 table.
    pub table3: &'static Fmu3Table,
    pub name: String,
    /// Communication time as far as the test knows.
    pub t: f64,
    /// States handed out and not freed.
    pub states: Vec<fmi2FMUstate>,
    /// The phase as far as the test knows.
    pub phase: Mirror,
    /// FMI 3.0: the wheelsets in use (the size of every array) as far as the test knows;
    /// `None` after an FMU state of unknown origin was set.
    pub wheelsets: Option<usize>,
    /// FMI 3.0: `earlyReturnAllowed` of the instantiation.
    pub early_return: bool,
}

/// What the test knows of an FMI 3.0 FMU state: the phase, communication time and
/// wheelsets of the instance when it was taken.
#[derive(Debug, Clone, Copy)]
pub struct Saved {
    pub phase: Mirror,
    pub t: f64,
    pub wheelsets: Option<usize>,
}

/// What the watchdog sees of a worker: the call running and since when.
pub type Beat = Arc<Mutex<Option<(String, Instant)>>>;

pub struct World {
    pub rng: StdRng,
    pub seed: u64,
    pub sequence: usize,
    /// The share of FMI 3.0 instances among those the sequence starts with or makes
    /// when it has none (0: FMI 2.0 only, drawing nothing from the generator).
    pub fmi3_share: f64,
    pub slots: Vec<Slot>,
    pub freed_states: Vec<fmi2FMUstate>,
    /// FMI 3.0 states handed out, by address.
    pub saved: HashMap<usize, Saved>,
    /// Serialized states of either version (the same format).
    pub blobs: Vec<Vec<u8>>,
    pub foreign: Box<[u64; 4]>,
    pub trace: VecDeque<String>,
    pub beat: Beat,
    pub calls: usize,
    pub serial: usize,
    /// The call being made is a well-behaved one (valid arguments).
    pub valid: bool,
}

/// Status values of the C layer.
#[allow(dead_code)]
pub enum Status {
    Ok = 0,
    Warning = 1,
    Discard = 2,
    Error = 3,
}

impl World {
    /// A new world for sequence `sequence` of the run of base seed `seed`.
    pub fn new(seed: u64, sequence: usize, fmi3_share: f64, beat: Beat) -> World {
        use rand::SeedableRng;
        World {
            rng: StdRng::seed_from_u64(
                seed ^ (sequence as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15),
            ),
            seed,
            sequence,
            fmi3_share,
            slots: Vec::new(),
            freed_states: Vec::new(),
            saved: HashMap::new(),
            blobs: Vec::new(),
            foreign: Box::new([0; 4]),
            trace: VecDeque::new(),
            beat,
            calls: 0,
            serial: 0,
            valid: false,
        }
    }

    pub fn fail(&self, what: String) -> ! {
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

    /// A new instance of either version ([`World::fmi3_share`]).
    pub fn instantiate(&mut self, valid: bool) -> Option<usize> {
        let p = self.fmi3_share;
        let fmi3 = p >= 1.0 || (p > 0.0 && self.rng.random_bool(p));
        if fmi3 {
            self.instantiate3(valid)
        } else {
            self.instantiate2(valid)
        }
    }

    /// A new slot for the instance `c` of FMU `kind` just made.
    pub fn push_slot(
        &mut self,
        c: *mut c_void,
        version: Version,
        kind: usize,
        log: Box<Log>,
        name: String,
    ) {
        let (table, table3) = (FMUS[kind], FMI3_FMUS[kind]);
        let wheelsets = Some(crate::fmi3_args::start_wheelsets(table3));
        self.slots.push(Slot {
            c,
            version,
            log,
            logged: true,
            table,
            table3,
            name,
            t: 0.0,
            states: Vec::new(),
            phase: Mirror::Instantiated,
            wheelsets,
            early_return: false,
        });
    }

    pub fn instantiate2(&mut self, valid: bool) -> Option<usize> {
        let k = self.rng.random_range(0..FMUS.len());
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
                self.check_messages(
                    &log,
                    0,
                    "fmi2Instantiate",
                    Status::Error as c_int,
                    Version::Fmi2,
                );
            }
            return None;
        }
        self.push_slot(c, Version::Fmi2, k, log, name);
        Some(self.slots.len() - 1)
    }

    /// Runs `f` under the watchdog and records the call.
    pub fn timed<T>(&mut self, desc: String, f: impl FnOnce() -> T) -> (T, Duration) {
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
        if trace_calls() > 0 {
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

    /// Whether any instance may still own `p` (a pointer never handed out must be
    /// refused).
    pub fn maybe_state(&self, p: fmi2FMUstate) -> bool {
        self.slots.iter().any(|s| s.states.contains(&p)) || self.freed_states.contains(&p)
    }

    pub fn forget_state(&mut self, p: fmi2FMUstate) {
        for s in &mut self.slots {
            s.states.retain(|&q| q != p);
        }
        self.saved.remove(&(p as usize));
        self.freed_states.push(p);
    }

    /// One random call.
    pub fn one(&mut self, stats: &Stats) {
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
        match self.slots[i].version {
            Version::Fmi2 => self.one2(i, stats),
            Version::Fmi3 => self.one3(i, stats),
        }
    }

    /// One random FMI 2.0 call on instance `i`.
    fn one2(&mut self, i: usize, stats: &Stats) {
        let call = if self.valid {
            next_valid_call(&mut self.rng, self.slots[i].phase)
        } else {
            pick_call(&mut self.rng)
        };
        if call == Call::Instantiate {
            if self.slots.len() < MAX_INSTANCES {
                let made = self.instantiate2(false).is_some();
                stats.count(call, if made { 0 } else { 3 });
            }
            return;
        }
        if call == Call::FreeInstance {
            if self.slots.len() > 1 {
                self.free_instance(i);
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
        self.check_call(i, call.name(), &desc, status, null_component, from);
    }

    /// Frees instance `i` (of either version) and forgets it.
    pub fn free_instance(&mut self, i: usize) {
        let s = self.slots.remove(i);
        let from = s.log.len();
        let name = match s.version {
            Version::Fmi2 => "fmi2FreeInstance",
            Version::Fmi3 => "fmi3FreeInstance",
        };
        self.timed(format!("{}: {name}()", s.name), || unsafe {
            match s.version {
                Version::Fmi2 => fmi2FreeInstance(s.c),
                Version::Fmi3 => fmi3FreeInstance(s.c),
            }
        });
        self.check_messages(&s.log, from, name, 0, s.version);
        for p in s.states {
            self.saved.remove(&(p as usize));
            self.freed_states.push(p);
        }
    }

    /// Prints the variables of every instance and stops (`WHEELFLAT_FUZZ_STOP_AT`).
    pub fn dump(&self) -> ! {
        for s in &self.slots {
            if s.version == Version::Fmi3 {
                crate::fmi3_dispatch::dump3(s);
                continue;
            }
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

    /// After a state was set on FMI 2.0 instance `i`: the communication time and phase
    /// from the instance.
    pub fn refresh_time(&mut self, i: usize) {
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

    /// Follows the phase of FMI 2.0 instance `i` after `call` returned `status`.
    pub fn follow(&mut self, i: usize, call: Call, status: c_int) {
        let p = &mut self.slots[i].phase;
        *p = match (call, status) {
            (Call::EnterInitializationMode, 0) => Mirror::Initialization,
            // fmi2Warning: initialised, with a warning (a stopTime the fixed track cannot
            // reach, track.spans set on the endless track).
            (Call::ExitInitializationMode, 0 | 1) => Mirror::Stepping,
            (Call::Terminate, 0) => Mirror::Terminated,
            (Call::Reset, 0) => Mirror::Instantiated,
            (Call::DoStep, 2) => Mirror::Ended,
            _ => *p,
        };
    }

    pub fn free_all(&mut self) {
        for s in self.slots.drain(..) {
            match s.version {
                Version::Fmi2 => unsafe { fmi2FreeInstance(s.c) },
                Version::Fmi3 => unsafe { fmi3FreeInstance(s.c) },
            }
        }
    }
}
