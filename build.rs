//! Build script: turns the one variable table `modelDescription/variables.xml` into
//! - `$OUT_DIR/<modelIdentifier>.xml`, the modelDescription.xml of each FMU, with a
//!   GUID derived from its content;
//! - `$OUT_DIR/variables.rs`, the Rust table of the same variables (value references,
//!   types, causalities, ranges, start values) that the FMI layer reads and writes;
//! - `$OUT_DIR/VARIABLES.md`, the variables' documentation (`docs/VARIABLES.md` is this
//!   file, committed: a unit test fails when it is stale, and
//!   `cargo run --release --bin build_fmus -- fmu docs/VARIABLES.md` rewrites it);
//! - `$OUT_DIR/wheelflat_fmi2.h`, the C header of the exported FMI functions (cbindgen).

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use std::collections::BTreeMap;
use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::PathBuf;

const TABLE: &str = "modelDescription/variables.xml";
const FFI: &str = "src/fmu/ffi/exports.rs";

/// Attributes of one element, unescaped.
type Attrs = BTreeMap<String, String>;

fn attrs(e: &BytesStart) -> Attrs {
    e.attributes()
        .map(|a| {
            let a = a.expect("well-formed attribute in the variable table");
            (
                a.key.as_ref().to_string(),
                a.normalized_value(quick_xml::XmlVersion::Explicit1_0)
                    .expect("well-formed attribute value")
                    .into_owned(),
            )
        })
        .collect()
}

/// A variable of the table: its own attributes and per-FMU overrides.
struct TableVar {
    attrs: Attrs,
    overrides: BTreeMap<String, Attrs>,
}

/// A variable as one FMU sees it.
#[derive(Clone)]
struct FmuVar {
    vr: usize,
    a: Attrs,
}

