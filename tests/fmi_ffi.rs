//! The C boundary in-process: the state table through the exported functions,
//! fmi2Boolean arguments, FMU-state ownership, instance names and state buffers
//! (concurrent calls on one instance: `fmi_threads.rs`).

mod common;

use common::{Fmu, Log, callbacks};
use std::ffi::{CString, c_int};
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{COUPLED_SYSTEM, ROLL_PLANE_VEHICLE, TRACK_CONTACT, vr};

const OK: c_int = 0;
const DISCARD: c_int = 2;
const ERROR: c_int = 3;

// ------------------------------------------------------------------ state machine

#[test]
fn terminate_and_status_calls_follow_the_state_table() {
    let f = Fmu::new(&TRACK_CONTACT, "t");
    let (mut x, mut b) = (0.0, 0);
    unsafe {
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), ERROR);
        assert!(
            f.log
                .last()
                .starts_with("fmi2GetRealStatus is not allowed in state Instantiated")
        );
        assert_eq!(fmi2GetBooleanStatus(f.c, 3, &mut b), ERROR);
        assert!(
            f.log
                .last()
                .starts_with("fmi2GetBooleanStatus is not allowed in state Instantiated")
        );
        assert_eq!(fmi2EnterInitializationMode(f.c), OK);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), ERROR);
        assert!(f.log.last().contains("in state Initialization"));
        assert_eq!(fmi2GetBooleanStatus(f.c, 3, &mut b), ERROR);
        assert_eq!(fmi2Terminate(f.c), ERROR);
        assert_eq!(
            f.log.last(),
            "fmi2Terminate is not allowed in state Initialization; allowed in: StepComplete, StepFailed"
        );
        assert_eq!(fmi2ExitInitializationMode(f.c), OK);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), OK);
        assert_eq!(fmi2GetBooleanStatus(f.c, 3, &mut b), OK);
        assert_eq!(b, 0);
        assert_eq!(f.step(0.0, 1e-4), OK);
        assert_eq!(fmi2Terminate(f.c), OK);
        assert_eq!(fmi2Terminate(f.c), ERROR);
        assert!(
            f.log
                .last()
                .starts_with("fmi2Terminate is not allowed in state Terminated"),
            "{}",
            f.log.last()
        );
        // Terminated: outputs and status can still be read.
        assert_eq!(f.get(&[vr::CONTACT_LEFT_FORCE]).0, OK);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), OK);
        assert_eq!(x, 1e-4);
        assert_eq!(fmi2Reset(f.c), OK);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), ERROR);
    }
}

#[test]
fn after_the_run_ended_steps_are_refused_but_outputs_and_terminate_allowed() {
    // The thesis' fixed 30-span track, which the wheel leaves (the default track is
    // endless).
    let f = Fmu::new(&COUPLED_SYSTEM, "c");
    unsafe {
        assert_eq!(fmi2SetReal(f.c, &vr::TRACK_WINDOW_AHEAD, 1, &0.0), 0);
    }
    f.init();
    assert_eq!(f.step(0.0, 0.01), OK);
    assert_eq!(f.step(0.01, 5.0), DISCARD);
    assert!(
        f.log.last().contains("outside the track"),
        "{}",
        f.log.last()
    );
    let before = f.get(&f.real_outputs());
    assert_eq!(before.0, OK);
    for h in [1e-4, 0.01, 5.0] {
        let n = f.log.len();
        assert_eq!(f.step(0.01, h), ERROR);
        let m = f.log.since(n);
        assert_eq!(m.len(), 1, "one message per refusal");
        assert!(
            m[0].message.starts_with(
                "fmi2DoStep is not allowed in state StepFailed; allowed in: StepComplete; \
                 the model ended the run at t = 0.01 s"
            ) && m[0].message.contains("use fmi2Reset"),
            "{}",
            m[0].message
        );
    }
    // The refused steps changed nothing.
    assert_eq!(f.get(&f.real_outputs()).1, before.1);
    let (mut x, mut b) = (0.0, 0);
    unsafe {
        assert_eq!(fmi2GetBooleanStatus(f.c, 3, &mut b), OK);
        assert_eq!(b, 1);
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut x), OK);
        assert_eq!(x, 0.01);
        let v = [0.0];
        assert_eq!(fmi2SetReal(f.c, &vr::SPEED, 1, v.as_ptr()), ERROR);
        assert_eq!(fmi2Terminate(f.c), OK);
        assert_eq!(fmi2GetBooleanStatus(f.c, 3, &mut b), OK);
        assert_eq!(b, 1);
        assert_eq!(f.step(0.01, 1e-4), ERROR);
        assert!(f.log.last().contains("in state Terminated"));
        // fmi2Reset starts again.
        assert_eq!(fmi2Reset(f.c), OK);
    }
    f.init();
    assert_eq!(f.step(0.0, 1e-4), OK);
}

