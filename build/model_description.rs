//! Each FMU's modelDescription.xml, with a GUID derived from its content: the
//! variables in table order, the table's unit and log-category sections verbatim,
//! and a ModelStructure whose dependencies come from the table's `dependencies` and
//! `initialDependencies`.
//!
//! The table's enumerations (contact.model, interface, vehicle.model, flat shapes) are
//! written as Integer variables with their range and their items named in the
//! description ("1 = adaptive, 2 = hertz"), and the TypeDefinitions section is left out:
//! OSP libcosim ignores FMI 2.0 Enumeration variables and refuses them in its system
//! structures, and ecos does not set them, so a choice written as an Enumeration cannot
//! be made in either. Both read and write Integer. The names stay in the table, which
//! gives them to the Rust binding, docs/VARIABLES.md and each FMU's documentation page.

use crate::table::{Fmu, FmuVar, RAW_SECTIONS, Table};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// Escapes text for an XML (or HTML) attribute value or text node.
pub fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// 128-bit FNV-1a of the content, formatted as a GUID.
pub fn guid(content: &str) -> String {
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

/// The unit definitions `section` less the units none of the variables `fv` uses (one
/// `<Unit>` per line in the table); `None` when none is used.
pub fn used_units(section: &str, fv: &[crate::table::FmuVar]) -> Option<String> {
    let used: std::collections::BTreeSet<&str> = fv.iter().filter_map(|v| v.get("unit")).collect();
    let mut kept = 0;
    let lines: Vec<&str> = section
        .lines()
        .filter(|l| {
            let Some(rest) = l.trim_start().strip_prefix("<Unit name=\"") else {
                return true;
            };
            let name = &rest[..rest.find('"').expect("a closed unit name")];
            let keep = used.contains(name);
            kept += usize::from(keep);
            keep
        })
        .collect();
    (kept > 0).then(|| lines.join("\n"))
}

/// The model description of `fmu` (package version `version`) and its GUID.
pub fn write(table: &Table, fmu: &Fmu, version: &str) -> (String, String) {
    let id = fmu.id();
    let fv = &fmu.vars;
    let mut md = String::new();
    let desc = xml_escape(&fmu.attrs["description"]);
    let interpolate = fmu.capability("canInterpolateInputs", "false");
    let order = fmu.capability("maxOutputDerivativeOrder", "0");
    let directional = fmu.capability("providesDirectionalDerivative", "false");
    writeln!(
        md,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<fmiModelDescription\n  \
         fmiVersion=\"2.0\"\n  modelName=\"{id}\"\n  guid=\"@GUID@\"\n  \
         description=\"{desc}\"\n  author=\"wheelflat developers\"\n  \
         copyright=\"Copyright (c) 2026 wheelflat developers\"\n  license=\"MIT\"\n  \
         version=\"{version}\"\n  generationTool=\"wheelflat build.rs\"\n  \
         variableNamingConvention=\"structured\"\n  numberOfEventIndicators=\"0\">\n  \
         <CoSimulation\n    modelIdentifier=\"{id}\"\n    needsExecutionTool=\"false\"\n    \
         canHandleVariableCommunicationStepSize=\"true\"\n    canInterpolateInputs=\"{interpolate}\"\n    \
         maxOutputDerivativeOrder=\"{order}\"\n    canRunAsynchronuously=\"false\"\n    \
         canBeInstantiatedOnlyOncePerProcess=\"false\"\n    canNotUseMemoryManagementFunctions=\"true\"\n    \
         canGetAndSetFMUstate=\"true\"\n    canSerializeFMUstate=\"true\"\n    \
         providesDirectionalDerivative=\"{directional}\"/>"
    )
    .unwrap();
    for s in RAW_SECTIONS {
        let text = match s {
            "UnitDefinitions" => used_units(&table.sections[s], fv),
            // No variable is written as an Enumeration (see the module's comment).
            "TypeDefinitions" => None,
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
    for (k, v) in fv.iter().enumerate() {
        md.push_str(&scalar_variable(table, k + 1, v));
    }
    md.push_str("  </ModelVariables>\n  <ModelStructure>\n");
    // 1-based indices of the FMU's ModelVariables.
    let index: BTreeMap<&str, usize> = fv
        .iter()
        .enumerate()
        .map(|(k, v)| (v.name(), k + 1))
        .collect();
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
            let d = expand(table, fmu, &index, v.get(attr), inputs_only);
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
    (md.replace("@GUID@", &g), g)
}

/// One `<ScalarVariable>`, numbered `k` in a comment.
/// The description of `v` as the model description gives it: an enumeration's with its
/// items' codes and names appended, `(1 = adaptive, 2 = hertz)`.
pub fn description(table: &Table, v: &FmuVar) -> String {
    match (v.ty(), v.get("declaredType")) {
        ("Enumeration", Some(ty)) => format!(
            "{} ({})",
            v.get("description").unwrap_or(""),
            table.enums[ty]
                .iter()
                .map(|i| format!("{} = {}", i.value, i.name))
                .collect::<Vec<_>>()
                .join(", ")
        ),
        _ => v.get("description").unwrap_or("").to_string(),
    }
}

fn scalar_variable(table: &Table, k: usize, v: &FmuVar) -> String {
    let enumeration = v.ty() == "Enumeration";
    let description = description(table, v);
    let mut line = format!(
        "    <!-- {k} -->\n    <ScalarVariable name=\"{}\" valueReference=\"{}\" causality=\"{}\" variability=\"{}\"",
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
        xml_escape(&description),
        if enumeration { "Integer" } else { v.ty() }
    )
    .unwrap();
    if enumeration {
        let (lo, hi) = table.enum_range(v.get("declaredType").expect("an enumeration's type"));
        write!(line, " min=\"{lo}\" max=\"{hi}\"").unwrap();
    }
    if v.ty() == "String" {
        // A String parameter's start, empty as it may be, is required (initial exact).
        write!(
            line,
            " start=\"{}\"",
            xml_escape(v.a.get("start").map_or("", |s| s))
        )
        .unwrap();
    }
    for k in ["declaredType", "unit", "displayUnit", "start", "min", "max"] {
        if enumeration && k == "declaredType" {
            continue;
        }
        if k == "start" && v.ty() == "String" {
            continue;
        }
        if let Some(x) = v.get(k) {
            if v.ty() != "Real" && matches!(k, "unit" | "displayUnit") {
                continue;
            }
            write!(line, " {k}=\"{}\"", xml_escape(x)).unwrap();
        }
    }
    writeln!(line, "/>\n    </ScalarVariable>").unwrap();
    line
}

/// The ModelVariables indices a dependency list names: plain names and prefixes with a
/// trailing `*`, kept when they are inputs (`inputs_only`) or knowns of initialization
/// mode. A plain name must exist in the table (catches typos); it may belong to
/// another FMU.
pub fn expand(
    table: &Table,
    fmu: &Fmu,
    index: &BTreeMap<&str, usize>,
    list: Option<&str>,
    inputs_only: bool,
) -> Vec<usize> {
    let mut out = Vec::new();
    for pat in list.unwrap_or("").split_whitespace() {
        let mut hit = false;
        for v in &fmu.vars {
            let ok = if inputs_only {
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
        assert!(
            hit || pat.ends_with('*') || table.names.contains_key(pat),
            "{}: unknown name {pat}",
            fmu.id()
        );
    }
    out.sort_unstable();
    out.dedup();
    out
}

/// ` dependencies="..." dependenciesKind="..."` of an `<Unknown>`.
fn deps_attr(d: &[usize]) -> String {
    let s: Vec<String> = d.iter().map(|x| x.to_string()).collect();
    let kinds: Vec<&str> = d.iter().map(|_| "dependent").collect();
    format!(
        " dependencies=\"{}\" dependenciesKind=\"{}\"",
        s.join(" "),
        kinds.join(" ")
    )
}
