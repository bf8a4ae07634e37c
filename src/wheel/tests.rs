//! Tests of the wheel profile: flat shapes against the thesis' formulas, the vector
//! evaluation against the scalar one, validation, overlapping flats, and the
//! small-angle functions the profile evaluates.

use super::*;
use crate::error::Error;
use crate::numerics::{LANES, SMALL_ANGLE, cos_half_pi, tan_small, wrap_angle};
use std::f64::consts::PI;

const R: f64 = 0.475;

#[test]
fn haversine_depth_at_centre_and_zero_at_edges() {
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.3)], "flat.left").unwrap();
    // Centre of the flat lies at space angle 0.3 - gamma.
    assert!((w.reduction(0.3, 0.0) - 0.0015).abs() < 1e-15);
    assert!((w.reduction(0.0, 0.3) - 0.0015).abs() < 1e-15);
    let phi = 0.1 / (2.0 * R);
    assert!(w.reduction(0.3 + phi * 0.9999999, 0.0) < 1e-9);
    assert_eq!(w.reduction(0.3 + phi * 1.01, 0.0), 0.0);
    // Profile is continuous at both ends (clamping of x).
    assert!(w.reduction(0.3 - phi + 1e-12, 0.0) < 1e-12);
}

#[test]
fn reduction_lanes_give_the_same_bits_as_reduction() {
    // Haversine and chord flats, angles inside, at the edge of and outside the flat:
    // every lane equals the one-angle evaluation bit for bit; a lane inside the
    // flat beyond SMALL_ANGLE (library functions there) refuses the batch.
    let flats = [
        FlatSpec::haversine(0.1, 0.0015, 0.0),
        FlatSpec::chord(0.08, 0.0),
        FlatSpec::haversine(0.3, 0.004, 0.0),
    ];
    let w = WheelProfile::new(R, &flats, "flat.left").unwrap();
    for fl in w.flats() {
        let h = fl.half_angle;
        for k in 0..200 {
            let psi: [f64; LANES] = std::array::from_fn(|l| {
                (k as f64 * 0.37 + l as f64 * 0.93).sin() * (1.3 * h).min(SMALL_ANGLE)
            });
            let want = psi.map(|p| fl.reduction(p));
            let got = fl
                .reduction_lanes(&psi)
                .expect("all lanes within SMALL_ANGLE");
            for l in 0..LANES {
                assert_eq!(
                    got[l].to_bits(),
                    want[l].to_bits(),
                    "{:?} psi {}",
                    fl.shape,
                    psi[l]
                );
            }
            assert!(want.iter().any(|&f| f > 0.0));
        }
        if h > SMALL_ANGLE {
            continue;
        }
        let mut edge = [0.0; LANES];
        edge[0] = h;
        edge[1] = -h;
        edge[2] = h * (1.0 - 1e-15);
        let got = fl.reduction_lanes(&edge).unwrap();
        assert_eq!(
            got.map(f64::to_bits),
            edge.map(|p| fl.reduction(p).to_bits())
        );
    }
    // The 300 mm flat reaches beyond SMALL_ANGLE (half angle 0.316 rad).
    let wide = &w.flats()[2];
    assert!(wide.half_angle > SMALL_ANGLE);
    let mut psi = [0.0; LANES];
    psi[3] = 0.25;
    assert_eq!(wide.reduction_lanes(&psi), None);
    // ... but outside a flat a large angle needs no library function.
    psi[3] = 0.5;
    assert!(wide.reduction_lanes(&psi).is_some());
}

#[test]
fn default_depths_follow_seed() {
    let h = WheelProfile::new(
        R,
        &[FlatSpec {
            length: 0.1,
            depth: None,
            angle: 0.0,
            shape: FlatShape::Haversine,
        }],
        "f",
    )
    .unwrap();
    assert!((h.flats()[0].depth - 0.01 / (16.0 * R)).abs() < 1e-15);
    let c = WheelProfile::new(R, &[FlatSpec::chord(0.1, 0.0)], "f").unwrap();
    let d = R - (R * R - 0.0025f64).sqrt();
    assert!((c.flats()[0].depth - d).abs() < 1e-15);
    // A chord flat is a straight line: R cos(psi) = R_w - D across it.
    for psi in [-0.1, -0.05, 0.0, 0.07] {
        let r = c.radius_at(psi, 0.0);
        assert!((r * psi.cos() - (R - d)).abs() < 1e-14);
    }
    // and meets the circle at its ends: chord length equals l_f.
    let half = c.flats()[0].half_angle;
    assert!((2.0 * R * half.sin() - 0.1).abs() < 1e-12);
}

