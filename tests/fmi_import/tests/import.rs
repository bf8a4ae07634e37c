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
    // The converged reference peak of docs/VALIDATION.md: 306.4 kN.
    assert!((v[0] - 306.4e3).abs() < 0.005 * 306.4e3, "peak {}", v[0]);
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
    let overlap = vr(&import, "contact.left.overlap");
    let mut p = [0.0, 0.0];
    inst.get_real(&[force, overlap], &mut p).unwrap();
    let (p0, d0) = (p[0], p[1]);
    // Lower the wheel by 0.1 um: the force rises at once (no step in between), by the
    // contact stiffness dP/d(delta) = 3/2 P / delta of the small-overlap law.
    let mut zs = [0.0];
    inst.get_real(&[z], &mut zs).unwrap();
    let dz = 1e-7;
    inst.set_real(&[z], &[zs[0] - dz]).unwrap();
    inst.get_real(&[force, overlap], &mut p).unwrap();
    assert!(
        (p[1] - (d0 + dz)).abs() < 1e-12,
        "overlap {} -> {}",
        d0,
        p[1]
    );
    let expected = 1.5 * p0 / d0 * dz;
    assert!(
        ((p[0] - p0) - expected).abs() < 0.02 * expected,
        "{p0} -> {} (expected +{expected})",
        p[0]
    );
    inst.do_step(0.0, 1e-4, true).unwrap();
    inst.terminate().unwrap();
}
