//! The state machine, the variable table and value access.

use super::*;

#[test]
fn default_start_values_are_the_reference_scenario() {
    // Table 4.4 with the reference flat, on the endless track's default window.
    let (i, _) = instance(Kind::CoupledSystem);
    let mut reference = Scenario::table_4_4_flat();
    reference.window = Some(crate::sim::TrackWindow::DEFAULT);
    let mut a = Simulation::new(&i.scenario()).unwrap();
    let mut b = Simulation::new(&reference).unwrap();
    for _ in 0..3000 {
        assert_eq!(a.step().unwrap(), b.step().unwrap());
    }
    // The literal handshake defaults of the table equal what the models compute.
    let w = match Scenario::table_4_4().vehicle {
        VehicleSpec::RollPlane(p) => p.static_wheel_load(),
        _ => unreachable!(),
    };
    let (t, _) = instance(Kind::TrackContact);
    assert_eq!(t.value(vr::STATIC_LOAD_LEFT), w);
    let sim = Simulation::new(&t.scenario()).unwrap();
    assert_eq!(t.value(vr::WHEEL_LEFT_Z), sim.wheel_z()[0]);
    let (v, _) = instance(Kind::ROLL_PLANE_VEHICLE);
    assert_eq!(v.value(vr::STATIC_WHEEL_Z_LEFT), sim.wheel_z()[0]);
    assert_eq!(v.value(vr::CONTACT_LEFT_FORCE), w);
}

#[test]
fn docs_variables_md_is_the_generated_file() {
    // The build script (build/) generates it from the table; a stale copy fails here.
    assert!(
        include_str!("../../../docs/VARIABLES.md") == vars::VARIABLES_MD,
        "docs/VARIABLES.md is stale: run `cargo build --release && cargo run --release \
         --bin build_fmus -- fmu docs/VARIABLES.md`"
    );
    for t in vars::FMUS {
        for v in t.vars {
            assert!(vars::VARIABLES_MD.contains(&format!("| `{}` |", v.name)));
        }
    }
    // One causality column per FMU, the FMI 3.0 name, and every row as wide as the
    // header.
    let header = vars::VARIABLES_MD
        .lines()
        .find(|l| l.starts_with("| name |"))
        .expect("the table's header");
    let cells = |l: &str| l.matches('|').count() - 1;
    assert_eq!(cells(header), 7 + vars::FMUS.len(), "{header}");
    for row in vars::VARIABLES_MD.lines().filter(|l| l.starts_with("| `")) {
        assert_eq!(cells(row), cells(header), "{row}");
    }
}

#[test]
fn refusals_name_the_variable_and_leave_the_instance_usable() {
    let (mut i, log) = instance(Kind::TrackContact);
    assert!(i.do_step(0.0, 1e-5).is_err());
    let e = i.set_real(&[vr::TRACK_PAD_STIFFNESS], &[-1.0]).unwrap_err();
    assert_eq!(e.status, Status::Error);
    assert!(
        e.message.contains("`track.pad.stiffness` = -1 N/m"),
        "{}",
        e.message
    );
    assert_eq!(
        i.value(vr::TRACK_PAD_STIFFNESS),
        140e6,
        "a refused set changes nothing"
    );
    let e = i.set_integer(&[vr::TRACK_SPANS], &[1]).unwrap_err();
    assert!(e.message.contains("`track.spans` = 1"), "{}", e.message);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.do_step(0.0, 1e-4).unwrap();
    let mut p = [0.0];
    i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
    assert!((p[0] - 107.66e3).abs() < 2e3);
    assert_eq!(log.lock().unwrap().len(), 3, "each refusal logged once");
}

#[test]
fn the_state_table_lists_every_function_once_in_enum_order() {
    for (k, (call, name, _)) in CALLS.iter().enumerate() {
        assert_eq!(*call as usize, k, "{name}");
        assert_eq!(call.name(), *name);
        assert_eq!(Call::from_name(name), Some(*call));
    }
    for p in ALL {
        assert_eq!(Phase::from_u8(*p as u8), Some(*p));
    }
    assert_eq!(Phase::from_u8(6), None);
}

