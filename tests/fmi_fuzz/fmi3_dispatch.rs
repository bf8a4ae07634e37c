//! Making one FMI 3.0 call: the instantiation, the function from
//! [`crate::fmi3_calls`], its arguments from [`crate::fmi3_args`], the call under the
//! watchdog, the checks of what it returns (Float64 values and sensitivities finite with
//! fmi3OK, `wheelsets` in its range, strings readable, `fmi3DoStep`'s out-arguments
//! consistent, refused functions fmi3Error) and the phase the instance is in after it.
//! The FMU-state calls are [`crate::fmu_state`]'s, the refused functions
//! [`crate::fmi3_refused`]'s.

use crate::MAX_INSTANCES;
use crate::args::{nasty, step_size};
use crate::calls::Mirror;
use crate::common::{Log, record3};
use crate::fmi3_args::{
    TIME_VR, bad_token, element_specs, experiment, float64, float64_of, int32, int64, n_values,
    refs3, start_wheelsets, structural, tolerance, value_name, values_of, var2, wheelsets_value,
    wheelsets_var,
};
use crate::fmi3_calls::{F3, next_valid_call3, pick_call3};
use crate::fmu_state::StateOp;
use crate::stats::Stats;
use crate::world::{Slot, Status, Version, World};
use rand::Rng;
use std::ffi::{CStr, CString, c_int, c_void};
use std::fmt::Debug;
use std::sync::atomic::Ordering;
use std::time::Duration;
use wheelflat::fmu::ffi3::*;
use wheelflat::fmu::vars::{FMI3_FMUS, Type3};

/// An `fmi3Get<Type>` of a scalar type.
pub type Get<T> =
    unsafe extern "C" fn(fmi3Instance, *const fmi3ValueReference, usize, *mut T, usize) -> c_int;
/// An `fmi3Set<Type>` of a scalar type.
pub type Set<T> =
    unsafe extern "C" fn(fmi3Instance, *const fmi3ValueReference, usize, *const T, usize) -> c_int;

/// The `instanceEnvironment` that makes the logger record into `log`.
pub fn env(log: &Log) -> *mut c_void {
    log as *const Log as *mut c_void
}

/// `p`, or null when `null`.
pub fn or_null<T>(null: bool, p: *const T) -> *const T {
    if null { std::ptr::null() } else { p }
}

/// `p`, or null when `null`.
pub fn or_null_mut<T>(null: bool, p: *mut T) -> *mut T {
    if null { std::ptr::null_mut() } else { p }
}

/// A call's status, description and duration.
pub type Made = (c_int, String, Duration);

