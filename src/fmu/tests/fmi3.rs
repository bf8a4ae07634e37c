//! The FMI 3.0 units through the Rust API of an FMI 3.0 instance: arrays of wheelsets
//! equal the FMI 2.0 unit's variables bit for bit, `wheelsets` is set in Configuration
//! Mode only, counts, types and calls are refused by name, the adjoint derivative is the
//! transpose of the directional one, FMU states carry the configuration.

use super::*;
use crate::fmu::fmi3::Call3;
use crate::fmu::vars::{Type3, vr_of};

fn instance3(kind: Kind) -> (Instance3, Arc<Mutex<Vec<String>>>) {
    let log = Arc::new(Mutex::new(Vec::new()));
    let l2 = log.clone();
    let logger: Logger = Box::new(move |_, _, m| l2.lock().unwrap().push(m.to_string()));
    (Instance3::new(kind.table3(), "test", logger, false), log)
}

fn v(name: &str) -> u32 {
    vr_of(name).unwrap_or_else(|| panic!("no variable {name}"))
}

fn refused<T: std::fmt::Debug>(r: FmiResult<T>, parts: &[&str]) {
    let e = r.expect_err("refused");
    assert_eq!(e.status, Status::Error, "{e:?}");
    for p in parts {
        assert!(e.message.contains(p), "{:?} lacks {p:?}", e.message);
    }
}

/// CoupledSystem on two wheelsets, as FMI 3.0 (configured) and FMI 2.0, initialised.
fn two_wheelsets() -> (Instance3, Instance) {
    let (mut a, _) = instance3(Kind::CoupledSystem);
    a.enter_configuration().unwrap();
    a.set_uint64(&[vr::WHEELSETS], &[2]).unwrap();
    a.exit_configuration().unwrap();
    a.enter_initialization(None, 0.0, None).unwrap();
    a.exit_initialization().unwrap();
    let (mut b, _) = instance(Kind::CoupledSystem);
    b.set_integer(&[vr::WHEELSETS], &[2]).unwrap();
    b.setup_experiment(0.0, None).unwrap();
    b.enter_initialization().unwrap();
    b.exit_initialization().unwrap();
    (a, b)
}

#[test]
fn an_array_of_two_wheelsets_is_the_fmi2_units_two_variables_bit_for_bit() {
    let (mut a, mut b) = two_wheelsets();
    let names = [
        "contact.left.force",
        "contact.right.force",
        "wheel.left.z",
        "rail.right.z",
    ];
    for k in 0..300 {
        let t = k as f64 * 1e-4;
        a.do_step(t, 1e-4).0.unwrap();
        b.do_step(t, 1e-4).unwrap();
    }
    let mut x = [0.0; 8];
    a.get_float64(&names.map(v), &mut x).unwrap();
    let fmi2: Vec<u32> = names
        .iter()
        .flat_map(|n| [v(n), v(&format!("wheelset[2].{n}"))])
        .collect();
    let mut y = [0.0; 8];
    b.get_real(&fmi2, &mut y).unwrap();
    assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits));
    // Both wheelsets carry their load: neither element is empty.
    assert!(x[0] > 5e4 && x[1] > 5e4, "{x:?}");
}

