//! Tests of the wagon against the general eigenvalues of `M^-1 K`, its static loads and
//! state, and the exact reduction to two half-car bogies.

use super::*;
use nalgebra::{DMatrix, DVector};

/// Table 4.4's wagon: bogies 10 m apart, wheelbase 1.8 m, side frames 100 kg m^2.
fn wagon() -> WagonParams {
    let crate::sim::VehicleSpec::RollPlane(p) = crate::sim::Scenario::table_4_4().vehicle else {
        unreachable!("table 4.4 has the roll-plane vehicle")
    };
    WagonParams::table_4_4(&p, 10.0, 1.8, 100.0)
}

/// `o` wheelset by wheelset, as a vehicle's [`Axles`].
fn flat(o: Octet) -> Axles {
    [o[0][0], o[0][1], o[1][0], o[1][1]]
}

/// `q` as the first two wheelsets of a vehicle's [`Axles`].
fn first_two(q: Quad) -> Axles {
    [q[0], q[1], [0.0; 2], [0.0; 2]]
}

#[test]
fn natural_frequencies_are_the_general_eigenvalues_of_m_inverse_k() {
    let w = wagon();
    w.validate().unwrap();
    let m = w.mass_diagonal();
    let k = w.stiffness_matrix();
    // M^-1 K as it stands (not symmetric), through nalgebra's Schur decomposition.
    let a = DMatrix::from_fn(WAGON_DOFS, WAGON_DOFS, |i, j| k[(i, j)] / m[i]);
    let mut general: Vec<f64> = a
        .complex_eigenvalues()
        .iter()
        .map(|l| {
            assert!(l.im.abs() < 1e-6 * (1.0 + l.re.abs()), "{l}");
            l.re.max(0.0).sqrt()
        })
        .collect();
    general.sort_by(f64::total_cmp);
    let symmetric = w.natural_frequencies();
    let top = symmetric[WAGON_DOFS - 1];
    for (a, b) in symmetric.iter().zip(&general) {
        assert!((a - b).abs() < 1e-6 * top, "{a} against {b}");
    }
    // Free of the rails: seven rigid modes (the whole wagon's bounce, pitch and roll,
    // and each bogie's pitch and warp under the car body, as the half-car's).
    let rigid = symmetric.iter().filter(|&&x| x < 1e-3 * top).count();
    assert_eq!(rigid, 7, "{symmetric:?}");
    // The wagon bouncing as a whole, every body moving alike on its side, is a chain of
    // three masses: the car body with its bolsters on the four secondary springs, the
    // four side frames on the eight primary springs, the four wheelsets. Its two
    // frequencies are among the wagon's.
    let (mb, _, _) = w.body_with_bolsters();
    let b = &w.bogie;
    let (k2, k1) = (4.0 * b.secondary_stiffness, 8.0 * b.primary_stiffness);
    let masses = [mb, 4.0 * b.sideframe_mass, 4.0 * b.wheelset_mass];
    let chain = nalgebra::Matrix3::new(k2, -k2, 0.0, -k2, k2 + k1, -k1, 0.0, -k1, k1);
    let chain = nalgebra::Matrix3::from_fn(|i, j| chain[(i, j)] / (masses[i] * masses[j]).sqrt());
    for l in chain.symmetric_eigenvalues().iter().filter(|&&l| l > 1.0) {
        let f = l.sqrt();
        let near = symmetric
            .iter()
            .fold(f64::INFINITY, |m, x| m.min((x - f).abs()));
        assert!(
            near < 1e-6 * f,
            "the chain's {f} rad/s is not the wagon's: {symmetric:?}"
        );
    }
}

#[test]
fn every_wheel_carries_an_eighth_of_the_wagon_and_the_static_state_holds() {
    let w = wagon();
    // Table 4.4's roll-plane vehicle carries 107.665 kN a wheel; the wagon, four such
    // quarters with their bogies, carries the same.
    let load = w.static_wheel_load();
    assert!((load - 107_664.75).abs() < 1e-6, "{load}");
    // Wheels held at uneven heights (a twisted track): the car body and side frames
    // settle, and the wheels carry the weight: each wheelset its quarter, split by the
    // twist between its wheels.
    let z = [
        [[-1.0e-3, -1.2e-3], [-1.1e-3, -0.9e-3]],
        [[-1.0e-3, -1.0e-3], [-0.8e-3, -1.3e-3]],
    ];
    let d = w.static_state(z).unwrap();
    let f = w.static_contact_forces(&d);
    let total: f64 = f.iter().flatten().flatten().sum();
    assert!((total - 8.0 * load).abs() < 1e-8 * 8.0 * load, "{total}");
    let level = w.static_state([[[-1e-3; 2]; 2]; 2]).unwrap();
    for pair in w.static_contact_forces(&level).iter().flatten() {
        for &p in pair {
            assert!((p - load).abs() < 1e-8 * load, "{p}");
        }
    }
    // At rest: nothing accelerates (K d - F = the contact forces' generalised force).
    let r = w.stiffness_matrix() * d - w.gravity_force() - w.contact_force(f);
    assert!(r.norm() < 1e-8 * load, "{}", r.norm());
}

