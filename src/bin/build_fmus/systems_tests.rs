//! Tests of the shipped system files: every input fed, the steps and parameter sets,
//! the components' names and OMSimulator's annotation.

use super::*;

fn inputs(s: &System, to: &str) -> Vec<(&'static str, &'static str)> {
    s.connections
        .iter()
        .filter(|c| c.to == to)
        .map(|c| (c.output, c.input))
        .collect()
}

#[test]
fn connections_follow_the_table() {
    let s = system("RollPlaneVehicle", Interface::Contact);
    assert_eq!(
        inputs(&s, "TrackContact"),
        [
            ("wheel.left.z", "wheel.left.z"),
            ("wheel.right.z", "wheel.right.z"),
            ("wheel.rotation", "wheel.rotation")
        ]
    );
    assert_eq!(
        inputs(&s, "RollPlaneVehicle"),
        [
            ("contact.left.force", "contact.left.force"),
            ("contact.right.force", "contact.right.force")
        ]
    );
    let s = system("HalfCarBogie", Interface::AxleBox);
    let track = inputs(&s, "TrackContact");
    assert_eq!(track.len(), 8, "{track:?}");
    assert!(track.iter().all(|(o, i)| o == i && wheelset_of(i) <= 2));
    assert!(track.contains(&(
        "wheelset[2].sideframe.right.v",
        "wheelset[2].sideframe.right.v"
    )));
    let vehicle = inputs(&s, "HalfCarBogie");
    assert_eq!(vehicle.len(), 4, "{vehicle:?}");
    assert!(vehicle.contains(&(
        "wheelset[2].primary.left.force",
        "wheelset[2].axle_box.left.force"
    )));
    assert!(vehicle.contains(&("primary.right.force", "axle_box.right.force")));
    assert_eq!(s.step, AXLE_BOX_STEP);
}

#[test]
fn bogie_parameters_and_track_step() {
    let s = system("HalfCarBogie", Interface::Contact);
    let get = |n: &str| {
        s.track_values
            .iter()
            .find(|(k, _)| *k == n)
            .map(|(_, v)| *v)
    };
    assert_eq!(get("wheelsets"), Some(Value::Integer(2)));
    assert_eq!(get("wheelset[2].offset"), Some(Value::Real(1.8)));
    assert_eq!(get("vehicle.model"), Some(Value::Integer(2)));
    assert_eq!(get("interface"), Some(Value::Integer(1)));
    // 0.9 of the critical step of the default track, about 14.4 us.
    assert!(s.step > 1.0e-5 && s.step < 2.0e-5, "{}", s.step);
    assert_eq!(inputs(&s, "TrackContact").len(), 6);
    assert_eq!(inputs(&s, "HalfCarBogie").len(), 4);
}

#[test]
fn axle_box_force_is_fed_by_the_primary_force() {
    assert_eq!(source_name("axle_box.left.force"), "primary.left.force");
    assert_eq!(
        source_name("wheelset[2].axle_box.right.force"),
        "wheelset[2].primary.right.force"
    );
    assert_eq!(source_name("wheel.left.z"), "wheel.left.z");
    assert_eq!(wheelset_of("wheelset[3].wheel.left.z"), 3);
    assert_eq!(wheelset_of("wheel.left.z"), 1);
}

/// The text of every `attr="..."` of `xml`, in order.
fn attributes<'a>(xml: &'a str, attr: &str) -> Vec<&'a str> {
    let key = format!(r#" {attr}=""#);
    xml.match_indices(&key)
        .map(|(i, _)| {
            let rest = &xml[i + key.len()..];
            &rest[..rest.find('"').unwrap()]
        })
        .collect()
}

