//! Tests of the co-simulation units: the shared clock, the vehicle unit against the
//! monolithic simulation, and the vehicle unit's substeps.

use super::clock::{Clock, ForceExtremes, Stepping};
use super::*;
use crate::limits::MIN_STEP_FRACTION;
use crate::vehicle::{CarrierSpec, RollPlaneParams};

/// Couples an external-wheel track simulation with a vehicle unit, as two FMUs
/// would be coupled, and returns the contact forces per step.
fn run_pair(s: &Scenario, h_per_dt: u64, steps: usize) -> Vec<[f64; 2]> {
    let VehicleSpec::RollPlane(vp) = s.vehicle else {
        panic!("roll-plane scenario expected")
    };
    let w = vp.static_wheel_load();
    let mut ts = s.clone();
    ts.vehicle = VehicleSpec::External {
        static_load: [w, w],
    };
    let mut track = Simulation::new(&ts).unwrap();
    let mut veh = VehicleUnit::new(&VehicleUnitParams {
        speed: s.speed,
        wheel_radius: s.wheel_radius,
        dt: 0.0,
        axle_box: false,
        model: CarrierSpec::RollPlane(vp),
        trailing_static_wheel_z: [[0.0; 2]; 3],
        static_wheel_z: track.wheel_z(),
    })
    .unwrap();
    let h = track.dt() * h_per_dt as f64;
    let mut out = Vec::new();
    for _ in 0..steps {
        track
            .set_wheel_inputs(veh.wheel_z(), veh.rotation())
            .unwrap();
        let c = track.sample().contact;
        let p = [c[0].force, c[1].force];
        veh.set_forces(p).unwrap();
        out.push(p);
        track.advance_steps(h_per_dt).unwrap();
        veh.advance(h, 0.0).unwrap();
    }
    out
}

#[test]
fn pair_at_the_track_step_is_the_monolithic_solver_bit_for_bit() {
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    s.dt = 45e-6;
    let steps = 4000; // 0.18 s: passes the first impact of the flat
    let pair = run_pair(&s, 1, steps);
    let mut sim = Simulation::new(&s).unwrap();
    let mut peak = 0.0f64;
    for (j, p) in pair.iter().enumerate() {
        let m = sim.step().unwrap();
        assert_eq!(
            [m.contact[0].force, m.contact[1].force],
            *p,
            "step {j} differs"
        );
        peak = peak.max(p[0]);
    }
    // The run did reach the impact (well above the 107.7 kN static load).
    assert!(peak > 300e3, "peak {peak}");
}

/// Table 4.4's vehicle at 20 m/s with step `dt` (0: the default) at rest on
/// `static_wheel_z`.
fn table_4_4_unit(
    dt: impl Fn(&RollPlaneParams) -> f64,
    static_wheel_z: [f64; 2],
) -> VehicleUnitParams {
    let VehicleSpec::RollPlane(vp) = Scenario::table_4_4().vehicle else {
        unreachable!()
    };
    VehicleUnitParams {
        speed: 20.0,
        wheel_radius: 0.475,
        dt: dt(&vp),
        static_wheel_z,
        axle_box: false,
        model: CarrierSpec::RollPlane(vp),
        trailing_static_wheel_z: [[0.0; 2]; 3],
    }
}

#[test]
fn state_vector_round_trip_continues_identically() {
    let p = table_4_4_unit(|_| 0.0, [-1e-3, -1.1e-3]);
    let mut a = VehicleUnit::new(&p).unwrap();
    a.set_forces([150e3, 90e3]).unwrap();
    a.advance(3.3e-3, 0.0).unwrap();
    let mut b = VehicleUnit::new(&p).unwrap();
    b.set_state_vector(&a.state_vector()).unwrap();
    a.advance(1e-3, 0.0).unwrap();
    b.advance(1e-3, 0.0).unwrap();
    assert_eq!(a.state_vector(), b.state_vector());
}