impl World {
    /// `fmi3InstantiateCoSimulation` of a random FMU: valid, or with a bad token, a
    /// null or blank name, Event Mode, intermediate variables, no logger; it must make
    /// an instance exactly when the arguments are valid.
    pub fn instantiate3(&mut self, valid: bool) -> Option<usize> {
        let k = self.rng.random_range(0..FMI3_FMUS.len());
        let table = FMI3_FMUS[k];
        let log = Box::<Log>::default();
        self.serial += 1;
        let name = format!("fuzz{}", self.serial);
        let rng = &mut self.rng;
        let bad = !valid && rng.random_bool(0.15);
        let token = if bad {
            bad_token(rng, table)
        } else {
            table.token.into()
        };
        let null_token = bad && rng.random_bool(0.2);
        // 0: the name, 1: null, 2: empty, 3: blank.
        let name_kind = if valid || rng.random_bool(0.94) {
            0
        } else {
            rng.random_range(1..4)
        };
        let (visible, logging_on) = (rng.random_bool(0.5), rng.random_bool(0.5));
        let event_mode = !valid && rng.random_bool(0.05);
        let early_return = rng.random_bool(0.5);
        let n_required = if !valid && rng.random_bool(0.05) {
            rng.random_range(1..4)
        } else {
            0
        };
        let null_required = n_required > 0 && rng.random_bool(0.3);
        let no_logger = !valid && rng.random_bool(0.03);
        let null_path = rng.random_bool(0.1);
        let required = [0u32, 1, 2];
        let cname = CString::new(match name_kind {
            2 => "",
            3 => "  ",
            _ => name.as_str(),
        })
        .unwrap();
        let ctoken = CString::new(token.clone()).unwrap();
        let refuse = bad || name_kind != 0 || event_mode || n_required > 0;
        let desc = format!(
            "fmi3InstantiateCoSimulation({}, token {}, {}, visible {visible}, loggingOn \
             {logging_on}, eventModeUsed {event_mode}, earlyReturnAllowed {early_return}, \
             {n_required} intermediate variables{}{}{})",
            match name_kind {
                0 => name.as_str(),
                1 => "null name",
                2 => "empty name",
                _ => "blank name",
            },
            if null_token {
                "null".into()
            } else {
                format!("{token:?}")
            },
            table.fmi2.model_identifier,
            if null_required { " (null)" } else { "" },
            if null_path { ", null resourcePath" } else { "" },
            if no_logger { ", no logger" } else { "" },
        );
        let e = env(&log);
        let (c, _) = self.timed(desc.clone(), || unsafe {
            fmi3InstantiateCoSimulation(
                or_null(name_kind == 1, cname.as_ptr()),
                or_null(null_token, ctoken.as_ptr()),
                or_null(null_path, c"file:///nowhere/".as_ptr()),
                visible,
                logging_on,
                event_mode,
                early_return,
                or_null(null_required, required.as_ptr()),
                n_required,
                e,
                if no_logger { None } else { Some(record3) },
                std::ptr::null(),
            )
        });
        let call = "fmi3InstantiateCoSimulation";
        if c.is_null() {
            if !refuse {
                self.fail(format!(
                    "{desc}: a valid instantiation failed: {}",
                    log.text()
                ));
            }
            if !no_logger {
                self.check_messages(&log, 0, call, Status::Error as c_int, Version::Fmi3);
            }
            return None;
        }
        if refuse {
            unsafe { fmi3FreeInstance(c) };
            self.fail(format!("{desc}: an invalid instantiation made an instance"));
        }
        self.check_messages(&log, 0, call, 0, Version::Fmi3);
        self.push_slot(c, Version::Fmi3, k, log, name);
        let s = self.slots.last_mut().unwrap();
        s.logged = !no_logger;
        s.early_return = early_return;
        Some(self.slots.len() - 1)
    }

    /// One random FMI 3.0 call on instance `i`.
    pub fn one3(&mut self, i: usize, stats: &Stats) {
        let table = self.slots[i].table3;
        let f = if self.valid {
            next_valid_call3(
                &mut self.rng,
                self.slots[i].phase,
                structural(table).is_some(),
            )
        } else {
            pick_call3(&mut self.rng)
        };
        if f == F3::InstantiateCoSimulation {
            if self.slots.len() < MAX_INSTANCES {
                let made = self.instantiate3(false).is_some();
                stats.count3(f, if made { 0 } else { 3 });
            }
            return;
        }
        if f == F3::FreeInstance {
            if self.slots.len() > 1 {
                self.free_instance(i);
                stats.count3(f, 0);
            }
            return;
        }
        let null_instance = !self.valid
            && self.rng.random_ratio(1, 100)
            && !matches!(
                f,
                F3::GetVersion | F3::InstantiateModelExchange | F3::InstantiateScheduledExecution
            );
        if self.slots[i].wheelsets.is_none() {
            self.query_wheelsets(i);
        }
        let c = if null_instance {
            std::ptr::null_mut()
        } else {
            self.slots[i].c
        };
        let name = self.slots[i].name.clone();
        let from = self.slots[i].log.len();
        let (status, desc, d) = self.dispatch3(f, i, c, &name);
        if !null_instance {
            self.follow3(i, f, status);
        }
        stats.count3(f, status);
        stats
            .slowest_us
            .fetch_max(d.as_micros() as usize, Ordering::Relaxed);
        if f.unsupported() && status != Status::Error as c_int {
            self.fail(format!(
                "{desc}: returned {status} for a function these units refuse"
            ));
        }
        self.check_call(i, f.name(), &desc, status, null_instance, from);
    }

