//! The start of a run: the first step's wheel heights and forces, what exit
//! initialisation reports once (a parameter error, an unused `track.spans`, an
//! unreachable stop time), and the communication point and the master's clock far
//! from zero.

use super::*;

#[test]
fn the_first_step_s_wheel_heights_are_the_static_state_and_later_ones_move_from_it() {
    // inputs.datum = first_step (the default): a partner at rest on other heights (2 cm
    // lower here) starts at rest; a change after the first step moves the wheel.
    let (mut i, _) = instance(Kind::TrackContact);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    // At standstill the wheel held at its static height stays at the static load.
    i.set_real(&[vr::SPEED], &[0.0]).unwrap();
    let mut s = [0.0; 2];
    i.get_real(&[vr::STATIC_LOAD_LEFT, vr::STATIC_WHEEL_Z_LEFT], &mut s)
        .unwrap();
    let [w, z0] = s;
    let refs = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z];
    i.set_real(&refs, &[z0 - 0.02, z0 - 0.02]).unwrap();
    let mut p = [0.0];
    i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
    assert_eq!(p[0], w);
    // Seven track steps with the heights held: taken, and warned of.
    stepped(i.do_step(0.0, 1e-4), true);
    i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
    assert!((p[0] / w - 1.0).abs() < 1e-6, "{} against {w}", p[0]);
    // 10 um down from there: the contact stiffness, about 1.45e9 N/m, times it.
    i.set_real(&refs, &[z0 - 0.02 - 1e-5, z0 - 0.02 - 1e-5])
        .unwrap();
    i.get_real(&[vr::CONTACT_LEFT_FORCE], &mut p).unwrap();
    let k = (p[0] - w) / 1e-5;
    assert!(k > 1.3e9 && k < 1.6e9, "{k:e}");
}

#[test]
fn a_parameter_error_is_reported_once_at_exit_initialization() {
    let (mut i, log) = instance(Kind::TrackContact);
    i.set_real(&[vr::FLAT_LEFT_2_DEPTH], &[1e-3]).unwrap();
    i.enter_initialization().unwrap();
    let e = i.exit_initialization().unwrap_err();
    assert!(e.message.contains("flat.left[2]"), "{}", e.message);
    assert_eq!(log.lock().unwrap().len(), 1);
}

#[test]
fn track_spans_set_on_the_endless_default_is_named_at_initialisation() {
    // Issue 29's breaker: a script written for the old default (the fixed track) that
    // sets track.spans ran the 10 m window silently.
    let (mut i, log) = instance(Kind::CoupledSystem);
    i.set_integer(&[vr::TRACK_SPANS], &[600]).unwrap();
    i.enter_initialization().unwrap();
    let w = i.exit_initialization().unwrap_err();
    assert_eq!(w.status, Status::Warning);
    assert!(
        w.message.contains("track.spans = 600 is not used")
            && w.message.contains("track.window.ahead = 0"),
        "{}",
        w.message
    );
    assert_eq!(log.lock().unwrap().len(), 1);
    i.do_step(0.0, 1e-3).unwrap();
    // On the fixed track it is used: no warning.
    let (mut i, _) = fixed_track_instance(Kind::CoupledSystem);
    i.set_integer(&[vr::TRACK_SPANS], &[600]).unwrap();
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
}

#[test]
fn an_unreachable_stop_time_is_named_at_initialisation() {
    let (mut i, log) = fixed_track_instance(Kind::CoupledSystem);
    i.setup_experiment(0.0, Some(2.0)).unwrap();
    i.enter_initialization().unwrap();
    // Initialised, with the warning as the status.
    let w = i.exit_initialization().unwrap_err();
    assert_eq!(w.status, Status::Warning);
    assert!(w.message.contains("stopTime = 2 s cannot be reached"));
    i.do_step(0.0, 1e-3).unwrap();
    let log = log.lock().unwrap();
    assert_eq!(log.len(), 1);
    // 30 spans of 0.685 m from 1.37 m at 70 km/h: the last sleeper but one (19.865 m)
    // at 0.951 s; 2 s needs 1.37 + 38.9 m of track, 59 spans, plus the two kept clear
    // of the end.
    assert!(
        log[0].contains("stopTime = 2 s cannot be reached"),
        "{}",
        log[0]
    );
    assert!(log[0].contains("t = 0.951"), "{}", log[0]);
    assert!(log[0].contains("track.spans >= 61"), "{}", log[0]);
}

#[test]
fn the_communication_point_must_be_the_fmu_time_to_the_clock_rounding() {
    // At t = 1e9 s a tolerance relative to 1 + |t| let 0.5 s jumps and steps back
    // through with fmi2OK.
    let (mut i, _) = instance(Kind::CoupledSystem);
    i.setup_experiment(1e9, None).unwrap();
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    for t in [1e9 + 0.5, 1e9 - 0.4, 1e9 + 1e-4] {
        let e = i.do_step(t, 1e-4).unwrap_err();
        assert!(e.message.contains("but the FMU is at"), "{}", e.message);
    }
    // A few units in the last place are the master's rounding.
    i.do_step(1e9 + 2.0 * 1.2e-7, 1e-4).unwrap();
    assert_eq!(i.phase(), Phase::StepComplete);
}

#[test]
fn the_vehicle_follows_the_masters_clock_far_from_zero() {
    // At t = 1e9 s each t + 1e-3 rounds by up to 6e-8 s; summing the h given drifted
    // 1e-3 s from the clock over 2e4 calls.
    let (mut v, _) = instance(Kind::ROLL_PLANE_VEHICLE);
    v.setup_experiment(1e9, None).unwrap();
    v.enter_initialization().unwrap();
    v.exit_initialization().unwrap();
    let mut t = 1e9;
    for _ in 0..20_000 {
        let next = t + 1e-3;
        v.do_step(t, next - t).unwrap();
        t = next;
    }
    let mut rot = [0.0];
    v.get_real(&[vr::WHEEL_ROTATION], &mut rot).unwrap();
    let model_time = rot[0] * 0.475 / (70.0 / 3.6);
    let dt = real(&mut v, vr::SOLVER_STEP);
    assert!(
        (model_time - (t - 1e9)).abs() <= 1e-3 * dt + 1e-9,
        "{model_time} against {}",
        t - 1e9
    );
}

#[test]
fn a_vehicle_whose_first_forces_are_all_zero_is_told_of_connectors_that_start_at_zero() {
    // Issue 38: fmpy's simulate_ssp starts every connector at 0; the vehicle's warning
    // told the user to set TrackContact's static_load.*, which already matched.
    let (mut i, log) = instance(Kind::ROLL_PLANE_VEHICLE);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.set_real(
        &[vr::CONTACT_LEFT_FORCE, vr::CONTACT_RIGHT_FORCE],
        &[0.0, 0.0],
    )
    .unwrap();
    assert_eq!(i.do_step(0.0, 1e-4).unwrap_err().status, Status::Warning);
    let log = log.lock().unwrap();
    let w = log.last().unwrap();
    assert!(
        w.contains("are all 0 N") && w.contains("simulate_ssp") && !w.contains("static_load"),
        "{w}"
    );
}