#[test]
fn wheelsets_is_set_in_configuration_mode_only_and_within_its_range() {
    let (mut i, _) = instance3(Kind::TrackContact);
    refused(
        i.set_uint64(&[vr::WHEELSETS], &[2]),
        &["fmi3SetUInt64", "state Instantiated", "ConfigurationMode"],
    );
    i.enter_configuration().unwrap();
    refused(
        i.set_uint64(&[vr::WHEELSETS], &[5]),
        &["fmi3SetUInt64", "wheelsets", "5", "4"],
    );
    refused(
        i.set_float64(&[vr::SPEED], &[10.0]),
        &["fmi3SetFloat64", "ConfigurationMode"],
    );
    i.set_uint64(&[vr::WHEELSETS], &[3]).unwrap();
    let mut n = [0];
    i.get_uint64(&[vr::WHEELSETS], &mut n).unwrap();
    assert_eq!(n, [3]);
    // Beyond 32 bits, refused as given.
    refused(
        i.set_uint64(&[vr::WHEELSETS], &[1 << 63]),
        &[
            "fmi3SetUInt64",
            "`wheelsets` = 9223372036854775808",
            "1 to 4",
        ],
    );
    i.exit_configuration().unwrap();
    refused(
        i.set_uint64(&[vr::WHEELSETS], &[2]),
        &["fmi3SetUInt64", "ConfigurationMode"],
    );
    // Three values for an array now; a scalar one.
    i.set_float64(
        &[v("wheel.left.z"), vr::SPEED],
        &[-1e-3, -1.1e-3, -1.2e-3, 20.0],
    )
    .unwrap();
    assert_eq!(i.fmi2().value(v("wheelset[3].wheel.left.z")), -1.2e-3);
    refused(
        i.set_float64(&[v("wheel.left.z")], &[-1e-3]),
        &["fmi3SetFloat64", "nValues = 1", "3 values", "wheelsets = 3"],
    );
    // In Instantiated a parameter's or an input's value can be read, an output not yet.
    let mut z = [0.0; 3];
    i.get_float64(&[v("wheel.left.z")], &mut z).unwrap();
    assert_eq!(z[2], -1.2e-3);
    let mut model = [0];
    i.get_int64(&[v("contact.model")], &mut model).unwrap();
    assert_eq!(model, [1]);
    refused(
        i.get_float64(&[v("contact.left.force")], &mut z),
        &[
            "fmi3GetFloat64",
            "`contact.left.force`",
            "fmi3EnterInitializationMode",
        ],
    );
    // A reset returns wheelsets to its start.
    i.reset().unwrap();
    assert_eq!(i.wheelsets(), 1);
}

#[test]
fn a_vehicles_wheelsets_is_a_constant_and_it_has_no_configuration_mode() {
    for (kind, n) in [(Kind::ROLL_PLANE_VEHICLE, 1), (Kind::Vehicle(2), 4)] {
        let (mut i, _) = instance3(kind);
        let mut x = [0];
        i.get_uint64(&[vr::WHEELSETS], &mut x).unwrap();
        assert_eq!(x, [n]);
        refused(i.enter_configuration(), &["no structural parameter"]);
        refused(
            i.set_uint64(&[vr::WHEELSETS], &[1]),
            &["fmi3SetUInt64", "no structural parameter", "a constant"],
        );
        i.enter_initialization(None, 0.0, None).unwrap();
        let mut loads = vec![0.0; 2];
        i.get_float64(&[vr::STATIC_LOAD_LEFT, vr::STATIC_LOAD_RIGHT], &mut loads)
            .unwrap();
        let mut z = vec![0.0; n as usize];
        i.get_float64(&[v("wheel.left.z")], &mut z).unwrap();
        assert!(z.iter().all(|x| x.is_finite()), "{z:?}");
    }
}