    /// `wheelsets` of FMI 3.0 instance `i` from the instance (after an FMU state of
    /// unknown origin was set); unknown when it cannot be read.
    fn query_wheelsets(&mut self, i: usize) {
        let s = &mut self.slots[i];
        let Some(w) = wheelsets_var(s.table3) else {
            return;
        };
        let mut n = 0u64;
        if unsafe { fmi3GetUInt64(s.c, &w.vr, 1, &mut n, 1) } == 0 {
            s.wheelsets = Some(n as usize);
        }
    }

    /// After the FMU state `p` was set on FMI 3.0 instance `i`: phase and wheelsets as
    /// when it was taken (Configuration Mode left: Instantiated), the time from the
    /// instance.
    pub fn restored(&mut self, i: usize, p: *mut c_void) {
        let saved = self.saved.get(&(p as usize)).copied();
        let s = &mut self.slots[i];
        match saved {
            Some(x) => {
                s.phase = match x.phase {
                    Mirror::Configuration => Mirror::Instantiated,
                    other => other,
                };
                s.wheelsets = x.wheelsets;
                s.t = x.t;
            }
            None => {
                s.phase = Mirror::Unknown;
                s.wheelsets = None;
            }
        }
        let mut t = 0.0;
        if unsafe { fmi3GetFloat64(s.c, &TIME_VR, 1, &mut t, 1) } == 0 {
            s.t = t;
        }
    }

    /// Follows the phase of FMI 3.0 instance `i` after `f` returned `status`.
    fn follow3(&mut self, i: usize, f: F3, status: c_int) {
        let s = &mut self.slots[i];
        s.phase = match (f, status) {
            (F3::EnterConfigurationMode, 0) => Mirror::Configuration,
            (F3::ExitConfigurationMode, 0) => Mirror::Instantiated,
            (F3::EnterInitializationMode, 0) => Mirror::Initialization,
            (F3::ExitInitializationMode, 0 | 1) => Mirror::Stepping,
            (F3::Terminate, 0) => Mirror::Terminated,
            (F3::Reset, 0) => {
                s.t = 0.0;
                s.wheelsets = Some(start_wheelsets(s.table3));
                Mirror::Instantiated
            }
            (F3::DoStep, 2) => Mirror::Ended,
            (F3::DoStep, 0 | 1) if s.phase != Mirror::Ended => Mirror::Stepping,
            _ => s.phase,
        };
    }