#[test]
fn every_component_is_named_after_its_fmu() {
    // OMSimulator reads a parameter's leading `<component>.` as the component: a
    // component named `track` would lose TrackContact's `track.window.ahead`.
    for s in systems() {
        let (track, vehicle) = (s.track.model_identifier, s.vehicle.model_identifier);
        assert!(
            s.connections
                .iter()
                .all(|c| [c.from, c.to] == [track, vehicle] || [c.from, c.to] == [vehicle, track]),
            "{}: {:?}",
            s.name,
            s.connections
        );
        let ssd = s.ssd();
        assert_eq!(
            ssd.matches("<ssd:Component ").count(),
            2,
            "{}: {ssd}",
            s.name
        );
        for id in [track, vehicle] {
            assert!(
                ssd.contains(&format!(
                    r#"<ssd:Component name="{id}" source="resources/{id}.fmu">"#
                )),
                "{}: {ssd}",
                s.name
            );
        }
        for e in attributes(&ssd, "startElement")
            .into_iter()
            .chain(attributes(&ssd, "endElement"))
        {
            assert!(e == track || e == vehicle, "{}: element {e}", s.name);
        }
        let osp = s.osp("../..");
        let simulators = attributes(&osp, "simulator");
        assert_eq!(simulators.len(), 2 * s.connections.len());
        assert!(simulators.iter().all(|e| *e == track || *e == vehicle));
        for id in [track, vehicle] {
            assert!(
                osp.contains(&format!(
                    r#"<Simulator name="{id}" source="../../{id}.fmu">"#
                )),
                "{}: {osp}",
                s.name
            );
        }
        // No parameter of a component begins with that component's name.
        for (t, values) in s.components() {
            let prefix = format!("{}.", t.model_identifier);
            assert!(values.iter().all(|(n, _)| !n.starts_with(&prefix)));
        }
    }
}

#[test]
fn the_root_system_carries_omsimulators_fixed_step_master() {
    // OMSimulator (2.1) takes a system's type only from its own annotation of the root
    // system (without it: "[NewSystem] internal error"); a fixed-step master at the
    // shipped base step, written as OMSimulator writes it, the oms prefix declared.
    for s in systems() {
        let ssd = s.ssd();
        assert!(ssd.contains(&format!(r#"xmlns:oms="{OMS_NAMESPACE}""#)));
        // The root system's last child, after its connections: one org.openmodelica
        // annotation holding a fixed-step master (the structure, not the packer's text).
        let tail = &ssd[ssd.find("</ssd:Connections>").expect("connections")..];
        let end = tail.find("</ssd:System>").expect("the root system's end");
        let annotations = &tail[..end];
        assert!(
            annotations
                .trim_start_matches("</ssd:Connections>")
                .trim_start()
                .starts_with("<ssd:Annotations>")
        );
        assert_eq!(
            annotations
                .matches(r#"<ssc:Annotation type="org.openmodelica">"#)
                .count(),
            1,
            "{}",
            s.name
        );
        assert_eq!(
            annotations.matches("<oms:FixedStepMaster ").count(),
            1,
            "{}",
            s.name
        );
        assert!(
            annotations.trim_end().ends_with("</ssd:Annotations>"),
            "{}",
            s.name
        );
        assert_eq!(ssd.matches("<ssd:System ").count(), 1);
        assert_eq!(ssd.matches("</ssd:System>").count(), 1);
        // The same step as the OSP annotation libcosim reads.
        assert_eq!(
            attributes(&ssd, "stepSize"),
            attributes(&ssd, "baseStepSize"),
            "{}",
            s.name
        );
        assert_eq!(attributes(&ssd, "stepSize")[0].parse::<f64>(), Ok(s.step));
    }
}

#[test]
fn the_fmi3_ssp_of_the_roll_plane_pair_types_its_parameters_as_fmi_3_does() {
    let contact = system("RollPlaneVehicle", Interface::Contact);
    let axle_box = system("RollPlaneVehicle", Interface::AxleBox);
    assert!(contact.has_fmi3_ssp() && axle_box.has_fmi3_ssp());
    assert!(!system("HalfCarBogie", Interface::Contact).has_fmi3_ssp());
    let (c, a) = (contact.ssd3(), axle_box.ssd3());
    // The structural parameter is left out; an enumeration at its start too, one set
    // otherwise is an ssv:Enumeration of its item, on both components.
    for x in [&c, &a] {
        assert!(!x.contains(r#"name="wheelsets""#), "{x}");
        assert!(!x.contains(r#"name="vehicle.model""#), "{x}");
        assert!(!x.contains("ssv:Integer"), "{x}");
    }
    assert!(!c.contains(r#"name="interface""#), "{c}");
    let set =
        r#"<ssv:Parameter name="interface"><ssv:Enumeration value="axle_box"/></ssv:Parameter>"#;
    assert_eq!(a.matches(set).count(), 2, "{a}");
    // The rest is the FMI 2.0 system's.
    let fmi2 = axle_box.ssd();
    for line in a
        .lines()
        .filter(|l| l.contains("ssv:Real") || l.contains("ssd:Connection "))
    {
        assert!(fmi2.contains(line), "{line}");
    }
}