#[test]
fn types_references_and_calls_are_refused_by_name_in_fmi3_terms() {
    let (mut i, _) = instance3(Kind::TrackContact);
    refused(
        i.set_int32(&[v("flat.left[1].shape")], &[1]),
        &[
            "fmi3SetInt32",
            "flat.left[1].shape",
            "Enumeration",
            "fmi3SetInt64",
        ],
    );
    refused(
        i.set_int64(&[v("contact.model")], &[7]),
        &["fmi3SetInt64", "contact.model", "7"],
    );
    refused(
        i.set_int64(&[v("contact.model")], &[1 << 40]),
        &["fmi3SetInt64", "`contact.model` = 1099511627776", "1 to 2"],
    );
    // A count far beyond the references' refused, not allocated.
    refused(
        i.elements(Call3::GetFloat64, &[vr::SPEED], &[Type3::Float64], 1 << 60),
        &["nValues = 1152921504606846976", "1 values"],
    );
    i.set_int64(&[v("contact.model")], &[2]).unwrap();
    refused(
        i.set_float64(&[crate::fmu::vars::N_VR as u32], &[0.0]),
        &["fmi3SetFloat64", "independent variable time"],
    );
    // The time reads (among other variables) as the FMU's clock.
    let mut t = [1.0, 1.0];
    i.get_float64(&[crate::fmu::vars::N_VR as u32, vr::SPEED], &mut t)
        .unwrap();
    assert_eq!(t, [0.0, 70.0 / 3.6]);
    let mut speed = [0.0];
    i.get_float64(&[vr::SPEED], &mut speed).unwrap();
    assert_eq!(speed[0], 70.0 / 3.6);
    let (r, _) = i.do_step(0.0, 1e-3);
    refused(
        r,
        &[
            "fmi3DoStep is not allowed in state Instantiated",
            "StepMode",
        ],
    );
    refused(
        i.check(Call3::EnterEventMode),
        &["fmi3EnterEventMode", "no Event Mode"],
    );
    refused(
        i.no_such_type("fmi3SetBoolean", false, &[vr::SPEED]),
        &["fmi3SetBoolean", "speed", "no variable of this type"],
    );
    assert!(i.no_such_type("fmi3SetBoolean", false, &[]).is_ok());
    // An FMI 2.0 layer's refusal reaches the logger in FMI 3.0 terms.
    let (mut j, log) = instance3(Kind::TrackContact);
    j.enter_configuration().unwrap();
    j.set_uint64(&[vr::WHEELSETS], &[2]).unwrap();
    j.exit_configuration().unwrap();
    let _ = j.set_float64(&[v("wheel.left.z")], &[0.0, 1.0]);
    let text = log.lock().unwrap().join("\n");
    assert!(
        text.contains("fmi3SetFloat64") && text.contains("wheel.left.z[2]"),
        "{text}"
    );
    assert!(!text.contains("fmi2"), "{text}");
}

#[test]
fn the_adjoint_derivative_is_the_transpose_of_the_directional_one() {
    let (mut i, _) = instance3(Kind::TrackContact);
    i.enter_configuration().unwrap();
    i.set_uint64(&[vr::WHEELSETS], &[2]).unwrap();
    i.exit_configuration().unwrap();
    i.enter_initialization(None, 0.0, None).unwrap();
    i.exit_initialization().unwrap();
    // Before the first step the wheel heights stand for the static state (derivatives
    // 0); after it they are the wheels'.
    i.do_step(0.0, 1e-4).0.unwrap();
    let unknowns = [v("contact.left.force"), v("contact.right.force")];
    let knowns = [v("wheel.left.z"), v("wheel.right.z")];
    // J column by column: 4 outputs (2 arrays of 2) by 4 inputs.
    let mut j = [[0.0; 4]; 4];
    for c in 0..4 {
        let mut seed = [0.0; 4];
        seed[c] = 1.0;
        let mut col = [0.0; 4];
        i.directional_derivative(&unknowns, &knowns, &seed, &mut col)
            .unwrap();
        for r in 0..4 {
            j[r][c] = col[r];
        }
    }
    // The left force of wheelset 1 depends on its own left wheel, stiffly (a wheel
    // lifted unloads it: dP/dz = -k / (1 + c k)), and on no other wheel's height.
    assert!(j[0][0] < -1e8 && j[3][3] < -1e8, "{j:?}");
    assert_eq!((j[0][1], j[0][2], j[0][3]), (0.0, 0.0, 0.0), "{j:?}");
    let w = [1.0, -2.0, 0.5, 3.0];
    let mut adj = [0.0; 4];
    i.adjoint_derivative(&unknowns, &knowns, &w, &mut adj)
        .unwrap();
    for c in 0..4 {
        let expect: f64 = (0..4).map(|r| j[r][c] * w[r]).sum();
        assert!((adj[c] - expect).abs() <= 1e-12 * expect.abs(), "{adj:?}");
    }
    refused(
        i.adjoint_derivative(&unknowns, &knowns, &w[..3], &mut adj),
        &["fmi3GetAdjointDerivative", "nSeed = 3"],
    );
}

