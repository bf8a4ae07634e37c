//! Loads the wheelflat FMUs with the `fmi` crate and steps them: the FMI 2.0 units of
//! `fmu/` and the FMI 3.0 units of `fmu/fmi3/`, the same runs bit for bit.

use fmi::fmi2::import::Fmi2Import;
use fmi::fmi2::instance::{CoSimulation, Common};
use fmi::fmi3::import::Fmi3Import;
use fmi::fmi3::instance::InstanceCS as Instance3;
use fmi::fmi3::{CoSimulation as _, Common as _, Fmi3Error, Fmi3Model as _, GetSet as _};
use fmi::traits::FmiImport;
use std::path::PathBuf;

/// The packed FMU `fmu/<name>.fmu`.
fn packed(name: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../../fmu/{name}.fmu"));
    assert!(
        path.exists(),
        "{} missing: build the FMUs first (scripts/test.sh does)",
        path.display()
    );
    path
}

/// The FMI 2.0 unit `fmu/<name>.fmu`, imported.
fn fmu(name: &str) -> Fmi2Import {
    fmi::import::from_path(packed(name)).expect("fmi crate imports the FMU")
}

/// The attributes of FMI 3.0 variables that the fmi crate's model description (fmi-schema
/// 0.8.0, strict) does not know although the FMI 3.0 schema allows them
/// (`fmi3RealBaseAttributes`): it refuses the whole model description on the first one.
const UNREAD3: [(&str, &str); 2] = [("<Float64 ", "unit"), ("<Float64 ", "displayUnit")];

/// The FMI 3.0 unit `fmu/fmi3/<name>.fmu`, imported with [`UNREAD3`] left out of the
/// model description the fmi crate parses (the unit's own file is not changed; value
/// references, types, dimensions and the token are all fmi's reading). The unchanged
/// model description is refused for one of them, so this fails once fmi reads them.
fn fmu3(name: &str) -> Fmi3Import {
    let path = packed(&format!("fmi3/{name}"));
    let refused = fmi::import::from_path::<Fmi3Import>(&path)
        .expect_err("fmi reads the units of Float64 variables now: import with from_path");
    let why = format!("{refused:?}");
    assert!(
        UNREAD3
            .iter()
            .any(|(_, a)| why.contains(&format!("field: \"{a}\""))),
        "{why}"
    );
    let dir = tempfile::Builder::new().prefix("fmi-rs").tempdir().unwrap();
    let file = std::fs::File::open(&path).unwrap();
    zip::ZipArchive::new(file).unwrap().extract(&dir).unwrap();
    let xml = std::fs::read_to_string(dir.path().join("modelDescription.xml")).unwrap();
    let xml: Vec<String> = xml
        .lines()
        .map(|line| {
            UNREAD3
                .iter()
                .filter(|(tag, _)| line.trim_start().starts_with(tag))
                .fold(line.to_string(), |l, (_, attr)| without(&l, attr))
        })
        .collect();
    Fmi3Import::new(dir, &xml.join("\n")).expect("fmi crate imports the FMI 3.0 unit")
}

/// `line` without its attribute `attr="..."`.
fn without(line: &str, attr: &str) -> String {
    let key = format!(" {attr}=\"");
    match line.find(&key) {
        None => line.to_string(),
        Some(a) => {
            let value = a + key.len();
            let end = value + line[value..].find('"').expect("closing quote") + 1;
            format!("{}{}", &line[..a], &line[end..])
        }
    }
}

fn vr(import: &Fmi2Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variable_by_name(name)
        .unwrap_or_else(|_| panic!("{name} in the model description"))
        .value_reference
}

fn vr3(import: &Fmi3Import, name: &str) -> u32 {
    import
        .model_description()
        .model_variables
        .iter_abstract()
        .find(|v| v.name() == name)
        .unwrap_or_else(|| panic!("{name} in the FMI 3.0 model description"))
        .value_reference()
}

