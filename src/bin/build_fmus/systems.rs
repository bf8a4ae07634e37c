//! The system structures shipped beside the FMUs, under `<out>/systems/`: TrackContact
//! with each vehicle (RollPlaneVehicle, HalfCarBogie, Wagon) at each interface (contact,
//! axle_box), as
//!
//! - an SSP 1.0 archive, `<system>.ssp`: `SystemStructure.ssd` at its root, both FMUs
//!   under `resources/`, the parameters as an inline `ssv:ParameterSet` named
//!   `wheelflat`, the base step as the `osp:FixedStepAlgorithm` annotation and a
//!   `DefaultExperiment` to [`STOP_TIME`] (libcosim and ecos both read it: the literal
//!   prefixes `ssd:`, `ssc:`, `ssv:`, `osp:` and `version="1.0"` are what both accept),
//!   and the same base step as OMSimulator's fixed-step master in the root system's
//!   `org.openmodelica` annotation (OMSimulator takes the system's type from it alone
//!   and refuses an SSP without it);
//! - an OSP system structure, `<system>/OspSystemStructure.xml` (libcosim), its sources
//!   `../../<modelIdentifier>.fmu`, relative to the file's folder;
//! - for the systems on one wheelset, `fmi3/<system>.ssp`, the same of the FMI 3.0 units
//!   ([`System::ssd3`]; SSP 1.0 connects scalars, which a wheelset's arrays are only with
//!   one wheelset).
//!
//! Every component (OSP simulator) is named after its FMU's `modelIdentifier`
//! (`TrackContact`, `RollPlaneVehicle`, ...): OMSimulator reads a parameter's leading
//! `<component>.` as the component, so TrackContact's `track.*` parameters on a component
//! named `track` would be lost there.
//!
//! The connections come from the variable table, never by hand: at interface X every
//! input of either FMU that is used when `interface` = X (`VarSpec::used_when`) and
//! that belongs to a wheelset the vehicle has is fed by the partner's output of the same
//! name, except that a vehicle's `[wheelset[k].]axle_box.<side>.force` is fed by
//! TrackContact's `[wheelset[k].]primary.<side>.force` (the force at the communication
//! point, for these Jacobi masters). The packer panics when a source is not an output
//! of the partner.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;
use std::sync::{Arc, Mutex};
use wheelflat::fmu::vars::{Causality, FMUS, FmuTable, VarSpec, VarType, enums};
use wheelflat::fmu::{Instance, Kind, Logger, Status};
use wheelflat::vehicle::{VEHICLE_KINDS, kind_of_fmu};
use zip::write::SimpleFileOptions;

/// `DefaultExperiment stopTime` of every SSP (s).
pub const STOP_TIME: f64 = 0.6;
/// Base step of the axle-box couplings (s): within 1 % of the monolithic peaks.
pub const AXLE_BOX_STEP: f64 = 1e-3;
/// `track.window.ahead` and `track.window.behind` (m): the endless track, converged.
pub const WINDOW: f64 = 20.0;
/// The `xmlns:oms` namespace OMSimulator writes in the SSDs it exports.
const OMS_NAMESPACE: &str =
    "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd";

/// Where the vehicle meets the track: the value of the FMUs' `interface` parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Interface {
    /// Wheel heights and axle rotation to the track, contact forces back.
    Contact,
    /// Side frames' motion to the track, primary (axle-box) forces back.
    AxleBox,
}

impl Interface {
    fn value(self) -> f64 {
        match self {
            Interface::Contact => enums::interface::CONTACT,
            Interface::AxleBox => enums::interface::AXLE_BOX,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Interface::Contact => "contact",
            Interface::AxleBox => "axle_box",
        }
    }
}

/// A parameter or input value as the structure files write it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Value {
    /// `fmi2Real`.
    Real(f64),
    /// `fmi2Integer` (the model descriptions write enumerations as Integer).
    Integer(i32),
}

