//! Tests of the contact laws: the adaptive integral against the closed form, a
//! brute-force sum of the radial springs and the thesis' patch ends (2.22); the
//! small-overlap and Hertz limits; the calibration of `K_w`; the stiffness and the
//! inverse overlap.

use super::perfect::perfect_patch;
use super::*;
use crate::numerics::cos_small;
use crate::wheel::{FlatSpec, WheelProfile};

const R: f64 = 0.475;
const KW: f64 = 3.3443e10;

fn brute_force(kw: f64, w: &WheelProfile, gamma: f64, delta: f64, n: usize) -> f64 {
    let aw = patch_angle(delta, w.radius());
    let h = w.radius() - delta;
    let da = 2.0 * aw / n as f64;
    let mut s = 0.0;
    for i in 0..n {
        let a = -aw + (i as f64 + 0.5) * da;
        s += (w.radius_at(a, gamma) * a.cos() - h).max(0.0);
    }
    kw * s * da
}

#[test]
fn integral_equals_closed_form_for_perfect_wheel() {
    let w = WheelProfile::perfect(R).unwrap();
    for delta in [1e-7, 1e-6, 3e-5, 1e-4, 5e-4, 2e-3] {
        let closed = perfect_wheel_force(KW, R, delta);
        let num = adaptive_numeric(KW, &w, 0.0, delta).force;
        let fast = ContactLaw::adaptive(KW)
            .unwrap()
            .evaluate(&w, 0.0, delta)
            .force;
        // Independent form of (2.5) with the textbook acos.
        let a = ((R - delta) / R).acos();
        let textbook = 2.0 * KW * R * (a.sin() - a * a.cos());
        assert!(
            ((num - closed) / closed).abs() < 1e-9,
            "{delta}: {num} vs {closed}"
        );
        assert_eq!(fast, closed);
        assert!(((textbook - closed) / closed).abs() < 1e-6);
    }
}

#[test]
fn small_overlap_law_is_hertz_like() {
    for delta in [1e-7, 1e-6, 1e-5, 1e-4] {
        let p = perfect_wheel_force(KW, R, delta);
        let law = 4.0 * 2f64.sqrt() / 3.0 * KW / R.sqrt() * delta.powf(1.5);
        assert!(((p - law) / law).abs() < 0.01, "{delta}: {p} vs {law}");
    }
}

#[test]
fn kw_calibration_reproduces_static_load() {
    let (ch, p0) = (0.87e11, 82e3);
    let kw = kw_from_hertz(ch, p0, 0.4572).unwrap();
    let d0 = (p0 / ch).powf(2.0 / 3.0);
    let p = perfect_wheel_force(kw, 0.4572, d0);
    assert!(((p - p0) / p0).abs() < 1e-12);
    // Small-angle limit: K_w = 3 C_H sqrt(R) / (4 sqrt 2).
    let approx = 3.0 * ch * 0.4572f64.sqrt() / (4.0 * 2f64.sqrt());
    assert!(((kw - approx) / approx).abs() < 1e-3);
}

#[test]
fn short_flat_inside_patch_splits_it_and_matches_brute_force() {
    // 8 mm x 0.3 mm flat, slightly off centre, inside a ~19 mm patch.
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.008, 0.0003, 0.002)], "f").unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    let delta = 1e-4;
    let st = law.evaluate(&w, 0.0, delta);
    assert_eq!(st.intervals, 2, "{st:?}");
    let bf = brute_force(KW, &w, 0.0, delta, 100_000);
    assert!(
        ((st.force - bf) / bf).abs() < 1e-6,
        "{} vs {}",
        st.force,
        bf
    );
    // The patch keeps its perfect-wheel ends.
    let aw = patch_angle(delta, R);
    assert!((st.front_angle - aw).abs() < 1e-12 && (st.rear_angle + aw).abs() < 1e-12);
    assert!(st.force < perfect_wheel_force(KW, R, delta));
}

#[test]
fn partial_and_asymmetric_contact_match_brute_force() {
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    for (gamma, delta) in [
        (-0.09, 2e-4),
        (-0.1, 1e-3),
        (0.05, 1.6e-3),
        (0.0, 1.8e-3),
        (0.11, 3e-4),
    ] {
        let st = law.evaluate(&w, gamma, delta);
        let bf = brute_force(KW, &w, gamma, delta, 200_000);
        if bf == 0.0 {
            assert_eq!(st.force, 0.0);
            assert!(st.lost());
            continue;
        }
        assert!(
            ((st.force - bf) / bf).abs() < 1e-6,
            "{gamma} {delta}: {} vs {}",
            st.force,
            bf
        );
        // Extreme contact points satisfy R(alpha) cos(alpha) = h (2.22).
        let h = R - delta;
        for a in [st.front_angle, st.rear_angle] {
            let aw = patch_angle(delta, R);
            if (a.abs() - aw).abs() > 1e-12 {
                assert!((w.radius_at(a, gamma) * a.cos() - h).abs() < 1e-12);
            }
        }
    }
    // Flat entering from the front: the front edge recedes, the rear stays at -alpha_w.
    let delta = 2e-4;
    let aw = patch_angle(delta, R);
    let st = law.evaluate(&w, -0.095, delta);
    assert!(
        st.front_angle < aw - 1e-6 && (st.rear_angle + aw).abs() < 1e-12,
        "{st:?}"
    );
}