/// A co-simulation instance of an FMI 3.0 unit (no Event Mode, no early return).
fn instance3(import: &Fmi3Import, name: &str) -> Instance3 {
    import
        .instantiate_cs(name, false, false, false, false, &[])
        .expect("fmi3InstantiateCoSimulation")
}

/// `fmi3DoStep` from `t` by `h`: no event, no early return, the simulation goes on.
fn step3(inst: &mut Instance3, t: f64, h: f64) {
    let (mut event, mut terminate, mut early, mut last) = (true, true, true, f64::NAN);
    inst.do_step(
        t,
        h,
        true,
        &mut event,
        &mut terminate,
        &mut early,
        &mut last,
    )
    .unwrap();
    assert!(!event && !terminate && !early, "fmi3DoStep at {t}");
    assert!(
        (last - (t + h)).abs() < 1e-12,
        "lastSuccessfulTime {last} at {t} + {h}"
    );
}

/// CoupledSystem through the first impact: 0.06 s in steps of `solver.step`.
struct Impact {
    /// `solver.step`.
    h: f64,
    /// `contact.left.force` after initialisation: the static load.
    load: f64,
    /// `contact.left.force` after each step.
    forces: Vec<f64>,
    /// `contact.left.max_force` at the end.
    peak: f64,
}

impl Impact {
    /// What the run must give, whichever FMI version ran it.
    fn check(&self) {
        let h = self.h;
        assert!((h - 1.4413057013760613e-5).abs() < 1e-12, "solver.step {h}");
        assert!(
            (self.load - 107_664.75).abs() < 1.0,
            "static load {}",
            self.load
        );
        assert_eq!(self.forces.len(), (0.06 / h) as usize);
        // The converged reference peak of docs/VALIDATION.md: 301.9 kN.
        let peak = self.peak;
        assert!((peak - 301.9e3).abs() < 0.005 * 301.9e3, "peak {peak}");
    }

    /// Every number as its bits.
    fn bits(&self) -> Vec<u64> {
        [self.h, self.load, self.peak]
            .iter()
            .chain(&self.forces)
            .map(|x| x.to_bits())
            .collect()
    }
}

/// The first impact through the FMI 2.0 CoupledSystem.
fn impact2(import: &Fmi2Import) -> Impact {
    let force = vr(import, "contact.left.force");
    let max_force = vr(import, "contact.left.max_force");
    let step = vr(import, "solver.step");
    let mut inst = import.instantiate_cs("coupled", false, false).unwrap();
    inst.setup_experiment(None, 0.0, None).unwrap();
    inst.enter_initialization_mode().unwrap();
    inst.exit_initialization_mode().unwrap();
    let mut v = [0.0];
    inst.get_real(&[step], &mut v).unwrap();
    let h = v[0];
    inst.get_real(&[force], &mut v).unwrap();
    let load = v[0];
    let forces = (0..(0.06 / h) as usize)
        .map(|k| {
            inst.do_step(k as f64 * h, h, true).unwrap();
            inst.get_real(&[force], &mut v).unwrap();
            v[0]
        })
        .collect();
    inst.get_real(&[max_force], &mut v).unwrap();
    inst.terminate().unwrap();
    Impact {
        h,
        load,
        forces,
        peak: v[0],
    }
}

/// The first impact through the FMI 3.0 CoupledSystem (one wheelset: each array has one
/// element).
fn impact3(import: &Fmi3Import) -> Impact {
    let force = vr3(import, "contact.left.force");
    let max_force = vr3(import, "contact.left.max_force");
    let step = vr3(import, "solver.step");
    let mut inst = instance3(import, "coupled");
    inst.enter_initialization_mode(None, 0.0, None).unwrap();
    inst.exit_initialization_mode().unwrap();
    let mut v = [0.0];
    inst.get_float64(&[step], &mut v).unwrap();
    let h = v[0];
    inst.get_float64(&[force], &mut v).unwrap();
    let load = v[0];
    let forces = (0..(0.06 / h) as usize)
        .map(|k| {
            step3(&mut inst, k as f64 * h, h);
            inst.get_float64(&[force], &mut v).unwrap();
            v[0]
        })
        .collect();
    inst.get_float64(&[max_force], &mut v).unwrap();
    inst.terminate().unwrap();
    Impact {
        h,
        load,
        forces,
        peak: v[0],
    }
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
    impact2(&import).check();
}

