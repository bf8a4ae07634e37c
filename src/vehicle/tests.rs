//! Tests of the vehicle models against closed forms and eigenvalues.

use super::*;
use nalgebra::{DMatrix, SymmetricEigen, Vector6};

/// Table 4.4 vehicle, from the preset.
fn table_4_4() -> RollPlaneParams {
    match crate::sim::Scenario::table_4_4().vehicle {
        crate::sim::VehicleSpec::RollPlane(p) => p,
        _ => unreachable!("table 4.4 has the roll-plane vehicle"),
    }
}

#[test]
fn static_wheel_load_is_seeds_107_6_kn() {
    let w = table_4_4().static_wheel_load();
    assert!((w - 107.6e3).abs() < 0.1e3, "{w}");
}

#[test]
fn static_state_has_zero_residual() {
    let p = table_4_4();
    let mut v = RollPlaneVehicle::new(p, 45e-6).unwrap();
    v.set_static([-1e-3, -1.2e-3]).unwrap();
    let w = p.static_wheel_load();
    // Unequal wheel heights and equal loads: the wheelset rolls, nothing accelerates.
    let r = v.static_residual([w, w]);
    assert!(r.norm() < 1e-6, "{r}");
    let before = *v.displacements();
    for _ in 0..1000 {
        v.step([w, w]);
    }
    let drift = (v.displacements() - before).norm();
    assert!(drift < 1e-12, "{drift:e}");
    let b = v.bearing_forces();
    let upper = w - 0.5 * p.wheelset_mass * p.gravity;
    assert!(
        (b[0] - upper).abs() < 1e-6 && (b[1] - upper).abs() < 1e-6,
        "{b:?}"
    );
}

/// Spectrum magnitude of `sig` at frequency f (Hz), Hann-windowed.
fn dft_mag(sig: &[f64], dt: f64, f: f64) -> f64 {
    let n = sig.len();
    let (mut re, mut im) = (0.0, 0.0);
    for (i, s) in sig.iter().enumerate() {
        let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
        let ph = 2.0 * std::f64::consts::PI * f * i as f64 * dt;
        re += w * s * ph.cos();
        im += w * s * ph.sin();
    }
    (re * re + im * im).sqrt()
}

#[test]
fn free_decay_frequencies_match_eigenvalues_of_m_inv_k() {
    let mut p = table_4_4();
    p.primary_damping = 0.0;
    p.secondary_damping = 0.0;
    p.gravity = 0.0;
    // Eigenvalues of M^-1 K via the symmetric form M^-1/2 K M^-1/2.
    let m = p.mass_diagonal();
    let k = p.stiffness_matrix();
    let ks = DMatrix::from_fn(6, 6, |i, j| k[(i, j)] / (m[i] * m[j]).sqrt());
    let mut freqs: Vec<f64> = SymmetricEigen::new(ks)
        .eigenvalues
        .iter()
        .filter(|l| **l > 1e-6)
        .map(|l| l.sqrt() / (2.0 * std::f64::consts::PI))
        .collect();
    freqs.sort_by(|a, b| a.total_cmp(b));
    assert_eq!(freqs.len(), 4, "two rigid-body modes of the free vehicle");
    // Free decay from an arbitrary initial displacement.
    let dt = 1e-4;
    let mut v = RollPlaneVehicle::new(p, dt).unwrap();
    let d0 = Vector6::new(1e-3, 2e-3, -1.5e-3, 0.7e-3, 0.4e-3, -1e-3);
    v.set_state(d0, d0);
    let mut hist: Vec<Vector6<f64>> = Vec::new();
    for _ in 0..200_000 {
        v.step([0.0, 0.0]);
        hist.push(*v.displacements());
    }
    // Every eigenfrequency appears as a local spectral peak in some coordinate;
    // locate it by golden-section search near the eigenvalue and compare.
    for f in freqs {
        let mut best = (0.0, 0.0);
        for c in 0..6 {
            let sig: Vec<f64> = hist.iter().map(|d| d[c]).collect();
            let mag = dft_mag(&sig, dt, f);
            if mag > best.0 {
                best = (mag, c as f64);
            }
        }
        let sig: Vec<f64> = hist.iter().map(|d| d[best.1 as usize]).collect();
        let (mut lo, mut hi) = (0.97 * f, 1.03 * f);
        for _ in 0..60 {
            let a = hi - 0.618 * (hi - lo);
            let b = lo + 0.618 * (hi - lo);
            if dft_mag(&sig, dt, a) > dft_mag(&sig, dt, b) {
                hi = b;
            } else {
                lo = a;
            }
        }
        let peak = 0.5 * (lo + hi);
        // Central differences shift omega by (omega dt)^2 / 24: far below 0.1 %.
        assert!(((peak - f) / f).abs() < 1e-3, "peak {peak} vs eigen {f}");
    }
}

#[test]
fn bad_vehicle_parameters_are_refused() {
    let mut p = table_4_4();
    p.wheelset_mass = -1.0;
    let e = RollPlaneVehicle::new(p, 1e-5).unwrap_err().to_string();
    assert!(
        e.contains("vehicle.wheelset.mass") && e.contains("-1"),
        "{e}"
    );
    let mut p = table_4_4();
    p.primary_damping = f64::NAN;
    let e = RollPlaneVehicle::new(p, 1e-5).unwrap_err().to_string();
    assert!(e.contains("vehicle.primary.damping"), "{e}");
}