#[test]
fn terminate_and_status_follow_the_state_table() {
    let (mut i, log) = instance(Kind::TrackContact);
    let last = |log: &Arc<Mutex<Vec<String>>>| log.lock().unwrap().last().cloned().unwrap();
    for call in [Call::GetRealStatus, Call::GetBooleanStatus, Call::Terminate] {
        assert_eq!(i.check(call).unwrap_err().status, Status::Error);
        let m = last(&log);
        assert!(
            m.starts_with(&format!(
                "{} is not allowed in state Instantiated",
                call.name()
            )),
            "{m}"
        );
    }
    i.enter_initialization().unwrap();
    for call in [Call::GetRealStatus, Call::GetBooleanStatus] {
        assert!(i.check(call).is_err());
        assert!(last(&log).contains("in state Initialization"));
    }
    let e = i.terminate().unwrap_err();
    assert_eq!(
        e.message,
        "fmi2Terminate is not allowed in state Initialization; allowed in: StepComplete, StepFailed"
    );
    i.exit_initialization().unwrap();
    i.check(Call::GetRealStatus).unwrap();
    i.terminate().unwrap();
    assert_eq!(i.phase(), Phase::Terminated);
    let e = i.terminate().unwrap_err();
    assert!(
        e.message
            .starts_with("fmi2Terminate is not allowed in state Terminated"),
        "{}",
        e.message
    );
    assert!(e.message.contains("fmi2Reset"), "{}", e.message);
    i.check(Call::GetBooleanStatus).unwrap();
    i.reset().unwrap();
    assert_eq!(i.phase(), Phase::Instantiated);
    assert!(i.check(Call::GetRealStatus).is_err());
}

#[test]
fn after_the_model_ended_the_run_steps_are_refused_and_outputs_readable() {
    let (mut i, log) = fixed_track_instance(Kind::CoupledSystem);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.do_step(0.0, 0.01).unwrap();
    let e = i.do_step(0.01, 5.0).unwrap_err();
    assert_eq!(e.status, Status::Discard);
    assert_eq!(i.phase(), Phase::StepFailed);
    assert!(i.terminated_by_model());
    assert_eq!(i.last_successful_time(), 0.01);
    let n = log.lock().unwrap().len();
    for h in [1e-4, 5.0] {
        let e = i.do_step(0.01, h).unwrap_err();
        assert_eq!(e.status, Status::Error);
        assert!(
            e.message
                .starts_with("fmi2DoStep is not allowed in state StepFailed; allowed in: StepComplete; the model ended the run at t = 0.01 s"),
            "{}",
            e.message
        );
        assert!(e.message.contains("use fmi2Reset"), "{}", e.message);
    }
    assert_eq!(log.lock().unwrap().len(), n + 2, "each refusal logged");
    // Inputs can no longer be set; outputs and status can be read.
    assert!(i.set_real(&[vr::SPEED], &[10.0]).is_err());
    let mut p = [0.0];
    i.get_real(&[vr::POSITION], &mut p).unwrap();
    // The track stands at its grid point nearest 0.01 s.
    let dt = real(&mut i, vr::SOLVER_STEP);
    assert!((p[0] - (1.37 + (0.01 / dt).round() * dt * 70.0 / 3.6)).abs() < 1e-9);
    i.check(Call::GetRealStatus).unwrap();
    i.check(Call::GetBooleanStatus).unwrap();
    // A state taken here restores the failed step.
    let s = i.get_state().unwrap();
    let b = i.serialize(&s).unwrap();
    i.terminate().unwrap();
    assert_eq!(i.phase(), Phase::Terminated);
    assert!(i.terminated_by_model());
    let d = i.deserialize(&b).unwrap();
    i.set_state(&d).unwrap();
    assert_eq!(i.phase(), Phase::StepFailed);
    assert!(i.do_step(0.01, 1e-4).is_err());
    i.reset().unwrap();
    assert!(!i.terminated_by_model());
    assert_eq!(i.phase(), Phase::Instantiated);
}