    /// Makes the call `f` on instance `i` (instance pointer `c`, which may be null,
    /// named `name`).
    fn dispatch3(&mut self, f: F3, i: usize, c: fmi3Instance, name: &str) -> Made {
        let valid = self.valid;
        let null_ptr = !valid && self.rng.random_ratio(1, 25);
        match f {
            F3::GetVersion => {
                let (p, d) = self.timed(format!("{name}: fmi3GetVersion()"), || fmi3GetVersion());
                if p.is_null() || unsafe { CStr::from_ptr(p) } != c"3.0" {
                    self.fail("fmi3GetVersion did not return \"3.0\"".into());
                }
                (0, f.name().into(), d)
            }
            F3::SetDebugLogging => self.set_debug_logging3(c, name, null_ptr),
            F3::EnterConfigurationMode => run!(
                self,
                name,
                "fmi3EnterConfigurationMode()",
                fmi3EnterConfigurationMode(c)
            ),
            F3::ExitConfigurationMode => run!(
                self,
                name,
                "fmi3ExitConfigurationMode()",
                fmi3ExitConfigurationMode(c)
            ),
            F3::EnterInitializationMode => {
                let (td, tol) = tolerance(&mut self.rng, valid);
                let (start, sd, stop) = experiment(&mut self.rng, valid);
                let r = run!(
                    self,
                    name,
                    format!(
                        "fmi3EnterInitializationMode(toleranceDefined {td}, {tol:?}, start \
                         {start:?}, stopTimeDefined {sd}, {stop:?})"
                    ),
                    fmi3EnterInitializationMode(c, td, tol, start, sd, stop)
                );
                if r.0 == 0 {
                    self.slots[i].t = start;
                }
                r
            }
            F3::ExitInitializationMode => run!(
                self,
                name,
                "fmi3ExitInitializationMode()",
                fmi3ExitInitializationMode(c)
            ),
            F3::Terminate => run!(self, name, "fmi3Terminate()", fmi3Terminate(c)),
            F3::Reset => run!(self, name, "fmi3Reset()", fmi3Reset(c)),
            F3::GetFloat64
            | F3::GetInt32
            | F3::GetInt64
            | F3::GetUInt64
            | F3::GetString
            | F3::SetFloat64
            | F3::SetInt32
            | F3::SetInt64
            | F3::SetUInt64
            | F3::SetString => self.value_call(f, i, c, name, null_ptr),
            F3::GetFMUState => self.state_call(StateOp::Get, i, c, name, null_ptr),
            F3::SetFMUState => self.state_call(StateOp::Set, i, c, name, null_ptr),
            F3::FreeFMUState => self.state_call(StateOp::Free, i, c, name, null_ptr),
            F3::SerializedFMUStateSize => self.state_call(StateOp::Size, i, c, name, null_ptr),
            F3::SerializeFMUState => self.state_call(StateOp::Serialize, i, c, name, null_ptr),
            F3::DeserializeFMUState => self.state_call(StateOp::Deserialize, i, c, name, null_ptr),
            F3::GetDirectionalDerivative | F3::GetAdjointDerivative => {
                self.derivative(f, i, c, name, null_ptr)
            }
            F3::GetOutputDerivatives => self.output_derivatives(i, c, name, null_ptr),
            F3::DoStep => self.do_step3(i, c, name),
            F3::InstantiateCoSimulation | F3::FreeInstance => unreachable!(),
            _ if f.absent_type() => self.absent_type(f, i, c, name, null_ptr),
            _ => self.refused(f, i, c, name, null_ptr),
        }
    }

    fn set_debug_logging3(&mut self, c: fmi3Instance, name: &str, null_ptr: bool) -> Made {
        let rng = &mut self.rng;
        let on = rng.random_bool(0.5);
        let names = [
            c"logStatusError",
            c"logStatusWarning",
            c"logCalls",
            c"logEvents",
            c"noSuchCategory",
        ];
        let n = rng.random_range(0..4);
        let mut cats: Vec<fmi3String> = (0..n)
            .map(|_| names[rng.random_range(0..names.len())].as_ptr())
            .collect();
        if null_ptr && n > 0 {
            cats[0] = std::ptr::null();
        }
        let nulled = !self.valid && rng.random_ratio(1, 30);
        run!(
            self,
            name,
            format!(
                "fmi3SetDebugLogging({on}, {n} categories{})",
                if nulled { ", null" } else { "" }
            ),
            fmi3SetDebugLogging(c, on, n, or_null(nulled, cats.as_ptr()))
        )
    }