/// One connection: `from` (component, output) feeds `to` (component, input); a
/// component is named after its FMU's `modelIdentifier`.
#[derive(Debug, Clone, PartialEq)]
pub struct Connection {
    /// Source component name.
    pub from: &'static str,
    /// Source output name.
    pub output: &'static str,
    /// Target component name.
    pub to: &'static str,
    /// Target input name.
    pub input: &'static str,
}

/// One shipped system: TrackContact and a vehicle at one interface.
#[derive(Debug)]
pub struct System {
    /// `TrackContact_<vehicle>_<interface>`.
    pub name: String,
    /// The interface.
    pub interface: Interface,
    /// TrackContact.
    pub track: &'static FmuTable,
    /// The vehicle.
    pub vehicle: &'static FmuTable,
    /// Connections, TrackContact's inputs first.
    pub connections: Vec<Connection>,
    /// TrackContact's parameters (and `speed`), by name.
    pub track_values: Vec<(&'static str, Value)>,
    /// The vehicle's.
    pub vehicle_values: Vec<(&'static str, Value)>,
    /// Base step of the fixed-step master (s).
    pub step: f64,
}

fn table(id: &str) -> &'static FmuTable {
    FMUS.iter()
        .copied()
        .find(|t| t.model_identifier == id)
        .unwrap_or_else(|| panic!("no FMU {id} in the variable table"))
}

fn spec(t: &'static FmuTable, name: &str) -> &'static VarSpec {
    t.vars
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("{} has no variable {name}", t.model_identifier))
}

/// The wheelset a variable belongs to: k for `wheelset[k].*`, 1 otherwise.
fn wheelset_of(name: &str) -> usize {
    name.strip_prefix("wheelset[")
        .and_then(|r| r.split_once(']'))
        .and_then(|(k, _)| k.parse().ok())
        .unwrap_or(1)
}

/// How many wheelsets an FMU carries: 1 + its highest `wheelset[k].` index.
fn wheelsets(t: &FmuTable) -> usize {
    t.vars
        .iter()
        .map(|v| wheelset_of(v.name))
        .max()
        .unwrap_or(1)
}

/// The partner's output that feeds `input`: the same name, except a vehicle's
/// `[wheelset[k].]axle_box.<side>.force`, fed by TrackContact's
/// `[wheelset[k].]primary.<side>.force`.
fn source_name(input: &str) -> String {
    match input.split_once("axle_box.") {
        Some((prefix, rest)) if rest.ends_with(".force") => format!("{prefix}primary.{rest}"),
        _ => input.to_string(),
    }
}

/// Every input of `to` used at `interface` and on one of the first `n` wheelsets,
/// with its source in `from`; panics where `from` lacks that output.
fn feeds(
    from: (&'static str, &'static FmuTable),
    to: (&'static str, &'static FmuTable),
    interface: Interface,
    n: usize,
) -> Vec<Connection> {
    to.1.vars
        .iter()
        .filter(|v| v.causality == Causality::Input)
        .filter(|v| v.used_when.is_some_and(|u| u.value == interface.value()))
        .filter(|v| wheelset_of(v.name) <= n)
        .map(|v| {
            let source = source_name(v.name);
            let out = from
                .1
                .vars
                .iter()
                .find(|o| o.name == source && o.causality == Causality::Output)
                .unwrap_or_else(|| {
                    panic!(
                        "{}: input {} ({}) needs the output {source} of {}, which has none",
                        to.1.model_identifier,
                        v.name,
                        v.used_when.map_or("", |u| u.text),
                        from.1.model_identifier
                    )
                });
            assert_eq!(
                (out.ty, v.ty),
                (VarType::Real, VarType::Real),
                "{source} -> {}: only Real connections",
                v.name
            );
            Connection {
                from: from.0,
                output: out.name,
                to: to.0,
                input: v.name,
            }
        })
        .collect()
}

/// `name = value` for `t`, typed by the table; panics unless `name` is a parameter
/// or an input of `t`.
fn value(t: &'static FmuTable, name: &str, x: f64) -> (&'static str, Value) {
    let s = spec(t, name);
    assert!(
        matches!(s.causality, Causality::Parameter | Causality::Input),
        "{}: {name} is not a parameter or an input",
        t.model_identifier
    );
    assert!(
        x >= s.min && x <= s.max,
        "{}: {name} = {x} outside [{}, {}]",
        t.model_identifier,
        s.min,
        s.max
    );
    let v = if s.ty == VarType::Real {
        Value::Real(x)
    } else {
        assert_eq!(x.fract(), 0.0, "{name} = {x}: a whole number");
        Value::Integer(x as i32)
    };
    (s.name, v)
}

/// TrackContact's `solver.step` (s) with these values, through the crate's FMI layer:
/// what the FMU computes after initialisation.
fn track_step(track: &'static FmuTable, values: &[(&'static str, Value)]) -> f64 {
    assert_eq!(
        Kind::TrackContact.table().model_identifier,
        track.model_identifier
    );
    let log = Arc::new(Mutex::new(Vec::<String>::new()));
    let sink = log.clone();
    let logger: Logger = Box::new(move |_, _, m| sink.lock().unwrap().push(m.to_string()));
    let mut inst = Instance::new(Kind::TrackContact.table(), "build_fmus", logger, false);
    let fail = |what: &str, log: &Arc<Mutex<Vec<String>>>| -> ! {
        panic!(
            "TrackContact refused {what}: {}",
            log.lock().unwrap().join("; ")
        )
    };
    if inst.setup_experiment(0.0, None).is_err() {
        fail("fmi2SetupExperiment", &log);
    }
    for &(name, v) in values {
        let vr = spec(track, name).vr;
        let r = match v {
            Value::Real(x) => inst.set_real(&[vr], &[x]),
            Value::Integer(i) => inst.set_integer(&[vr], &[i]),
        };
        if r.is_err() {
            fail(name, &log);
        }
    }
    if inst.enter_initialization().is_err() {
        fail("fmi2EnterInitializationMode", &log);
    }
    match inst.exit_initialization() {
        Ok(()) => {}
        Err(e) if e.status == Status::Warning => {}
        Err(_) => fail("fmi2ExitInitializationMode", &log),
    }
    let mut h = [0.0];
    if inst
        .get_real(&[spec(track, "solver.step").vr], &mut h)
        .is_err()
    {
        fail("solver.step", &log);
    }
    assert!(h[0].is_finite() && h[0] > 0.0, "solver.step = {}", h[0]);
    h[0]
}

