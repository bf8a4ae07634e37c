//! The FMI 2.0 layer's messages in FMI 3.0 terms: the functions by their FMI 3.0 names
//! ([`super::calls::fmi3_name`]) and a trailing wheelset's variable as the element of
//! its array (`wheelset[2].wheel.left.z` is `wheel.left.z[2]`).

use super::calls::{Call3, fmi3_name};
use crate::fmu::fmi2::CALLS;
use crate::fmu::vars::{FMI3_FMUS, Fmu3Table};

/// The FMI 2.0 layer's phase names and the FMI 3.0 states they are
/// ([`super::Phase3::of`]).
const PHASES: [(&str, &str); 3] = [
    ("StepComplete", "StepMode"),
    ("StepFailed", "RunEnded"),
    ("Initialization;", "InitializationMode;"),
];

/// `message` of the FMI 2.0 layer as an FMI 3.0 unit of `table` says it, during the
/// call `running`.
pub fn translate(message: &str, running: Option<Call3>, table: &Fmu3Table) -> String {
    let mut m = message
        .replace("fmi2Terminated status", "terminateSimulation")
        .replace("(fmi2Terminated)", "(terminateSimulation)")
        .replace("FMUstate", "FMUState");
    // FMI 2.0's capability, phase and type names.
    if m.contains("providesDirectionalDerivative is false") {
        let flag = match running {
            Some(Call3::GetAdjointDerivative) => "providesAdjointDerivatives",
            _ => "providesDirectionalDerivatives",
        };
        m = m.replace(
            "providesDirectionalDerivative is false",
            &format!("{flag} is false"),
        );
    }
    for (fmi2, fmi3) in PHASES {
        m = m.replace(&format!("state {fmi2}"), &format!("state {fmi3}"));
    }
    m = m.replace("is not a Real ", "is not a Float64 ");
    // An FMU's identity: its FMI 3.0 instantiation token, not its FMI 2.0 GUID.
    for t in FMI3_FMUS {
        if m.contains(t.fmi2.guid) {
            m = m.replace(t.fmi2.guid, t.token);
        }
    }
    // FMI 3.0 has no input derivatives: the advice to give them points to FMI 2.0.
    m = m.replace(
        "(fmi2SetRealInputDerivatives)",
        "(input derivatives, which FMI 3.0 lacks: the FMI 2.0 unit takes them)",
    );
    if m.contains("fmi2") {
        // Longest names first: fmi2GetRealOutputDerivatives before fmi2GetReal.
        let mut calls: Vec<_> = CALLS.iter().collect();
        calls.sort_by_key(|c| std::cmp::Reverse(c.1.len()));
        for (call, name, _) in calls {
            let name = name.replace("FMUstate", "FMUState");
            if m.contains(&name) {
                let new = fmi3_name(*call, running);
                if !new.is_empty() {
                    m = m.replace(&name, new);
                }
            }
        }
        m = m.replace("fmi2", "fmi3");
    }
    if m.contains("wheelset[") {
        m = elements(&m, table);
    }
    m
}

/// `wheelset[k].<name>` as `<name>[k]` where `<name>` is an array of `table`.
fn elements(m: &str, table: &Fmu3Table) -> String {
    let mut out = String::with_capacity(m.len());
    let mut rest = m;
    while let Some(at) = rest.find("wheelset[") {
        out.push_str(&rest[..at]);
        let tail = &rest[at + "wheelset[".len()..];
        let parsed = tail.find("].").and_then(|close| {
            let k: usize = tail[..close].parse().ok()?;
            let after = &tail[close + 2..];
            let end = after
                .find(|c: char| !(c.is_ascii_alphanumeric() || "._[]".contains(c)))
                .unwrap_or(after.len());
            // The longest array name the text starts with.
            let name = table
                .vars
                .iter()
                .filter(|v| v.array && after[..end].starts_with(v.name))
                .map(|v| v.name)
                .max_by_key(|n| n.len())?;
            Some((k, name, close + 2 + name.len()))
        });
        match parsed {
            Some((k, name, used)) => {
                out.push_str(&format!("{name}[{k}]"));
                rest = &tail[used..];
            }
            None => {
                out.push_str("wheelset[");
                rest = tail;
            }
        }
    }
    out.push_str(rest);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmu::vars::FMI3_TRACK_CONTACT;

    #[test]
    fn fmi2_names_become_fmi3_names_and_trailing_wheelsets_array_elements() {
        let t = &FMI3_TRACK_CONTACT;
        assert_eq!(
            translate(
                "fmi2SetReal: wheelset[2].wheel.left.z = 1 m; call fmi2Reset or fmi2SetFMUstate",
                Some(Call3::SetFloat64),
                t
            ),
            "fmi3SetFloat64: wheel.left.z[2] = 1 m; call fmi3Reset or fmi3SetFMUState"
        );
        // An enumeration is set through fmi3SetInt64, which the FMI 2.0 layer answers as
        // fmi2SetInteger.
        assert_eq!(
            translate("fmi2SetInteger: x", Some(Call3::SetInt64), t),
            "fmi3SetInt64: x"
        );
        assert_eq!(
            translate(
                "fmi2GetRealOutputDerivatives and fmi2GetReal",
                Some(Call3::GetFloat64),
                t
            ),
            "fmi3GetOutputDerivatives and fmi3GetFloat64"
        );
        assert_eq!(
            translate("fmi2Terminated status is true", None, t),
            "terminateSimulation is true"
        );
        assert_eq!(
            translate(
                "`x` (Parameter) cannot be set in state StepComplete; y is not a Real input; \
                 providesDirectionalDerivative is false",
                Some(Call3::GetAdjointDerivative),
                t
            ),
            "`x` (Parameter) cannot be set in state StepMode; y is not a Float64 input; \
             providesAdjointDerivatives is false"
        );
        assert_eq!(
            translate(
                "use at most 1e-4 s, give the wheel velocities (fmi2SetRealInputDerivatives), or",
                Some(Call3::DoStep),
                t
            ),
            "use at most 1e-4 s, give the wheel velocities (input derivatives, which FMI 3.0 \
             lacks: the FMI 2.0 unit takes them), or"
        );
        assert_eq!(
            translate(&format!("the state of {}", t.fmi2.guid), None, t),
            format!("the state of {}", t.token)
        );
        // A name that is no array stays as it is.
        assert_eq!(
            translate("wheelset[2].offset = 0.05 m", None, t),
            "wheelset[2].offset = 0.05 m"
        );
        assert_eq!(
            translate("`wheelset[3].flat.left[1].shape` = 7", None, t),
            "`flat.left[1].shape[3]` = 7"
        );
    }
}