    /// A get or set of Float64, Int32, Int64 (the Enumerations), UInt64 (`wheelsets`)
    /// or String: arrays sized by the wheelsets the test knows, right or wrong counts,
    /// null pointers.
    fn value_call(&mut self, f: F3, i: usize, c: fmi3Instance, name: &str, null_ptr: bool) -> Made {
        let valid = self.valid;
        let (table, n) = (self.slots[i].table3, self.slots[i].wheelsets.unwrap_or(1));
        let types: &[Type3] = match f {
            F3::GetFloat64 | F3::SetFloat64 => &[Type3::Float64],
            F3::GetInt32 | F3::SetInt32 => &[Type3::Int32],
            F3::GetInt64 | F3::SetInt64 => &[Type3::Enumeration],
            F3::GetUInt64 => &[Type3::Wheelsets, Type3::Constant],
            F3::SetUInt64 => &[Type3::Wheelsets],
            _ => &[Type3::String],
        };
        let get = matches!(
            f,
            F3::GetFloat64 | F3::GetInt32 | F3::GetInt64 | F3::GetUInt64 | F3::GetString
        );
        let rng = &mut self.rng;
        let vrs: Vec<u32> = if f == F3::GetFloat64 && rng.random_bool(0.15) {
            // Every Float64 variable, and the time.
            let all = table.vars.iter().filter(|v| v.ty == Type3::Float64);
            all.map(|v| v.vr).chain([TIME_VR]).collect()
        } else {
            refs3(rng, table, types, get, valid)
        };
        let specs = element_specs(table, &vrs, n);
        let nv = n_values(rng, specs.len(), valid);
        let null_values = !valid && rng.random_ratio(1, 25);
        let spec = |k: usize| specs.get(k).copied().flatten();
        let desc = |what: &str| format!("{}(vr={vrs:?}, nValues={nv}{what})", f.name());
        macro_rules! get {
            ($ffi:expr, $fill:expr) => {
                self.get_values(
                    desc(""),
                    name,
                    c,
                    &vrs,
                    nv,
                    $fill,
                    $ffi,
                    null_ptr,
                    null_values,
                )
            };
        }
        macro_rules! set {
            ($ffi:expr, $v:expr) => {{
                let d = desc(&format!(", {:?}", $v));
                self.set_values(d, name, c, &vrs, $v, $ffi, null_ptr, null_values)
            }};
        }
        let r = match f {
            F3::GetFloat64 => {
                let (r, out) = get!(fmi3GetFloat64, f64::NAN);
                if r.0 == 0
                    && !null_values
                    && let Some(k) = out.iter().position(|x| !x.is_finite())
                {
                    self.fail(format!(
                        "{}: fmi3GetFloat64 returned fmi3OK with `{}` = {}",
                        r.1,
                        value_name(table, &vrs, n, k),
                        out[k]
                    ));
                }
                r
            }
            F3::GetInt32 => get!(fmi3GetInt32, 0).0,
            F3::GetInt64 => get!(fmi3GetInt64, 0).0,
            F3::GetUInt64 => {
                let (r, out) = get!(fmi3GetUInt64, 0);
                if r.0 == 0 && !null_values {
                    let max = start_max(table);
                    if let Some(x) = out.iter().find(|&&x| x < 1 || x > max) {
                        self.fail(format!("{}: wheelsets = {x}; its range is 1 to {max}", r.1));
                    }
                    if let Some(&x) = out.first() {
                        self.slots[i].wheelsets = Some(x as usize);
                    }
                }
                r
            }
            F3::GetString => {
                let (r, out) = get!(fmi3GetString, std::ptr::null());
                if r.0 == 0 && !null_values {
                    if let Some(k) = out.iter().position(|p| p.is_null()) {
                        self.fail(format!(
                            "{}: fmi3OK with a null string for `{}`",
                            r.1,
                            value_name(table, &vrs, n, k)
                        ));
                    }
                    for p in &out {
                        // Readable until the next fmi3GetString.
                        let _ = unsafe { CStr::from_ptr(*p) }.to_bytes().len();
                    }
                }
                r
            }
            F3::SetFloat64 => {
                let v: Vec<f64> = (0..nv).map(|k| float64(rng, spec(k), valid)).collect();
                set!(fmi3SetFloat64, &v)
            }
            F3::SetInt32 => {
                let v: Vec<i32> = (0..nv).map(|k| int32(rng, spec(k), valid)).collect();
                set!(fmi3SetInt32, &v)
            }
            F3::SetInt64 => {
                let v: Vec<i64> = (0..nv).map(|k| int64(rng, spec(k), valid)).collect();
                set!(fmi3SetInt64, &v)
            }
            F3::SetUInt64 => {
                let max = start_max(table);
                let v: Vec<u64> = (0..nv).map(|_| wheelsets_value(rng, max, valid)).collect();
                let r = set!(fmi3SetUInt64, &v);
                if r.0 == 0
                    && let Some(&x) = v.last()
                {
                    self.slots[i].wheelsets = Some(x as usize);
                }
                r
            }
            _ => {
                let texts = [c"", c"text", c"none"];
                let mut v: Vec<fmi3String> = (0..nv)
                    .map(|_| texts[rng.random_range(0..texts.len())].as_ptr())
                    .collect();
                if null_values && nv > 0 {
                    v[0] = std::ptr::null();
                }
                self.set_values(desc(""), name, c, &vrs, &v, fmi3SetString, null_ptr, false)
            }
        };
        if r.0 == 0 && ((null_ptr && !vrs.is_empty()) || (null_values && nv > 0)) {
            self.fail(format!(
                "{}: fmi3OK with a null pointer and a count > 0",
                r.1
            ));
        }
        r
    }

