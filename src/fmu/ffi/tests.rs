//! Tests of the C boundary that need its private parts.

use super::binary::*;
use crate::fmu::Kind;

#[test]
fn the_file_stem_of_the_binary_is_the_model_identifier() {
    for (path, kind) in [
        (
            "/tmp/x/binaries/linux64/TrackContact.so",
            Some(Kind::TrackContact),
        ),
        ("RollPlaneVehicle.so", Some(Kind::ROLL_PLANE_VEHICLE)),
        (
            "C:/fmu/binaries/win64/CoupledSystem.dll",
            Some(Kind::CoupledSystem),
        ),
        (
            "binaries/darwin64/CoupledSystem.dylib",
            Some(Kind::CoupledSystem),
        ),
        ("/work/target/release/libwheelflat.so", None),
        ("/work/target/release/deps/fmi_fuzz-0123abcd", None),
        ("binaries/linux64/trackcontact.so", None),
        ("binaries/linux64/TrackContact2.so", None),
        ("", None),
    ] {
        assert_eq!(kind_of_binary(path), kind, "{path}");
    }
}

#[test]
fn a_binary_of_one_fmu_instantiates_only_its_guid() {
    let kinds = Kind::ALL.map(|k| (k, k.table().guid));
    for (k, g) in kinds {
        // The development library (or a test executable): every GUID.
        assert_eq!(kind_for_guid(None, g), Ok(k));
        for (b, _) in kinds {
            let r = kind_for_guid(Some(b), g);
            if b == k {
                assert_eq!(r, Ok(k));
            } else {
                let m = r.unwrap_err();
                let want = format!(
                    "belongs to {}, but this binary is {}",
                    k.table().model_identifier,
                    b.table().model_identifier
                );
                assert!(m.contains(&want), "{m}");
            }
        }
    }
    let m = kind_for_guid(Some(Kind::TrackContact), "{0}").unwrap_err();
    assert!(
        m.contains("matches none of") && m.contains("this binary is TrackContact"),
        "{m}"
    );
    assert!(
        kind_for_guid(None, "")
            .unwrap_err()
            .contains("matches none of")
    );
    // Tests link the crate into their own executable: not an FMU binary.
    let exe = loaded_binary().expect("dladdr names the executable");
    assert_eq!(kind_of_binary(&exe), None, "{exe}");
}