#[test]
fn vehicle_default_step_resolves_its_fastest_mode() {
    let s = Scenario::table_4_4();
    let VehicleSpec::RollPlane(vp) = s.vehicle else {
        unreachable!()
    };
    let w = vp.natural_frequencies();
    // Free wheelset (rigid-body) modes are zero; the fastest is a wheelset mode on
    // the primary springs: omega^2 = 2 k1 / m_w bounds it from below.
    assert!(w[0].abs() < 1e-6 * w[5]);
    assert!(w[5] >= (2.0 * vp.primary_stiffness / vp.wheelset_mass).sqrt() * 0.999);
    let dt = vp.default_dt();
    assert!((dt * w[5] - std::f64::consts::TAU / 50.0).abs() < 1e-12);
    assert!(dt < vp.critical_time_step());
}

#[test]
fn any_sequence_of_communication_steps_stays_stable_and_close_to_fixed_steps() {
    // solver.dt at its largest allowed value, half the critical step, and 1e5
    // communication steps cycling through sizes that force a change of the step
    // at almost every call. The wheels rest on linear springs fed back by the
    // master (a stand-in track) and get a 10 ms push of half the static load.
    let p = table_4_4_unit(|vp| 0.5 * vp.critical_time_step(), [-1.4e-3, -1.4e-3]);
    let w = p.model.model().static_wheel_load();
    let forces = |u: &VehicleUnit, t: f64| {
        let (z, k) = (u.wheel_z(), 2e7);
        let push = if t < 0.01 { 0.5 * w } else { 0.0 };
        [w - k * (z[0] + 1.4e-3) + push, w - k * (z[1] + 1.4e-3)]
    };
    let mut var = VehicleUnit::new(&p).unwrap();
    let mut fixed = VehicleUnit::new(&p).unwrap();
    let dt = var.dt_base();
    // Seven sizes adding up to four steps: every seven calls both runs are at the
    // same time and are compared there.
    let sizes = [0.5, 1.0, 0.23, 0.77, 0.5, 0.1, 0.9];
    let (mut t, mut tf) = (0.0, 0.0);
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for k in 0..7 * 14_286 {
        let h = sizes[k % sizes.len()] * dt;
        var.set_forces(forces(&var, t)).unwrap();
        var.advance(h, 0.0).unwrap();
        t += h;
        if k % sizes.len() == sizes.len() - 1 {
            for _ in 0..4 {
                fixed.set_forces(forces(&fixed, tf)).unwrap();
                fixed.advance(dt, 0.0).unwrap();
                tf += dt;
            }
            let (a, b) = (var.wheel_z()[0] + 1.4e-3, fixed.wheel_z()[0] + 1.4e-3);
            worst = worst.max((a - b).abs());
            largest = largest.max(b.abs());
        }
    }
    assert!((t - tf).abs() < 1e-9 * t, "{t} {tf}");
    // 1e5 steps of on average 0.57 dt: 220 s. Bounded (advance checks the health
    // bounds), and the left wheel's excursion from rest differs from the
    // fixed-step run's by the first-order error of the step changes.
    assert!(t > 200.0, "{t}");
    assert!(
        largest > 1e-3 && worst < 0.1 * largest,
        "{worst} of {largest}"
    );
    println!("largest excursion {largest:e} m, largest difference {worst:e} m");
}

#[test]
fn a_grid_clock_ends_at_the_grid_point_nearest_the_masters_time() {
    let dt = 45e-6;
    let mut c = Clock::new(dt, Stepping::Grid);
    assert_eq!(c.steps_to(3.4 * dt, 0.0), 3.0);
    assert_eq!(c.steps_to(3.6 * dt, 0.0), 4.0);
    // Within the clock's rounding of a whole multiple: exactly that many steps.
    assert_eq!(c.steps_to(3.0 * dt * (1.0 + 1e-15), 0.0), 3.0);
    assert_eq!(c.steps_to(3.0 * dt * (1.0 - 1e-15), 0.0), 3.0);
    // A step shorter than half a grid step may advance no grid point.
    assert_eq!(c.steps_to(0.4 * dt, 0.0), 0.0);
    for _ in 0..3 {
        c.tick();
    }
    assert_eq!(c.time(), 3.0 * dt);
    assert_eq!(c.steps_to(3.4 * dt, 0.0), 0.0);
    assert_eq!(c.steps_to(7.2 * dt, 0.0), 4.0);
    // A point behind the clock takes no step.
    assert_eq!(c.steps_to(dt, 0.0), 0.0);
    // After a change of the step, the grid is the new step's from the change on.
    c.restart(2.0 * dt);
    assert_eq!(c.time(), 3.0 * dt);
    assert_eq!(c.steps_to(6.8 * dt, 0.0), 2.0);
}

