//! The FMI 3.0 view of each FMU and its modelDescription.xml, from the same table as the
//! FMI 2.0 ones ([`crate::model_description`]), and that view as Rust for the FMI 3.0
//! layer (`src/fmu/fmi3/`).
//!
//! - A variable with copies `wheelset[k].<name>` for the wheelsets behind the leading
//!   one is one array `<name>`, the leading wheelset first, sized by `wheelsets`; its
//!   value reference is the leading wheelset's, and its elements are the FMI 2.0
//!   variables (`elements`). Where `wheelsets` is a parameter (TrackContact,
//!   CoupledSystem) it is a UInt64 structural parameter (FMI 3.0, 2.4.7.5: set in
//!   Configuration Mode); a vehicle's FMU carries its count as a UInt64 constant.
//! - The table's enumerations are Enumerations of their TypeDefinitions (FMI 3.0 masters
//!   set them through `fmi3SetInt64`); Integer is Int32; Real is Float64.
//! - The other variables, and rows `wheelset[k].<name>` whose leading wheelset has no
//!   `<name>` (the offsets), stay scalars of their FMI 2.0 name.

use crate::model_description::{description, expand, guid, used_units, xml_escape};
use crate::table::{Fmu, FmuVar, RAW_SECTIONS, Table};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// One FMI 3.0 variable of an FMU.
pub struct Var3 {
    /// The leading element's (or the scalar's) resolved attributes.
    pub v: FmuVar,
    /// The FMI 3.0 type: `Float64`, `Int32`, `UInt64`, `Enumeration`, `String`.
    pub ty: &'static str,
    /// FMI 3.0 causality (`structuralParameter` for `wheelsets` where it is set).
    pub causality: String,
    /// The FMI 2.0 variables of its elements, the leading wheelset's first.
    pub elements: Vec<FmuVar>,
    /// An array sized by `wheelsets`.
    pub array: bool,
}

/// The name of the trailing wheelset's copy `wheelset[k].name`: `(k, name)`.
fn trailing(name: &str) -> Option<(usize, &str)> {
    let rest = name.strip_prefix("wheelset[")?;
    let close = rest.find("].")?;
    Some((rest[..close].parse().ok()?, &rest[close + 2..]))
}

/// The FMI 3.0 variables of `fmu`, in the order of its FMI 2.0 variables.
pub fn view(table: &Table, fmu: &Fmu) -> Vec<Var3> {
    let wheelsets_vr = table.names["wheelsets"];
    let has = |name: &str| table.names.get(name).and_then(|&vr| fmu.var(vr));
    let mut out = Vec::new();
    if let Some(n) = fmu.attrs.get("wheelsets") {
        let mut v = FmuVar {
            vr: wheelsets_vr,
            a: Default::default(),
        };
        for (k, x) in [
            ("name", "wheelsets"),
            ("type", "Integer"),
            ("causality", "local"),
            ("variability", "constant"),
            ("start", n.as_str()),
            (
                "description",
                "Number of wheelsets of the vehicle: the size of every per-wheelset array",
            ),
        ] {
            v.a.insert(k.into(), x.into());
        }
        out.push(Var3 {
            causality: "local".into(),
            ty: "UInt64",
            elements: vec![v.clone()],
            v,
            array: false,
        });
    }
    for v in &fmu.vars {
        if let Some((_, base)) = trailing(v.name())
            && has(base).is_some()
        {
            continue; // an element of the array `base`
        }
        let copies: Vec<&FmuVar> = (2..)
            .map_while(|k| has(&format!("wheelset[{k}].{}", v.name())))
            .collect();
        let per_wheelset = (2..=4).any(|k| {
            table
                .names
                .contains_key(&format!("wheelset[{k}].{}", v.name()))
        });
        let ty = match (v.ty(), v.name()) {
            ("Real", _) => "Float64",
            ("Integer", "wheelsets") => "UInt64",
            ("Integer", _) => "Int32",
            ("Enumeration", _) => "Enumeration",
            ("String", _) => "String",
            (t, n) => panic!("{}: {n}: no FMI 3.0 type for {t}", fmu.id()),
        };
        let causality = match v.name() {
            "wheelsets" => "structuralParameter".to_string(),
            _ => v.causality().to_string(),
        };
        let mut elements = vec![v.clone()];
        elements.extend(copies.into_iter().cloned());
        for e in &elements[1..] {
            for k in ["type", "unit", "min", "max", "causality", "declaredType"] {
                assert_eq!(
                    e.get(k),
                    v.get(k),
                    "{}: {} and {} differ in {k}: an array's elements share it",
                    fmu.id(),
                    v.name(),
                    e.name()
                );
            }
        }
        if let Some(n) = fmu.attrs.get("wheelsets").filter(|_| per_wheelset) {
            assert_eq!(
                n.parse::<usize>().unwrap(),
                elements.len(),
                "{}: {} has {} elements, the vehicle {n} wheelsets",
                fmu.id(),
                v.name(),
                elements.len()
            );
        }
        out.push(Var3 {
            v: v.clone(),
            ty,
            causality,
            elements,
            array: per_wheelset,
        });
    }
    // `wheelsets` before the arrays it sizes (FMI 3.0 sets no order, but the Reference
    // FMUs' fmusim resolves a Dimension's reference as it reads).
    out.sort_by_key(|x| x.v.name() != "wheelsets");
    out
}