#[test]
fn fmi3_coupled_system_steps_through_the_first_impact_as_the_fmi2_unit_bit_for_bit() {
    let import = fmu3("CoupledSystem");
    let md = import.model_description();
    assert_eq!(md.fmi_version, "3.0");
    // Every variable of the XML parsed (each has a name; the Dimensions have none) but the
    // Enumerations, which fmi-schema 0.8.0 has no type for and skips.
    let xml = std::fs::read_to_string(import.archive_path().join("modelDescription.xml")).unwrap();
    let vars = xml
        .split("<ModelVariables>")
        .nth(1)
        .and_then(|x| x.split("</ModelVariables>").next())
        .expect("ModelVariables");
    let enumerations = vars.matches("<Enumeration ").count();
    assert_eq!(
        md.model_variables.len(),
        vars.matches(" name=\"").count() - enumerations
    );
    let a = impact3(&import);
    a.check();
    let b = impact2(&fmu("CoupledSystem"));
    let (x, y) = (a.bits(), b.bits());
    assert_eq!(x.len(), y.len());
    let first = x.iter().zip(&y).position(|(p, q)| p != q);
    // 0: solver.step, 1: the static load, 2: the peak, 3 + k: the force after step k.
    assert_eq!(first, None, "the FMI 3.0 and FMI 2.0 runs differ");
}

#[test]
fn fmi3_track_contact_configures_two_wheelsets_and_its_arrays_have_two_elements() {
    let import = fmu3("TrackContact");
    let wheelsets = vr3(&import, "wheelsets");
    let force = vr3(&import, "contact.left.force");
    let mut inst = instance3(&import, "track");
    inst.enter_configuration_mode().unwrap();
    inst.set_uint64(&[wheelsets], &[2]).unwrap();
    inst.exit_configuration_mode().unwrap();
    let mut n = [0];
    inst.get_uint64(&[wheelsets], &mut n).unwrap();
    assert_eq!(n, [2]);
    // The importer's own reading of the array's <Dimension valueReference="wheelsets"/>.
    assert_eq!(
        inst.get_variable_dimensions(import.model_description(), &[force]),
        2
    );
    inst.enter_initialization_mode(None, 0.0, None).unwrap();
    inst.exit_initialization_mode().unwrap();
    step3(&mut inst, 0.0, 1e-4);
    let mut x = [0.0; 2];
    inst.get_float64(&[force], &mut x).unwrap();
    // One value for the two elements is refused.
    assert_eq!(
        inst.get_float64(&[force], &mut [0.0]),
        Err(Fmi3Error::Error)
    );
    inst.terminate().unwrap();
    // The FMI 2.0 unit on two wheelsets gives the same forces as two variables.
    let import2 = fmu("TrackContact");
    let mut b = import2.instantiate_cs("track", false, false).unwrap();
    b.set_integer(&[vr(&import2, "wheelsets")], &[2]).unwrap();
    b.setup_experiment(None, 0.0, None).unwrap();
    b.enter_initialization_mode().unwrap();
    b.exit_initialization_mode().unwrap();
    b.do_step(0.0, 1e-4, true).unwrap();
    let forces = [
        vr(&import2, "contact.left.force"),
        vr(&import2, "wheelset[2].contact.left.force"),
    ];
    let mut y = [0.0; 2];
    b.get_real(&forces, &mut y).unwrap();
    assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits), "{x:?} {y:?}");
    // Both wheelsets carry their load: neither element is empty.
    assert!(x[0] > 5e4 && x[1] > 5e4, "{x:?}");
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