    /// A get through `ffi` of `nv` values of `vrs` into a buffer filled with `fill`
    /// (null pointers for the references or the values when asked); the call and the
    /// buffer.
    #[allow(clippy::too_many_arguments)]
    pub fn get_values<T: Copy>(
        &mut self,
        desc: String,
        name: &str,
        c: fmi3Instance,
        vrs: &[u32],
        nv: usize,
        fill: T,
        ffi: Get<T>,
        null_vr: bool,
        null_out: bool,
    ) -> (Made, Vec<T>) {
        let mut out = vec![fill; nv];
        let (vp, op) = (
            or_null(null_vr, vrs.as_ptr()),
            or_null_mut(null_out, out.as_mut_ptr()),
        );
        let r = run!(self, name, desc, ffi(c, vp, vrs.len(), op, nv));
        (r, out)
    }

    /// A set through `ffi` of `values` of `vrs` (null pointers when asked).
    #[allow(clippy::too_many_arguments)]
    pub fn set_values<T: Debug>(
        &mut self,
        desc: String,
        name: &str,
        c: fmi3Instance,
        vrs: &[u32],
        values: &[T],
        ffi: Set<T>,
        null_vr: bool,
        null_in: bool,
    ) -> Made {
        let (vp, ip) = (
            or_null(null_vr, vrs.as_ptr()),
            or_null(null_in, values.as_ptr()),
        );
        run!(self, name, desc, ffi(c, vp, vrs.len(), ip, values.len()))
    }