impl FmuVar {
    fn get(&self, k: &str) -> Option<&str> {
        self.a.get(k).map(|s| s.as_str()).filter(|s| !s.is_empty())
    }
    fn name(&self) -> &str {
        self.get("name").unwrap()
    }
    fn causality(&self) -> &str {
        self.get("causality").unwrap()
    }
    fn ty(&self) -> &str {
        self.get("type").unwrap()
    }
    /// Known in initialization mode: inputs and parameters with exact start values.
    fn is_known(&self) -> bool {
        matches!(self.causality(), "parameter" | "input")
    }
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Rust constant name of a variable: `flat.left[1].length` -> `FLAT_LEFT_1_LENGTH`.
fn const_name(name: &str) -> String {
    name.replace(['.', '['], "_")
        .replace(']', "")
        .to_uppercase()
}

/// 128-bit FNV-1a of the content, formatted as a GUID.
fn guid(content: &str) -> String {
    let mut h: u128 = 0x6c62272e07bb014262b821756295c58d;
    for b in content.bytes() {
        h ^= b as u128;
        h = h.wrapping_mul(0x0000000001000000000000000000013B);
    }
    let x = format!("{h:032x}");
    format!(
        "{{{}-{}-{}-{}-{}}}",
        &x[0..8],
        &x[8..12],
        &x[12..16],
        &x[16..20],
        &x[20..32]
    )
}

fn main() {
    println!("cargo:rerun-if-changed={TABLE}");
    println!("cargo:rerun-if-changed={FFI}");
    println!("cargo:rerun-if-changed=build.rs");
    let out = PathBuf::from(env::var("OUT_DIR").unwrap());
    let text = fs::read_to_string(TABLE).expect("read modelDescription/variables.xml");

    // ---- read the table
    let mut reader = Reader::from_str(&text);
    let mut fmus: Vec<Attrs> = Vec::new();
    let mut vars: Vec<TableVar> = Vec::new();
    let mut raw_sections: BTreeMap<String, String> = BTreeMap::new();
    loop {
        let pos = reader.buffer_position() as usize;
        match reader.read_event().expect("well-formed variable table") {
            Event::Eof => break,
            Event::Start(e)
                if matches!(
                    e.name().as_ref(),
                    "UnitDefinitions" | "TypeDefinitions" | "LogCategories"
                ) =>
            {
                // Copied verbatim into every model description.
                let name = e.name().as_ref().to_string();
                reader.read_to_end(e.name()).expect("closed section");
                let end = reader.buffer_position() as usize;
                let start = text[pos..].find('<').unwrap() + pos;
                raw_sections.insert(name, text[start..end].to_string());
            }
            Event::Empty(e) if e.name().as_ref() == "Fmu" => fmus.push(attrs(&e)),
            Event::Start(e) | Event::Empty(e) if e.name().as_ref() == "Variable" => {
                vars.push(TableVar {
                    attrs: attrs(&e),
                    overrides: BTreeMap::new(),
                });
            }
            Event::Empty(e) if e.name().as_ref() == "Override" => {
                let mut a = attrs(&e);
                let fmu = a.remove("fmu").expect("Override needs fmu=");
                vars.last_mut()
                    .expect("Override inside a Variable")
                    .overrides
                    .insert(fmu, a);
            }
            _ => {}
        }
    }

    // ---- resolve each FMU's variables
    let mut rust = String::new();
    writeln!(
        rust,
        "// Generated by build.rs from {TABLE}; do not edit.\n\n\
         /// Number of value references (one per variable name, shared by the FMUs).\n\
         pub const N_VR: usize = {};\n\n\
         /// Value references by variable name (`flat.left[1].length` -> `FLAT_LEFT_1_LENGTH`).\n\
         pub mod vr {{",
        vars.len()
    )
    .unwrap();
    let mut names_seen = BTreeMap::new();
    for (i, v) in vars.iter().enumerate() {
        let name = &v.attrs["name"];
        assert!(
            names_seen.insert(name.clone(), i).is_none(),
            "duplicate variable {name}"
        );
        writeln!(
            rust,
            "    /// `{name}`\n    pub const {}: u32 = {i};",
            const_name(name)
        )
        .unwrap();
    }
    writeln!(rust, "}}\n").unwrap();

    // ---- enumerations: item values by type, from TypeDefinitions
    let mut enums: BTreeMap<String, Vec<(String, i64, String)>> = BTreeMap::new();
    {
        let mut r = Reader::from_str(&raw_sections["TypeDefinitions"]);
        let mut current = String::new();
        loop {
            match r.read_event().expect("well-formed TypeDefinitions") {
                Event::Eof => break,
                Event::Start(e) if e.name().as_ref() == "SimpleType" => {
                    current = attrs(&e)["name"].clone();
                }
                Event::Empty(e) if e.name().as_ref() == "Item" => {
                    let a = attrs(&e);
                    let value = a["value"].parse().expect("integer item value");
                    enums.entry(current.clone()).or_default().push((
                        a["name"].clone(),
                        value,
                        a.get("description").cloned().unwrap_or_default(),
                    ));
                }
                _ => {}
            }
        }
    }
    writeln!(
        rust,
        "/// Values of the enumerations' items (as `f64`, the FMI layer's value type), one\n\
         /// module per enumeration type (`ContactModel` -> `contact_model`).\npub mod enums {{"
    )
    .unwrap();
    for (ty, items) in &enums {
        let mut snake = String::new();
        for (k, ch) in ty.chars().enumerate() {
            if ch.is_uppercase() && k > 0 {
                snake.push('_');
            }
            snake.push(ch.to_ascii_lowercase());
        }
        writeln!(rust, "    /// `{ty}`\n    pub mod {snake} {{").unwrap();
        for (name, value, desc) in items {
            writeln!(
                rust,
                "        /// {desc}\n        pub const {}: f64 = {value}.0;",
                const_name(name)
            )
            .unwrap();
        }
        writeln!(rust, "    }}").unwrap();
    }
    writeln!(rust, "}}\n").unwrap();

    // ---- the flats' value references, [side][k][length, depth, angle, shape]
    let per_wheel = (1..)
        .take_while(|k| names_seen.contains_key(&format!("flat.left[{k}].length")))
        .count();
    writeln!(
        rust,
        "/// Value references of the flats `[side][k]`: length, depth, angle, shape.\n\
         pub const FLAT_VRS: [[[u32; 4]; {per_wheel}]; 2] = ["
    )
    .unwrap();
    for side in ["left", "right"] {
        write!(rust, "    [").unwrap();
        for k in 1..=per_wheel {
            let r: Vec<String> = ["length", "depth", "angle", "shape"]
                .iter()
                .map(|f| {
                    let n = format!("flat.{side}[{k}].{f}");
                    names_seen
                        .get(&n)
                        .unwrap_or_else(|| panic!("{n} missing from the table"))
                        .to_string()
                })
                .collect();
            write!(rust, "[{}], ", r.join(", ")).unwrap();
        }
        writeln!(rust, "],").unwrap();
    }
    writeln!(rust, "];\n").unwrap();

    // Per variable and FMU: the resolved attributes (for docs/VARIABLES.md).
    let mut resolved: Vec<BTreeMap<String, Attrs>> = vec![BTreeMap::new(); vars.len()];

    for fmu in &fmus {
        let id = &fmu["modelIdentifier"];
        let mut fv: Vec<FmuVar> = Vec::new();
        for (i, v) in vars.iter().enumerate() {
            if !v.attrs["fmus"].split_whitespace().any(|f| f == id) {
                assert!(
                    !v.overrides.contains_key(id),
                    "override for {id} on a variable it lacks"
                );
                continue;
            }
            let mut a = v.attrs.clone();
            if let Some(o) = v.overrides.get(id) {
                for (k, val) in o {
                    a.insert(k.clone(), val.clone());
                }
            }
            let c = a["causality"].clone();
            let (variability, initial) = match (c.as_str(), a["type"].as_str()) {
                ("parameter", _) => ("fixed", Some("exact")),
                ("calculatedParameter", _) => ("fixed", Some("calculated")),
                ("input", "Real") => ("continuous", None),
                ("input", _) => ("discrete", None),
                ("output", "Real") => ("continuous", Some("calculated")),
                ("output", _) => ("discrete", Some("calculated")),
                (c, _) => panic!("unknown causality {c}"),
            };
            a.insert("variability".into(), variability.into());
            a.insert("initial".into(), initial.unwrap_or("").into());
            if matches!(c.as_str(), "parameter" | "input") {
                assert!(
                    a.get("start").is_some_and(|s| !s.is_empty()),
                    "{id}: {} needs a start value",
                    a["name"]
                );
            } else {
                a.insert("start".into(), String::new());
            }
            resolved[i].insert(id.clone(), a.clone());
            fv.push(FmuVar { vr: i, a });
        }
        // 1-based indices of the FMU's ModelVariables.
        let index: BTreeMap<String, usize> = fv
            .iter()
            .enumerate()
            .map(|(k, v)| (v.name().to_string(), k + 1))
            .collect();
        let expand = |list: Option<&str>, knowns_only_inputs: bool| -> Vec<usize> {
            let mut out = Vec::new();
            for pat in list.unwrap_or("").split_whitespace() {
                let mut hit = false;
                for v in &fv {
                    let ok = if knowns_only_inputs {
                        v.causality() == "input"
                    } else {
                        v.is_known()
                    };
                    let m = match pat.strip_suffix('*') {
                        Some(prefix) => v.name().starts_with(prefix),
                        None => v.name() == pat,
                    };
                    if m {
                        hit = true;
                        if ok {
                            out.push(index[v.name()]);
                        }
                    }
                }
                // A plain name must exist in the table (catches typos); it may belong
                // to another FMU.
                assert!(
                    hit || pat.ends_with('*') || names_seen.contains_key(pat),
                    "{id}: unknown name {pat}"
                );
            }
            out.sort_unstable();
            out.dedup();
            out
        };

        // ---- modelDescription.xml
        let mut md = String::new();
        let desc = xml_escape(&fmu["description"]);
        writeln!(
            md,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription\n  \
             fmiVersion=\"2.0\"\n  modelName=\"{id}\"\n  guid=\"@GUID@\"\n  \
             description=\"{desc}\"\n  author=\"wheelflat developers\"\n  \
             version=\"{}\"\n  generationTool=\"wheelflat build.rs\"\n  \
             variableNamingConvention=\"structured\"\n  numberOfEventIndicators=\"0\">\n  \
             <CoSimulation\n    modelIdentifier=\"{id}\"\n    needsExecutionTool=\"false\"\n    \
             canHandleVariableCommunicationStepSize=\"true\"\n    canInterpolateInputs=\"false\"\n    \
             maxOutputDerivativeOrder=\"0\"\n    canRunAsynchronuously=\"false\"\n    \
             canBeInstantiatedOnlyOncePerProcess=\"false\"\n    canNotUseMemoryManagementFunctions=\"true\"\n    \
             canGetAndSetFMUstate=\"true\"\n    canSerializeFMUstate=\"true\"\n    \
             providesDirectionalDerivative=\"false\"/>",
            env::var("CARGO_PKG_VERSION").unwrap()
        )
        .unwrap();
        for s in ["UnitDefinitions", "TypeDefinitions", "LogCategories"] {
            writeln!(md, "  {}", raw_sections[s]).unwrap();
        }
        writeln!(
            md,
            "  <DefaultExperiment startTime=\"0\" stopTime=\"{}\" stepSize=\"{}\"/>\n  <ModelVariables>",
            fmu["stopTime"], fmu["stepSize"]
        )
        .unwrap();
        for (k, v) in fv.iter().enumerate() {
            let mut line = format!(
                "    <!-- {} -->\n    <ScalarVariable name=\"{}\" valueReference=\"{}\" causality=\"{}\" variability=\"{}\"",
                k + 1,
                xml_escape(v.name()),
                v.vr,
                v.causality(),
                v.get("variability").unwrap()
            );
            if let Some(i) = v.get("initial") {
                write!(line, " initial=\"{i}\"").unwrap();
            }
            write!(
                line,
                " description=\"{}\">\n      <{}",
                xml_escape(v.get("description").unwrap_or("")),
                v.ty()
            )
            .unwrap();
            for k in ["declaredType", "unit", "displayUnit", "start", "min", "max"] {
                if let Some(x) = v.get(k) {
                    if v.ty() != "Real" && matches!(k, "unit" | "displayUnit") {
                        continue;
                    }
                    write!(line, " {k}=\"{}\"", xml_escape(x)).unwrap();
                }
            }
            writeln!(line, "/>\n    </ScalarVariable>").unwrap();
            md.push_str(&line);
        }
        md.push_str("  </ModelVariables>\n  <ModelStructure>\n");
        let deps_attr = |d: &[usize]| {
            let s: Vec<String> = d.iter().map(|x| x.to_string()).collect();
            let kinds: Vec<&str> = d.iter().map(|_| "dependent").collect();
            format!(
                " dependencies=\"{}\" dependenciesKind=\"{}\"",
                s.join(" "),
                kinds.join(" ")
            )
        };
        // One <Unknown> list: Outputs (dependencies on inputs) or InitialUnknowns
        // (dependencies on the knowns of initialization mode).
        let mut unknowns = |tag: &str, causalities: &[&str], attr: &str, inputs_only: bool| {
            let list: Vec<&FmuVar> = fv
                .iter()
                .filter(|v| causalities.contains(&v.causality()))
                .collect();
            if list.is_empty() {
                return;
            }
            writeln!(md, "    <{tag}>").unwrap();
            for v in list {
                let d = expand(v.get(attr), inputs_only);
                writeln!(
                    md,
                    "      <Unknown index=\"{}\"{}/>",
                    index[v.name()],
                    deps_attr(&d)
                )
                .unwrap();
            }
            writeln!(md, "    </{tag}>").unwrap();
        };
        unknowns("Outputs", &["output"], "dependencies", true);
        unknowns(
            "InitialUnknowns",
            &["output", "calculatedParameter"],
            "initialDependencies",
            false,
        );
        md.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
        let g = guid(&md);
        let md = md.replace("@GUID@", &g);
        fs::write(out.join(format!("{id}.xml")), &md).unwrap();

        // ---- Rust table
        let num = |v: &FmuVar, k: &str, dflt: &str| -> String {
            match v.get(k) {
                Some(x) => {
                    let f: f64 = x
                        .parse()
                        .unwrap_or_else(|_| panic!("{id}: {} {k}={x}", v.name()));
                    format!("{f:?}")
                }
                None => dflt.to_string(),
            }
        };
        // TrackContact -> TRACK_CONTACT
        let mut upper = String::new();
        for (k, ch) in id.chars().enumerate() {
            if ch.is_uppercase() && k > 0 {
                upper.push('_');
            }
            upper.push(ch.to_ascii_uppercase());
        }
        writeln!(
            rust,
            "/// The `{id}` FMU: identity, model description and variables.\n\
             pub static {upper}: FmuTable = FmuTable {{\n    \
             model_identifier: \"{id}\",\n    guid: \"{g}\",\n    \
             model_description: include_str!(concat!(env!(\"OUT_DIR\"), \"/{id}.xml\")),\n    \
             vars: &["
        )
        .unwrap();
        for v in &fv {
            let ty = match v.ty() {
                "Real" => "Real",
                "Integer" => "Integer",
                "Enumeration" => "Enumeration",
                t => panic!("type {t}"),
            };
            let (lo, hi) = if v.ty() == "Enumeration" {
                let ty = v
                    .get("declaredType")
                    .expect("Enumeration with declaredType");
                let values: Vec<i64> = enums[ty].iter().map(|x| x.1).collect();
                let (lo, hi) = (values.iter().min().unwrap(), values.iter().max().unwrap());
                assert_eq!(
                    (hi - lo + 1) as usize,
                    values.len(),
                    "{ty}: item values must be consecutive"
                );
                (format!("{lo}.0"), format!("{hi}.0"))
            } else {
                (
                    num(v, "min", "f64::NEG_INFINITY"),
                    num(v, "max", "f64::INFINITY"),
                )
            };
            let causality = match v.causality() {
                "parameter" => "Parameter",
                "calculatedParameter" => "CalculatedParameter",
                "input" => "Input",
                _ => "Output",
            };
            writeln!(
                rust,
                "        VarSpec {{ vr: {}, name: {:?}, ty: VarType::{ty}, causality: Causality::{causality}, \
                 start: {}, min: {lo}, max: {hi}, unit: {:?} }},",
                v.vr,
                v.name(),
                num(v, "start", "f64::NAN"),
                v.get("unit").unwrap_or("")
            )
            .unwrap();
        }
        writeln!(rust, "    ],\n}};\n").unwrap();
    }
    writeln!(
        rust,
        "/// docs/VARIABLES.md as the table generates it.\n\
         pub const VARIABLES_MD: &str = include_str!(concat!(env!(\"OUT_DIR\"), \"/VARIABLES.md\"));"
    )
    .unwrap();
    fs::write(out.join("variables.rs"), rust).unwrap();
    fs::write(
        out.join("VARIABLES.md"),
        variables_md(&vars, &fmus, &resolved, &enums),
    )
    .unwrap();

    // ---- C header of the exported functions
    let config = cbindgen::Config {
        language: cbindgen::Language::C,
        include_guard: Some("WHEELFLAT_FMI2_H".into()),
        header: Some(
            "/* Exported FMI 2.0 co-simulation functions of the wheelflat FMUs.\n   \
             Generated by cbindgen from src/fmu/ffi/exports.rs; include fmi2Functions.h first. */"
                .into(),
        ),
        includes: vec!["fmi2Functions.h".into()],
        no_includes: true,
        usize_is_size_t: true,
        export: cbindgen::ExportConfig {
            exclude: [
                "fmi2Component",
                "fmi2ComponentEnvironment",
                "fmi2FMUstate",
                "fmi2ValueReference",
                "fmi2Real",
                "fmi2Integer",
                "fmi2Boolean",
                "fmi2Char",
                "fmi2String",
                "fmi2Byte",
                "fmi2Status",
                "fmi2Type",
                "fmi2StatusKind",
                "fmi2CallbackFunctions",
                "fmi2CallbackLogger",
                "fmi2CallbackAllocateMemory",
                "fmi2CallbackFreeMemory",
                "fmi2StepFinished",
            ]
            .iter()
            .map(|s| s.to_string())
            .collect(),
            ..Default::default()
        },
        ..Default::default()
    };
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(FFI)
        .generate()
        .expect("cbindgen: C header of src/fmu/ffi/exports.rs")
        .write_to_file(out.join("wheelflat_fmi2.h"));
}

/// docs/VARIABLES.md: one row per variable, its causality in each FMU, type, unit,
/// start value, range and description.
fn variables_md(
    vars: &[TableVar],
    fmus: &[Attrs],
    resolved: &[BTreeMap<String, Attrs>],
    enums: &BTreeMap<String, Vec<(String, i64, String)>>,
) -> String {
    let ids: Vec<&str> = fmus.iter().map(|f| f["modelIdentifier"].as_str()).collect();
    let mut md = String::from(
        "# FMU variables\n\n\
         Generated by `build.rs` from `modelDescription/variables.xml`, the one table behind the\n\
         three model descriptions and the Rust variable table; do not edit: after a change of the\n\
         table, `cargo run --release --bin build_fmus -- fmu docs/VARIABLES.md` rewrites this\n\
         file, and a unit test fails while it is stale.\n\n\
         Columns: T = TrackContact, V = RollPlaneVehicle, C = CoupledSystem, with the variable's\n\
         causality in each (par = parameter, calc = calculated parameter, in = input, out =\n\
         output). Units are SI; the display unit is what tools may show. The range is what\n\
         `fmi2SetReal`/`fmi2SetInteger` accept (the physical ranges of `src/limits.rs`); the\n\
         engine checks the rest at `fmi2ExitInitializationMode`.\n\n\
         | name | T | V | C | type | unit (display) | start | range | description |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    let order = ["TrackContact", "RollPlaneVehicle", "CoupledSystem"];
    assert!(order.iter().all(|o| ids.contains(o)), "FMUs of the table");
    for (i, v) in vars.iter().enumerate() {
        let per = &resolved[i];
        let cols: Vec<&str> = order
            .iter()
            .map(|id| match per.get(*id).map(|a| a["causality"].as_str()) {
                Some("parameter") => "par",
                Some("calculatedParameter") => "calc",
                Some("input") => "in",
                Some("output") => "out",
                _ => "",
            })
            .collect();
        // The first FMU (in column order) that defines a value gives it.
        let first = |k: &str| {
            order
                .iter()
                .filter_map(|id| per.get(*id))
                .find_map(|a| a.get(k).filter(|x| !x.is_empty()).cloned())
                .unwrap_or_default()
        };
        let ty = v
            .attrs
            .get("declaredType")
            .unwrap_or(&v.attrs["type"])
            .clone();
        let unit = match (first("unit"), first("displayUnit")) {
            (u, d) if d.is_empty() => u,
            (u, d) => format!("{u} ({d})"),
        };
        let range = match enums.get(&ty) {
            Some(items) => items
                .iter()
                .map(|(n, val, _)| format!("{val} {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            None => match (first("min"), first("max")) {
                (lo, hi) if lo.is_empty() && hi.is_empty() => String::new(),
                (lo, hi) if hi.is_empty() => format!(">= {lo}"),
                (lo, hi) if lo.is_empty() => format!("<= {hi}"),
                (lo, hi) => format!("{lo} to {hi}"),
            },
        };
        writeln!(
            md,
            "| `{}` | {} | {} | {} | {ty} | {unit} | {} | {range} | {} |",
            v.attrs["name"],
            cols[0],
            cols[1],
            cols[2],
            first("start"),
            v.attrs.get("description").cloned().unwrap_or_default()
        )
        .unwrap();
    }
    md
}