// ------------------------------------------------------------------ fmi2Boolean

#[test]
fn booleans_other_than_true_and_false_are_refused() {
    // fmi2Instantiate: logged through the callback, NULL returned.
    for (visible, logging_on, what, v) in [
        (2, 0, "visible", 2),
        (0, -1, "loggingOn", -1),
        (1, 256, "loggingOn", 256),
    ] {
        let log = Box::<Log>::default();
        let cb = callbacks(&log);
        let guid = CString::new(TRACK_CONTACT.guid).unwrap();
        let c = unsafe {
            fmi2Instantiate(
                c"b".as_ptr(),
                1,
                guid.as_ptr(),
                c"".as_ptr(),
                &cb,
                visible,
                logging_on,
            )
        };
        assert!(c.is_null());
        assert_eq!(
            log.last(),
            format!(
                "fmi2Instantiate: argument `{what}` = {v} is not an fmi2Boolean; allowed: fmi2True (1) or fmi2False (0)"
            )
        );
    }
    let f = Fmu::new(&TRACK_CONTACT, "b");
    let refused = |status: c_int, what: &str, v: c_int, call: &str| {
        assert_eq!(status, ERROR);
        assert_eq!(
            f.log.last(),
            format!(
                "{call}: argument `{what}` = {v} is not an fmi2Boolean; allowed: fmi2True (1) or fmi2False (0)"
            )
        );
    };
    unsafe {
        refused(
            fmi2SetDebugLogging(f.c, 2, 0, std::ptr::null()),
            "loggingOn",
            2,
            "fmi2SetDebugLogging",
        );
        refused(
            fmi2SetupExperiment(f.c, 7, 1e-6, 0.0, 0, 0.0),
            "toleranceDefined",
            7,
            "fmi2SetupExperiment",
        );
        refused(
            fmi2SetupExperiment(f.c, 0, 0.0, 0.0, -1, 0.5),
            "stopTimeDefined",
            -1,
            "fmi2SetupExperiment",
        );
        // True and false are accepted; a refused stopTimeDefined set no stop time.
        assert_eq!(fmi2SetDebugLogging(f.c, 1, 0, std::ptr::null()), OK);
        assert_eq!(fmi2SetDebugLogging(f.c, 0, 0, std::ptr::null()), OK);
        assert_eq!(fmi2SetupExperiment(f.c, 1, 1e-6, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(f.c), OK);
        assert_eq!(fmi2ExitInitializationMode(f.c), OK);
        refused(
            fmi2DoStep(f.c, 0.0, 1e-4, 2),
            "noSetFMUStatePriorToCurrentPoint",
            2,
            "fmi2DoStep",
        );
        let mut t = -1.0;
        assert_eq!(fmi2GetRealStatus(f.c, 2, &mut t), OK);
        assert_eq!(t, 0.0, "the refused step did not step");
        assert_eq!(fmi2DoStep(f.c, 0.0, 1e-4, 0), OK);
        assert_eq!(fmi2DoStep(f.c, 1e-4, 1e-4, 1), OK);
        let vrs = [0u32, 1];
        let vals = [1, 42];
        refused(
            fmi2SetBoolean(f.c, vrs.as_ptr(), 2, vals.as_ptr()),
            "value[1]",
            42,
            "fmi2SetBoolean",
        );
        // Proper booleans get the refusal for the value reference (no Boolean variables).
        let vals = [1, 0];
        assert_eq!(fmi2SetBoolean(f.c, vrs.as_ptr(), 2, vals.as_ptr()), ERROR);
        assert!(f.log.last().contains("unknown value reference 0"));
        assert_eq!(fmi2SetBoolean(f.c, vrs.as_ptr(), 0, vals.as_ptr()), OK);
    }
}

// ------------------------------------------------------------------ FMU states

/// Pointers that must never be dereferenced: unmapped addresses (a dereference would
/// crash the test) and a live object that is not an FMU state.
fn foreign_pointers(local: &mut f64) -> [fmi2FMUstate; 3] {
    [
        8 as fmi2FMUstate,
        usize::MAX as fmi2FMUstate,
        local as *mut f64 as fmi2FMUstate,
    ]
}

#[test]
fn a_state_is_used_only_by_the_instance_that_handed_it_out() {
    let a = Fmu::initialised(&TRACK_CONTACT, "a");
    let b = Fmu::initialised(&TRACK_CONTACT, "b");
    let outs = [vr::CONTACT_LEFT_FORCE, vr::RAIL_LEFT_Z];
    unsafe {
        assert_eq!(a.step(0.0, 1e-3), OK);
        let mut sa: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(a.c, &mut sa), OK);
        assert!(!sa.is_null());
        let at = a.get(&outs).1;

        // Another instance's state: refused without use, whatever the call.
        let not_ours = |m: &str, call: &str| {
            assert!(
                m.starts_with(call) && m.contains("is not an FMU state of this instance"),
                "{m}"
            );
        };
        assert_eq!(fmi2SetFMUstate(b.c, sa), ERROR);
        not_ours(&b.log.last(), "fmi2SetFMUstate");
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(b.c, sa, &mut size), ERROR);
        not_ours(&b.log.last(), "fmi2SerializedFMUstateSize");
        let mut buf = vec![0 as fmi2Byte; 1 << 16];
        assert_eq!(
            fmi2SerializeFMUstate(b.c, sa, buf.as_mut_ptr(), buf.len()),
            ERROR
        );
        not_ours(&b.log.last(), "fmi2SerializeFMUstate");
        let mut copy = sa;
        assert_eq!(fmi2GetFMUstate(b.c, &mut copy), ERROR, "no overwrite");
        not_ours(&b.log.last(), "fmi2GetFMUstate");
        assert_eq!(copy, sa);
        assert_eq!(fmi2FreeFMUstate(b.c, &mut copy), ERROR);
        not_ours(&b.log.last(), "fmi2FreeFMUstate");
        assert_eq!(copy, sa, "a refused free leaves the pointer");

        // Still a valid state of a: it continues bit-identically.
        assert_eq!(a.step(1e-3, 1e-3), OK);
        assert_eq!(fmi2SetFMUstate(a.c, sa), OK);
        assert_eq!(a.get(&outs).1, at);

        // Freed once through a (with a copy of the pointer kept): every later use is
        // refused, also a second free.
        let kept = sa;
        assert_eq!(fmi2FreeFMUstate(a.c, &mut sa), OK);
        assert!(sa.is_null());
        assert_eq!(fmi2FreeFMUstate(a.c, &mut sa), OK, "NULL: nothing to free");
        let mut again = kept;
        assert_eq!(fmi2FreeFMUstate(a.c, &mut again), ERROR, "double free");
        not_ours(&a.log.last(), "fmi2FreeFMUstate");
        assert_eq!(fmi2SetFMUstate(a.c, kept), ERROR, "use after free");
        not_ours(&a.log.last(), "fmi2SetFMUstate");

        // Foreign pointers.
        let mut local = 1.0;
        for p in foreign_pointers(&mut local) {
            assert_eq!(fmi2SetFMUstate(a.c, p), ERROR);
            not_ours(&a.log.last(), "fmi2SetFMUstate");
            assert_eq!(fmi2SerializedFMUstateSize(a.c, p, &mut size), ERROR);
            let mut q = p;
            assert_eq!(fmi2FreeFMUstate(a.c, &mut q), ERROR);
            assert_eq!(q, p);
            assert_eq!(fmi2GetFMUstate(a.c, &mut q), ERROR);
            assert_eq!(q, p);
        }
        assert_eq!(local, 1.0);
        assert_eq!(a.step(1e-3, 1e-3), OK, "a still usable");
        assert_eq!(b.step(0.0, 1e-3), OK, "b still usable");
    }
}