#[test]
fn flat_passage_sweep_matches_brute_force() {
    // Every axle angle across the passage of a haversine flat, a chord flat and a
    // pair of overlapping flats, at light, static and heavy overlap: the adaptive
    // integral against a 200,000-point midpoint sum of the radial springs.
    let wheels = [
        WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap(),
        WheelProfile::new(R, &[FlatSpec::chord(0.06, 0.0)], "f").unwrap(),
        WheelProfile::new(
            R,
            &[
                FlatSpec::haversine(0.05, 0.0004, 0.0),
                FlatSpec::haversine(0.03, 0.0006, 0.03),
            ],
            "f",
        )
        .unwrap(),
    ];
    let law = ContactLaw::adaptive(KW).unwrap();
    let mut worst: f64 = 0.0;
    let mut evaluated = 0;
    for w in &wheels {
        for delta in [5e-5, 1.5e-4, 6e-4] {
            for i in 0..=40 {
                let gamma = -0.16 + 0.32 * i as f64 / 40.0;
                let st = law.evaluate(w, gamma, delta);
                let bf = brute_force(KW, w, gamma, delta, 200_000);
                let scale = perfect_wheel_force(KW, R, delta);
                worst = worst.max((st.force - bf).abs() / scale);
                evaluated += 1;
            }
        }
    }
    assert_eq!(evaluated, 3 * 3 * 41);
    // The midpoint sum itself is good to about 1e-8 of the perfect-wheel force.
    assert!(
        worst < 1e-7,
        "worst error {worst:e} of the perfect-wheel force"
    );
}

#[test]
fn small_angle_cosine_is_the_cosine() {
    let mut worst: f64 = 0.0;
    for i in 0..=20_000 {
        let a = -0.25 + 0.5 * i as f64 / 20_000.0;
        worst = worst.max((cos_small(a) - a.cos()).abs());
    }
    assert!(worst <= 2.3e-16, "{worst:e}");
}

#[test]
fn small_arcsine_is_the_arcsine() {
    // The series patch angle 2 s P(s^2) against the library arcsine, across the
    // switch to the library at s = 0.05.
    let mut worst: f64 = 0.0;
    for i in 1..=20_000 {
        let s = 0.06 * i as f64 / 20_000.0;
        let (a, _, x) = perfect_patch(2.0 * R * s * s, R);
        let want = 2.0 * x.sqrt().asin();
        worst = worst.max(((a - want) / want).abs());
    }
    assert!(worst < 6e-16, "{worst:e}");
    // The series s^3 Q(s^2) for sin a - a cos a against its alternating Taylor
    // series in a (no cancellation), summed to convergence in f64.
    let mut worst: f64 = 0.0;
    for i in 1..=2_000 {
        let s = 0.05 * i as f64 / 2_000.0;
        let (a, got, _) = perfect_patch(2.0 * R * s * s, R);
        // sum over n >= 1 of (-1)^(n+1) 2n a^(2n+1) / (2n+1)!
        let (mut term, mut want) = (a * a * a / 3.0, 0.0);
        for n in 1..30 {
            want += term;
            let n = n as f64;
            term *= -a * a * (2.0 * n + 2.0) / (2.0 * n * (2.0 * n + 2.0) * (2.0 * n + 3.0));
        }
        worst = worst.max(((got - want) / want).abs());
    }
    // The reference starts from the rounded angle (2 ulp), an error that the
    // cube-like growth of sin a - a cos a triples.
    assert!(worst < 2e-15, "sin a - a cos a: {worst:e}");
    // Perfect-wheel patch length from the identity against the direct sine.
    let law = ContactLaw::adaptive(KW).unwrap();
    let w = WheelProfile::perfect(R).unwrap();
    for delta in [1e-6, 1e-4, 2e-3, 0.01] {
        let st = law.evaluate(&w, 0.0, delta);
        let direct = 2.0 * R * ((R - delta) / R).acos().sin();
        assert!(((st.length - direct) / direct).abs() < 1e-9, "{delta}");
    }
}

