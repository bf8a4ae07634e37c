//! The oracle of every call: the status is one FMI defines, a call on a null instance
//! is refused, and the messages logged name the function and the cause without
//! reporting a caught panic; an FMI 3.0 instance's messages are in FMI 3.0 terms (no
//! `fmi2...` name, no `fmi3...` name that FMI 3.0 does not have).

use crate::common::Log;
use crate::fmi3_calls::F3S;
use crate::world::{Status, Version, World};
use std::ffi::c_int;
use std::sync::OnceLock;

/// The identifiers in `m` that start with `prefix` (`fmi2`, `fmi3`).
fn identifiers<'a>(m: &'a str, prefix: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    m.match_indices(prefix).filter_map(move |(at, _)| {
        let before = m[..at].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') {
            return None;
        }
        let end = m[at..]
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .map_or(m.len(), |k| at + k);
        Some(&m[at..end])
    })
}

/// The names FMI 3.0 has, sorted: its functions ([`F3S`]), the types of
/// `fmi3FunctionTypes.h` and `fmi3PlatformTypes.h` (as the crate's header declares them)
/// and the statuses.
fn fmi3_names() -> &'static [&'static str] {
    static NAMES: OnceLock<Vec<&'static str>> = OnceLock::new();
    NAMES.get_or_init(|| {
        let header = wheelflat::fmu::vars::C_HEADER3;
        let mut v: Vec<&str> = F3S
            .iter()
            .map(|f| f.1)
            .chain(identifiers(header, "fmi3"))
            .chain([
                "fmi3OK",
                "fmi3Warning",
                "fmi3Discard",
                "fmi3Error",
                "fmi3Fatal",
            ])
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    })
}

/// What is wrong with the wording of an FMI 3.0 instance's message `m`: an FMI 2.0
/// name (but the pointer of a refused `fmi3InstantiateCoSimulation` given an FMI 2.0
/// GUID to the FMI 2.0 FMU, "instantiate the FMI 2.0 FMU with fmi2Instantiate"), or
/// an `fmi3...` name FMI 3.0 does not have.
pub fn fmi3_wording(m: &str) -> Option<String> {
    let m = m.replace("the FMI 2.0 FMU with fmi2Instantiate", "");
    if let Some(w) = identifiers(&m, "fmi2").next() {
        return Some(format!("the FMI 2.0 name `{w}`"));
    }
    identifiers(&m, "fmi3")
        .find(|w| fmi3_names().binary_search(w).is_err())
        .map(|w| format!("`{w}`, which FMI 3.0 does not have"))
}

impl World {
    /// The messages logged since `from` must include one of status >= Warning that
    /// names `call` and says why; none may report an internal error; an FMI 3.0
    /// instance's must be in FMI 3.0 terms ([`fmi3_wording`]).
    pub fn check_messages(
        &self,
        log: &Log,
        from: usize,
        call: &str,
        status: c_int,
        version: Version,
    ) {
        let recs = log.since(from);
        if crate::trace_calls() > 1 {
            for r in &recs {
                eprintln!("      -> {} {}: {}", r.status, r.category, r.message);
            }
        }
        for r in &recs {
            if r.message.contains("internal error") {
                self.fail(format!("{call}: a panic was caught: {}", r.message));
            }
            if version == Version::Fmi3
                && let Some(w) = fmi3_wording(&r.message)
            {
                self.fail(format!(
                    "{call}: an FMI 3.0 message says {w}: {:?}",
                    r.message
                ));
            }
        }
        if status == 0 {
            return;
        }
        let named = recs.iter().any(|r| {
            r.status >= 1
                && r.message.contains(call)
                && r.message.len() > call.len() + 12
                && r.category.starts_with("logStatus")
        });
        if !named {
            self.fail(format!(
                "{call} returned {status} without a message naming it and the cause; logged: {:?}",
                recs
            ));
        }
    }

    /// Checks the call of function `call` on instance `i` (`desc`), which returned
    /// `status`: a status of FMI (OK, Warning, Discard, Error), Error on a null
    /// instance, and the messages logged since `from` ([`World::check_messages`];
    /// none for an FMI 3.0 instance made without a logger).
    pub fn check_call(
        &self,
        i: usize,
        call: &str,
        desc: &str,
        status: c_int,
        null_component: bool,
        from: usize,
    ) {
        if !(0..=3).contains(&status) {
            self.fail(format!("{desc} returned status {status}"));
        }
        if null_component {
            if status != Status::Error as c_int {
                self.fail(format!("{desc} on a null instance returned {status}"));
            }
            return;
        }
        let s = &self.slots[i];
        if s.logged {
            self.check_messages(&s.log, from, call, status, s.version);
        }
    }
}

#[test]
fn the_wording_check_flags_fmi2_names_and_names_fmi3_does_not_have() {
    assert_eq!(
        fmi3_wording("fmi3DoStep: h = NaN s; allowed: finite and > 0 s"),
        None
    );
    assert_eq!(
        fmi3_wording(
            "fmi3InstantiateCoSimulation: ... it is an FMI 2.0 GUID: instantiate the FMI 2.0 FMU with fmi2Instantiate"
        ),
        None
    );
    assert!(fmi3_wording("fmi2DoStep: h = NaN s").is_some());
    assert!(fmi3_wording("call fmi3Reset or fmi2SetFMUstate").is_some());
    assert!(fmi3_wording("fmi3Get: argument `valueReferences` is a null pointer").is_some());
    assert!(fmi3_wording("see fmi3GetRealStatus").is_some());
    // Names inside longer words are not names.
    assert_eq!(fmi3_wording("xfmi2y and fmi3Float64 values"), None);
}
