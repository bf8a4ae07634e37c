//! Does the wheel/rail contact lower the stability limit of the explicit track scheme?
//! (issue 13). Table 4.4 track and contact, n = 2 (the seed's grid) and n = 8 (the
//! default).
//!
//! 1. The contact stiffness `k_c = dP/d delta` of the adaptive law at 1, 4, 10 and 20
//!    times the static wheel load: perfect wheel, and the largest over the rotation
//!    angles at which the 100 mm x 1.5 mm haversine flat is in the patch, at equal force.
//! 2. The critical step without and with `k_c`: the reported bound, the bound with
//!    Weyl's `lambda + k_c / (m dx)`, the bound of
//!    `TrackParams::critical_time_step_with_contact`, the exact undamped limit
//!    `2 / sqrt(lambda_max)` of the assembled track (30 spans) with the contact spring,
//!    and the measured threshold: the actual `Track` stepper (damped), the contact as a
//!    linear spring `F = k_c z_rail(x_w)` applied every step as a `PointLoad` at a fixed
//!    wheel position, started from a random perturbation; bisection on `dt / dt_c`
//!    (unstable: the amplitude grows by 1e6 within 40,000 steps).
//! 3. The coupled reference case (table 4.4, 70 km/h, flat) at 0.99 of the reported
//!    limit through ten flat impacts, n = 2 and n = 8.
//!
//! `cargo run --release --example stability_limit` (about 30 s).
use nalgebra::SymmetricEigen;
use wheelflat::contact::ContactLaw;
use wheelflat::sim::{Scenario, Simulation, TrackSpec, VehicleSpec};
use wheelflat::track::{Track, TrackParams, perturbation_growth};
use wheelflat::wheel::{FlatSpec, WheelProfile};

/// Exact undamped limit `2 / sqrt(lambda_max)` (s) of the assembled track with a spring
/// `kc` (N/m) to ground under the wheel at `x` (m) on the left rail.
fn exact_limit(p: TrackParams, kc: f64, x: f64) -> f64 {
    let t = Track::new(p, 1e-7).unwrap();
    let mut k = t.stiffness_matrix();
    let nk = t.nodes();
    let (node, w) = t.locate(x);
    for (i, a) in [(node, 1.0 - w), (node + 1, w)] {
        for (j, b) in [(node, 1.0 - w), (node + 1, w)] {
            if i > 0 && j > 0 && i + 1 < nk && j + 1 < nk {
                k[(i, j)] += kc * a * b;
            }
        }
    }
    let r = &p.rail;
    let dx = p.dx();
    let ns = p.spans + 1;
    let mass = |i: usize| {
        if i < 2 * nk {
            r.mass * dx
        } else if i < 4 * nk {
            r.rotary_inertia * dx
        } else if i < 4 * nk + ns {
            p.sleeper_mass
        } else {
            p.sleeper_inertia
        }
    };
    let n = k.nrows();
    for i in 0..n {
        for j in 0..n {
            k[(i, j)] /= (mass(i) * mass(j)).sqrt();
        }
    }
    2.0 / SymmetricEigen::new(k).eigenvalues.max().sqrt()
}

/// True when the track stepped at `dt` (s) with a contact spring `kc` (N/m) under
/// `x + v t` (m) on the left rail grows from a random perturbation by 1e6 within
/// `steps` ([`perturbation_growth`]).
fn unstable(p: TrackParams, dt: f64, kc: f64, x: f64, v: f64, steps: usize) -> bool {
    perturbation_growth(p, dt, kc, (x, v), steps, 1e6).unwrap() > 1e6
}