/// The map from the wagon's degrees of freedom to two half-car bogies' (10 each: bolster
/// bounce and roll, side frames, wheelsets): each bolster at its centre plate, both
/// bolsters rolling with the car body.
fn to_pair(d_half: f64) -> DMatrix<f64> {
    let mut t = DMatrix::zeros(2 * HALF_CAR_DOFS, WAGON_DOFS);
    for (b, x) in [(0usize, d_half), (1, -d_half)] {
        let r = HALF_CAR_DOFS * b;
        t[(r, 0)] = 1.0;
        t[(r, 1)] = x;
        t[(r + 1, 2)] = 1.0;
        for k in 0..8 {
            t[(r + 2 + k, bogie_start(b) + k)] = 1.0;
        }
    }
    t
}

/// Two half-cars side by side: each bogie of `w` carrying half its car body (and half
/// its roll inertia with the bolsters').
fn pair_of(w: &WagonParams) -> (DMatrix<f64>, DMatrix<f64>, DVector<f64>) {
    let (m, _, jr) = w.body_with_bolsters();
    let half = HalfCarParams {
        carbody_mass: 0.5 * m - w.bogie.bolster_mass,
        bolster_inertia: 0.5 * jr,
        ..w.bogie
    };
    let n = 2 * HALF_CAR_DOFS;
    let (mut mm, mut kk, mut g) = (
        DMatrix::zeros(n, n),
        DMatrix::zeros(n, n),
        DVector::zeros(n),
    );
    let (hm, hk, hg) = (
        half.mass_diagonal(),
        half.stiffness_matrix(),
        half.gravity_force(),
    );
    for b in 0..2 {
        let r = HALF_CAR_DOFS * b;
        for i in 0..HALF_CAR_DOFS {
            mm[(r + i, r + i)] = hm[i];
            g[r + i] = hg[i];
            for j in 0..HALF_CAR_DOFS {
                kk[(r + i, r + j)] = hk[(i, j)];
            }
        }
    }
    (mm, kk, g)
}

#[test]
fn with_a_dumbbells_pitch_inertia_the_wagon_is_two_half_cars_with_their_roll_tied() {
    let mut w = wagon();
    let (m, _, _) = w.body_with_bolsters();
    let hd = 0.5 * w.bogie_distance;
    // The car body's pitch inertia (with the bolsters') that of half its mass at each
    // centre plate: M (d/2)^2.
    w.carbody_pitch_inertia = m * hd * hd - 2.0 * w.bogie.bolster_mass * hd * hd;
    let t = to_pair(hd);
    let (mp, kp, gp) = pair_of(&w);
    let mw = DMatrix::from_diagonal(&DVector::from_iterator(
        WAGON_DOFS,
        w.mass_diagonal().iter().copied(),
    ));
    let kw = DMatrix::from_fn(WAGON_DOFS, WAGON_DOFS, |i, j| w.stiffness_matrix()[(i, j)]);
    let gw = DVector::from_iterator(WAGON_DOFS, w.gravity_force().iter().copied());
    // The wagon's matrices are the pair's on the tied coordinates, exactly.
    let scale = kw.amax();
    assert!((t.transpose() * &kp * &t - &kw).amax() < 1e-9 * scale);
    assert!((t.transpose() * &mp * &t - &mw).amax() < 1e-9 * mw.amax());
    assert!((t.transpose() * &gp - &gw).amax() < 1e-9 * gw.amax());

    // Statics under loads that differ between the bogies but roll neither (the front
    // bogie's side frames pressed down 20 kN more, the rear's lifted 5 kN): the wagon's
    // motion is the two independent half-cars', to 1e-9 of it.
    let mut extra = WagonVector::zeros();
    for (b, f) in [(0usize, -20e3), (1, 5e3)] {
        extra[bogie_start(b)] = f;
        extra[bogie_start(b) + 2] = f;
    }
    let z = [[[-1e-3; 2]; 2]; 2];
    let dw = w.static_state_under(z, &extra).unwrap();
    let solve_pair = |extra_pair: &DVector<f64>| {
        // The wheels held as the wagon's; the bolsters and side frames free.
        let free: Vec<usize> = (0..2)
            .flat_map(|b| (0..6).map(move |k| HALF_CAR_DOFS * b + k))
            .collect();
        let mut d = DVector::zeros(2 * HALF_CAR_DOFS);
        for b in 0..2 {
            for k in 6..10 {
                d[HALF_CAR_DOFS * b + k] = dw[bogie_start(b) + k - 2];
            }
        }
        let f = &gp + extra_pair - &kp * &d;
        let kff = DMatrix::from_fn(free.len(), free.len(), |i, j| kp[(free[i], free[j])]);
        let rhs = DVector::from_fn(free.len(), |i, _| f[free[i]]);
        let x = kff.lu().solve(&rhs).unwrap();
        for (i, &k) in free.iter().enumerate() {
            d[k] = x[i];
        }
        d
    };
    let extra_pair = &t * DVector::from_iterator(WAGON_DOFS, extra.iter().copied());
    // (The side-frame loads map one for one; the car body's rows carry none.)
    let dp = solve_pair(&extra_pair);
    let mapped = &t * DVector::from_iterator(WAGON_DOFS, dw.iter().copied());
    let size = dp.amax();
    assert!(
        (&mapped - &dp).amax() < 1e-9 * size,
        "{}",
        (&mapped - &dp).amax() / size
    );
    // A load that rolls one bogie only rolls the whole car body in the wagon; the pair
    // rolls only that bogie's bolster: there the two differ.
    let mut roll = WagonVector::zeros();
    roll[bogie_start(0)] = -20e3;
    roll[bogie_start(0) + 2] = 20e3;
    let dw = w.static_state_under(z, &roll).unwrap();
    let dp = solve_pair(&(&t * DVector::from_iterator(WAGON_DOFS, roll.iter().copied())));
    assert!((dp[HALF_CAR_DOFS + 1] - dw[2]).abs() > 0.1 * dw[2].abs());
}

