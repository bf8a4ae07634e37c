//! The C boundary in-process: concurrent calls on one instance (a second thread's call
//! refused as busy, two threads hammering one instance).

mod common;

use common::Fmu;
use std::ffi::c_int;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Barrier, Mutex, mpsc};
use std::time::{Duration, Instant};
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{COUPLED_SYSTEM, TRACK_CONTACT, vr};

const OK: c_int = 0;
const ERROR: c_int = 3;

/// A call of one instance from a second thread while the first is inside a call: the
/// logger of the first call blocks until the second thread has tried everything.
#[test]
fn a_second_thread_is_refused_while_a_call_runs() {
    let f = Arc::new(Fmu::with_logging(&TRACK_CONTACT, "busy", true));
    f.init();
    let (inside_tx, inside_rx) = mpsc::channel::<()>();
    let (done_tx, done_rx) = mpsc::channel::<()>();
    let armed = Arc::new(AtomicBool::new(true));
    {
        let armed = armed.clone();
        let inside_tx = Mutex::new(inside_tx);
        let done_rx = Mutex::new(done_rx);
        let hook: common::Hook = Box::new(move |r| {
            if r.message.starts_with("fmi2DoStep(") && armed.swap(false, Ordering::SeqCst) {
                inside_tx.lock().unwrap().send(()).unwrap();
                done_rx.lock().unwrap().recv().unwrap();
            }
        });
        *f.log.hook.lock().unwrap() = Some(Arc::new(hook));
    }
    let stepper = {
        let f = f.clone();
        std::thread::spawn(move || f.step(0.0, 1e-4))
    };
    inside_rx.recv().unwrap();
    // fmi2DoStep is running on the other thread (blocked in our logger).
    let n = f.log.len();
    let mut x = 0.0;
    let mut s: fmi2FMUstate = std::ptr::null_mut();
    unsafe {
        fmi2FreeInstance(f.c);
        assert_eq!(f.get(&[vr::CONTACT_LEFT_FORCE]).0, ERROR);
        assert_eq!(f.step(0.0, 1e-4), ERROR);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), ERROR);
        assert_eq!(fmi2GetFMUstate(f.c, &mut s), ERROR);
        assert_eq!(fmi2Reset(f.c), ERROR);
    }
    assert!(s.is_null());
    let m: Vec<String> = f.log.since(n).into_iter().map(|r| r.message).collect();
    assert_eq!(
        m[0],
        "fmi2FreeInstance: instance busy: fmi2FreeInstance called while fmi2DoStep is running \
         on another thread; the instance was not freed (FMI 2.0: one call at a time per instance)"
    );
    for (k, call) in [
        "fmi2GetReal",
        "fmi2DoStep",
        "fmi2GetRealStatus",
        "fmi2GetFMUstate",
        "fmi2Reset",
    ]
    .iter()
    .enumerate()
    {
        assert!(
            m[k + 1].starts_with(&format!(
                "{call}: instance busy: {call} called while fmi2DoStep is running on another thread"
            )),
            "{}",
            m[k + 1]
        );
    }
    assert_eq!(m.len(), 6);
    done_tx.send(()).unwrap();
    assert_eq!(stepper.join().unwrap(), OK, "the running step finished");
    // Nothing was touched: the instance continues (and is freed once, by Drop).
    unsafe {
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), OK);
    }
    assert_eq!(x, 1e-4);
    assert_eq!(f.step(1e-4, 1e-4), OK);
}

/// Two threads hammering one instance: one steps, one reads. No crash; some calls are
/// refused as busy; the refused calls change nothing (the stepping thread ends where an
/// instance alone ends after the same successful steps).
#[test]
fn two_threads_hammering_one_instance() {
    let f = Arc::new(Fmu::initialised(&COUPLED_SYSTEM, "hammer"));
    let outs = f.real_outputs();
    let h = 2e-5;
    let stop = Arc::new(AtomicBool::new(false));
    let busy_reads = Arc::new(AtomicUsize::new(0));
    let start = Arc::new(Barrier::new(2));
    let reader = {
        let (f, stop, busy_reads, start, outs) = (
            f.clone(),
            stop.clone(),
            busy_reads.clone(),
            start.clone(),
            outs.clone(),
        );
        std::thread::spawn(move || {
            start.wait();
            let mut ok = 0usize;
            while !stop.load(Ordering::Relaxed) {
                let (s, v) = f.get(&outs);
                match s {
                    OK => {
                        assert!(v.iter().all(|x| x.is_finite()));
                        ok += 1;
                    }
                    ERROR => {
                        busy_reads.fetch_add(1, Ordering::Relaxed);
                    }
                    s => panic!("fmi2GetReal returned {s}"),
                }
            }
            ok
        })
    };
    start.wait();
    let t0 = Instant::now();
    let (mut steps, mut busy_steps) = (0usize, 0usize);
    // At most 0.6 s of simulated time (the wheel leaves the track after about 1 s).
    while t0.elapsed() < Duration::from_secs(20)
        && steps < 30_000
        && (steps < 3000 || busy_steps < 20 || busy_reads.load(Ordering::Relaxed) < 20)
    {
        match f.step(steps as f64 * h, h) {
            OK => steps += 1,
            ERROR => busy_steps += 1,
            s => panic!("fmi2DoStep returned {s}"),
        }
        // A breath between steps, so that the reader gets in too (about 1 us).
        let pause = Instant::now();
        while pause.elapsed() < Duration::from_micros(1) {
            std::hint::spin_loop();
        }
    }
    stop.store(true, Ordering::Relaxed);
    let reads = reader.join().unwrap();
    let busy_reads = busy_reads.load(Ordering::Relaxed);
    eprintln!(
        "{steps} steps ({busy_steps} refused), {reads} reads ({busy_reads} refused) in {:.2} s",
        t0.elapsed().as_secs_f64()
    );
    assert!(
        busy_steps + busy_reads > 0,
        "no call was ever refused as busy"
    );
    // Every refusal was logged as busy, naming both functions.
    let text = f.log.text();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), busy_steps + busy_reads, "{text}");
    for l in lines {
        assert!(
            l == "fmi2DoStep: instance busy: fmi2DoStep called while fmi2GetReal is running on \
                  another thread; the call was refused and the instance left as it was (FMI \
                  2.0: one call at a time per instance)"
                || l == "fmi2GetReal: instance busy: fmi2GetReal called while fmi2DoStep is \
                         running on another thread; the call was refused and the instance left \
                         as it was (FMI 2.0: one call at a time per instance)",
            "{l}"
        );
    }
    // The same successful steps alone give the same outputs, bit for bit.
    let alone = Fmu::initialised(&COUPLED_SYSTEM, "alone");
    for k in 0..steps {
        assert_eq!(alone.step(k as f64 * h, h), OK);
    }
    assert_eq!(f.get(&outs), alone.get(&outs));
}
