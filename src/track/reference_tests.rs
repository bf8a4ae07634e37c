//! The track against reference solutions: the settled dynamic response against the
//! static solve, the banded static solve against a dense one and on a long track, the
//! sleepers' bounce and roll against single-mass estimates, the free rail against the
//! Timoshenko beam, the undamped energy, a load between nodes against a refined grid.

use super::tests::seed_track;
use super::*;

/// Mean period (s) from upward zero crossings of a signal sampled every dt.
fn mean_period(sig: &[f64], dt: f64) -> f64 {
    let mean = sig.iter().sum::<f64>() / sig.len() as f64;
    let mut ups = Vec::new();
    for i in 1..sig.len() {
        let (a, b) = (sig[i - 1] - mean, sig[i] - mean);
        if a < 0.0 && b >= 0.0 {
            ups.push((i as f64 - 1.0 + a / (a - b)) * dt);
        }
    }
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
}

#[test]
fn settled_dynamic_response_equals_direct_static_solve() {
    let p = seed_track(8, 2);
    let x = 4.0 * 0.685 + 0.2;
    let loads = [
        PointLoad {
            rail: 0,
            position: x,
            force: 1.0e5,
        },
        PointLoad {
            rail: 1,
            position: x,
            force: 0.6e5,
        },
    ];
    let mut stat = Track::new(p, 40e-6).unwrap();
    stat.set_static(&loads).unwrap();
    let mut dynm = Track::new(p, 40e-6).unwrap();
    for _ in 0..45_000 {
        dynm.step(&loads);
    }
    // Average over the last 5000 steps: the rotation field keeps a faint, almost
    // undamped ringing near 4.9 kHz (damping reaches it only through the pads).
    let mut zavg = vec![0.0; dynm.z.len()];
    let mut thavg = vec![0.0; dynm.z.len()];
    for _ in 0..5_000 {
        dynm.step(&loads);
        for i in 0..zavg.len() {
            zavg[i] += dynm.z[i] / 5000.0;
            thavg[i] += dynm.th[i] / 5000.0;
        }
    }
    dynm.z.copy_from_slice(&zavg);
    dynm.th.copy_from_slice(&thavg);
    let zs = stat.rail_z_at(0, x);
    let zd = dynm.rail_z_at(0, x);
    assert!(((zs - zd) / zs).abs() < 1e-6, "{zs} vs {zd}");
    let thmax = stat.th.iter().fold(0.0f64, |m, t| m.max(t.abs()));
    let dz = (0..stat.z.len()).fold(0.0f64, |m, i| m.max((stat.z[i] - dynm.z[i]).abs()));
    let dth = (0..stat.z.len()).fold(0.0f64, |m, i| m.max((stat.th[i] - dynm.th[i]).abs()));
    assert!(
        dz < 1e-6 * zs.abs() && dth < 1e-6 * thmax,
        "{dz} {dth} {thmax}"
    );
    // Global equilibrium on a long track (ends far away): ballast carries the loads.
    let long = seed_track(40, 2);
    let mid = 20.0 * 0.685 + 0.2;
    let mut lt = Track::new(long, 40e-6).unwrap();
    lt.set_static(&[
        PointLoad {
            rail: 0,
            position: mid,
            force: 1.0e5,
        },
        PointLoad {
            rail: 1,
            position: mid,
            force: 0.6e5,
        },
    ])
    .unwrap();
    let ballast: f64 = lt
        .zs
        .iter()
        .map(|z| -2.0 * long.ballast_stiffness * z)
        .sum();
    assert!((ballast - 1.6e5).abs() < 1e-5 * 1.6e5, "{ballast}");
    // Roll: moment of the ballast reactions balances the unequal rail loads.
    let ls = 0.5 * long.rail_seat_distance;
    let moment: f64 = lt
        .ph
        .iter()
        .map(|f| 2.0 * ls * ls * long.ballast_stiffness * f)
        .sum();
    assert!(
        (moment - ls * (1.0e5 - 0.6e5)).abs() < 1e-5 * ls * 1e5,
        "{moment}"
    );
    // A static state is a fixed point of the stepper.
    let before = stat.z.clone();
    for _ in 0..100 {
        stat.step(&loads);
    }
    for (a, b) in before.iter().zip(stat.z.iter()) {
        assert!((a - b).abs() < 1e-12 * zs.abs());
    }
}

