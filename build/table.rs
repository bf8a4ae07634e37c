//! Reads and checks `modelDescription/variables.xml`, the one variable table, and
//! resolves each FMU's view of it (overrides applied, variability and initial derived
//! from the causality). Every generator reads the table through [`Table`].

use quick_xml::Reader;
use quick_xml::events::{BytesStart, Event};
use std::collections::BTreeMap;

/// Where the table lives, relative to the package root.
pub const TABLE: &str = "modelDescription/variables.xml";

/// The sections copied verbatim into every model description, in their order there.
pub const RAW_SECTIONS: [&str; 3] = ["UnitDefinitions", "TypeDefinitions", "LogCategories"];

/// Attributes of one element, unescaped.
pub type Attrs = BTreeMap<String, String>;

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
pub struct TableVar {
    pub attrs: Attrs,
    pub overrides: BTreeMap<String, Attrs>,
}

impl TableVar {
    pub fn name(&self) -> &str {
        &self.attrs["name"]
    }
}

/// A variable as one FMU sees it.
#[derive(Clone)]
pub struct FmuVar {
    /// Value reference: the variable's position in the table.
    pub vr: usize,
    /// Resolved attributes, `variability` and `initial` included.
    pub a: Attrs,
}

impl FmuVar {
    /// A non-empty attribute.
    pub fn get(&self, k: &str) -> Option<&str> {
        self.a.get(k).map(|s| s.as_str()).filter(|s| !s.is_empty())
    }
    pub fn name(&self) -> &str {
        self.get("name").unwrap()
    }
    pub fn causality(&self) -> &str {
        self.get("causality").unwrap()
    }
    pub fn ty(&self) -> &str {
        self.get("type").unwrap()
    }
    /// Known in initialization mode: inputs and parameters with exact start values.
    pub fn is_known(&self) -> bool {
        matches!(self.causality(), "parameter" | "input")
    }
}

/// An item of an enumeration type.
pub struct Item {
    pub name: String,
    pub value: i64,
    pub description: String,
}

/// One FMU: its `<Fmu>` attributes and its variables in ModelVariables order.
pub struct Fmu {
    pub attrs: Attrs,
    pub vars: Vec<FmuVar>,
}

impl Fmu {
    /// `modelIdentifier`.
    pub fn id(&self) -> &str {
        &self.attrs["modelIdentifier"]
    }

    /// A co-simulation capability of the `<Fmu>` element (`canInterpolateInputs`,
    /// `maxOutputDerivativeOrder`, `providesDirectionalDerivative`), or `default`.
    pub fn capability<'a>(&'a self, name: &str, default: &'a str) -> &'a str {
        self.attrs.get(name).map_or(default, |s| s.as_str())
    }

    /// The resolved attributes of the variable with value reference `vr`, if this FMU
    /// has it.
    pub fn var(&self, vr: usize) -> Option<&FmuVar> {
        self.vars.iter().find(|v| v.vr == vr)
    }
}

/// The whole table.
pub struct Table {
    pub fmus: Vec<Fmu>,
    /// Every variable, in table (value reference) order.
    pub vars: Vec<TableVar>,
    /// [`RAW_SECTIONS`] as written in the table.
    pub sections: BTreeMap<String, String>,
    /// Enumeration items by type name, from TypeDefinitions.
    pub enums: BTreeMap<String, Vec<Item>>,
    /// Value reference by variable name.
    pub names: BTreeMap<String, usize>,
}

