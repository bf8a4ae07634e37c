//! Helpers of the in-process FMI tests: a C logger that records every message of an
//! instance, and an instance handle over the exported `extern "C"` functions.

#![allow(dead_code)]

use std::ffi::{CStr, CString, c_char, c_int, c_void};
use std::sync::Mutex;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::FmuTable;

/// One logged message.
#[derive(Debug, Clone)]
pub struct Record {
    /// The instance name the logger was given.
    pub instance: String,
    pub status: c_int,
    pub category: String,
    pub message: String,
}

/// Called after a message is recorded (outside the lock), on the thread that logs.
pub type Hook = Box<dyn Fn(&Record) + Send + Sync>;

/// The messages of one instance (the `componentEnvironment` of its callbacks).
#[derive(Default)]
pub struct Log {
    pub records: Mutex<Vec<Record>>,
    pub hook: Mutex<Option<std::sync::Arc<Hook>>>,
}

impl Log {
    pub fn len(&self) -> usize {
        self.records.lock().unwrap().len()
    }
    /// Messages from index `from` on.
    pub fn since(&self, from: usize) -> Vec<Record> {
        self.records.lock().unwrap()[from..].to_vec()
    }
    pub fn last(&self) -> String {
        self.records
            .lock()
            .unwrap()
            .last()
            .map(|r| r.message.clone())
            .unwrap_or_default()
    }
    pub fn text(&self) -> String {
        let r = self.records.lock().unwrap();
        r.iter()
            .map(|r| r.message.as_str())
            .collect::<Vec<_>>()
            .join("\n")
    }
}

/// The logger: a plain C function; the FMU passes the message as the format string with
/// '%' doubled and no further arguments, so it is called through the variadic
/// `fmi2CallbackLogger` type (same calling convention for the fixed arguments).
unsafe extern "C" fn record(
    env: fmi2ComponentEnvironment,
    name: fmi2String,
    status: fmi2Status,
    category: fmi2String,
    message: fmi2String,
) {
    let log = unsafe { &*(env as *const Log) };
    log.push(Record {
        instance: text(name),
        status,
        category: text(category),
        message: text(message).replace("%%", "%"),
    });
}

fn text(p: *const c_char) -> String {
    if p.is_null() {
        String::new()
    } else {
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }
}

impl Log {
    /// Records `r` and calls the hook.
    fn push(&self, r: Record) {
        self.records.lock().unwrap().push(r.clone());
        let hook = self.hook.lock().unwrap().clone();
        if let Some(h) = hook {
            h(&r);
        }
    }
}

/// The FMI 3.0 logger (`fmi3LogMessageCallback`, whose `instanceEnvironment` is the
/// [`Log`]): the message is plain text (no format string) and names no instance.
pub unsafe extern "C" fn record3(
    env: *mut c_void,
    status: c_int,
    category: *const c_char,
    message: *const c_char,
) {
    let log = unsafe { &*(env as *const Log) };
    log.push(Record {
        instance: String::new(),
        status,
        category: text(category),
        message: text(message),
    });
}

type Plain =
    unsafe extern "C" fn(fmi2ComponentEnvironment, fmi2String, fmi2Status, fmi2String, fmi2String);

type Variadic = unsafe extern "C" fn(
    fmi2ComponentEnvironment,
    fmi2String,
    fmi2Status,
    fmi2String,
    fmi2String,
    ...
);

/// Callbacks that record into `log`.
pub fn callbacks(log: &Log) -> fmi2CallbackFunctions {
    let f: Plain = record;
    fmi2CallbackFunctions {
        // SAFETY: see `record`.
        logger: Some(unsafe { std::mem::transmute::<Plain, Variadic>(f) }),
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: log as *const Log as *mut c_void,
    }
}

/// An instance made through `fmi2Instantiate`, freed on drop.
pub struct Fmu {
    pub c: fmi2Component,
    pub log: Box<Log>,
    pub table: &'static FmuTable,
}

// The tests hand the component to other threads on purpose.
unsafe impl Send for Fmu {}
unsafe impl Sync for Fmu {}

impl Fmu {
    pub fn new(table: &'static FmuTable, name: &str) -> Fmu {
        Self::with_logging(table, name, false)
    }

    pub fn with_logging(table: &'static FmuTable, name: &str, logging_on: bool) -> Fmu {
        let log = Box::<Log>::default();
        let cb = callbacks(&log);
        let name = CString::new(name).unwrap();
        let guid = CString::new(table.guid).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                name.as_ptr(),
                1,
                guid.as_ptr(),
                c"".as_ptr(),
                &cb,
                0,
                logging_on as c_int,
            )
        };
        assert!(!c.is_null(), "{}", log.text());
        Fmu { c, log, table }
    }

    /// Instantiated -> StepComplete with start values.
    pub fn initialised(table: &'static FmuTable, name: &str) -> Fmu {
        let f = Fmu::new(table, name);
        f.init();
        f
    }

    pub fn init(&self) {
        unsafe {
            assert_eq!(
                fmi2SetupExperiment(self.c, 0, 0.0, 0.0, 0, 0.0),
                0,
                "{}",
                self.log.last()
            );
            assert_eq!(
                fmi2EnterInitializationMode(self.c),
                0,
                "{}",
                self.log.last()
            );
            assert_eq!(fmi2ExitInitializationMode(self.c), 0, "{}", self.log.last());
        }
    }

    pub fn step(&self, t: f64, h: f64) -> c_int {
        unsafe { fmi2DoStep(self.c, t, h, 1) }
    }

    pub fn get(&self, vrs: &[u32]) -> (c_int, Vec<f64>) {
        let mut v = vec![f64::NAN; vrs.len()];
        let s = unsafe { fmi2GetReal(self.c, vrs.as_ptr(), vrs.len(), v.as_mut_ptr()) };
        (s, v)
    }

    /// Value references of this FMU's Real outputs.
    pub fn real_outputs(&self) -> Vec<u32> {
        use wheelflat::fmu::vars::{Causality, VarType};
        self.table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output && v.ty == VarType::Real)
            .map(|v| v.vr)
            .collect()
    }
}

impl Drop for Fmu {
    fn drop(&mut self) {
        unsafe { fmi2FreeInstance(self.c) };
    }
}