#[test]
fn banded_static_solve_equals_dense_lu_and_refuses_a_singular_track() {
    for n in [1usize, 2, 5] {
        let p = seed_track(7, n);
        let t = Track::new(p, 20e-6).unwrap();
        let k = t.stiffness_matrix();
        let mut f = DVector::<f64>::zeros(k.nrows());
        // Loads on both rails at interior nodes, and a moment on a rotation.
        f[2] = -1e5;
        f[t.nk + 3] = -6e4;
        f[2 * t.nk + 4] = 250.0;
        let dense = k.clone().lu().solve(&f).unwrap();
        let banded = t.solve_static_banded(f.as_slice()).unwrap();
        let scale = dense.amax();
        for (a, b) in dense.iter().zip(&banded) {
            assert!((a - b).abs() < 1e-12 * scale, "n = {n}: {a} vs {b}");
        }
    }
    // No pads and no ballast: the sleepers float, the stiffness is singular.
    let mut p = seed_track(4, 2);
    p.pad_stiffness = 0.0;
    p.ballast_stiffness = 0.0;
    let mut t = Track::new(p, 20e-6).unwrap();
    let err = t
        .set_static(&[PointLoad {
            rail: 0,
            position: 1.0,
            force: 1e5,
        }])
        .unwrap_err();
    assert!(err.to_string().contains("singular"), "{err}");
}

#[test]
fn long_track_static_solve_is_local_and_needs_no_dense_matrix() {
    // 4000 spans at n = 4: 16,001 nodes a rail and 72,006 unknowns, whose dense
    // stiffness matrix would take 41 GB. The band is assembled directly. The
    // deflection bowl around a wheelset in the middle must equal the one on a
    // 60-span track (30 spans, 20 m, of track on each side: the bowl decays over
    // about a metre: the two agree to 1e-13 of the peak here).
    let a = 0.685;
    let bowl = |spans: usize| {
        let mut t = Track::new(seed_track(spans, 4), 20e-6).unwrap();
        let x = 0.5 * spans as f64 * a + 0.3 * a;
        let loads = [
            PointLoad {
                rail: 0,
                position: x,
                force: 1.2e5,
            },
            PointLoad {
                rail: 1,
                position: x,
                force: 0.8e5,
            },
        ];
        t.set_static(&loads).unwrap();
        let mid = spans / 2 * 4;
        let (z0, z1) = (t.rail_z(0), t.rail_z(1));
        let near = |z: &[f64]| z[mid - 80..=mid + 80].to_vec();
        let sleepers = t.sleeper_z()[spans / 2 - 20..=spans / 2 + 20].to_vec();
        (near(&z0), near(&z1), sleepers, z0[4], z0[mid])
    };
    let start = std::time::Instant::now();
    let long = bowl(4000);
    let took = start.elapsed().as_secs_f64();
    let short = bowl(60);
    let peak = short.4.abs();
    assert!(peak > 1e-4, "the wheel must deflect the rail: {peak}");
    let worst = [
        (&long.0, &short.0),
        (&long.1, &short.1),
        (&long.2, &short.2),
    ]
    .iter()
    .flat_map(|(l, s)| l.iter().zip(s.iter()).map(|(a, b)| (a - b).abs()))
    .fold(0.0f64, f64::max);
    assert!(
        worst < 1e-11 * peak,
        "bowls differ by {worst:e} of {peak:e}"
    );
    assert!(long.3.abs() < 1e-12 * peak, "far field {:e}", long.3);
    assert!(took < 5.0, "static solve of 72,006 unknowns took {took} s");
}