/// Smallest `dt / dt_c` (reported) at which the stepper is unstable, to 1e-6, the
/// wheel starting at `x` (m) and moving at `v` (m/s) for `steps`.
fn measured_ratio(p: TrackParams, kc: f64, x: f64, v: f64, steps: usize) -> f64 {
    let dtc = p.critical_time_step().0;
    let (mut lo, mut hi) = (0.25, 1.3);
    assert!(!unstable(p, lo * dtc, kc, x, v, steps), "unstable at {lo}");
    assert!(unstable(p, hi * dtc, kc, x, v, steps), "stable at {hi}");
    while hi - lo > 1e-6 {
        let mid = 0.5 * (lo + hi);
        if unstable(p, mid * dtc, kc, x, v, steps) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

fn main() {
    let s = Scenario::table_4_4();
    let TrackSpec::Discrete(base) = s.track else {
        unreachable!()
    };
    let VehicleSpec::RollPlane(veh) = s.vehicle else {
        unreachable!()
    };
    let p0 = veh.static_wheel_load();
    let law = ContactLaw::adaptive(s.kw).unwrap();
    let perfect = WheelProfile::perfect(s.wheel_radius).unwrap();
    let beta0 = std::f64::consts::FRAC_PI_2;
    let flat = WheelProfile::new(
        s.wheel_radius,
        &[FlatSpec::haversine(0.1, 0.0015, beta0)],
        "flat",
    )
    .unwrap();
    let multiples = [1.0, 4.0, 10.0, 20.0];

    println!(
        "## 1. Contact stiffness dP/d delta, table 4.4 (K_w = {:.4e} N/m/rad, R_w = {} m, static load {:.1} kN)\n",
        s.kw,
        s.wheel_radius,
        p0 / 1e3
    );
    println!(
        "| force | delta, perfect (um) | k_c perfect (N/m) | 2 K_w alpha_w (N/m) | k_c, flat in patch, max over gamma (N/m) | at flat angle (deg) | flat / perfect |"
    );
    println!("|---|---|---|---|---|---|---|");
    let half = 0.1 / (2.0 * s.wheel_radius);
    let mut kc_perfect = Vec::new();
    let mut kc_flat = Vec::new();
    for &mlt in &multiples {
        let p = mlt * p0;
        let d = law.overlap_for_force(&perfect, 0.0, p);
        let kp = law.stiffness(&perfect, 0.0, p);
        let alpha = 2.0 * (d / (2.0 * s.wheel_radius)).sqrt().asin();
        // Flat centre at beta0 - gamma relative to the contact point: scan it across
        // the patch and a little beyond (flat half-angle plus the widest patch).
        let mut best = (0.0, 0.0);
        let samples = 2000;
        for i in 0..=samples {
            let rel = -(half + 0.06) + 2.0 * (half + 0.06) * i as f64 / samples as f64;
            let gamma = beta0 - rel;
            let k = law.stiffness(&flat, gamma, p);
            if k > best.0 {
                best = (k, rel);
            }
        }
        println!(
            "| {mlt} x ({:.0} kN) | {:.1} | {:.3e} | {:.3e} | {:.3e} | {:+.2} | {:.2} |",
            p / 1e3,
            d * 1e6,
            kp,
            2.0 * s.kw * alpha,
            best.0,
            best.1.to_degrees(),
            best.0 / kp
        );
        kc_perfect.push(kp);
        kc_flat.push(best.0);
    }

    println!("\n## 2. Critical step with the contact spring (table 4.4 track, 30 spans)\n");
    println!(
        "Ratios are dt / dt_c (reported, without the contact). Measured: damped stepper, wheel fixed at the position named; exact: undamped, same track.\n"
    );
    println!(
        "| n | k_c (N/m) | load | dt_c reported (us) | Weyl lambda + k_c/(m dx) (us) | with_contact bound (us) | exact undamped, over node at sleeper (us) | measured: node at sleeper | node mid-span | w = 0.5 next to sleeper | w = 0.5 nearest mid-span | moving at 70 km/h |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for n in [2usize, 8] {
        let mut p = base;
        p.nodes_per_span = n;
        p.spans = 30;
        let a = p.sleeper_spacing;
        let dx = p.dx();
        let (dtc, _) = p.critical_time_step();
        let lam = (2.0 / dtc).powi(2);
        let md = p.rail.mass * dx;
        let mut cases: Vec<(f64, String)> = vec![(0.0, "none".into())];
        for (i, &mlt) in multiples.iter().enumerate() {
            cases.push((kc_perfect[i], format!("{mlt} x static")));
        }
        cases.push((kc_flat[3], "20 x static, flat (max)".into()));
        // Far beyond any force (20 x static is 3.9e9): where the contact starts to
        // matter, to check the bound against the exact and measured limits.
        cases.push((3e10, "none reached (check)".into()));
        cases.push((1e11, "none reached (check)".into()));
        let x_sleeper = 15.0 * a;
        let x_mid = 15.0 * a + (n / 2) as f64 * dx;
        let x_half_sleeper = 15.0 * a + 0.5 * dx;
        let x_half_mid = 15.0 * a + ((n / 2) as f64 - 0.5) * dx;
        for (kc, what) in cases {
            let weyl = 2.0 / (lam + kc / md).sqrt();
            let bound = p.critical_time_step_with_contact(kc).0;
            let exact = exact_limit(p, kc, x_sleeper);
            let m = [x_sleeper, x_mid, x_half_sleeper, x_half_mid]
                .map(|x| measured_ratio(p, kc, x, 0.0, 40_000));
            // Moving at 70 km/h from 5 spans in, 10,000 steps (about 9 m at n = 2).
            let moving = measured_ratio(p, kc, 5.0 * a, s.speed, 10_000);
            println!(
                "| {n} | {kc:.3e} | {what} | {:.3} | {:.3} ({:.4}) | {:.3} ({:.6}{}) | {:.3} ({:.6}) | {:.6} | {:.6} | {:.6} | {:.6} | {moving:.6} |",
                dtc * 1e6,
                weyl * 1e6,
                weyl / dtc,
                bound * 1e6,
                bound / dtc,
                if bound == dtc { ", same bits" } else { "" },
                exact * 1e6,
                exact / dtc,
                m[0],
                m[1],
                m[2],
                m[3]
            );
        }
    }

    println!("\n## The seed's setting: table 4.4, n = 2, dt = 45 us\n");
    let mut p = base;
    p.nodes_per_span = 2;
    let (dtc, _) = p.critical_time_step();
    for (kc, what) in [
        (
            kc_perfect[1],
            "4 x static (the seed-grid reference run's 430 kN)",
        ),
        (kc_flat[3], "20 x static, flat in the patch"),
        (1e11, "1e11 N/m (none reached; the contact sets the limit)"),
    ] {
        let (dt, text) = p.critical_time_step_with_contact(kc);
        println!(
            "* k_c = {kc:.3e} N/m, {what}: {:.3} us (45 us is {:.4} of it): {text}",
            dt * 1e6,
            45e-6 / dt
        );
    }
    println!(
        "* without the contact: {:.3} us (45 us is {:.4} of it); Weyl's lambda + k_c/(m dx) at 4 x static would give {:.3} us, below 45 us",
        dtc * 1e6,
        45e-6 / dtc,
        2.0 / ((2.0 / dtc).powi(2) + kc_perfect[1] / (p.rail.mass * p.dx())).sqrt() * 1e6
    );

    println!("\n## 3. Coupled reference case at 0.99 of the reported limit, ten flat impacts\n");
    println!("| n | dt (us) | peak per revolution, left (kN) | max |rail z| (mm) |");
    println!("|---|---|---|---|");
    for n in [2usize, 8] {
        let mut sc = Scenario::table_4_4_flat();
        sc.set_nodes_per_span(n);
        sc.set_spans(50);
        let TrackSpec::Discrete(tp) = sc.track else {
            unreachable!()
        };
        sc.dt = 0.99 * tp.critical_time_step().0;
        let mut sim = Simulation::new(&sc).unwrap();
        let rev = std::f64::consts::TAU * sc.wheel_radius / sc.speed;
        // Impact i when the flat, 90 deg ahead at the start, reaches the contact point.
        let t_imp = |i: usize| (0.25 + i as f64) * rev;
        let duration = t_imp(9) + 0.5 * rev;
        let mut peaks = [0.0f64; 10];
        let mut zmax: f64 = 0.0;
        sim.run(duration, |smp| {
            let i = ((smp.time / rev - 0.25) + 0.5).floor().clamp(0.0, 9.0) as usize;
            peaks[i] = peaks[i].max(smp.contact[0].force);
            zmax = zmax.max(smp.rail_z[0].abs()).max(smp.rail_z[1].abs());
        })
        .unwrap();
        let list: Vec<String> = peaks.iter().map(|p| format!("{:.1}", p / 1e3)).collect();
        println!(
            "| {n} | {:.3} | {} | {:.3} |",
            sc.dt * 1e6,
            list.join(", "),
            zmax * 1e3
        );
    }
}