#[test]
fn get_and_deserialize_overwrite_only_own_states_in_place() {
    let a = Fmu::initialised(&COUPLED_SYSTEM, "a");
    let b = Fmu::initialised(&COUPLED_SYSTEM, "b");
    let outs = a.real_outputs();
    unsafe {
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(a.c, &mut s), OK);
        let first = s;
        assert_eq!(a.step(0.0, 2e-3), OK);
        let at = a.get(&outs).1;
        // Overwritten in place: same pointer, new content.
        assert_eq!(fmi2GetFMUstate(a.c, &mut s), OK);
        assert_eq!(s, first);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(a.c, s, &mut size), OK);
        let mut blob = vec![0 as fmi2Byte; size];
        assert_eq!(fmi2SerializeFMUstate(a.c, s, blob.as_mut_ptr(), size), OK);
        assert_eq!(a.step(2e-3, 2e-3), OK);
        assert_eq!(fmi2SetFMUstate(a.c, s), OK);
        assert_eq!(a.get(&outs).1, at);

        // Deserialize into b: a new state of b; into a's state through b: refused.
        let mut sb: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(b.c, blob.as_ptr(), size, &mut sb),
            OK
        );
        let mut via_b = s;
        assert_eq!(
            fmi2DeSerializeFMUstate(b.c, blob.as_ptr(), size, &mut via_b),
            ERROR
        );
        assert!(
            b.log
                .last()
                .contains("is not an FMU state of this instance")
        );
        assert_eq!(via_b, s);
        // Deserialize over b's own state: in place.
        let keep = sb;
        assert_eq!(
            fmi2DeSerializeFMUstate(b.c, blob.as_ptr(), size, &mut sb),
            OK
        );
        assert_eq!(sb, keep);
        assert_eq!(fmi2SetFMUstate(b.c, sb), OK);
        assert_eq!(b.get(&outs).1, at);
        // States left unfreed are freed with their instance (checked under valgrind).
        let mut extra: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(b.c, &mut extra), OK);
    }
}

