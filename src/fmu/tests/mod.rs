//! Tests of the FMI layer with this project's models, through the Rust API of an
//! instance (the C boundary has its own in `tests/fmi_ffi.rs`, `tests/fmi_threads.rs` and
//! `tests/fmi_fuzz/`).

mod bounds;
mod clock;
mod fmi3;
mod fmu_states;
mod machine;
mod start;
mod tables;

pub(super) use crate::fmu::fmi2::{ALL, MAGIC};
pub(super) use crate::fmu::vars::{self, Causality, VarType, vr};
pub(super) use crate::fmu::*;
pub(super) use crate::sim::Simulation;
pub(super) use crate::sim::{Scenario, VehicleSpec};
pub(super) use std::sync::{Arc, Mutex};

pub(super) fn instance(kind: Kind) -> (Instance, Arc<Mutex<Vec<String>>>) {
    let log = Arc::new(Mutex::new(Vec::new()));
    let l2 = log.clone();
    let logger: Logger = Box::new(move |_, _, m| l2.lock().unwrap().push(m.to_string()));
    (Instance::new(kind.table(), "test", logger, false), log)
}

/// A new instance of `kind` on the thesis' fixed 30-span track (`track.window.ahead =
/// 0`; the default is the endless track).
pub(super) fn fixed_track_instance(kind: Kind) -> (Instance, Arc<Mutex<Vec<String>>>) {
    let (mut i, log) = instance(kind);
    i.set_real(&[vr::TRACK_WINDOW_AHEAD], &[0.0]).unwrap();
    (i, log)
}

/// A calculated parameter or output of `i`.
pub(super) fn real(i: &mut Instance, r: u32) -> f64 {
    let mut x = [0.0];
    i.get_real(&[r], &mut x).unwrap();
    x[0]
}

/// The coupled simulation of a track-carrying instance.
pub(super) fn simulation(i: &Instance) -> &Simulation {
    i.model()
        .and_then(FmuModel::simulation)
        .expect("a track-carrying model")
}

pub(super) fn coupled(start: f64, params: &[(u32, f64)], integers: &[(u32, i32)]) -> Instance {
    let (mut i, _) = instance(Kind::CoupledSystem);
    i.setup_experiment(start, None).unwrap();
    for &(r, x) in params {
        i.set_real(&[r], &[x]).unwrap();
    }
    for &(r, x) in integers {
        i.set_integer(&[r], &[x]).unwrap();
    }
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i
}

pub(super) const FORCES: [u32; 4] = [
    vr::CONTACT_LEFT_FORCE,
    vr::CONTACT_RIGHT_FORCE,
    vr::WHEEL_LEFT_Z,
    vr::POSITION,
];

/// A step that went through: `fmi2OK`, or `fmi2Warning` when `warned` (a communication
/// step beyond what the contact exchange tolerates, say, taken and warned of).
pub(super) fn stepped(r: crate::fmu::fmi2::FmiResult, warned: bool) {
    match r {
        Ok(()) => assert!(!warned, "a warning was expected"),
        Err(e) if warned && e.status == Status::Warning => {}
        Err(e) => panic!("{e:?}"),
    }
}
