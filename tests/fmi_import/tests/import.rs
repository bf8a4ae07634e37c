//! Loads the wheelflat FMUs with the `fmi` crate and steps them.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::traits::FmiImport;
use std::path::PathBuf;

fn fmu(name: &str) -> Fmi2Import {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../fmu/{name}.fmu"));
    assert!(
        path.exists(),
        "{} missing: build the FMUs first (scripts/test.sh does)",
        path.display()
    );
    fmi::import::from_path(&path).expect("fmi crate imports the FMU")
}

fn vr(import: &Fmi2Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variable_by_name(name)
        .unwrap_or_else(|_| panic!("{name} in the model description"))
        .value_reference
}

#[test]
fn coupled_system_steps_through_the_first_impact() {
    let import = fmu("CoupledSystem");
    let md = import.model_description();
    assert_eq!(md.fmi_version, "2.0");
    let xml = std::fs::read_to_string(import.archive_path().join("modelDescription.xml")).unwrap();
    assert_eq!(
        md.model_variables.variables.len(),
        xml.matches("<ScalarVariable ").count()
    );
    let force = vr(&import, "contact.left.force");
    let max_force = vr(&import, "contact.left.max_force");
    let step = vr(&import, "solver.step");
    let mut inst = import.instantiate_cs("coupled", false, false).unwrap();
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    let mut v = [0.0];
    inst.get_real(&[step], &mut v).unwrap();
    let h = v[0];
    assert!((h - 1.4413057013760613e-5).abs() < 1e-12, "solver.step {h}");
    inst.get_real(&[force], &mut v).unwrap();
    assert!((v[0] - 107_664.75).abs() < 1.0, "static load {}", v[0]);
    let n = (0.06 / h) as usize;
    for k in 0..n {
        inst.do_step(k as f64 * h, h, true).unwrap();
    }
    inst.get_real(&[max_force], &mut v).unwrap();
    // The converged reference peak of docs/VALIDATION.md: 301.9 kN.
    assert!((v[0] - 301.9e3).abs() < 0.005 * 301.9e3, "peak {}", v[0]);
    inst.terminate().unwrap();
}

#[test]
fn track_contact_forces_are_direct_feedthrough() {
    let import = fmu("TrackContact");
    let z = vr(&import, "wheel.left.z");
    let force = vr(&import, "contact.left.force");
    let mut inst = import.instantiate_cs("track", false, false).unwrap();
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    // The wheel heights received before the first step stand for the static state
    // (inputs.datum = first_step): step once, then the force follows them.
    inst.do_step(0.0, 1e-4, true).unwrap();
    let overlap = vr(&import, "contact.left.overlap");
    let mut p = [0.0, 0.0];
    inst.get_real(&[force, overlap], &mut p).unwrap();
    let (p0, d0) = (p[0], p[1]);
    // Lower the wheel by 0.1 um: the force rises at once (no step in between), by the
    // contact stiffness dP/d(delta) = 3/2 P / delta of the small-overlap law. The
    // overlap rises by 1 / (1 + c k) of it: the rail under the wheel gives way by the
    // rest through its local compliance c between nodes (docs/MODEL.md), at most
    // dx / (4 kAG), 13 % of the contact's at the static load on table 4.4's track.
    let mut zs = [0.0];
    inst.get_real(&[z], &mut zs).unwrap();
    let dz = 1e-7;
    inst.set_real(&[z], &[zs[0] - dz]).unwrap();
    inst.get_real(&[force, overlap], &mut p).unwrap();
    let rise = p[1] - d0;
    assert!(
        rise <= dz * (1.0 + 1e-6) && rise > dz / 1.14,
        "overlap {} -> {}",
        d0,
        p[1]
    );
    let expected = 1.5 * p0 / d0 * rise;
    assert!(
        ((p[0] - p0) - expected).abs() < 0.02 * expected,
        "{p0} -> {} (expected +{expected})",
        p[0]
    );
    inst.terminate().unwrap();
}