#[test]
fn a_simulation_advances_to_the_grid_point_nearest_the_masters_time() {
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    s.dt = 45e-6;
    let mut sim = Simulation::new(&s).unwrap();
    let dt = sim.dt();
    let to = |sim: &mut Simulation, end: f64| {
        let plan = sim.plan_to(end, 1e-18).unwrap();
        sim.advance_to(plan).unwrap();
        plan.steps()
    };
    assert_eq!(to(&mut sim, 2.6 * dt), 3.0);
    assert_eq!((sim.steps(), sim.time()), (3, 3.0 * dt));
    assert_eq!(to(&mut sim, 3.4 * dt), 0.0);
    assert_eq!(sim.steps(), 3);
    assert_eq!(to(&mut sim, 10.0 * dt), 7.0);
    assert_eq!(sim.steps(), 10);
    // The same steps as stepping one by one.
    let mut one = Simulation::new(&s).unwrap();
    for _ in 0..10 {
        one.step().unwrap();
    }
    assert_eq!(one.state_vector().unwrap(), sim.state_vector().unwrap());
    // Work beyond the limit is refused before anything moves.
    let w = sim.plan_to(1e4, 0.0).expect_err("refused");
    assert!(w.contains("node updates"), "{w}");
    assert_eq!(sim.steps(), 10);
}

#[test]
fn a_substepping_clock_takes_whole_multiples_as_they_are_and_carries_short_steps() {
    let dt = 1e-4;
    let c = Clock::new(dt, Stepping::Substeps);
    // h = 3 dt up to the clock's rounding: 3 steps of the step in use.
    let tol = 1e-17;
    for h in [3.0 * dt, 3.0 * dt + 5e-18, 3.0 * dt - 5e-18] {
        let s = c.substeps(h, tol);
        assert_eq!((s.n, s.dt), (3.0, None), "h = {h:e}");
    }
    // Beyond the rounding: one more step, all of the same shorter length.
    let s = c.substeps(3.5 * dt, tol);
    assert_eq!((s.n, s.dt), (4.0, Some(3.5 * dt / 4.0)));
    // Below the least step: nothing now, the time carried over.
    let s = c.substeps(0.5 * MIN_STEP_FRACTION * dt, tol);
    assert_eq!((s.n, s.total), (0.0, 0.5 * MIN_STEP_FRACTION * dt));
    // To the master's time: what is ahead of the time taken in, the carried time
    // included, so the clock lands on it.
    let mut c = c;
    c.carried = 0.5 * MIN_STEP_FRACTION * dt;
    assert_eq!(c.steps_to(2.0 * dt, tol), 2.0);
    assert_eq!(c.substeps(2.0 * dt - c.carried, tol).dt, None);
}

#[test]
fn a_vehicle_unit_carries_steps_below_the_least_over_and_follows_the_masters_clock() {
    let p = table_4_4_unit(|_| 0.0, [-1e-3, -1.1e-3]);
    let mut u = VehicleUnit::new(&p).unwrap();
    let dt = u.dt_base();
    let short = 0.6 * MIN_STEP_FRACTION * dt;
    u.advance(short, 0.0).unwrap();
    assert_eq!((u.time(), u.carried()), (0.0, short));
    // Together with the carried time the next step is long enough: one step of both.
    u.advance(short, 0.0).unwrap();
    assert_eq!(u.carried(), 0.0);
    assert_eq!(u.time(), short + short);
    // h = 3 dt up to the clock's rounding: 3 steps of the base step.
    let mut v = VehicleUnit::new(&p).unwrap();
    let tol = 16.0 * f64::EPSILON * 3.0 * dt;
    assert_eq!(v.steps_for(3.0 * dt * (1.0 + 2.0 * f64::EPSILON), tol), 3.0);
    assert_eq!(v.steps_for(3.0 * dt * (1.0 - 2.0 * f64::EPSILON), tol), 3.0);
    let plan = v.plan_to(3.0 * dt, tol).unwrap();
    assert_eq!(plan.steps(), 3.0);
    v.advance_to(plan).unwrap();
    assert_eq!(v.time(), 3.0 * dt);
    // A time behind the clock takes no step.
    let plan = v.plan_to(2.0 * dt, tol).unwrap();
    assert_eq!(plan.steps(), 0.0);
    v.advance_to(plan).unwrap();
    assert_eq!(v.time(), 3.0 * dt);
    let w = v.plan_to(1e4, tol).expect_err("refused");
    assert!(w.contains("steps of solver.step"), "{w}");
}