impl Table {
    /// Reads the table; panics naming what is wrong with it.
    pub fn read(text: &str) -> Table {
        let groups = groups(text);
        let mut reader = Reader::from_str(text);
        let mut fmus: Vec<Attrs> = Vec::new();
        let mut vars: Vec<TableVar> = Vec::new();
        let mut sections: BTreeMap<String, String> = BTreeMap::new();
        loop {
            let pos = reader.buffer_position() as usize;
            match reader.read_event().expect("well-formed variable table") {
                Event::Eof => break,
                Event::Start(e) if RAW_SECTIONS.contains(&e.name().as_ref()) => {
                    let name = e.name().as_ref().to_string();
                    reader.read_to_end(e.name()).expect("closed section");
                    let end = reader.buffer_position() as usize;
                    let start = text[pos..].find('<').unwrap() + pos;
                    sections.insert(name, text[start..end].to_string());
                }
                Event::Empty(e) if e.name().as_ref() == "Fmu" => fmus.push(attrs(&e)),
                Event::Start(e) if e.name().as_ref() == "Repeat" => {
                    // The body once per position of the attributes' lists, `{name}`
                    // replaced by the list's item there.
                    let lists: Vec<(String, Vec<String>)> = attrs(&e)
                        .into_iter()
                        // An item `-` stands for nothing (a name absent from some items).
                        .map(|(k, v)| {
                            let items = v
                                .split_whitespace()
                                .map(|x| {
                                    if x == "-" {
                                        String::new()
                                    } else {
                                        x.to_string()
                                    }
                                })
                                .collect();
                            (k, items)
                        })
                        .collect();
                    let body_start = reader.buffer_position() as usize;
                    reader.read_to_end(e.name()).expect("closed Repeat");
                    let end = reader.buffer_position() as usize;
                    let body = &text[body_start..text[..end].rfind("</Repeat>").unwrap()];
                    let n = lists.first().map_or(0, |(_, l)| l.len());
                    assert!(
                        lists.iter().all(|(_, l)| l.len() == n),
                        "Repeat: every list must have {n} items"
                    );
                    for i in 0..n {
                        let mut b = body.to_string();
                        for (k, l) in &lists {
                            b = b.replace(&format!("{{{k}}}"), &l[i]);
                        }
                        read_variables(&mut Reader::from_str(&b), &mut vars, &groups);
                    }
                }
                Event::Start(e) | Event::Empty(e) if e.name().as_ref() == "Variable" => {
                    variable_event(&e, &mut vars, &groups);
                }
                Event::Empty(e) if e.name().as_ref() == "Override" => {
                    variable_event(&e, &mut vars, &groups);
                }
                _ => {}
            }
        }
        for s in RAW_SECTIONS {
            assert!(sections.contains_key(s), "the table lacks {s}");
        }
        let mut names = BTreeMap::new();
        for (i, v) in vars.iter().enumerate() {
            let name = v.name();
            assert!(
                names.insert(name.to_string(), i).is_none(),
                "duplicate variable {name}"
            );
        }
        let enums = enumerations(&sections["TypeDefinitions"]);
        let fmus = fmus
            .into_iter()
            .map(|attrs| {
                let vars = resolve(&attrs["modelIdentifier"], &vars);
                Fmu { attrs, vars }
            })
            .collect();
        Table {
            fmus,
            vars,
            sections,
            enums,
            names,
        }
    }

    /// The least and largest item value of enumeration type `ty`; its values must be
    /// consecutive (the FMI layer accepts exactly that range).
    pub fn enum_range(&self, ty: &str) -> (i64, i64) {
        let values: Vec<i64> = self.enums[ty].iter().map(|x| x.value).collect();
        let (lo, hi) = (*values.iter().min().unwrap(), *values.iter().max().unwrap());
        assert_eq!(
            (hi - lo + 1) as usize,
            values.len(),
            "{ty}: item values must be consecutive"
        );
        (lo, hi)
    }
}

/// The FMU groups a `fmus` list may name as `@name`: each `<Group name fmus>` of the
/// table, `@vehicles` (every `<Fmu>` with a `vehicle` attribute: a kind of vehicle's own
/// FMU) and `@axles2` to `@axles4` (those on at least that many wheelsets, their
/// `wheelsets` attribute).
fn groups(text: &str) -> BTreeMap<String, String> {
    let mut groups = BTreeMap::new();
    let mut vehicles: Vec<(String, usize)> = Vec::new();
    let mut r = Reader::from_str(text);
    loop {
        match r.read_event().expect("well-formed variable table") {
            Event::Eof => break,
            Event::Empty(e) if e.name().as_ref() == "Group" => {
                let a = attrs(&e);
                groups.insert(format!("@{}", a["name"]), a["fmus"].clone());
            }
            Event::Empty(e) if e.name().as_ref() == "Fmu" => {
                let a = attrs(&e);
                if a.contains_key("vehicle") {
                    let n = a["wheelsets"]
                        .parse()
                        .expect("an Fmu's wheelsets is a count");
                    vehicles.push((a["modelIdentifier"].clone(), n));
                }
            }
            _ => {}
        }
    }
    let of = |least: usize| {
        vehicles
            .iter()
            .filter(|(_, n)| *n >= least)
            .map(|(id, _)| id.as_str())
            .collect::<Vec<_>>()
            .join(" ")
    };
    groups.insert("@vehicles".into(), of(1));
    for k in 2..=4 {
        groups.insert(format!("@axles{k}"), of(k));
    }
    groups
}