/// The number of wheelsets `fmu` starts with: the start of `wheelsets`.
fn start_wheelsets(vars: &[Var3]) -> usize {
    vars.iter()
        .find(|x| x.v.name() == "wheelsets")
        .map_or(1, |x| x.v.get("start").unwrap().parse().unwrap())
}

/// The `<EnumerationType>` elements of the types `used`, from the table's
/// TypeDefinitions (its FMI 2.0 `<SimpleType>`s).
fn enumeration_types(table: &Table, used: &BTreeSet<&str>) -> String {
    let section = &table.sections["TypeDefinitions"];
    let mut s = String::new();
    for ty in used {
        let head = format!("<SimpleType name=\"{ty}\"");
        let at = section.find(&head).expect("a declared enumeration type");
        let line = &section[at..section[at..].find('>').unwrap() + at];
        let desc = line
            .split("description=\"")
            .nth(1)
            .map_or("", |d| &d[..d.find('"').unwrap()]);
        writeln!(
            s,
            "    <EnumerationType name=\"{ty}\" description=\"{desc}\">"
        )
        .unwrap();
        for i in &table.enums[*ty] {
            writeln!(
                s,
                "      <Item name=\"{}\" value=\"{}\" description=\"{}\"/>",
                xml_escape(&i.name),
                i.value,
                xml_escape(&i.description)
            )
            .unwrap();
        }
        writeln!(s, "    </EnumerationType>").unwrap();
    }
    s
}

