//! Each FMU's `documentation/index.html`: what the model is, its variables, how to use
//! it and its limits. `build/pages/page.html` is the page with these sections;
//! `build/pages/<modelIdentifier>.html` gives the model's prose for them, three parts
//! separated by the lines `<!-- use -->` and `<!-- limits -->`. The tables come from the
//! variable table.
//!
//! Placeholders: `@INCLUDE name@` is `build/pages/name.html`; `@VARIABLES@` the FMU's
//! variables; `@CONNECTIONS@` the variables that join TrackContact and
//! RollPlaneVehicle; `@WHAT@`, `@USE@`, `@LIMITS@` the model's parts; `@ID@`,
//! `@VERSION@`, `@GUID@` and `@DESCRIPTION@` what their names say.

use crate::model_description::xml_escape;
use crate::table::{Fmu, FmuVar, Table};
use crate::variables_md::range;
use std::fmt::Write as _;
use std::fs;

/// The folder of the page templates.
pub const PAGES: &str = "build/pages";

/// The two FMUs a master couples, in the order of the connection table.
const PAIR: [&str; 2] = ["RollPlaneVehicle", "TrackContact"];

fn template(name: &str) -> String {
    let path = format!("{PAGES}/{name}.html");
    fs::read_to_string(&path).unwrap_or_else(|e| panic!("read {path}: {e}"))
}

/// The page of `fmu`, whose model description has GUID `guid`.
pub fn write(table: &Table, fmu: &Fmu, guid: &str, version: &str) -> String {
    let model = template(fmu.id());
    let (what, usage, limits) = parts(fmu.id(), &model);
    let mut page = template("page")
        .replace("@WHAT@", what.trim_end())
        .replace("@USE@", usage.trim_end())
        .replace("@LIMITS@", limits.trim_end());
    while let Some(at) = page.find("@INCLUDE ") {
        let end = at + page[at + 1..].find('@').expect("closed @INCLUDE name@") + 1;
        let name = page[at + "@INCLUDE ".len()..end].to_string();
        page.replace_range(at..=end, template(&name).trim_end());
    }
    let page = page
        .replace("@VARIABLES@", variables(table, fmu).trim_end())
        .replace("@CONNECTIONS@", &connections(table))
        .replace("@ID@", fmu.id())
        .replace("@VERSION@", version)
        .replace("@GUID@", guid)
        .replace("@DESCRIPTION@", &xml_escape(&fmu.attrs["description"]));
    if let Some(at) = page.find('@') {
        panic!(
            "{}: unknown placeholder at {:?}",
            fmu.id(),
            &page[at..page.len().min(at + 30)]
        );
    }
    page
}

/// The three parts of a model's prose: what it is, how to use it, its limits.
fn parts<'a>(id: &str, model: &'a str) -> (&'a str, &'a str, &'a str) {
    let split = |text: &'a str, marker: &str| {
        text.split_once(marker)
            .unwrap_or_else(|| panic!("{PAGES}/{id}.html: no line {marker:?}"))
    };
    let (what, rest) = split(model, "<!-- use -->\n");
    let (usage, limits) = split(rest, "<!-- limits -->\n");
    (what, usage, limits)
}

/// Unit and display unit of a Real variable (`m (mm)`), nothing for the others.
fn unit(v: &FmuVar) -> String {
    if v.ty() != "Real" {
        return String::new();
    }
    match (v.get("unit"), v.get("displayUnit")) {
        (Some(u), Some(d)) => format!("{} ({})", xml_escape(u), xml_escape(d)),
        (Some(u), None) => xml_escape(u),
        _ => String::new(),
    }
}