#[test]
fn half_car_bogie_rests_on_its_static_loads_and_falls_freely_without_them() {
    let import = fmu("HalfCarBogie");
    let get = |inst: &mut fmi::fmi2::instance::InstanceCS, names: &[&str]| {
        let r: Vec<u32> = names.iter().map(|n| vr(&import, n)).collect();
        let mut v = vec![0.0; r.len()];
        inst.get_real(&r, &mut v).unwrap();
        v
    };
    // The bogie's mass centre from its outputs: bolster (with half the car body), side
    // frames (their centres midway between the two axle boxes), wheelsets.
    let bodies = [
        "bolster.z",
        "sideframe.left.z",
        "wheelset[2].sideframe.left.z",
        "sideframe.right.z",
        "wheelset[2].sideframe.right.z",
        "wheelset.z",
        "wheelset[2].z",
    ];
    let masses = [
        "vehicle.carbody_mass",
        "vehicle.bolster.mass",
        "vehicle.sideframe.mass",
        "vehicle.wheelset.mass",
    ];
    let mut inst = import.instantiate_cs("bogie", false, false).unwrap();
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    let m = get(&mut inst, &masses);
    // The half-car's masses are twice the roll-plane vehicle's, wheelsets as they are.
    let (mb, msf, mw) = (2.0 * (m[0] + m[1]), 2.0 * m[2], m[3]);
    let centre = |z: &[f64]| {
        (mb * z[0] + msf * (z[1] + z[2] + z[3] + z[4]) / 2.0 + mw * (z[5] + z[6]))
            / (mb + 2.0 * msf + 2.0 * mw)
    };
    let load = get(&mut inst, &["static_load.left"])[0];
    // Half a bogie's weight per wheel pair of table 4.4: 107.66 kN on each wheel.
    assert!((load - 107_664.75).abs() < 1.0, "static load {load}");
    let z0 = get(&mut inst, &bodies);
    // On its static loads (the unset inputs) it stays at rest for 0.1 s.
    for k in 0..100 {
        inst.do_step(k as f64 * 1e-3, 1e-3, true).unwrap();
    }
    let z = get(&mut inst, &bodies);
    for (a, b) in z.iter().zip(&z0) {
        assert!((a - b).abs() < 1e-9, "{z:?} against {z0:?}");
    }
    // Without the contact forces the suspension's forces are internal: the mass
    // centre falls freely, by g t^2 / 2 = 0.49 mm in 0.01 s; central differences from
    // rest give exactly g dt^2 n (n + 1) / 2 after n steps.
    let forces: Vec<u32> = [
        "contact.left.force",
        "contact.right.force",
        "wheelset[2].contact.left.force",
        "wheelset[2].contact.right.force",
    ]
    .iter()
    .map(|n| vr(&import, n))
    .collect();
    inst.set_real(&forces, &[0.0; 4]).unwrap();
    for k in 0..10 {
        inst.do_step(0.1 + k as f64 * 1e-3, 1e-3, true).unwrap();
    }
    let z = get(&mut inst, &bodies);
    let fall = centre(&z) - centre(&z0);
    // Each 1 ms step is cut into equal substeps of at most solver.step.
    let base = get(&mut inst, &["solver.step"])[0];
    let per = (1e-3 / base).ceil();
    let (dt, n) = (1e-3 / per, 10.0 * per);
    let exact = 9.81 * dt * dt * n * (n + 1.0) / 2.0;
    assert!(
        (fall + exact).abs() < 1e-6 * exact,
        "{fall} against -{exact}"
    );
    let drop = 0.5 * 9.81 * 0.01f64.powi(2);
    assert!((fall + drop).abs() < 0.05 * drop, "{fall} against -{drop}");
    // The wheelsets, pressed down by their primary springs too, fall much faster.
    assert!(z[5] - z0[5] < -5.0 * drop, "{z:?}");
    inst.terminate().unwrap();
}