    /// `fmi3DoStep` from the instance's time (or a bad clock) by a step of any size,
    /// with null out-pointers sometimes; the out-arguments of a step done must agree
    /// with it.
    fn do_step3(&mut self, i: usize, c: fmi3Instance, name: &str) -> Made {
        let valid = self.valid;
        let rng = &mut self.rng;
        let now = self.slots[i].t;
        let t = if valid || rng.random_bool(0.85) {
            now
        } else if rng.random_bool(0.5) {
            nasty(rng)
        } else {
            now + [1e-9, -1e-6, 1e-3, 1.0][rng.random_range(0..4)]
        };
        let h = step_size(rng, valid);
        let no_set = rng.random_bool(0.5);
        // eventHandlingNeeded, terminateSimulation, earlyReturn, lastSuccessfulTime.
        let nulls: [bool; 4] = std::array::from_fn(|_| !valid && rng.random_ratio(1, 40));
        let (mut event, mut end, mut early, mut last) = (true, false, false, f64::NAN);
        let r = run!(
            self,
            name,
            format!(
                "fmi3DoStep(t={t:?}, h={h:?}, noSetFMUStatePriorToCurrentPoint={no_set}{})",
                if nulls.contains(&true) {
                    format!(", null out-pointers {nulls:?}")
                } else {
                    String::new()
                }
            ),
            fmi3DoStep(
                c,
                t,
                h,
                no_set,
                or_null_mut(nulls[0], &mut event),
                or_null_mut(nulls[1], &mut end),
                or_null_mut(nulls[2], &mut early),
                or_null_mut(nulls[3], &mut last)
            )
        );
        if nulls.contains(&true) && r.0 == 0 {
            self.fail(format!("{}: fmi3OK with a null out-pointer", r.1));
        }
        if c.is_null() || nulls.contains(&true) {
            return r;
        }
        let tol = 64.0 * f64::EPSILON * (t + h).abs().max(t.abs());
        if r.0 <= 1 {
            // A step done.
            if event {
                self.fail(format!("{}: eventHandlingNeeded without Event Mode", r.1));
            }
            if early && !self.slots[i].early_return {
                self.fail(format!("{}: earlyReturn without earlyReturnAllowed", r.1));
            }
            let ok = match early {
                false => (last - (t + h)).abs() <= tol,
                true => last >= t - tol && last <= t + h + tol,
            };
            if !ok {
                self.fail(format!(
                    "{}: returned {} with lastSuccessfulTime = {last:?} from {t:?} by {h:?} \
                     and earlyReturn {early}; logged: {}",
                    r.1,
                    r.0,
                    self.slots[i].log.last()
                ));
            }
            self.slots[i].t = if early { last } else { t + h };
        }
        if r.0 <= 2 && !last.is_finite() {
            self.fail(format!("{}: lastSuccessfulTime = {last:?}", r.1));
        }
        if r.0 <= 2 && end {
            self.slots[i].phase = Mirror::Ended;
        }
        r
    }

    /// `fmi3GetDirectionalDerivative` (`sensitivity = J seed`) or
    /// `fmi3GetAdjointDerivative` (`sensitivity = J^T seed`) of Float64 outputs with
    /// respect to Float64 inputs, right or wrong counts, NaN and huge seeds; the
    /// sensitivities of fmi3OK must be finite.
    fn derivative(&mut self, f: F3, i: usize, c: fmi3Instance, name: &str, null_ptr: bool) -> Made {
        let valid = self.valid;
        let (table, n) = (self.slots[i].table3, self.slots[i].wheelsets.unwrap_or(1));
        let rng = &mut self.rng;
        let unknowns = float64_of(rng, table, "output", valid);
        let knowns = float64_of(rng, table, "input", valid);
        let (nu, nk) = (values_of(table, &unknowns, n), values_of(table, &knowns, n));
        let (n_seed, n_sens) = match f {
            F3::GetDirectionalDerivative => (nk, nu),
            _ => (nu, nk),
        };
        let (n_seed, n_sens) = (n_values(rng, n_seed, valid), n_values(rng, n_sens, valid));
        let seed: Vec<f64> = (0..n_seed)
            .map(|_| {
                if valid || rng.random_bool(0.8) {
                    rng.random_range(-1.0..1.0)
                } else {
                    nasty(rng)
                }
            })
            .collect();
        let mut out = vec![f64::NAN; n_sens];
        let null_out = !valid && rng.random_ratio(1, 25);
        let ffi = match f {
            F3::GetDirectionalDerivative => fmi3GetDirectionalDerivative,
            _ => fmi3GetAdjointDerivative,
        };
        let r = run!(
            self,
            name,
            format!(
                "{}(unknowns={unknowns:?}, knowns={knowns:?}, seed={seed:?}, nSensitivity={n_sens})",
                f.name()
            ),
            ffi(
                c,
                or_null(null_ptr, unknowns.as_ptr()),
                unknowns.len(),
                knowns.as_ptr(),
                knowns.len(),
                seed.as_ptr(),
                seed.len(),
                or_null_mut(null_out, out.as_mut_ptr()),
                n_sens
            )
        );
        if r.0 == 0 && ((null_ptr && !unknowns.is_empty()) || (null_out && n_sens > 0)) {
            self.fail(format!(
                "{}: fmi3OK with a null pointer and a count > 0",
                r.1
            ));
        }
        if r.0 == 0
            && !null_out
            && let Some(x) = out.iter().find(|x| !x.is_finite())
        {
            self.fail(format!("{}: fmi3OK with a sensitivity {x}", r.1));
        }
        r
    }