#[test]
fn free_instance_frees_its_states_and_null_components_are_refused() {
    unsafe {
        assert_eq!(fmi2DoStep(std::ptr::null_mut(), 0.0, 1e-4, 1), ERROR);
        fmi2FreeInstance(std::ptr::null_mut());
        let mut s: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(fmi2GetFMUstate(std::ptr::null_mut(), &mut s), ERROR);
    }
    for t in [&TRACK_CONTACT, &ROLL_PLANE_VEHICLE, &COUPLED_SYSTEM] {
        let f = Fmu::initialised(t, "states");
        for _ in 0..5 {
            let mut s: fmi2FMUstate = std::ptr::null_mut();
            assert_eq!(unsafe { fmi2GetFMUstate(f.c, &mut s) }, OK);
        }
        // Dropped: fmi2FreeInstance frees the five states (valgrind: no leak).
    }
}

/// `fmi2Instantiate` with the raw bytes `name` (NUL-terminated by this function) as the
/// instance name: the component (null when refused) and the log.
fn instantiate_named(name: Option<&[u8]>) -> (fmi2Component, Box<Log>) {
    let log = Box::<Log>::default();
    let cb = callbacks(&log);
    let guid = CString::new(TRACK_CONTACT.guid).unwrap();
    let owned = name.map(|n| CString::new(n).unwrap());
    let ptr = owned.as_ref().map_or(std::ptr::null(), |n| n.as_ptr());
    let c = unsafe { fmi2Instantiate(ptr, 1, guid.as_ptr(), c"".as_ptr(), &cb, 0, 0) };
    (c, log)
}