/// The table of the FMU's variables, in ModelVariables order, and the items of the
/// enumerations they use.
fn variables(table: &Table, fmu: &Fmu) -> String {
    let count = |c: &str| fmu.vars.iter().filter(|v| v.causality() == c).count();
    let mut h = String::new();
    writeln!(
        h,
        "<p>{} variables: {} parameters, {} calculated parameters, {} inputs, {} outputs. \
         Units are SI; the display unit in parentheses is what tools may show. The range is \
         what <code>fmi2SetReal</code>/<code>fmi2SetInteger</code> accept.</p>",
        fmu.vars.len(),
        count("parameter"),
        count("calculatedParameter"),
        count("input"),
        count("output")
    )
    .unwrap();
    h.push_str(
        "<table>\n<tr><th>name</th><th>causality</th><th>variability</th><th>type</th>\
         <th>unit</th><th>start</th><th>min/max</th><th>description</th></tr>\n",
    );
    let mut used_enums = Vec::new();
    for v in &fmu.vars {
        let ty = match v.get("declaredType") {
            Some(t) => {
                if !used_enums.contains(&t) {
                    used_enums.push(t);
                }
                // Written as an Integer (model_description.rs says why).
                format!("Integer ({})", xml_escape(t))
            }
            None => v.ty().to_string(),
        };
        let limits = match v.get("declaredType") {
            Some(t) => {
                let (lo, hi) = table.enum_range(t);
                range(&lo.to_string(), &hi.to_string())
            }
            None => range(v.get("min").unwrap_or(""), v.get("max").unwrap_or("")),
        };
        writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{ty}</td><td>{}</td>\
             <td class=\"num\">{}</td><td class=\"num\">{}</td><td>{}</td></tr>",
            xml_escape(v.name()),
            v.causality(),
            v.get("variability").unwrap(),
            unit(v),
            xml_escape(v.get("start").unwrap_or("")),
            xml_escape(&limits),
            xml_escape(&crate::model_description::description(table, v))
        )
        .unwrap();
    }
    h.push_str("</table>\n");
    for ty in used_enums {
        writeln!(
            h,
            "<p>Enumeration <code>{}</code>:</p>\n<ul>",
            xml_escape(ty)
        )
        .unwrap();
        for item in &table.enums[ty] {
            writeln!(
                h,
                "<li>{} <code>{}</code>: {}</li>",
                item.value,
                xml_escape(&item.name),
                xml_escape(&item.description)
            )
            .unwrap();
        }
        h.push_str("</ul>\n");
    }
    h
}

/// The variables that join the pair: an output (or calculated parameter) of one FMU
/// that is an input (or parameter) of the other.
fn connections(table: &Table) -> String {
    let fmu = |id: &str| table.fmus.iter().find(|f| f.id() == id).unwrap();
    let pair = PAIR.map(fmu);
    let mut h = String::from(
        "<table>\n<tr><th>variable</th><th>from</th><th>to</th><th>unit</th><th>when</th></tr>\n",
    );
    for vr in 0..table.vars.len() {
        let (Some(a), Some(b)) = (pair[0].var(vr), pair[1].var(vr)) else {
            continue;
        };
        let when = |from: &FmuVar, to: &FmuVar| match (from.causality(), to.causality()) {
            ("calculatedParameter", "parameter") => Some("initialization mode"),
            ("output", "input") => Some("initialization mode and every communication point"),
            _ => None,
        };
        let (from, to, when) = match (when(a, b), when(b, a)) {
            (Some(w), _) => (pair[0], pair[1], w),
            (None, Some(w)) => (pair[1], pair[0], w),
            (None, None) => continue,
        };
        writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{when}</td></tr>",
            xml_escape(a.name()),
            from.id(),
            to.id(),
            unit(a)
        )
        .unwrap();
    }
    h.push_str("</table>");
    h
}

/// `$OUT_DIR/documentation.rs`, which `build_fmus` includes: the pages by
/// modelIdentifier, each in `$OUT_DIR/documentation/<modelIdentifier>.html`.
pub fn index(table: &Table) -> String {
    let mut rust = String::from(
        "// Generated by build/documentation.rs; do not edit.\n\n\
         /// Each FMU's documentation/index.html, by modelIdentifier.\n\
         pub const DOCUMENTATION: &[(&str, &str)] = &[\n",
    );
    for fmu in &table.fmus {
        writeln!(
            rust,
            "    (\"{0}\", include_str!(concat!(env!(\"OUT_DIR\"), \"/documentation/{0}.html\"))),",
            fmu.id()
        )
        .unwrap();
    }
    rust.push_str("];\n");
    rust
}
