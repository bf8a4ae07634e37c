//! FMU states: one saved before the first step restores in a fresh instance, a doctored
//! one is refused and changes nothing.

use super::*;

#[test]
fn a_state_saved_before_the_first_step_restores_in_a_fresh_instance() {
    for kind in Kind::ALL {
        let (mut a, _) = instance(kind);
        a.enter_initialization().unwrap();
        a.exit_initialization().unwrap();
        let state = a.get_state().unwrap();
        let bytes = a.serialize(&state).unwrap();
        let (mut b, _) = instance(kind);
        let s = b.deserialize(&bytes).unwrap();
        b.set_state(&s).unwrap();
        for i in [&mut a, &mut b] {
            i.do_step(0.0, 1e-3).unwrap();
        }
        let (mut x, mut y) = ([0.0; 2], [0.0; 2]);
        let vrs = [vr::WHEEL_LEFT_Z, vr::CONTACT_LEFT_MAX_FORCE];
        a.get_real(&vrs, &mut x).unwrap();
        b.get_real(&vrs, &mut y).unwrap();
        assert_eq!(x, y, "{kind:?}");
    }
}

#[test]
fn a_doctored_state_is_refused_and_leaves_the_instance_as_it_was() {
    let (mut i, _) = instance(Kind::CoupledSystem);
    i.enter_initialization().unwrap();
    i.exit_initialization().unwrap();
    i.do_step(0.0, 1e-3).unwrap();
    let state = i.get_state().unwrap();
    let b = i.serialize(&state).unwrap();
    let guid = i.table().guid.len();
    let time_at = MAGIC.len() + 8 + guid + 3;
    // The values after the clock, the (empty) reason and the calculated parameters.
    let values_at = time_at + 24 + 8 * <FmuModel as fmi2::Model>::CALCULATED + 8;
    let put = |at: usize, bytes: &[u8]| {
        let mut c = b.clone();
        c[at..at + bytes.len()].copy_from_slice(bytes);
        c
    };
    for (bytes, why) in [
        // the GUID's and the reason's lengths at their largest
        (put(MAGIC.len(), &u64::MAX.to_le_bytes()), "truncated"),
        (put(time_at + 16, &u64::MAX.to_le_bytes()), "truncated"),
        // solver.step (the fifth calculated parameter) and the clock
        (
            put(time_at + 24 + 4 * 8, &1e300f64.to_le_bytes()),
            "disagrees",
        ),
        (
            put(time_at, &0.5f64.to_le_bytes()),
            "disagrees with the model's clock",
        ),
        // a stepping state without its model (it would restart the model at t = 0)
        (put(time_at - 1, &[0]), "phase StepComplete without a model"),
        // an enumeration's code that is no whole number (the breaker's F3: it panicked
        // and stopped the instance)
        (
            put(
                values_at + 8 * vr::CONTACT_MODEL as usize,
                &1.5f64.to_le_bytes(),
            ),
            "`contact.model` = 1.5 is not a whole number",
        ),
    ] {
        let e = i.deserialize(&bytes).unwrap_err();
        assert!(e.message.contains(why), "{why}: {}", e.message);
    }
    assert_eq!(i.phase(), Phase::StepComplete);
    i.do_step(1e-3, 1e-3).unwrap();
}