/// `list` with every `@group` replaced by its FMUs.
fn expand(list: &str, groups: &BTreeMap<String, String>) -> String {
    list.split_whitespace()
        .map(|x| {
            if x.starts_with('@') {
                groups
                    .get(x)
                    .unwrap_or_else(|| panic!("no FMU group {x}"))
                    .clone()
            } else {
                x.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// A `<Variable>` (a new variable) or `<Override>` (of the last one) element.
fn variable_event(e: &BytesStart, vars: &mut Vec<TableVar>, groups: &BTreeMap<String, String>) {
    if e.name().as_ref() == "Variable" {
        let mut attrs = attrs(e);
        let fmus = expand(&attrs["fmus"], groups);
        attrs.insert("fmus".into(), fmus);
        vars.push(TableVar {
            attrs,
            overrides: BTreeMap::new(),
        });
    } else {
        // `fmu` names one FMU or several, space-separated; overrides of one FMU merge,
        // the later attribute winning.
        let mut a = attrs(e);
        // (An empty list, a Repeat item `-`, overrides nothing.)
        let fmus = expand(&a.remove("fmu").expect("Override needs fmu="), groups);
        let var = vars.last_mut().expect("Override inside a Variable");
        for fmu in fmus.split_whitespace() {
            var.overrides
                .entry(fmu.to_string())
                .or_default()
                .extend(a.clone());
        }
    }
}

/// The variables of a `<Repeat>` body, in order.
fn read_variables(
    reader: &mut Reader<&[u8]>,
    vars: &mut Vec<TableVar>,
    groups: &BTreeMap<String, String>,
) {
    loop {
        match reader.read_event().expect("well-formed Repeat body") {
            Event::Eof => break,
            Event::Start(e) | Event::Empty(e)
                if matches!(e.name().as_ref(), "Variable" | "Override") =>
            {
                variable_event(&e, vars, groups);
            }
            _ => {}
        }
    }
}

/// Enumeration items by type, from the TypeDefinitions section.
fn enumerations(type_definitions: &str) -> BTreeMap<String, Vec<Item>> {
    let mut enums: BTreeMap<String, Vec<Item>> = BTreeMap::new();
    let mut r = Reader::from_str(type_definitions);
    let mut current = String::new();
    loop {
        match r.read_event().expect("well-formed TypeDefinitions") {
            Event::Eof => break,
            Event::Start(e) if e.name().as_ref() == "SimpleType" => {
                current = attrs(&e)["name"].clone();
            }
            Event::Empty(e) if e.name().as_ref() == "Item" => {
                let a = attrs(&e);
                enums.entry(current.clone()).or_default().push(Item {
                    name: a["name"].clone(),
                    value: a["value"].parse().expect("integer item value"),
                    description: a.get("description").cloned().unwrap_or_default(),
                });
            }
            _ => {}
        }
    }
    enums
}

/// The variables of FMU `id`: overrides applied, variability and initial derived from
/// the causality and type, start values required of parameters and inputs and dropped
/// from the calculated ones.
fn resolve(id: &str, vars: &[TableVar]) -> Vec<FmuVar> {
    let mut fv = Vec::new();
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
            // A String parameter's start may be empty (it is written all the same).
            assert!(
                a.get("start")
                    .is_some_and(|s| !s.is_empty() || a["type"] == "String"),
                "{id}: {} needs a start value",
                a["name"]
            );
        } else {
            a.insert("start".into(), String::new());
        }
        fv.push(FmuVar { vr: i, a });
    }
    fv
}