/// The system of TrackContact and `vehicle` (a modelIdentifier) at `interface`.
pub fn system(vehicle: &str, interface: Interface) -> System {
    let track = table("TrackContact");
    let vehicle = table(vehicle);
    let n = wheelsets(vehicle);
    assert!(
        n <= wheelsets(track),
        "{} has {n} wheelsets, TrackContact carries {}",
        vehicle.model_identifier,
        wheelsets(track)
    );
    // Each component is named after its FMU.
    let (t, v) = (track.model_identifier, vehicle.model_identifier);
    let mut connections = feeds((v, vehicle), (t, track), interface, n);
    connections.extend(feeds((t, track), (v, vehicle), interface, n));
    let speed = spec(track, "speed").start;
    let mut track_values = vec![
        value(track, "speed", speed),
        value(track, "interface", interface.value()),
        value(track, "track.window.ahead", WINDOW),
        value(track, "track.window.behind", WINDOW),
    ];
    // The vehicle's kind in the registry: the track carries its wheelsets at the
    // offsets its own parameters give (the wheelbase, the wagon's bogie distance) and,
    // at the axle boxes, what its kind has there.
    let kind = kind_of_fmu(vehicle.model_identifier).expect("a vehicle of the registry");
    let start = |name: &str| spec(vehicle, name).start;
    track_values.push(value(track, "wheelsets", n as f64));
    let carrier = kind.own_carrier(&start);
    // The vehicle's static wheel load, where the track starts at rest with it (no
    // handshake in a master that does not run one).
    let load = carrier.model().static_wheel_load();
    for side in ["left", "right"] {
        track_values.push(value(track, &format!("static_load.{side}"), load));
    }
    let offsets = carrier.model().offsets();
    for ((x, _), k) in offsets.into_iter().zip(2..) {
        track_values.push(value(track, &format!("wheelset[{k}].offset"), x));
    }
    let model = enums::vehicle_model::ITEMS
        .iter()
        .find(|(item, _)| *item == kind.item)
        .expect("each kind is an item of VehicleModel")
        .1;
    track_values.push(value(track, "vehicle.model", model));
    let vehicle_values = vec![
        value(vehicle, "speed", speed),
        value(vehicle, "interface", interface.value()),
    ];
    let step = match interface {
        Interface::AxleBox => AXLE_BOX_STEP,
        // One master step is one step of the track.
        Interface::Contact => track_step(track, &track_values),
    };
    System {
        name: format!(
            "TrackContact_{}_{}",
            vehicle.model_identifier,
            interface.name()
        ),
        interface,
        track,
        vehicle,
        connections,
        track_values,
        vehicle_values,
        step,
    }
}

