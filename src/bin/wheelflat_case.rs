//! The engine's study runner: runs cases of CoupledSystem, each given by its FMU
//! variables, and prints one JSON line per case with what a parametric study keeps
//! (the sweep command `python -m wheelflat_study` drives it, one process per worker).
//!
//! ```text
//! wheelflat_case                 # reads cases from standard input, one per line
//! echo "speed=27.78 duration=0.5 keep=primary.left.force" | wheelflat_case
//! ```
//!
//! A case line holds `NAME=VALUE` tokens: CoupledSystem's parameters and inputs by name
//! (docs/VARIABLES.md; enumerations by number; a String parameter's table as a path or
//! as `x,y;x,y;...`, without blanks), `duration=S` (s, required) and
//! `keep=OUT1,OUT2` (outputs whose extremes to keep), and optionally `case=ID` (letters,
//! digits, `_`, `.`, `-`; at most 64), the caller's name for the case, which the answer
//! carries back so that no answer can be taken for another case's. The case runs through the FMU
//! layer in this process (the same model, checks and refusals as CoupledSystem.fmu)
//! and is sampled at every internal step. The JSON line has:
//!
//! * `case`: the request's `case=ID` (absent when the request had none);
//! * `version`, `guid`: the software version and CoupledSystem's GUID;
//! * `steps`, `step` (s), `wall_s`: the internal steps, their size and the wall time;
//! * `peak`: the largest contact force of each wheel (`left`, `right`,
//!   `wheelset[k].left`, ...) over the run (N);
//! * `impacts`: per impact of each leading-wheelset wheel with a flat (the window of one
//!   revolution centred on the first flat's passage): `wheel`, `k` (0 the first
//!   passage), `time` (s) and `peak` (N) of the largest force, `passage` (s) and
//!   `span_position`, the flat's position between sleepers at its passage (0 over a
//!   sleeper, 0.5 mid-span);
//! * `bearing`: the primary (bearing) forces' extremes of the leading wheelset (N);
//! * `contact_loss`: the time each leading wheel is out of contact (s);
//! * `extremes`: the largest and smallest value of each `keep` output;
//! * `warnings`: the FMU's warnings (fmi2Warning: the case ran, but near a fixed rail
//!   end, say), each condition once;
//! * `error`: null, or the refusal or failure in words (then the others may be
//!   missing).

use std::io::{BufRead, Write};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use wheelflat::error::num;
use wheelflat::fmu::vars::{Causality, VarSpec, VarType};
use wheelflat::fmu::{Instance, Kind, Logger};

/// One case: its variables, duration and the outputs to keep.
struct Case {
    sets: Vec<(String, f64)>,
    /// String parameters: a table's path, or the table itself (`x,y;x,y;...`: a token
    /// holds no blank).
    texts: Vec<(String, String)>,
    duration: f64,
    keep: Vec<String>,
}

fn parse(line: &str) -> Result<Case, String> {
    let mut case = Case {
        sets: Vec::new(),
        texts: Vec::new(),
        duration: f64::NAN,
        keep: Vec::new(),
    };
    let mut seen = std::collections::HashSet::new();
    for token in line.split_whitespace() {
        let (name, value) = token
            .split_once('=')
            .ok_or_else(|| format!("`{token}`: expected NAME=VALUE"))?;
        if !seen.insert(name.to_string()) {
            return Err(format!("`{name}` is given twice in one case"));
        }
        match name {
            "keep" => {
                case.keep = value
                    .split(',')
                    .filter(|s| !s.is_empty())
                    .map(String::from)
                    .collect()
            }
            _ if spec(name).is_ok_and(|s| s.ty == VarType::String) => {
                case.texts.push((name.to_string(), value.to_string()))
            }
            _ => {
                let x: f64 = value.parse().map_err(|_| match (name, spec(name)) {
                    ("duration", _) | (_, Ok(_)) => {
                        format!("`{name}`: `{value}` is not a number")
                    }
                    (_, Err(e)) => e,
                })?;
                if name == "duration" {
                    case.duration = x;
                } else {
                    case.sets.push((name.to_string(), x));
                }
            }
        }
    }
    if !(case.duration > 0.0 && case.duration <= 1e4) {
        return Err(format!(
            "duration = {}: give duration=S with 0 < S <= 1e4 s",
            case.duration
        ));
    }
    Ok(case)
}

