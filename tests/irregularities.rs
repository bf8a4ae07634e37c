//! Measured irregularities in the coupled engine: a wheel's out-of-roundness and a
//! rail's profile that describe the same geometry give the same forces, a wheel rides
//! a long rail wave at walking speed, a dipped weld as a ready shape and as a table
//! agree, and the endless track reads the rail profile in line coordinates.

use std::f64::consts::TAU;
use std::sync::Arc;
use wheelflat::contact::ContactModel;
use wheelflat::numerics::Table;
use wheelflat::sim::{Scenario, Simulation, TrackWindow};
use wheelflat::track::{RailDefect, RailProfile};
use wheelflat::wheel::OutOfRoundness;

/// Table 4.4 with perfect wheels at `speed` (m/s) from `start` (m).
fn case(speed: f64, start: f64) -> Scenario {
    let mut s = Scenario::table_4_4();
    s.speed = speed;
    s.start_position = start;
    s
}

/// `f` sampled every `dx` over `[a, b]`.
fn sampled(a: f64, b: f64, dx: f64, f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
    let n = ((b - a) / dx).round() as usize;
    (0..=n)
        .map(|i| {
            let x = a + i as f64 * dx;
            (x, f(x))
        })
        .unzip()
}

/// The contact forces of the left wheel over `duration` (s).
fn forces(s: &Scenario, duration: f64) -> (Vec<f64>, f64) {
    let mut sim = Simulation::new(s).unwrap();
    let mut f = Vec::new();
    sim.run(duration, |x| f.push(x.contact[0].force)).unwrap();
    (f, sim.static_load()[0])
}

#[test]
fn a_wheels_radius_deviation_and_a_rails_profile_of_the_same_geometry_give_the_same_forces() {
    // Hertz contact at 70 km/h from 4 m: a 0.15 mm wave of a sixth of the wheel's
    // circumference on the left rail, and the same wave on the left wheel's running
    // surface placed by x = x_0 + R beta (the point at wheel angle beta touches the
    // rail when the axle has turned by beta): the contact sees the same geometry, and
    // the forces agree to 1e-6 of the static load (the issue asks 1 %).
    let (v, x0) = (70.0 / 3.6, 4.0);
    let mut s = case(v, x0);
    s.contact_model = ContactModel::Hertz;
    let r = s.wheel_radius;
    let wave = |u: f64| 0.15e-3 * (6.0 * u).sin();
    let (b, h) = sampled(0.0, TAU - 1e-3, 1e-3, wave);
    let mut wheel = s.clone();
    wheel.roundness[0] = Some(Arc::new(
        OutOfRoundness::new(Table::new(b.clone(), h.clone(), "w").unwrap(), "w").unwrap(),
    ));
    let x: Vec<f64> = b.iter().map(|b| x0 + r * b).collect();
    let mut rail = s.clone();
    rail.rails[0].measured = Some(Arc::new(Table::new(x, h, "r").unwrap()));
    // Less than one turn (2 pi R = 2.98 m, 0.15 s).
    let (fw, load) = forces(&wheel, 0.14);
    let (fr, _) = forces(&rail, 0.14);
    let (plain, _) = forces(&s, 0.14);
    let worst = fw
        .iter()
        .zip(&fr)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 1e-6 * load, "{worst}");
    // And the wave is felt: the forces swing by tens of kN about the plain wheel's.
    let felt = fw
        .iter()
        .zip(&plain)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(felt > 0.1 * load, "{felt}");
}