/// The shipped systems: TrackContact with each kind of vehicle's FMU at each interface.
pub fn systems() -> Vec<System> {
    let mut all = Vec::new();
    for vehicle in VEHICLE_KINDS.iter().map(|k| k.fmu) {
        for interface in [Interface::Contact, Interface::AxleBox] {
            all.push(system(vehicle, interface));
        }
    }
    all
}

/// The name of item `value` of the enumeration parameter `s`.
fn item_name(s: &VarSpec, value: i32) -> &'static str {
    let item = match s.name {
        "interface" => enums::interface::item(value.into()),
        "vehicle.model" => enums::vehicle_model::item(value.into()),
        n => panic!("{n}: an enumeration set in a system needs its items here"),
    };
    item.unwrap_or_else(|| panic!("{} = {value}: no such item", s.name))
}

/// Shortest text that reads back as the same `f64`.
fn num(x: f64) -> String {
    format!("{x:?}")
}

fn description(s: &System) -> String {
    let step = match s.interface {
        Interface::Contact => "the track's solver.step",
        Interface::AxleBox => "1 ms",
    };
    format!(
        "TrackContact + {} at the {} interface, fixed step {} s ({step}), endless track; \
         generated by build_fmus from the variable table",
        s.vehicle.model_identifier,
        s.interface.name(),
        num(s.step)
    )
}