#[test]
fn bad_flats_are_refused_with_names() {
    let cases = [
        (FlatSpec::haversine(0.1, 0.0, 0.0), "flat.left[1].depth"),
        (FlatSpec::haversine(0.0, 0.001, 0.0), "flat.left[1].depth"),
        (FlatSpec::haversine(0.8, 0.001, 0.0), "flat.left[1].length"),
        (FlatSpec::haversine(0.1, 0.5, 0.0), "flat.left[1].depth"),
        (FlatSpec::haversine(-0.1, 0.001, 0.0), "flat.left[1].length"),
        (
            FlatSpec::haversine(0.1, f64::NAN, 0.0),
            "flat.left[1].depth",
        ),
        (
            FlatSpec {
                length: 0.1,
                depth: Some(0.0015),
                angle: 0.0,
                shape: FlatShape::Chord,
            },
            "flat.left[1].depth",
        ),
    ];
    for (spec, name) in cases {
        match WheelProfile::new(R, &[spec], "flat.left") {
            Err(Error::Parameter { name: n, .. }) => assert_eq!(n, name, "{spec:?}"),
            other => panic!("{spec:?} gave {other:?}"),
        }
    }
    // Zero length and zero depth is "no flat".
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.0, 0.0, 1.0)], "f").unwrap();
    assert!(w.flats().is_empty());
}

#[test]
fn overlapping_flats_take_larger_reduction() {
    let w = WheelProfile::new(
        R,
        &[
            FlatSpec::haversine(0.1, 0.001, 0.0),
            FlatSpec::haversine(0.05, 0.002, 0.02),
        ],
        "f",
    )
    .unwrap();
    assert!((w.reduction(0.02, 0.0) - 0.002).abs() < 1e-15);
    assert!((w.reduction(-0.05, 0.0) - w.flats()[0].reduction(-0.05)).abs() < 1e-15);
}

#[test]
fn polynomial_trig_matches_library() {
    let mut worst: f64 = 0.0;
    for i in 0..=20_000 {
        let a = -0.25 + 0.5 * i as f64 / 20_000.0;
        worst = worst.max(((tan_small(a) - a.tan()) / a.tan().abs().max(1e-300)).abs());
    }
    assert!(worst < 5e-16, "tan: {worst:e}");
    let mut worst: f64 = 0.0;
    for i in 0..=20_000 {
        let a = -0.5 * PI + PI * i as f64 / 20_000.0;
        worst = worst.max((cos_half_pi(a) - a.cos()).abs());
    }
    assert!(worst < 5e-16, "cos: {worst:e}");
}

#[test]
fn wrap_is_into_half_open_interval() {
    assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
    assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
    assert!((wrap_angle(0.1 - 4.0 * PI) - 0.1).abs() < 1e-12);
}

#[test]
fn an_out_of_roundness_takes_a_million_points_and_joins_its_ends_round_the_wheel() {
    use crate::numerics::{MAX_TABLE_POINTS, Table};
    use crate::wheel::OutOfRoundness;
    use std::f64::consts::TAU;
    let n = MAX_TABLE_POINTS;
    let b: Vec<f64> = (0..n).map(|i| 0.001 + 6.2 * i as f64 / n as f64).collect();
    let r: Vec<f64> = b.iter().map(|b| 1e-4 * b.sin()).collect();
    let w = OutOfRoundness::new(Table::new(b.clone(), r.clone(), "w").unwrap(), "w").unwrap();
    // Between the last point and the first a turn on: the straight line.
    let (b0, r0, b1, r1) = (b[n - 1], r[n - 1], b[0] + TAU, r[0]);
    let mid = 0.5 * (b0 + b1);
    assert!((w.at(mid) - 0.5 * (r0 + r1)).abs() < 1e-18);
    assert!((w.at(mid - TAU) - w.at(mid)).abs() < 1e-18);
    assert!((w.slope_at(mid) - (r1 - r0) / (b1 - b0)).abs() < 1e-12);
    assert!((w.at(b[7] + 3.0 * TAU) - r[7]).abs() < 1e-15);
}