#[test]
fn a_serialized_state_with_numbers_an_instance_cannot_hold_is_refused() {
    let (mut i, _) = instance(Kind::ROLL_PLANE_VEHICLE);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.do_step(0.0, 1e-3).unwrap();
    let s = i.get_state().unwrap();
    let b = i.serialize(&s).unwrap();
    assert!(i.deserialize(&b).is_ok());
    let put = |at: usize, x: f64| {
        let mut c = b.clone();
        c[at..at + 8].copy_from_slice(&x.to_le_bytes());
        c
    };
    let guid = i.table().guid.len();
    let time_at = MAGIC.len() + 8 + guid + 3;
    // time, start time, the reason's length (0), the calculated parameters (seven and
    // two static wheel heights per trailing wheelset), the value count
    let values_at = time_at + 8 * (3 + 7 + 2 * crate::fmu::vars::TRAILING) + 8;
    for (at, x, why) in [
        (b.len() - 8, f64::NAN, "model state"),
        (b.len() - 8, f64::INFINITY, "model state"),
        (time_at, -1.0, "stored time"),
        (time_at + 8, f64::NAN, "start time NaN"),
        (time_at + 24, f64::NAN, "calculated parameter"),
        (values_at + 8 * vr::SPEED as usize, -5.0, "`speed` = -5"),
        (
            values_at + 8 * vr::GRAVITY as usize,
            f64::NAN,
            "`gravity` = NaN",
        ),
    ] {
        let e = i.deserialize(&put(at, x)).unwrap_err();
        assert!(e.message.contains(why), "{why}: {}", e.message);
    }
}

#[test]
fn every_output_of_every_fmu_reads_its_quantity_from_the_engine() {
    for kind in Kind::ALL {
        let (mut i, _) = instance(kind);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        i.do_step(0.0, 1e-3).unwrap();
        for v in kind.table().vars {
            if matches!(v.causality, Causality::Parameter | Causality::Input) {
                continue;
            }
            assert!(
                vars::QUANTITIES[v.vr as usize].is_some(),
                "{kind:?}: `{}` has no quantity",
                v.name
            );
            let x = if v.ty == vars::VarType::Real {
                real(&mut i, v.vr)
            } else {
                let mut n = [0];
                i.get_integer(&[v.vr], &mut n).unwrap();
                n[0] as f64
            };
            assert!(x.is_finite(), "{kind:?}: `{}` = {x}", v.name);
        }
    }
    // Left and right are the sides of the engine's arrays.
    let (mut i, _) = instance(Kind::CoupledSystem);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.do_step(0.0, 1e-3).unwrap();
    let s = simulation(&i).sample();
    assert_eq!(real(&mut i, vr::CONTACT_RIGHT_FORCE), s.contact[1].force);
    assert_eq!(real(&mut i, vr::CONTACT_LEFT_OVERLAP), s.contact[0].overlap);
    assert_eq!(real(&mut i, vr::RAIL_RIGHT_Z), s.rail_z[1]);
    assert_eq!(real(&mut i, vr::WHEEL_RIGHT_Z), s.wheel_z[1]);
    // The rail under the wheel: sagging under the static load, as the track's own.
    let (left, right) = (
        simulation(&i).rail_under_wheel(0).unwrap(),
        simulation(&i).rail_under_wheel(1).unwrap(),
    );
    let m = real(&mut i, vr::RAIL_LEFT_BENDING_MOMENT);
    assert_eq!(m, left.bending_moment);
    assert!(m > 10e3 && m < 40e3, "{m}");
    assert_eq!(real(&mut i, vr::RAIL_RIGHT_SHEAR_FORCE), right.shear_force);
    let (d, bearing) = match simulation(&i).vehicle() {
        crate::sim::VehicleState::RollPlane(v) => (*v.displacements(), v.bearing_forces()),
        _ => unreachable!("CoupledSystem carries the roll-plane vehicle"),
    };
    assert_eq!(real(&mut i, vr::SIDEFRAME_RIGHT_Z), d[3]);
    assert_eq!(real(&mut i, vr::PRIMARY_RIGHT_FORCE), bearing[1]);
}