/// The FMI 3.0 model description of `fmu` and its instantiation token.
pub fn write(table: &Table, fmu: &Fmu, version: &str) -> (String, String) {
    let id = fmu.id();
    let vars = view(table, fmu);
    let n0 = start_wheelsets(&vars);
    let wheelsets_vr = table.names["wheelsets"];
    let mut md = String::new();
    let desc = xml_escape(&fmu.attrs["description"]);
    let order = fmu.capability("maxOutputDerivativeOrder", "0");
    let directional = fmu.capability("providesDirectionalDerivative", "false");
    // A model that carries a track stops where a wheel comes into contact or loses it.
    let early = !fmu.attrs.contains_key("vehicle");
    writeln!(
        md,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription\n  \
         fmiVersion=\"3.0\"\n  modelName=\"{id}\"\n  instantiationToken=\"@TOKEN@\"\n  \
         description=\"{desc}\"\n  author=\"wheelflat developers\"\n  \
         copyright=\"Copyright (c) 2026 wheelflat developers\"\n  license=\"MIT\"\n  \
         version=\"{version}\"\n  generationTool=\"wheelflat build.rs\"\n  \
         variableNamingConvention=\"structured\">\n  \
         <CoSimulation\n    modelIdentifier=\"{id}\"\n    needsExecutionTool=\"false\"\n    \
         canBeInstantiatedOnlyOncePerProcess=\"false\"\n    \
         canGetAndSetFMUState=\"true\"\n    canSerializeFMUState=\"true\"\n    \
         providesDirectionalDerivatives=\"{directional}\"\n    \
         providesAdjointDerivatives=\"{directional}\"\n    \
         canHandleVariableCommunicationStepSize=\"true\"\n    \
         maxOutputDerivativeOrder=\"{order}\"\n    hasEventMode=\"false\"\n    \
         providesIntermediateUpdate=\"false\"\n    mightReturnEarlyFromDoStep=\"{early}\"\n    \
         canReturnEarlyAfterIntermediateUpdate=\"false\"/>"
    )
    .unwrap();
    let used: BTreeSet<&str> = vars
        .iter()
        .filter_map(|x| x.v.get("declaredType"))
        .collect();
    for s in RAW_SECTIONS {
        let text = match s {
            "UnitDefinitions" => used_units(&table.sections[s], &fmu.vars),
            "TypeDefinitions" if used.is_empty() => None,
            "TypeDefinitions" => Some(format!(
                "<TypeDefinitions>\n{}  </TypeDefinitions>",
                enumeration_types(table, &used)
            )),
            _ => Some(table.sections[s].clone()),
        };
        if let Some(text) = text {
            writeln!(md, "  {text}").unwrap();
        }
    }
    writeln!(
        md,
        "  <DefaultExperiment startTime=\"0\" stopTime=\"{}\" stepSize=\"{}\"/>\n  <ModelVariables>",
        fmu.attrs["stopTime"], fmu.attrs["stepSize"]
    )
    .unwrap();
    // The independent variable FMI 3.0 requires, after every value reference of the
    // table.
    writeln!(
        md,
        "    <Float64 name=\"time\" valueReference=\"{}\" causality=\"independent\" \
         variability=\"continuous\" description=\"Simulation time\" unit=\"s\"/>",
        table.vars.len()
    )
    .unwrap();
    for x in &vars {
        md.push_str(&variable(table, x, n0, wheelsets_vr));
    }
    md.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // FMI 2.0 value reference -> the FMI 3.0 variable it is (an element of).
    let of: BTreeMap<usize, usize> = vars
        .iter()
        .flat_map(|x| x.elements.iter().map(move |e| (e.vr, x.v.vr)))
        .collect();
    let index: BTreeMap<&str, usize> = fmu
        .vars
        .iter()
        .enumerate()
        .map(|(k, v)| (v.name(), k + 1))
        .collect();
    let deps = |x: &Var3, attr: &str, inputs_only: bool| -> Vec<usize> {
        let mut d: Vec<usize> = x
            .elements
            .iter()
            .flat_map(|e| expand(table, fmu, &index, e.get(attr), inputs_only))
            .map(|i| of[&fmu.vars[i - 1].vr])
            .collect();
        d.sort_unstable();
        d.dedup();
        d
    };
    for (tag, causalities, attr, inputs_only) in [
        ("Output", &["output"][..], "dependencies", true),
        (
            "InitialUnknown",
            &["output", "calculatedParameter"][..],
            "initialDependencies",
            false,
        ),
    ] {
        for x in vars
            .iter()
            .filter(|x| causalities.contains(&x.causality.as_str()))
        {
            let d = deps(x, attr, inputs_only);
            let list: Vec<String> = d.iter().map(|v| v.to_string()).collect();
            let kinds: Vec<&str> = d.iter().map(|_| "dependent").collect();
            writeln!(
                md,
                "    <{tag} valueReference=\"{}\" dependencies=\"{}\" dependenciesKind=\"{}\"/>",
                x.v.vr,
                list.join(" "),
                kinds.join(" ")
            )
            .unwrap();
        }
    }
    md.push_str("  </ModelStructure>\n</fmiModelDescription>\n");
    let token = guid(&md);
    (md.replace("@TOKEN@", &token), token)
}