    /// `fmi3GetOutputDerivatives` of Float64 outputs, orders 1 to the FMU's most or
    /// (invalid) others; the derivatives of fmi3OK must be finite.
    fn output_derivatives(
        &mut self,
        i: usize,
        c: fmi3Instance,
        name: &str,
        null_ptr: bool,
    ) -> Made {
        let valid = self.valid;
        let (table, n) = (self.slots[i].table3, self.slots[i].wheelsets.unwrap_or(1));
        let rng = &mut self.rng;
        let vrs = float64_of(rng, table, "output", valid);
        let max = table.fmi2.max_output_derivative_order.max(1) as i32;
        let orders: Vec<i32> = vrs
            .iter()
            .map(|_| {
                if valid || rng.random_bool(0.8) {
                    rng.random_range(1..=max)
                } else {
                    [0, -1, max + 1, i32::MAX, i32::MIN][rng.random_range(0..5)]
                }
            })
            .collect();
        let nv = n_values(rng, values_of(table, &vrs, n), valid);
        let mut out = vec![f64::NAN; nv];
        let null_orders = !valid && rng.random_ratio(1, 25);
        let r = run!(
            self,
            name,
            format!("fmi3GetOutputDerivatives(vr={vrs:?}, orders={orders:?}, nValues={nv})"),
            fmi3GetOutputDerivatives(
                c,
                or_null(null_ptr, vrs.as_ptr()),
                vrs.len(),
                or_null(null_orders, orders.as_ptr()),
                out.as_mut_ptr(),
                nv
            )
        );
        if r.0 == 0 && (null_ptr || null_orders) && !vrs.is_empty() {
            self.fail(format!(
                "{}: fmi3OK with a null pointer and a count > 0",
                r.1
            ));
        }
        if r.0 == 0
            && let Some(x) = out.iter().find(|x| !x.is_finite())
        {
            self.fail(format!("{}: fmi3OK with an output derivative {x}", r.1));
        }
        r
    }
}

/// The most wheelsets `table`'s FMU can have (the range of its structural parameter,
/// or its constant).
fn start_max(table: &'static wheelflat::fmu::vars::Fmu3Table) -> u64 {
    match structural(table) {
        Some(v) => var2(table, v.vr).map_or(1, |s| s.max as u64),
        None => start_wheelsets(table) as u64,
    }
}

/// Prints every Float64 variable of FMI 3.0 instance `s` (`WHEELFLAT_FUZZ_STOP_AT`).
pub fn dump3(s: &Slot) {
    let table = s.table3;
    let n = s.wheelsets.unwrap_or(1);
    let vrs: Vec<u32> = table
        .vars
        .iter()
        .filter(|v| v.ty == Type3::Float64)
        .map(|v| v.vr)
        .chain([TIME_VR])
        .collect();
    let nv = values_of(table, &vrs, n);
    let mut x = vec![0.0; nv];
    let st = unsafe { fmi3GetFloat64(s.c, vrs.as_ptr(), vrs.len(), x.as_mut_ptr(), nv) };
    eprintln!(
        "{} ({}, FMI 3.0, wheelsets {n}), fmi3GetFloat64 -> {st}: {}",
        s.name,
        table.fmi2.model_identifier,
        s.log.last()
    );
    for (k, x) in x.iter().enumerate() {
        eprintln!("    {} = {x:?}", value_name(table, &vrs, n, k));
    }
}