#[test]
fn at_a_standstill_the_wagon_stays_in_its_static_state() {
    // Wheels held on a twisted track, the contact forces of the static state held: over
    // 20,000 steps (56 s) the wagon moves by nanometres (9 nm: free of the rails it
    // has rigid modes, which the rounding of the forces' balance drives), the
    // acceleration that takes below 1e-8 g.
    let w = wagon();
    let dt = 0.5 * LinearVehicle::critical_time_step(&w);
    let mut v = Wagon::new(w, dt).unwrap();
    let z = [
        [[-1.0e-3, -1.2e-3], [-1.1e-3, -0.9e-3]],
        [[-1.0e-3, -1.0e-3], [-0.8e-3, -1.3e-3]],
    ];
    v.set_static(&flat(z)).unwrap();
    let start = *v.displacements();
    let p = flat(w.static_contact_forces(&start));
    for _ in 0..20_000 {
        v.step(&p);
    }
    let drift = (v.displacements() - start).amax();
    let t = 20_000.0 * dt;
    let acceleration = 2.0 * drift / (t * t);
    assert!(acceleration < 1e-8 * w.bogie.gravity, "{drift} m in {t} s");
}

#[test]
fn in_time_the_wagon_moves_as_two_half_car_bogies_under_loads_that_roll_neither() {
    // The dumbbell's pitch inertia; the wheels pushed up and down, each wheelset by its
    // own force history (the same on its two wheels: no roll), for 0.2 s from the
    // static state: the wagon and two half-car bogies each carrying half its car body,
    // stepped alike, agree to 1e-7 of the motion.
    let mut w = wagon();
    let (m, _, jr) = w.body_with_bolsters();
    let hd = 0.5 * w.bogie_distance;
    w.carbody_pitch_inertia = (m - 2.0 * w.bogie.bolster_mass) * hd * hd;
    let half = HalfCarParams {
        carbody_mass: 0.5 * m - w.bogie.bolster_mass,
        bolster_inertia: 0.5 * jr,
        ..w.bogie
    };
    let dt = 0.5 * LinearVehicle::critical_time_step(&w).min(half.critical_time_step());
    let mut wagon = Wagon::new(w, dt).unwrap();
    let mut pair = [
        HalfCarBogie::new(half, dt).unwrap(),
        HalfCarBogie::new(half, dt).unwrap(),
    ];
    let z = [[[-1e-3; 2]; 2]; 2];
    wagon.set_static(&flat(z)).unwrap();
    for b in &mut pair {
        b.set_static(&first_two(z[0])).unwrap();
    }
    let load = w.static_wheel_load();
    let t = to_pair(hd);
    let mut worst: f64 = 0.0;
    let mut size: f64 = 0.0;
    for k in 0..((0.2 / dt) as usize) {
        let time = k as f64 * dt;
        let f = |b: usize, i: usize| {
            let phase = (2 * b + i) as f64;
            let x = load * (1.0 + 0.3 * (std::f64::consts::TAU * (7.0 + phase) * time).sin());
            [x, x]
        };
        let p: Octet = [0, 1].map(|b| [0, 1].map(|i| f(b, i)));
        wagon.step(&flat(p));
        for (b, bogie) in pair.iter_mut().enumerate() {
            bogie.step(&first_two(p[b]));
        }
        let mapped = &t * DVector::from_iterator(WAGON_DOFS, wagon.displacements().iter().copied());
        for b in 0..2 {
            for i in 0..HALF_CAR_DOFS {
                let x = pair[b].displacements()[i];
                worst = worst.max((mapped[HALF_CAR_DOFS * b + i] - x).abs());
                size = size.max(x.abs());
            }
        }
    }
    assert!(worst < 1e-7 * size, "{worst} of {size}");
}