#[test]
fn sleeper_bounce_and_roll_match_single_mass_estimates() {
    // With pads that barely couple the sleepers to the rails, each sleeper is a
    // single mass on 2 K_b (bounce) and 2 (L_s/2)^2 K_b (roll).
    let mut p = seed_track(4, 2);
    p.pad_stiffness = 1.0;
    p.pad_damping = 0.0;
    p.ballast_damping = 0.0;
    let dt = 20e-6;
    let mut t = Track::new(p, dt).unwrap();
    let ns = p.spans + 1;
    let mut zs = vec![0.0; ns];
    let mut ph = vec![0.0; ns];
    zs[2] = 1e-3;
    ph[2] = 1e-3;
    t.set_sleeper_state(&zs, &ph, &zs.clone(), &ph.clone());
    let (mut bz, mut bp) = (Vec::new(), Vec::new());
    for _ in 0..50_000 {
        t.step(&[]);
        bz.push(t.sleeper_z()[2]);
        bp.push(t.sleeper_roll()[2]);
    }
    let f_bounce = 1.0 / mean_period(&bz, dt);
    let f_roll = 1.0 / mean_period(&bp, dt);
    let est_b = (2.0 * p.ballast_stiffness / p.sleeper_mass).sqrt() / (2.0 * std::f64::consts::PI);
    let ls = 0.5 * p.rail_seat_distance;
    let est_r = (2.0 * ls * ls * p.ballast_stiffness / p.sleeper_inertia).sqrt()
        / (2.0 * std::f64::consts::PI);
    assert!(
        ((f_bounce - est_b) / est_b).abs() < 1e-3,
        "{f_bounce} vs {est_b}"
    );
    assert!(
        ((f_roll - est_r) / est_r).abs() < 1e-3,
        "{f_roll} vs {est_r}"
    );
}

/// Closed-form frequency (Hz) of mode j of a simply supported Timoshenko beam.
fn timoshenko_ss(r: &RailSection, len: f64, j: usize) -> f64 {
    let k = j as f64 * std::f64::consts::PI / len;
    // (kAG k^2 - m w^2)(EI k^2 + kAG - m r^2 w^2) = (kAG k)^2, lower root.
    let a = r.mass * r.rotary_inertia;
    let b = -(r.mass * (r.ei * k * k + r.kag) + r.rotary_inertia * r.kag * k * k);
    let c = r.kag * k * k * r.ei * k * k;
    let w2 = (-b - (b * b - 4.0 * a * c).sqrt()) / (2.0 * a);
    w2.sqrt() / (2.0 * std::f64::consts::PI)
}

#[test]
fn free_rail_converges_to_timoshenko_beam_at_second_order() {
    // Unsupported rail (no pads), pinned ends, started in the exact mode shape.
    let mut errs = Vec::new();
    for n in [4usize, 8, 16] {
        let mut p = seed_track(4, n);
        p.pad_stiffness = 0.0;
        p.pad_damping = 0.0;
        p.ends = RailEnds::Pinned;
        let len = p.length();
        let j = 2;
        let exact = timoshenko_ss(&p.rail, len, j);
        let kw = j as f64 * std::f64::consts::PI / len;
        // Rotation amplitude of the bending mode for unit deflection.
        let w2 = (2.0 * std::f64::consts::PI * exact).powi(2);
        let b = (p.rail.kag * kw * kw - p.rail.mass * w2) / (p.rail.kag * kw);
        let (dtc, _) = p.critical_time_step();
        let dt = 0.5 * dtc;
        let mut t = Track::new(p, dt).unwrap();
        let nk = t.nodes();
        let dx = p.dx();
        let mut z = vec![0.0; 2 * nk];
        let mut th = vec![0.0; 2 * nk];
        for i in 0..nk {
            let x = i as f64 * dx;
            z[i] = 1e-3 * (kw * x).sin();
            th[i] = 1e-3 * b * (kw * x).cos();
        }
        t.set_state(&z, &th, &z.clone(), &th.clone());
        let probe = nk / (2 * j);
        let steps = (20.0 / exact / dt) as usize;
        let mut sig = Vec::with_capacity(steps);
        for _ in 0..steps {
            t.step(&[]);
            sig.push(t.rail_z(0)[probe]);
        }
        let f = 1.0 / mean_period(&sig, dt);
        errs.push(((f - exact) / exact).abs());
    }
    // Errors fall by about 4x per halving of dx (second order).
    for w in errs.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!((1.8..2.3).contains(&order), "{errs:?}");
    }
    assert!(errs[2] < 1e-2, "{errs:?}");
}