fn spec(name: &str) -> Result<&'static VarSpec, String> {
    Kind::CoupledSystem
        .table()
        .vars
        .iter()
        .find(|v| v.name == name)
        .ok_or_else(|| format!("`{name}` is not a variable of CoupledSystem (docs/VARIABLES.md)"))
}

/// Extremes of one quantity.
#[derive(Clone, Copy)]
struct Range {
    max: f64,
    min: f64,
}

impl Range {
    const NONE: Range = Range {
        max: f64::NEG_INFINITY,
        min: f64::INFINITY,
    };
    fn take(&mut self, x: f64) {
        self.max = self.max.max(x);
        self.min = self.min.min(x);
    }
}

/// One impact of a wheel: the window of a revolution around a flat's passage.
struct Impact {
    wheel: &'static str,
    k: i64,
    peak: f64,
    time: f64,
    passage: f64,
    span_position: f64,
}

fn json_str(s: &str) -> String {
    let mut o = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => o.push_str("\\\""),
            '\\' => o.push_str("\\\\"),
            c if (c as u32) < 0x20 => o.push_str(&format!("\\u{:04x}", c as u32)),
            c => o.push(c),
        }
    }
    o.push('"');
    o
}

fn json_num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else {
        "null".into()
    }
}

fn run(case: &Case) -> Result<String, String> {
    let started = Instant::now();
    let log = Arc::new(Mutex::new(Vec::<String>::new()));
    let sink = log.clone();
    let logger: Logger = Box::new(move |_, _, m| sink.lock().unwrap().push(m.to_string()));
    let mut inst = Instance::new(Kind::CoupledSystem.table(), "case", logger, false);
    let last =
        |log: &Arc<Mutex<Vec<String>>>| log.lock().unwrap().last().cloned().unwrap_or_default();
    let fail = |e: wheelflat::fmu::Refusal| e.message;
    inst.setup_experiment(0.0, None).map_err(fail)?;
    for (name, text) in &case.texts {
        let s = spec(name)?;
        inst.set_string(&[s.vr], std::slice::from_ref(text))
            .map_err(fail)?;
    }
    for (name, x) in &case.sets {
        let s = spec(name)?;
        if !matches!(s.causality, Causality::Parameter | Causality::Input) {
            return Err(format!(
                "`{name}` is an output of CoupledSystem, not a parameter"
            ));
        }
        match s.ty {
            VarType::Real => inst.set_real(&[s.vr], &[*x]).map_err(fail)?,
            _ => {
                if x.fract() != 0.0 {
                    return Err(format!("`{name}` = {x}: a whole number is needed"));
                }
                if !(s.min..=s.max).contains(x) {
                    return Err(format!(
                        "`{name}` = {x} is out of range: {} <= {name} <= {}",
                        num(s.min),
                        num(s.max)
                    ));
                }
                inst.set_integer(&[s.vr], &[*x as i32]).map_err(fail)?
            }
        }
    }
    inst.enter_initialization().map_err(fail)?;
    // The FMU's warnings (fmi2Warning: the call went through), once each, for the
    // JSON line; an error ends the case.
    let mut warnings: Vec<String> = Vec::new();
    let warned = |r: wheelflat::fmu::FmiResult,
                  warnings: &mut Vec<String>|
     -> Result<(), wheelflat::fmu::Refusal> {
        match r {
            Err(e) if e.status == wheelflat::fmu::Status::Warning => {
                // A condition that still holds is logged as "still: <kind>" after its
                // first message: one entry per condition.
                if !e.message.contains(" still: ") && !warnings.contains(&e.message) {
                    warnings.push(e.message);
                }
                Ok(())
            }
            other => other,
        }
    };
    warned(inst.exit_initialization(), &mut warnings).map_err(fail)?;
    let value = |inst: &mut Instance, name: &str| -> Result<f64, String> {
        let s = spec(name)?;
        let mut x = [0.0];
        inst.get_real(&[s.vr], &mut x).map_err(|e| e.message)?;
        Ok(x[0])
    };
    let h = value(&mut inst, "solver.step")?;
    let wheelsets = inst.value(spec("wheelsets")?.vr) as usize;
    let spacing = value(&mut inst, "track.sleeper_spacing")?;
    // What is read at every step: the contact forces of every wheel, the axle angle
    // and position, the leading wheelset's bearing forces, the kept outputs.
    let mut names: Vec<String> = Vec::new();
    let mut wheel_names = Vec::new();
    for k in 0..wheelsets {
        for side in ["left", "right"] {
            let prefix = if k == 0 {
                String::new()
            } else {
                format!("wheelset[{}].", k + 1)
            };
            names.push(format!("{prefix}contact.{side}.force"));
            wheel_names.push(format!("{prefix}{side}"));
        }
    }
    let nw = names.len();
    for n in [
        "wheel.rotation",
        "position",
        "primary.left.force",
        "primary.right.force",
    ] {
        names.push(n.into());
    }
    for n in &case.keep {
        let s = spec(n)?;
        if s.ty != VarType::Real {
            return Err(format!("keep: `{n}` is not a Real variable"));
        }
        names.push(n.clone());
    }
    let vrs: Vec<u32> = names
        .iter()
        .map(|n| spec(n).map(|s| s.vr))
        .collect::<Result<_, _>>()?;
    let mut x = vec![0.0; vrs.len()];
    // The first flat of each leading wheel places its impacts.
    let mut flats = Vec::new();
    for (i, side) in ["left", "right"].into_iter().enumerate() {
        let length = inst.value(spec(&format!("flat.{side}[1].length"))?.vr);
        if length > 0.0 {
            flats.push((
                i,
                side,
                inst.value(spec(&format!("flat.{side}[1].angle"))?.vr),
            ));
        }
    }
    let mut peaks = vec![Range::NONE; nw];
    let mut bearing = [Range::NONE; 2];
    let mut loss = [0.0f64; 2];
    let mut kept = vec![Range::NONE; case.keep.len()];
    let mut impacts: Vec<Impact> = Vec::new();
    // Per flat: the window being filled and the sign of the angle from the passage.
    let mut open: Vec<Option<Impact>> = flats.iter().map(|_| None).collect();
    let mut before: Vec<f64> = vec![f64::NAN; flats.len()];
    let n = (case.duration / h).round() as u64;
    // A duration that rounds to no step would return the static state as the result.
    if n == 0 {
        return Err(format!(
            "duration = {} s is shorter than half the track's step solver.step = {} s, so no \
             step would run: give at least {} s",
            num(case.duration),
            num(h),
            num(0.5 * h)
        ));
    }
    for step in 0..=n {
        let t = step as f64 * h;
        inst.get_real(&vrs, &mut x).map_err(|e| e.message)?;
        for (p, &f) in peaks.iter_mut().zip(&x[..nw]) {
            p.take(f);
        }
        let (gamma, position) = (x[nw], x[nw + 1]);
        bearing[0].take(x[nw + 2]);
        bearing[1].take(x[nw + 3]);
        for (r, &v) in kept.iter_mut().zip(&x[nw + 4..]) {
            r.take(v);
        }
        for (side, l) in loss.iter_mut().enumerate() {
            if x[side] <= 0.0 && step < n {
                *l += h;
            }
        }
        for (j, &(i, wheel, angle)) in flats.iter().enumerate() {
            // The angle from the flat's nearest passage, in (-pi, pi], and which
            // passage it is.
            let turns = (gamma - angle) / std::f64::consts::TAU;
            let k = turns.round() as i64;
            let from = (turns - k as f64) * std::f64::consts::TAU;
            let force = x[i];
            let current = open[j].as_ref().map(|m| m.k);
            if current != Some(k) {
                if let Some(done) = open[j].take() {
                    impacts.push(done);
                }
                open[j] = Some(Impact {
                    wheel,
                    k,
                    peak: f64::NEG_INFINITY,
                    time: t,
                    passage: f64::NAN,
                    span_position: f64::NAN,
                });
            }
            let m = open[j].as_mut().expect("a window");
            if force > m.peak {
                m.peak = force;
                m.time = t;
            }
            if before[j] < 0.0 && from >= 0.0 || (from == 0.0 && m.passage.is_nan()) {
                m.passage = t;
                m.span_position = (position / spacing).rem_euclid(1.0);
            }
            before[j] = from;
        }
        if step == n {
            break;
        }
        warned(inst.do_step(t, h), &mut warnings).map_err(|e| {
            let logged = last(&log);
            if logged.is_empty() { e.message } else { logged }
        })?;
    }
    for m in open.into_iter().flatten() {
        impacts.push(m);
    }
    // Only windows that hold a passage are impacts (the run's ends may cut one).
    impacts.retain(|m| m.passage.is_finite());
    let mut o = String::new();
    o.push_str(&format!(
        "{{\"version\":{},\"guid\":{},\"steps\":{n},\"step\":{},\"wall_s\":{},\"peak\":{{",
        json_str(env!("CARGO_PKG_VERSION")),
        json_str(Kind::CoupledSystem.table().guid),
        json_num(h),
        json_num(started.elapsed().as_secs_f64())
    ));
    let list: Vec<String> = wheel_names
        .iter()
        .zip(&peaks)
        .map(|(w, p)| format!("{}:{}", json_str(w), json_num(p.max)))
        .collect();
    o.push_str(&list.join(","));
    o.push_str("},\"impacts\":[");
    let list: Vec<String> = impacts
        .iter()
        .map(|m| {
            format!(
                "{{\"wheel\":{},\"k\":{},\"time\":{},\"peak\":{},\"passage\":{},\"span_position\":{}}}",
                json_str(m.wheel),
                m.k,
                json_num(m.time),
                json_num(m.peak),
                json_num(m.passage),
                json_num(m.span_position)
            )
        })
        .collect();
    o.push_str(&list.join(","));
    o.push_str(&format!(
        "],\"bearing\":{{\"left\":{{\"max\":{},\"min\":{}}},\"right\":{{\"max\":{},\"min\":{}}}}},\
         \"contact_loss\":{{\"left\":{},\"right\":{}}},\"extremes\":{{",
        json_num(bearing[0].max),
        json_num(bearing[0].min),
        json_num(bearing[1].max),
        json_num(bearing[1].min),
        json_num(loss[0]),
        json_num(loss[1])
    ));
    let list: Vec<String> = case
        .keep
        .iter()
        .zip(&kept)
        .map(|(k, r)| {
            format!(
                "{}:{{\"max\":{},\"min\":{}}}",
                json_str(k),
                json_num(r.max),
                json_num(r.min)
            )
        })
        .collect();
    o.push_str(&list.join(","));
    let list: Vec<String> = warnings.iter().map(|w| json_str(w)).collect();
    o.push_str(&format!(
        "}},\"warnings\":[{}],\"error\":null}}",
        list.join(",")
    ));
    Ok(o)
}