#[test]
fn at_walking_speed_the_wheel_follows_a_long_rail_wave() {
    // A 1 mm sine of 8 m wavelength on both rails, passed at 1.4 m/s from its crest
    // (where the static start, at rest, matches the wave's zero slope): the wheels
    // ride it quasi-statically, their height following the rail's to 1 % of its
    // amplitude (1.6e-5 of it: 16 nm). (Started on the wave's flank, the vehicle's bounce takes up the
    // slope's 0.8 mm/s: 46 um.)
    let (v, x0, amplitude) = (1.4, 2.0, 1e-3);
    let wave = move |x: f64| amplitude * (TAU * x / 8.0).sin();
    let mut s = case(v, x0);
    let (x, h) = sampled(0.0, 20.0, 0.01, wave);
    let table = Arc::new(Table::new(x, h, "rail").unwrap());
    for rail in &mut s.rails {
        rail.measured = Some(table.clone());
    }
    // Against the same run on ideal rails: the wheel rides the track's own
    // deflection, which changes by tens of micrometres between sleepers.
    let heights = |s: &Scenario| {
        let mut sim = Simulation::new(s).unwrap();
        let mut z = Vec::new();
        sim.run(8.0 / v, |x| z.push((x.position, x.wheel_z[0])))
            .unwrap();
        z
    };
    let (waved, ideal) = (heights(&s), heights(&case(v, x0)));
    let worst = waved
        .iter()
        .zip(&ideal)
        .fold(0.0f64, |m, (&(x, a), &(_, b))| {
            m.max((a - b - wave(x)).abs())
        });
    assert!(worst < 0.01 * amplitude, "{worst}");
}

#[test]
fn a_dipped_weld_as_a_ready_shape_and_as_a_table_agree_and_raise_the_force() {
    // A 1 m long, 1 mm deep dipped weld under the left wheel at 10 m, passed at
    // 70 km/h from 8 m; the same cosine dip sampled every 2 mm as a measured profile.
    let (v, x0) = (70.0 / 3.6, 8.0);
    let weld = RailDefect {
        position: 10.0,
        length: 1.0,
        depth: 1e-3,
    };
    let mut shape = case(v, x0);
    shape.rails[0].defect = Some(weld);
    let dip = |x: f64| {
        let u = (x - 10.0) / 1.0;
        if u.abs() < 0.5 {
            -0.5e-3 * (1.0 + (TAU * u).cos())
        } else {
            0.0
        }
    };
    let (x, h) = sampled(9.0, 11.0, 0.002, dip);
    let mut table = case(v, x0);
    table.rails[0] = RailProfile {
        measured: Some(Arc::new(Table::new(x, h, "weld").unwrap())),
        defect: None,
        random: None,
    };
    let (fs, load) = forces(&shape, 0.2);
    let (ft, _) = forces(&table, 0.2);
    let (plain, _) = forces(&case(v, x0), 0.2);
    let worst = fs
        .iter()
        .zip(&ft)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 1e-3 * load, "{worst}");
    // The wheel drops into the dip (the force falls) and is thrown back at its far
    // side (the force rises above the plain run's): the dip's curvature, at most
    // depth / 2 (2 pi / length)^2 = 0.020 1/m, asks V^2 times that, 7.4 m/s^2, of
    // the wheel: 9 kN on the roll-plane vehicle's wheelset and track mass of about
    // 1.2 t under each wheel. The run gives +8.2 kN and -7.0 kN.
    let peak = fs.iter().cloned().fold(0.0, f64::max);
    let plain_peak = plain.iter().cloned().fold(0.0, f64::max);
    let low = fs.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(
        peak > plain_peak + 0.05 * load && peak < plain_peak + 0.15 * load,
        "{peak} against {plain_peak}"
    );
    assert!(low < 0.95 * load && low > 0.85 * load, "{low}");
}

#[test]
fn the_endless_track_reads_the_rail_profile_where_its_window_is() {
    // The weld at 40 m, reached from 35 m: the endless window (its node 0 well past
    // the line's origin by then) and a fixed 120-span track give the same forces to
    // the window's accuracy (0.6 % of the static load, docs/VALIDATION.md).
    let (v, x0) = (70.0 / 3.6, 35.0);
    let weld = RailDefect {
        position: 40.0,
        length: 1.0,
        depth: 1e-3,
    };
    let mut fixed = case(v, x0);
    fixed.set_spans(120);
    fixed.rails[0].defect = Some(weld);
    let mut endless = fixed.clone();
    endless.window = Some(TrackWindow::CONVERGED);
    let (ff, load) = forces(&fixed, 0.35);
    let (fe, _) = forces(&endless, 0.35);
    let worst = ff
        .iter()
        .zip(&fe)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 0.006 * load, "{worst}");
    let dip = ff.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(dip < 0.95 * load, "the weld is felt: {dip}");
}