impl System {
    /// The two components, TrackContact first: each FMU (whose `modelIdentifier` names
    /// its component) with its values.
    pub fn components(&self) -> [(&'static FmuTable, &[(&'static str, Value)]); 2] {
        [
            (self.track, &self.track_values),
            (self.vehicle, &self.vehicle_values),
        ]
    }

    /// `SystemStructure.ssd`.
    pub fn ssd(&self) -> String {
        self.ssd_of(false)
    }

    /// Whether the system is on one wheelset: only then an SSP of the FMI 3.0 units (SSP
    /// 1.0 connects scalars; a wheelset's variables are arrays in FMI 3.0, and an array of
    /// one element is connected as one value).
    pub fn has_fmi3_ssp(&self) -> bool {
        wheelsets(self.vehicle) == 1
    }

    /// The `SystemStructure.ssd` of the FMI 3.0 units ([`System::has_fmi3_ssp`]): the
    /// same, but for the parameters FMI 3.0 types otherwise. `wheelsets`, a structural
    /// parameter set in Configuration Mode only, and an enumeration at its start value
    /// are left out (ecos reads neither a structural parameter nor an `ssv:Enumeration`);
    /// an enumeration set otherwise (`interface = axle_box`) is an `ssv:Enumeration` of its
    /// item's name.
    pub fn ssd3(&self) -> String {
        assert!(self.has_fmi3_ssp(), "{}: no FMI 3.0 SSP", self.name);
        self.ssd_of(true)
    }

    fn ssd_of(&self, fmi3: bool) -> String {
        let mut x = String::new();
        let _ = write!(
            x,
            r#"<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations"
    xmlns:oms="{oms}"
    name="{name}" version="1.0">
  <ssd:System name="{name}" description="{desc}">
    <ssd:Elements>
"#,
            name = self.name,
            desc = description(self),
            oms = OMS_NAMESPACE
        );
        for (t, values) in self.components() {
            let comp = t.model_identifier;
            let _ = writeln!(
                x,
                r#"      <ssd:Component name="{comp}" source="resources/{comp}.fmu">"#
            );
            x.push_str("        <ssd:Connectors>\n");
            for c in &self.connections {
                let (name, kind) = if c.from == comp {
                    (c.output, "output")
                } else if c.to == comp {
                    (c.input, "input")
                } else {
                    continue;
                };
                let _ = writeln!(
                    x,
                    r#"          <ssd:Connector name="{name}" kind="{kind}"><ssc:Real/></ssd:Connector>"#
                );
            }
            x.push_str(
                r#"        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="wheelflat">
                <ssv:Parameters>
"#,
            );
            for (name, v) in values {
                let v = match (v, fmi3.then(|| spec(t, name))) {
                    (Value::Integer(_), Some(s)) if s.name == "wheelsets" => continue,
                    (Value::Integer(i), Some(s)) if s.ty == VarType::Enumeration => {
                        if f64::from(*i) == s.start {
                            continue;
                        }
                        format!(r#"<ssv:Enumeration value="{}"/>"#, item_name(s, *i))
                    }
                    (Value::Real(r), _) => format!(r#"<ssv:Real value="{}"/>"#, num(*r)),
                    (Value::Integer(i), _) => format!(r#"<ssv:Integer value="{i}"/>"#),
                };
                let _ = writeln!(
                    x,
                    r#"                  <ssv:Parameter name="{name}">{v}</ssv:Parameter>"#
                );
            }
            x.push_str(
                r#"                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>
"#,
            );
        }
        x.push_str("    </ssd:Elements>\n    <ssd:Connections>\n");
        for c in &self.connections {
            let _ = writeln!(
                x,
                r#"      <ssd:Connection startElement="{}" startConnector="{}" endElement="{}" endConnector="{}"/>"#,
                c.from, c.output, c.to, c.input
            );
        }
        // OMSimulator's own annotation of the root system, as it exports one: its
        // fixed-step master (a weakly coupled system) at the same base step.
        let _ = write!(
            x,
            r#"    </ssd:Connections>
    <ssd:Annotations>
      <ssc:Annotation type="org.openmodelica">
        <oms:Annotations>
          <oms:SimulationInformation>
            <oms:FixedStepMaster description="oms-ma" stepSize="{step}" absoluteTolerance="0.0001" relativeTolerance="0.0001"/>
          </oms:SimulationInformation>
        </oms:Annotations>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="{stop}">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm>
          <osp:FixedStepAlgorithm baseStepSize="{step}"/>
        </osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"#,
            stop = num(STOP_TIME),
            step = num(self.step)
        );
        x
    }

    /// `OspSystemStructure.xml`, its FMUs at `<fmu_dir>/<modelIdentifier>.fmu`
    /// (relative to the file's folder).
    pub fn osp(&self, fmu_dir: &str) -> String {
        let mut x = String::new();
        let _ = write!(
            x,
            r#"<?xml version="1.0" encoding="utf-8"?>
<!-- {desc} -->
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
  <StartTime>0.0</StartTime>
  <BaseStepSize>{step}</BaseStepSize>
  <Algorithm>fixedStep</Algorithm>
  <Simulators>
"#,
            desc = description(self),
            step = num(self.step)
        );
        for (t, values) in self.components() {
            let comp = t.model_identifier;
            let _ = writeln!(
                x,
                r#"    <Simulator name="{comp}" source="{fmu_dir}/{comp}.fmu">"#
            );
            x.push_str("      <InitialValues>\n");
            for (name, v) in values {
                let v = match v {
                    Value::Real(r) => format!(r#"<Real value="{}"/>"#, num(*r)),
                    Value::Integer(i) => format!(r#"<Integer value="{i}"/>"#),
                };
                let _ = writeln!(
                    x,
                    r#"        <InitialValue variable="{name}">{v}</InitialValue>"#
                );
            }
            x.push_str("      </InitialValues>\n    </Simulator>\n");
        }
        x.push_str("  </Simulators>\n  <Connections>\n");
        for c in &self.connections {
            let _ = writeln!(
                x,
                r#"    <VariableConnection><Variable simulator="{}" name="{}"/><Variable simulator="{}" name="{}"/></VariableConnection>"#,
                c.from, c.output, c.to, c.input
            );
        }
        x.push_str("  </Connections>\n</OspSystemStructure>\n");
        x
    }
}

/// Writes every system under `<out>/systems/` from the FMUs already packed in `out`.
pub fn write(out: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let dir = out.join("systems");
    std::fs::create_dir_all(&dir)?;
    // Generated files: keep them out of git wherever the packer writes them.
    std::fs::write(dir.join(".gitignore"), "# written by build_fmus\n*\n")?;
    for s in systems() {
        let ssp = dir.join(format!("{}.ssp", s.name));
        let mut z = crate::zip_in_memory();
        let deflated =
            SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
        z.start_file("SystemStructure.ssd", deflated)?;
        z.write_all(s.ssd().as_bytes())?;
        for t in [s.track, s.vehicle] {
            let fmu = std::fs::read(out.join(format!("{}.fmu", t.model_identifier)))?;
            // An FMU is a zip archive already: stored, not compressed again.
            z.start_file(
                format!("resources/{}.fmu", t.model_identifier),
                SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored),
            )?;
            z.write_all(&fmu)?;
        }
        crate::write_whole(&ssp, &z.finish()?.into_inner())?;
        if s.has_fmi3_ssp() {
            // The same system of the FMI 3.0 units, from fmi3/ beside the FMUs.
            let dir3 = dir.join("fmi3");
            std::fs::create_dir_all(&dir3)?;
            let ssp3 = dir3.join(format!("{}.ssp", s.name));
            let mut z = crate::zip_in_memory();
            z.start_file("SystemStructure.ssd", deflated)?;
            z.write_all(s.ssd3().as_bytes())?;
            for t in [s.track, s.vehicle] {
                let fmu = std::fs::read(out.join(format!("fmi3/{}.fmu", t.model_identifier)))?;
                z.start_file(
                    format!("resources/{}.fmu", t.model_identifier),
                    SimpleFileOptions::default().compression_method(zip::CompressionMethod::Stored),
                )?;
                z.write_all(&fmu)?;
            }
            crate::write_whole(&ssp3, &z.finish()?.into_inner())?;
            println!("{} (the FMI 3.0 units)", ssp3.display());
        }
        let osp_dir = dir.join(&s.name);
        std::fs::create_dir_all(&osp_dir)?;
        let osp = osp_dir.join("OspSystemStructure.xml");
        crate::write_whole(&osp, s.osp("../..").as_bytes())?;
        println!(
            "{} and {} ({} connections, step {} s)",
            ssp.display(),
            osp.display(),
            s.connections.len(),
            num(s.step)
        );
    }
    Ok(())
}

#[cfg(test)]
#[path = "systems_tests.rs"]
mod tests;