#[test]
fn force_is_continuous_as_flat_enters_patch() {
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    let delta = 2e-4;
    let aw = patch_angle(delta, R);
    let phi = 0.1 / (2.0 * R);
    // flat rear edge at space angle -gamma - phi... front edge reaches +aw when gamma = -(aw + phi)
    let g0 = -(aw + phi);
    let a = law.evaluate(&w, g0 - 1e-9, delta).force;
    let b = law.evaluate(&w, g0 + 1e-9, delta).force;
    assert!(((a - b) / a).abs() < 1e-8, "{a} {b}");
}

#[test]
fn full_loss_of_contact_inside_deep_flat() {
    let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    let st = law.evaluate(&w, 0.0, 1e-3);
    assert!(st.lost() && st.force == 0.0);
    let hz = ContactLaw::hertz(0.85e11).unwrap();
    assert_eq!(hz.evaluate(&w, 0.0, 1e-3).force, 0.0);
    let st = hz.evaluate(&w, 0.0, 1.6e-3);
    assert!((st.force - 0.85e11 * (1e-4f64).powf(1.5)).abs() < 1e-3);
}

#[test]
fn inverse_overlap() {
    let w = WheelProfile::perfect(R).unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    let d = law.overlap_for_force(&w, 0.0, 107.6e3);
    assert!((law.evaluate(&w, 0.0, d).force - 107.6e3).abs() < 1e-6);
}

#[test]
fn contact_stiffness_is_the_derivative_of_the_closed_forms() {
    // Adaptive, perfect wheel: differentiating (2.5) gives 2 K_w alpha_w with
    // cos alpha_w = (R_w - delta) / R_w; Hertz: 1.5 C_H delta^(1/2).
    let w = WheelProfile::perfect(R).unwrap();
    let law = ContactLaw::adaptive(KW).unwrap();
    for p in [50e3, 107.7e3, 430e3, 2.15e6] {
        let d = law.overlap_for_force(&w, 0.0, p);
        let alpha = ((R - d) / R).acos();
        let k = law.stiffness(&w, 0.0, p);
        assert!((k / (2.0 * KW * alpha) - 1.0).abs() < 1e-6, "{p}: {k}");
    }
    let hertz = ContactLaw::hertz(8.5e10).unwrap();
    let d = hertz.overlap_for_force(&w, 0.0, 107.7e3);
    let k = hertz.stiffness(&w, 0.0, 107.7e3);
    assert!((k / (1.5 * 8.5e10 * d.sqrt()) - 1.0).abs() < 1e-6, "{k}");
}

#[test]
fn exact_contact_stiffness_is_the_derivative_of_the_force() {
    // dP/d delta against a central difference of the force (relative step 1e-5), for
    // a round wheel, split contact (a short flat inside the patch), partial and
    // asymmetric contact as a long flat passes, and Hertz: within 1e-6.
    let round = WheelProfile::perfect(R).unwrap();
    let short = WheelProfile::new(R, &[FlatSpec::haversine(0.008, 0.0003, 0.002)], "f").unwrap();
    let long = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
    let adaptive = ContactLaw::adaptive(KW).unwrap();
    let hertz = ContactLaw::hertz(8.6e10).unwrap();
    let mut checked = 0;
    for (law, w, gammas) in [
        (&adaptive, &round, vec![0.0]),
        (&adaptive, &short, vec![0.0]),
        (&adaptive, &long, vec![-0.12, -0.08, -0.03, 0.0, 0.05, 0.1]),
        (&hertz, &round, vec![0.0]),
        (&hertz, &long, vec![0.0, 0.05]),
    ] {
        for gamma in gammas {
            for delta in [3e-5, 1e-4, 2e-3] {
                let e = 1e-5 * delta;
                let p = |x: f64| law.evaluate(w, gamma, x).force;
                if p(delta - e) <= 0.0 {
                    // Out of contact (inside a deep flat): no stiffness.
                    assert_eq!(law.stiffness_at(w, gamma, delta), 0.0);
                    continue;
                }
                let fd = (p(delta + e) - p(delta - e)) / (2.0 * e);
                let k = law.stiffness_at(w, gamma, delta);
                assert!(
                    (k / fd - 1.0).abs() < 1e-6,
                    "gamma {gamma} delta {delta}: {k} {fd}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "{checked}");
    // A round wheel: 2 K_w alpha_w (2.5).
    let aw = patch_angle(1e-4, R);
    assert!((adaptive.stiffness_at(&round, 0.0, 1e-4) / (2.0 * KW * aw) - 1.0).abs() < 1e-15);
}