#[test]
fn an_fmu_state_carries_the_configuration_into_a_fresh_instance() {
    let (mut a, _) = two_wheelsets();
    a.do_step(0.0, 1e-3).0.unwrap();
    let s = a.get_state().unwrap();
    let bytes = a.serialize(&s).unwrap();
    let (mut b, _) = instance3(Kind::CoupledSystem);
    let s2 = b.deserialize(&bytes).unwrap();
    b.set_state(&s2).unwrap();
    assert_eq!(b.wheelsets(), 2);
    for i in [&mut a, &mut b] {
        i.do_step(1e-3, 1e-3).0.unwrap();
    }
    let (mut x, mut y) = ([0.0; 2], [0.0; 2]);
    a.get_float64(&[v("contact.left.max_force")], &mut x)
        .unwrap();
    b.get_float64(&[v("contact.left.max_force")], &mut y)
        .unwrap();
    assert_eq!(x, y);
}

#[test]
fn with_early_return_a_step_ends_where_a_wheel_loses_contact_or_hits_the_rail_and_the_run_keeps_its_bits()
 {
    // The reference flat at 70 km/h lifts the left wheel off the rail and drops it back
    // (the impact) once a turn. Communication steps of 20 ms, early return allowed,
    // against the same run without it.
    let run = |early: bool| {
        let (mut i, log) = instance3(Kind::CoupledSystem);
        i.allow_early_return(early);
        i.set_debug_logging(true, &[]).unwrap();
        i.enter_initialization(None, 0.0, Some(0.3)).unwrap();
        i.exit_initialization().unwrap();
        let (mut t, mut stops) = (0.0f64, Vec::new());
        while t < 0.3 - 1e-12 {
            let h = (0.3 - t).min(0.02);
            let (r, rep) = i.do_step(t, h);
            r.unwrap();
            assert!(rep.last_successful_time > t && rep.last_successful_time <= t + h);
            if rep.early_return {
                assert!(rep.last_successful_time < t + h);
                stops.push(rep.last_successful_time);
            } else {
                assert_eq!(rep.last_successful_time, t + h);
            }
            t = rep.last_successful_time;
        }
        let mut x = [0.0; 3];
        i.get_float64(
            &[
                v("contact.left.max_force"),
                v("contact.left.force"),
                vr::POSITION,
            ],
            &mut x,
        )
        .unwrap();
        let text = log.lock().unwrap().join("\n");
        (x, stops, text)
    };
    let (plain, none, _) = run(false);
    let (early, stops, text) = run(true);
    assert!(none.is_empty());
    assert_eq!(plain.map(f64::to_bits), early.map(f64::to_bits));
    // Every turn of the wheel (0.475 m radius at 19.4 m/s: 0.153 s) loses contact once
    // and hits once; at least one turn in 0.3 s.
    assert!(stops.len() >= 2, "{stops:?}");
    assert!(
        text.contains("the left wheel of wheelset 1 lost contact"),
        "{text}"
    );
    assert!(
        text.contains("the left wheel of wheelset 1 came into contact (an impact)"),
        "{text}"
    );
}

#[test]
fn with_early_return_a_step_past_the_fixed_tracks_end_stops_at_its_last_step_on_the_track() {
    // The breaker's F8: a step that would carry the wheel off the fixed track ended the
    // run where it stood; with early return it ends at the last step on the track.
    let (mut i, _) = instance3(Kind::CoupledSystem);
    i.allow_early_return(true);
    i.set_float64(&[vr::TRACK_WINDOW_AHEAD], &[0.0]).unwrap();
    i.set_int32(&[v("track.spans")], &[10]).unwrap();
    i.enter_initialization(None, 0.0, None).unwrap();
    i.exit_initialization().unwrap();
    let (mut t, mut last) = (0.0, None);
    for _ in 0..20 {
        let (r, rep) = i.do_step(t, 0.5);
        if rep.terminate {
            // The next step after the end: the run ended there, nothing moved.
            assert_eq!(r.unwrap_err().status, Status::Discard);
            assert_eq!(rep.last_successful_time, t);
            last = Some(t);
            break;
        }
        // Near the rail end the step warns of the end's reflections.
        if let Err(e) = r {
            assert!(
                e.status == Status::Warning && e.message.contains("rail end"),
                "{e:?}"
            );
        }
        assert!(rep.early_return && rep.last_successful_time > t);
        t = rep.last_successful_time;
    }
    // Ten spans of 0.6 m from 1.37 m at 70 km/h: the running length ends near 0.25 s.
    let end = last.expect("the run ended");
    assert!(end > 0.2 && end < 0.26, "{end}");
}