#[test]
fn force_extremes_take_every_step_in() {
    let mut e = ForceExtremes::NONE;
    e.record([100e3, 90e3]);
    e.record([120e3, 80e3]);
    assert_eq!((e.max, e.min), ([120e3, 90e3], [100e3, 80e3]));
    assert_eq!(ForceExtremes::from_slice(&e.to_array()), e);
    assert_eq!(
        ForceExtremes::at([5.0, 6.0]).to_array(),
        [5.0, 6.0, 5.0, 6.0]
    );
}

/// A perfect wheel rolling over an observation point on a sleeper (70 km/h, table 4.4):
/// the extremes hold the largest and smallest value of every step, and the largest
/// rail seat force is within 3 % above the quasi-static one of a wheel standing over the
/// sleeper.
#[test]
fn a_site_records_what_the_track_feels_as_the_wheel_passes() {
    let site = 12.0 * 0.685;
    let mut s = Scenario::table_4_4();
    s.sites = vec![site];
    let mut sim = Simulation::new(&s).unwrap();
    let mut seen_max = *sim.sites()[0].now();
    let mut seen_min = seen_max;
    // The wheel passes the site at 0.35 s; run to 0.5 s.
    let n = (0.5 / sim.dt()).round() as u64;
    for _ in 0..n {
        sim.step().unwrap();
        let now = sim.sites()[0].now();
        for rail in 0..2 {
            for q in 0..crate::sim::SITE_QUANTITIES.len() {
                seen_max[rail][q] = seen_max[rail][q].max(now[rail][q]);
                seen_min[rail][q] = seen_min[rail][q].min(now[rail][q]);
            }
        }
    }
    assert_eq!(sim.sites()[0].max(), &seen_max);
    assert_eq!(sim.sites()[0].min(), &seen_min);
    // The quasi-static seat force under a wheel standing over the sleeper.
    let TrackSpec::Discrete(p) = s.track else {
        unreachable!()
    };
    let mut t = crate::track::Track::new(p, sim.dt()).unwrap();
    let w = sim.static_load();
    let loads = [0, 1].map(|rail| crate::track::PointLoad {
        rail,
        position: site,
        force: w[rail],
    });
    t.set_static(&loads).unwrap();
    let still = t.support_response(0, site).rail_seat_force;
    let passing = sim.sites()[0].max()[0][3];
    // Quasi-static at 70 km/h: 44.22 kN passing against 44.25 kN standing (45.02 kN
    // with the rail between nodes by (3.23), whose node-passing ripple added 1.8 %).
    assert!(
        (passing / still - 1.0).abs() < 0.005,
        "{passing} against {still}"
    );
}

/// Observation points travel with the state vector: a restored run continues with the
/// same extremes, bit for bit; too many points or one off the track are refused.
#[test]
fn sites_restore_with_the_state_and_are_checked() {
    let mut s = Scenario::table_4_4_flat();
    s.sites = vec![3.0, 5.5];
    let mut a = Simulation::new(&s).unwrap();
    for _ in 0..5000 {
        a.step().unwrap();
    }
    let v = a.state_vector().unwrap();
    let mut b = Simulation::new(&s).unwrap();
    b.set_state_vector(&v).unwrap();
    for _ in 0..5000 {
        a.step().unwrap();
        b.step().unwrap();
    }
    assert_eq!(a.sites(), b.sites());
    s.sites = vec![1.0; 9];
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(e.contains("at most 8"), "{e}");
    s.sites = vec![25.0];
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(e.contains("site[1].position") && e.contains("20.55"), "{e}");
}