#[test]
fn instance_names_are_non_empty_and_logged_as_given() {
    // Issue 25: FMI 2.0 requires a non-empty instance name; blanks are no name either.
    for name in [None, Some(&b""[..]), Some(&b"   "[..])] {
        let (c, log) = instantiate_named(name);
        assert!(c.is_null(), "{name:?}");
        assert!(
            log.last().contains("FMI 2.0 requires a non-empty name"),
            "{}",
            log.last()
        );
    }
    // A name that is not UTF-8 is logged with its bytes escaped, not replaced.
    let (c, log) = instantiate_named(Some(b"wheel\xff\xfe1"));
    assert!(!c.is_null());
    let f = Fmu {
        c,
        log,
        table: &TRACK_CONTACT,
    };
    unsafe {
        assert_eq!(fmi2SetupExperiment(f.c, 0, 0.0, 0.0, 1, -1.0), 3);
    }
    let records = f.log.records.lock().unwrap().clone();
    let instance = &records.last().unwrap().instance;
    assert_eq!(instance, "wheel\\xff\\xfe1");
}

#[test]
fn an_empty_experiment_is_accepted_and_a_larger_state_buffer_too() {
    // Issue 25: stopTime == startTime is a legal (empty) experiment; a serialization
    // buffer larger than the announced size is legal, and the padded bytes deserialize.
    let f = Fmu::new(&TRACK_CONTACT, "e");
    unsafe {
        assert_eq!(
            fmi2SetupExperiment(f.c, 0, 0.0, 0.0, 1, 0.0),
            0,
            "{}",
            f.log.text()
        );
    }
    let f = Fmu::initialised(&TRACK_CONTACT, "s");
    assert_eq!(f.step(0.0, 1e-4), 0);
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    let mut size = 0usize;
    unsafe {
        assert_eq!(fmi2GetFMUstate(f.c, &mut state), 0);
        assert_eq!(fmi2SerializedFMUstateSize(f.c, state, &mut size), 0);
        let mut buffer = vec![7 as fmi2Byte; size + 100];
        assert_eq!(
            fmi2SerializeFMUstate(f.c, state, buffer.as_mut_ptr(), buffer.len()),
            0,
            "{}",
            f.log.text()
        );
        assert!(buffer[size..].iter().all(|&b| b == 0));
        let mut back: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(f.c, buffer.as_ptr(), buffer.len(), &mut back),
            0,
            "{}",
            f.log.text()
        );
        // Damage after the state is still refused.
        buffer[size + 50] = 1;
        let mut bad: fmi2FMUstate = std::ptr::null_mut();
        assert_eq!(
            fmi2DeSerializeFMUstate(f.c, buffer.as_ptr(), buffer.len(), &mut bad),
            3
        );
        // Too small a buffer is refused.
        assert_eq!(
            fmi2SerializeFMUstate(f.c, state, buffer.as_mut_ptr(), size - 1),
            3
        );
        assert_eq!(fmi2SetFMUstate(f.c, back), 0);
        fmi2FreeFMUstate(f.c, &mut back);
        fmi2FreeFMUstate(f.c, &mut state);
    }
}