#[test]
fn undamped_discrete_energy_is_conserved_over_1e5_steps() {
    let mut p = seed_track(6, 2);
    p.pad_damping = 0.0;
    p.ballast_damping = 0.0;
    let (dtc, _) = p.critical_time_step();
    let mut t = Track::new(p, 0.9 * dtc).unwrap();
    // Start from a static deflection then release the load.
    t.set_static(&[PointLoad {
        rail: 0,
        position: 2.0,
        force: 1e5,
    }])
    .unwrap();
    let k = t.stiffness_matrix();
    let e0 = t.discrete_energy(&k);
    let mut worst: f64 = 0.0;
    for s in 0..100_000 {
        t.step(&[]);
        if s % 1000 == 0 {
            worst = worst.max(((t.discrete_energy(&k) - e0) / e0).abs());
        }
    }
    assert!(worst < 1e-9, "relative energy drift {worst}");
}

#[test]
fn the_rail_under_a_load_between_nodes_matches_a_refined_grid() {
    // Issue 27: a static 100 kN wheel load at w of the way through an element of the
    // default grid (n = 8), against the n = 64 grid, on whose nodes every place tried
    // lies (w = 1/8 ... 7/8). Taken as (3.23) alone the rail under the load is too
    // stiff by up to dx / (4 kAG) (the shear kink it misses) plus the bending sag; with
    // the beam's shape between nodes (the sag, and the kink's compliance times the
    // load) the deflection under the load follows the refined grid's.
    let load = 100e3;
    let under = |n: usize, between: RailBetweenNodes, x: f64| {
        let mut p = seed_track(30, n);
        p.between_nodes = between;
        let mut t = Track::new(p, 1e-6).unwrap();
        let loads = [0, 1].map(|rail| PointLoad {
            rail,
            position: x,
            force: load,
        });
        t.set_static(&loads).unwrap();
        t.rail_z_at(0, x) - t.shear_compliance(x) * load
    };
    let dx = 0.685 / 8.0;
    let x0 = 15.0 * 0.685 + 3.0 * dx;
    // The deflection under the load as it moves through the element, less its chord
    // between the element's nodes: the bump a rolling wheel feels once per element
    // (the chord itself, the nodes' own values, converges with the grid as before).
    let bumps = |n: usize, between: RailBetweenNodes| -> Vec<f64> {
        let d: Vec<f64> = (0..=8)
            .map(|k| under(n, between, x0 + k as f64 / 8.0 * dx))
            .collect();
        (0..=8)
            .map(|k| d[k] - (d[0] + k as f64 / 8.0 * (d[8] - d[0])))
            .collect()
    };
    let fine = bumps(64, RailBetweenNodes::Beam);
    let linear = bumps(8, RailBetweenNodes::Linear);
    let beam = bumps(8, RailBetweenNodes::Beam);
    let worst = |b: &[f64]| {
        b.iter()
            .zip(&fine)
            .fold(0.0f64, |m, (x, f)| m.max((x - f).abs()))
    };
    let (worst_linear, worst_beam) = (worst(&linear), worst(&beam));
    let beam16 = worst(&bumps(16, RailBetweenNodes::Beam));
    // Measured: the refined grid's rail under the load sags 1.0 um below the chord
    // mid-element; (3.23) alone puts it 14.9 um above (15.9 um off: the shear kink's
    // dx / (4 kAG) times the load is 10.0 um of it, the bending sag 2.9 um); the
    // beam's shape leaves 3.0 um at n = 8, 0.6 um at n = 16 (the scheme's own error
    // near a point load, which shrinks with the grid).
    assert!(worst_linear > 15e-6, "{worst_linear}");
    assert!(
        worst_beam < 0.2 * worst_linear,
        "{worst_beam} vs {worst_linear}"
    );
    assert!(beam16 < 0.3 * worst_beam, "{beam16} vs {worst_beam}");
    // On a node the two agree (to rounding: the place is a node to within an ulp).
    let (a, b) = (
        under(8, RailBetweenNodes::Linear, x0),
        under(8, RailBetweenNodes::Beam, x0),
    );
    assert!(((a - b) / a).abs() < 1e-12, "{a} vs {b}");
}