#[test]
fn every_input_at_its_declared_start_is_accepted_and_an_input_never_set_reads_back_its_start() {
    // Issue 38 (N7, N8): a master that wrote every input's start value failed at
    // fmi2ExitInitializationMode (the unused interface's inputs were refused even at
    // their start); an input never set read back another value than its start.
    let settings = Kind::ALL.into_iter().flat_map(|k| {
        let interfaces: &[i32] = if k == Kind::CoupledSystem {
            &[1]
        } else {
            &[1, 2]
        };
        let datums: &[i32] = if k == Kind::TrackContact {
            &[1, 2]
        } else {
            &[1]
        };
        (interfaces.iter()).flat_map(move |&f| datums.iter().map(move |&d| (k, f, d)))
    });
    for (kind, interface, datum) in settings {
        let table = kind.table();
        let configure = |i: &mut Instance| {
            if kind != Kind::CoupledSystem {
                i.set_integer(&[vr::INTERFACE], &[interface]).unwrap();
            }
            if kind == Kind::TrackContact {
                i.set_integer(&[vr::INPUTS_DATUM], &[datum]).unwrap();
            }
        };
        let kind = (kind, interface, datum);
        let (mut i, _) = instance(kind.0);
        configure(&mut i);
        i.enter_initialization().unwrap();
        i.exit_initialization().unwrap();
        let mut off = Vec::new();
        for v in table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Input)
        {
            // A vehicle's force input never set reads its forces at rest, which its
            // declared start writes out: the same to the last bits, which the
            // summation order of `K d - F` may move between builds (debug, release).
            let x = real(&mut i, v.vr);
            if (x - v.start).abs() > 4.0 * f64::EPSILON * v.start.abs() {
                off.push(format!("{} reads {x}, start {}", v.name, v.start));
            }
        }
        assert!(off.is_empty(), "{kind:?}: {off:?}");
        // Every input written at its start, before and after initialisation.
        let (mut j, _) = instance(kind.0);
        configure(&mut j);
        let reals: Vec<_> = (table.vars.iter())
            .filter(|v| v.causality == Causality::Input && v.ty == VarType::Real)
            .collect();
        let (vrs, starts): (Vec<u32>, Vec<f64>) = reals.iter().map(|v| (v.vr, v.start)).unzip();
        j.set_real(&vrs, &starts).unwrap();
        j.enter_initialization().unwrap();
        j.set_real(&vrs, &starts).unwrap();
        j.exit_initialization()
            .unwrap_or_else(|e| panic!("{kind:?}: {}", e.message));
        j.set_real(&vrs, &starts)
            .unwrap_or_else(|e| panic!("{kind:?}: {}", e.message));
        // (TrackContact warns of the long step of held heights once they are given.)
        for k in [&mut i, &mut j] {
            match k.do_step(0.0, 1e-3) {
                Ok(()) => {}
                Err(e) if e.status == Status::Warning => {}
                Err(e) => panic!("{kind:?}: {}", e.message),
            }
        }
        // The same run as one whose inputs were never set.
        for v in table
            .vars
            .iter()
            .filter(|v| v.causality == Causality::Output)
        {
            if v.ty == VarType::Real {
                // To rounding: a height given is moved by its offset to the static one.
                let (a, b) = (real(&mut i, v.vr), real(&mut j, v.vr));
                assert!(
                    (a - b).abs() <= 1e-9 * a.abs().max(1e-3),
                    "{kind:?}: {} {a} {b}",
                    v.name
                );
            }
        }
    }
}