/// `--variables`: CoupledSystem's parameters and inputs, one per line: name, type,
/// min, max; then its Real outputs (what `keep` may name): name, `output`, `-`, `-`
/// (for the sweep command's checks before a study starts).
fn list_variables() {
    let mut out = std::io::stdout().lock();
    for v in Kind::CoupledSystem.table().vars {
        if matches!(v.causality, Causality::Parameter | Causality::Input) {
            let ty = match v.ty {
                VarType::Real => "Real",
                VarType::String => "String",
                _ => "Integer",
            };
            let _ = writeln!(
                out,
                "{}\t{ty}\t{:?}\t{:?}\t{}",
                v.name, v.min, v.max, v.unit
            );
        }
    }
    for v in Kind::CoupledSystem.table().vars {
        if v.causality == Causality::Output && v.ty == VarType::Real {
            let _ = writeln!(out, "{}\toutput\t-\t-\t{}", v.name, v.unit);
        }
    }
}

/// The request's `case=ID` token taken out of `line`: (the id, the rest of the line);
/// an id that is not one is an error (the answer then carries no id).
fn case_id(line: &str) -> (Result<Option<String>, String>, String) {
    let mut id = Ok(None);
    let mut rest = Vec::new();
    for token in line.split_whitespace() {
        match token.strip_prefix("case=") {
            Some(v) if matches!(id, Ok(None)) => {
                let good = !v.is_empty()
                    && v.len() <= 64
                    && v.bytes()
                        .all(|b| b.is_ascii_alphanumeric() || b"_.-".contains(&b));
                id = if good {
                    Ok(Some(v.to_string()))
                } else {
                    Err(format!(
                        "case = `{v}`: a case id is 1 to 64 letters, digits, '_', '.' or '-'"
                    ))
                };
            }
            Some(_) => id = Err("`case` is given twice in one case".into()),
            None => rest.push(token),
        }
    }
    (id, rest.join(" "))
}

