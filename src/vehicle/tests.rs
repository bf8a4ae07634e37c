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

/// `q` as the first two wheelsets of a vehicle's [`Axles`].
fn axles(q: Quad) -> Axles {
    [q[0], q[1], [0.0; 2], [0.0; 2]]
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

/// The half-car bogie of table 4.4 with a freight bogie's 1.8 m wheelbase and a side
/// frame's pitch inertia of 90 kg m^2 (about a 450 kg, 1.5 m side frame).
fn half_car() -> HalfCarParams {
    HalfCarParams::from_roll_plane(&table_4_4(), 1.8, 90.0)
}

#[test]
fn half_car_natural_frequencies_are_the_eigenvalues_of_m_inv_k() {
    // The symmetric route (M^-1/2 K M^-1/2) against the general eigenvalues of M^-1 K.
    let p = half_car();
    p.validate().unwrap();
    let minv = HalfCarMatrix::from_diagonal(&p.mass_diagonal().map(|m| 1.0 / m));
    let general = (minv * p.stiffness_matrix()).complex_eigenvalues();
    let mut lambda: Vec<f64> = general.iter().map(|c| c.re).collect();
    lambda.sort_by(f64::total_cmp);
    let top = lambda[HALF_CAR_DOFS - 1];
    for (w, l) in p.natural_frequencies().iter().zip(&lambda) {
        assert!((w * w - l).abs() <= 1e-9 * top, "{w} {l}");
    }
    for c in general.iter() {
        assert!(c.im.abs() < 1e-9 * top, "{c}");
    }
    // Without the rails under the wheels the bogie moves freely as a whole: bounce,
    // roll, pitch and warp (the side frames pitching against each other, the wheelsets
    // rolling against each other) are rigid; the other six modes are elastic.
    let w = p.natural_frequencies();
    let rigid = w
        .iter()
        .filter(|&&x| x < 1e-3 * w[HALF_CAR_DOFS - 1])
        .count();
    assert_eq!(rigid, 4, "{w:?}");
}

#[test]
fn half_car_static_loads_share_the_weight_equally_and_balance_it() {
    let p = half_car();
    let d = p.static_state([[0.0; 2]; 2]).unwrap();
    let f = p.static_contact_forces(&d);
    let w = p.static_wheel_load();
    // Twice the roll-plane vehicle's wheel load: the same 107.66 kN per wheel.
    assert!((w / table_4_4().static_wheel_load() - 1.0).abs() < 1e-12);
    for x in f.iter().flatten() {
        assert!((x / w - 1.0).abs() < 1e-9, "{x} {w}");
    }
    // Unequal wheel heights: the forces change, their sum is the weight.
    let d = p
        .static_state([[-1e-3, -1.2e-3], [-1.1e-3, -0.9e-3]])
        .unwrap();
    let f = p.static_contact_forces(&d);
    let sum: f64 = f.iter().flatten().sum();
    assert!((sum / (4.0 * w) - 1.0).abs() < 1e-9, "{sum}");
    // And the state is an equilibrium: K d = F_gravity + F_contact.
    let r = p.stiffness_matrix() * d - p.gravity_force() - p.contact_force(f);
    assert!(r.norm() < 1e-6 * w, "{r}");
}

#[test]
fn half_car_with_its_wheelsets_moving_alike_is_the_roll_plane_vehicle() {
    // Cut fore and aft, the in-phase half of the half-car bogie is twice the
    // roll-plane vehicle: its six natural frequencies are among the half-car's ten,
    // whatever the wheelbase and the side frames' pitch inertia (those set the other
    // four, the pitch and out-of-phase modes).
    let rp = table_4_4();
    // The thesis' roll-plane vehicle carries the car body as a weight on the bolster,
    // not as its mass (3.1-3.3); the half-car bogie carries the car body's share as
    // the bolster's mass. Compared like with like: the roll-plane vehicle with the car
    // body's mass on its bolster (the same weight).
    let mut massive = rp;
    massive.bolster_mass += massive.carbody_mass;
    massive.carbody_mass = 0.0;
    let six = massive.natural_frequencies();
    // Its four elastic modes (bounce and roll of the whole are rigid without the
    // rails).
    let elastic: Vec<f64> = six.iter().copied().filter(|&w| w > 1e-3 * six[5]).collect();
    assert_eq!(elastic.len(), 4, "{six:?}");
    for (a, j) in [(1.8, 90.0), (2.5, 40.0), (1.5, 300.0)] {
        let ten = HalfCarParams::from_roll_plane(&rp, a, j).natural_frequencies();
        for &w in &elastic {
            let nearest = ten.iter().map(|x| (x - w).abs()).fold(f64::MAX, f64::min);
            assert!(nearest <= 1e-9 * w, "wheelbase {a}: {w} not among {ten:?}");
        }
    }
    // A static state with both wheelsets alike equals the roll-plane vehicle's.
    let p = half_car();
    let z = [-1.0e-3, -1.3e-3];
    let d = p.static_state([z, z]).unwrap();
    let mut v = RollPlaneVehicle::new(rp, 45e-6).unwrap();
    v.set_static(z).unwrap();
    let r = v.displacements();
    for (a, b) in [(d[0], r[0]), (d[1], r[1]), (d[2], r[2]), (d[4], r[3])] {
        assert!((a - b).abs() <= 1e-12 + 1e-9 * b.abs(), "{a} {b}");
    }
    assert!(d[3].abs() < 1e-15 && d[5].abs() < 1e-15);
}

#[test]
fn half_car_driven_alike_on_both_wheelsets_moves_as_the_roll_plane_vehicle() {
    // Time domain: the same contact forces on both wheelsets, and the half-car
    // bogie's bolster, side frames (without pitch) and wheelsets follow the roll-plane
    // vehicle with the car body's mass on its bolster step by step, to rounding.
    let mut rp = table_4_4();
    rp.bolster_mass += rp.carbody_mass;
    rp.carbody_mass = 0.0;
    let dt = 2e-5;
    let h = HalfCarParams::from_roll_plane(&rp, 1.8, 90.0);
    let mut bogie = HalfCarBogie::new(h, dt).unwrap();
    let mut roll = RollPlaneVehicle::new(rp, dt).unwrap();
    let z = [-1.2e-3, -1.4e-3];
    bogie.set_static(&axles([z, z])).unwrap();
    roll.set_static(z).unwrap();
    let w = rp.static_wheel_load();
    let (mut worst, mut motion): (f64, f64) = (0.0, 0.0);
    let r0 = *roll.displacements();
    for j in 0..20_000 {
        // An impact on the left wheel and a slow roll load.
        let t = j as f64 * dt;
        let pulse = if (0.01..0.012).contains(&t) {
            2.0e5
        } else {
            0.0
        };
        let p = [w + pulse, w - 3e4 * (50.0 * t).sin()];
        bogie.step(&axles([p, p]));
        roll.step(p);
        let (b, r) = (bogie.displacements(), roll.displacements());
        for (x, y) in [
            (b[0], r[0]),
            (b[1], r[1]),
            (b[2], r[2]),
            (b[4], r[3]),
            (b[6], r[4]),
            (b[7], r[5]),
            (b[8], r[4]),
            (b[9], r[5]),
        ] {
            worst = worst.max((x - y).abs());
        }
        motion = motion.max((r - r0).amax());
        // No pitch: rounding only, which drifts in the free bogie's rigid pitch mode
        // (side frames pitching with the wheelsets off the rails).
        assert!(b[3].abs() < 1e-9 && b[5].abs() < 1e-9, "{} {}", b[3], b[5]);
    }
    // Off the rails the vehicle moves as a free body under the net force, and the
    // rounding of two different sums grows with it: agreement to 1e-7 of the motion.
    assert!(worst < 1e-7 * motion, "{worst} {motion}");
    // Its bearing forces are the roll-plane vehicle's on each wheelset.
    let (fb, fr) = (bogie.bearing_forces(), roll.bearing_forces());
    for k in 0..2 {
        for s in 0..2 {
            assert!((fb[k][s] - fr[s]).abs() < 1e-6 * w, "{fb:?} {fr:?}");
        }
    }
}

/// The largest difference (m, rad) between the half-car bogie above its primary
/// suspension, driven by the whole bogie's primary forces, and the whole bogie, over
/// 0.1 s at the step `dt` (s), and the largest motion from rest.
fn sprung_half_car_against_the_whole(dt: f64) -> (f64, f64) {
    let h = HalfCarParams::from_roll_plane(&table_4_4(), 1.8, 90.0);
    let mut whole = HalfCarBogie::new(h, dt).unwrap();
    let mut above = SprungHalfCar::new(h, dt).unwrap();
    let z = axles([[-1.2e-3, -1.3e-3], [-1.1e-3, -1.25e-3]]);
    whole.set_static(&z).unwrap();
    let f0 = above.set_static(&z).unwrap();
    let fw = whole.bearing_forces();
    for k in 0..2 {
        for s in 0..2 {
            assert!(
                (f0[k][s] - fw[k][s]).abs() < 1e-6 * fw[k][s].abs(),
                "{f0:?} {fw:?}"
            );
        }
    }
    let w = h.static_wheel_load();
    let (mut worst, mut motion): (f64, f64) = (0.0, 0.0);
    let d0 = *whole.displacements();
    for j in 0..(0.1 / dt).round() as usize {
        let t = j as f64 * dt;
        let p = [
            [w + 1e5 * (300.0 * t).sin(), w],
            [w, w - 5e4 * (80.0 * t).cos()],
        ];
        // The whole bogie's primary forces at t_j drive the part above them.
        above.step(&whole.bearing_forces());
        whole.step(&axles(p));
        let (a, b) = (above.displacements(), whole.displacements());
        for i in 0..6 {
            worst = worst.max((a[i] - b[i]).abs());
            motion = motion.max((b[i] - d0[i]).abs());
        }
    }
    (worst, motion)
}

#[test]
fn half_car_above_its_primary_suspension_converges_to_the_whole() {
    // Fed the whole bogie's primary forces step by step, the bogie above its primary
    // suspension follows the whole: not bit for bit, since the whole takes its primary
    // damping implicitly (3.25) and the cut takes it as a force at t_j; the difference is
    // of first order in the step and small against the motion.
    let (e1, m1) = sprung_half_car_against_the_whole(2e-5);
    let (e2, _) = sprung_half_car_against_the_whole(1e-5);
    assert!(e1 < 1e-3 * m1, "{e1} {m1}");
    let order = (e1 / e2).log2();
    assert!((0.8..1.2).contains(&order), "{e1} {e2} {order}");
}

/// The exchange's estimated stable steps (ms) of a vehicle's own bogie against what
/// TrackContact estimates from the side frames it carries alone ([`carried_limits`]).
fn own_and_carried_limits(
    sprung: &dyn SprungVehicle,
    wheelset: &RollPlaneParams,
    inertia: SideFrameInertia,
    shared: bool,
    z: &Axles,
    base: f64,
    load: [f64; 2],
) -> (ExchangeLimits, ExchangeLimits) {
    let own = sprung.exchange_limits(z, base, CONTACT_STIFFNESS).unwrap();
    let carried = carried_limits(wheelset, inertia, shared, load, CONTACT_STIFFNESS)
        .unwrap()
        .unwrap();
    (own, carried)
}

#[test]
fn the_carried_side_frames_alone_estimate_the_exchanges_stable_steps_of_the_whole_bogie() {
    // The roll-plane vehicle and the half-car bogie of table 4.4: their own estimates
    // (the whole bogie with its substeps) and TrackContact's from the side frames it
    // carries alone. The exchange's fast modes are the side frames on their primary
    // springs, so the two agree; the bogie's own central differences, whose velocity
    // lags half a substep, make its Jacobi limit the lower.
    let p = table_4_4();
    let mut bogie = SprungBogie::new(p, p.default_dt()).unwrap();
    let z = [[-1.2e-3; 2], [0.0; 2], [0.0; 2], [0.0; 2]];
    SprungVehicle::set_static(&mut bogie, &z).unwrap();
    let load = [p.static_wheel_load(); 2];
    let (own, carried) = own_and_carried_limits(
        &bogie,
        &p,
        SideFrameInertia::single(p.sideframe_mass),
        false,
        &z,
        p.default_dt(),
        load,
    );
    // Same scan, same bins (ratio 1.1): equal to the last figure.
    assert_eq!(own, carried, "roll-plane");
    let h = half_car();
    let mut above = SprungHalfCar::new(h, h.default_dt()).unwrap();
    let zq = axles([[-1.2e-3; 2], [-1.2e-3; 2]]);
    SprungVehicle::set_static(&mut above, &zq).unwrap();
    let (own_h, carried_h) = own_and_carried_limits(
        &above,
        &h.wheelset(),
        h.above_axle_boxes(),
        true,
        &zq,
        h.default_dt(),
        [h.static_wheel_load(); 2],
    );
    assert_eq!(own_h, carried_h, "half-car");
    // Table 4.4: 4.0 ms (roll-plane) and 2.3 ms (this half-car) under Jacobi, 20 ms (the
    // scan's end) under a sequential master.
    assert!((own.jacobi - 4.01e-3).abs() < 0.01e-3, "{own:?}");
    assert!((own_h.jacobi - 2.26e-3).abs() < 0.01e-3, "{own_h:?}");
    assert!(own.sequential > 20e-3 && own_h.sequential > 20e-3);
    // Side frames of half the mass and pitch inertia: the Jacobi limit falls by about
    // sqrt(2) or more (1.28 ms), the partner's side frames being the fast modes.
    let light = carried_limits(
        &h.wheelset(),
        SideFrameInertia::pitching(
            0.5 * h.sideframe_mass,
            0.5 * h.sideframe_pitch_inertia,
            h.wheelbase,
        ),
        true,
        [h.static_wheel_load(); 2],
        CONTACT_STIFFNESS,
    )
    .unwrap()
    .unwrap();
    assert!(light.jacobi < own_h.jacobi / 2f64.sqrt(), "{light:?}");
    // Nothing carried: no estimate.
    assert!(
        carried_limits(&p, SideFrameInertia::NONE, false, load, CONTACT_STIFFNESS)
            .unwrap()
            .is_none()
    );
}