/// One variable element: `<Float64 .../>`, with its `<Dimension>` when it is an array.
fn variable(table: &Table, x: &Var3, n0: usize, wheelsets_vr: usize) -> String {
    let v = &x.v;
    let mut description = description(table, v);
    if x.array {
        description.push_str(" [one element per wheelset, the leading one first]");
    }
    let mut s = format!(
        "    <{} name=\"{}\" valueReference=\"{}\" causality=\"{}\" variability=\"{}\"",
        x.ty,
        xml_escape(v.name()),
        v.vr,
        x.causality,
        v.get("variability").unwrap()
    );
    if let Some(i) = v
        .get("initial")
        .filter(|_| x.causality != "structuralParameter")
    {
        write!(s, " initial=\"{i}\"").unwrap();
    }
    write!(s, " description=\"{}\"", xml_escape(&description)).unwrap();
    if let Some(t) = v.get("declaredType") {
        write!(s, " declaredType=\"{t}\"").unwrap();
    }
    for k in ["unit", "displayUnit", "min", "max"] {
        if let Some(a) = v.get(k).filter(|_| x.ty == "Float64" || !k.contains("nit")) {
            write!(s, " {k}=\"{}\"", xml_escape(a)).unwrap();
        }
    }
    // An array starts with as many elements as `wheelsets` starts with.
    let starts: Vec<&str> = x
        .elements
        .iter()
        .take(if x.array { n0 } else { 1 })
        .filter_map(|e| e.a.get("start").map(|s| s.as_str()))
        .collect();
    let has_start = v.get("start").is_some() || (x.ty == "String" && v.a.contains_key("start"));
    if has_start && x.ty != "String" {
        write!(s, " start=\"{}\"", starts.join(" ")).unwrap();
    }
    // The schema's order: the dimensions, then a String's start values.
    let mut body = String::new();
    if x.array {
        write!(
            body,
            "\n      <Dimension valueReference=\"{wheelsets_vr}\"/>"
        )
        .unwrap();
    }
    if has_start && x.ty == "String" {
        for st in &starts {
            write!(body, "\n      <Start value=\"{}\"/>", xml_escape(st)).unwrap();
        }
    }
    if body.is_empty() {
        writeln!(s, "/>").unwrap();
    } else {
        writeln!(s, ">{body}\n    </{}>", x.ty).unwrap();
    }
    s
}

/// The FMI 3.0 tables as Rust, for `src/fmu/vars.rs`: each FMU's `Fmu3Table` (its FMI
/// 2.0 table, token, model description and variables) and `FMI3_FMUS`.
pub fn rust(table: &Table, tokens: &[String]) -> String {
    let mut rust = String::from("\n// ---- FMI 3.0 ----\n\n");
    let mut statics = Vec::new();
    for (fmu, token) in table.fmus.iter().zip(tokens) {
        let id = fmu.id();
        let name = format!("FMI3_{}", crate::rust_binding::split_camel(id, true));
        writeln!(
            rust,
            "/// The `{id}` FMU as an FMI 3.0 co-simulation unit.\n\
             pub static {name}: Fmu3Table = Fmu3Table {{\n    \
             fmi2: &{},\n    token: \"{token}\",\n    \
             model_description: include_str!(concat!(env!(\"OUT_DIR\"), \"/fmi3/{id}.xml\")),\n    \
             vars: &[",
            crate::rust_binding::split_camel(id, true)
        )
        .unwrap();
        for x in view(table, fmu) {
            let ty = match (x.ty, x.causality.as_str()) {
                ("UInt64", "structuralParameter") => "Type3::Wheelsets",
                ("UInt64", _) => "Type3::Constant",
                ("Float64", _) => "Type3::Float64",
                ("Int32", _) => "Type3::Int32",
                ("Enumeration", _) => "Type3::Enumeration",
                _ => "Type3::String",
            };
            let elements: Vec<String> = x.elements.iter().map(|e| e.vr.to_string()).collect();
            let constant = match ty {
                "Type3::Constant" => format!("{}.0", x.v.get("start").unwrap()),
                _ => "f64::NAN".into(),
            };
            writeln!(
                rust,
                "        Var3Spec {{ vr: {}, name: {:?}, ty: {ty}, causality: {:?}, array: {}, \
                 elements: &[{}], constant: {constant} }},",
                x.v.vr,
                x.v.name(),
                x.causality,
                x.array,
                elements.join(", ")
            )
            .unwrap();
        }
        writeln!(rust, "    ],\n}};\n").unwrap();
        statics.push(format!("&{name}"));
    }
    writeln!(
        rust,
        "/// Every FMU's FMI 3.0 table, in the order of [`FMUS`].\n\
         pub static FMI3_FMUS: [&Fmu3Table; {}] = [{}];",
        statics.len(),
        statics.join(", ")
    )
    .unwrap();
    rust
}
