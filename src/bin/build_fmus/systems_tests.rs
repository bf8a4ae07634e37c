//! Tests of the shipped system files: every input fed, the steps and parameter sets.

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
        inputs(&s, TRACK),
        [
            ("wheel.left.z", "wheel.left.z"),
            ("wheel.right.z", "wheel.right.z"),
            ("wheel.rotation", "wheel.rotation")
        ]
    );
    assert_eq!(
        inputs(&s, VEHICLE),
        [
            ("contact.left.force", "contact.left.force"),
            ("contact.right.force", "contact.right.force")
        ]
    );
    let s = system("HalfCarBogie", Interface::AxleBox);
    let track = inputs(&s, TRACK);
    assert_eq!(track.len(), 8, "{track:?}");
    assert!(track.iter().all(|(o, i)| o == i && wheelset_of(i) <= 2));
    assert!(track.contains(&(
        "wheelset[2].sideframe.right.v",
        "wheelset[2].sideframe.right.v"
    )));
    let vehicle = inputs(&s, VEHICLE);
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
    assert_eq!(inputs(&s, TRACK).len(), 6);
    assert_eq!(inputs(&s, VEHICLE).len(), 4);
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