fn main() {
    match std::env::args().nth(1).as_deref() {
        Some("--variables") => {
            list_variables();
            return;
        }
        Some("--help" | "-h") => {
            println!(
                "usage: wheelflat_case [--variables]\n\
                 Runs cases of CoupledSystem read from standard input, one per line of NAME=VALUE \
                 tokens with duration=S (and keep=OUT1,OUT2, case=ID), answering one JSON line \
                 each; --variables lists CoupledSystem's parameters, inputs and outputs with \
                 their ranges and units (NAME TYPE MIN MAX UNIT, tab-separated). The sweep command (python -m wheelflat_study) drives it."
            );
            return;
        }
        Some(a) => {
            eprintln!("wheelflat_case: {a}: no such option (--help, --variables)");
            std::process::exit(2);
        }
        None => {}
    }
    let mut stdin = std::io::stdin().lock();
    let mut out = std::io::stdout().lock();
    let mut bytes = Vec::new();
    loop {
        bytes.clear();
        match stdin.read_until(b'\n', &mut bytes) {
            Ok(0) | Err(_) => break,
            Ok(_) => {}
        }
        // Every line gets one answer, a line that is not UTF-8 or holds no case too.
        let (id, line) = case_id(String::from_utf8_lossy(&bytes).trim());
        // A panic in a case is reported as that case's error; the runner goes on.
        let result = if let Err(e) = &id {
            Err(e.clone())
        } else if line.is_empty() {
            Err("an empty case line: give NAME=VALUE tokens and duration=S".into())
        } else {
            std::panic::catch_unwind(|| parse(&line).and_then(|c| run(&c)))
                .unwrap_or_else(|_| Err("internal error (panic) in the case runner".into()))
        };
        let text = match result {
            Ok(s) => s,
            Err(e) => format!(
                "{{\"version\":{},\"guid\":{},\"error\":{}}}",
                json_str(env!("CARGO_PKG_VERSION")),
                json_str(Kind::CoupledSystem.table().guid),
                json_str(&e)
            ),
        };
        // The answer names its case first: `{"case":"ID",...}`.
        let text = match id {
            Ok(Some(id)) => format!("{{\"case\":{},{}", json_str(&id), &text[1..]),
            _ => text,
        };
        if writeln!(out, "{text}").and_then(|_| out.flush()).is_err() {
            break;
        }
    }
}
