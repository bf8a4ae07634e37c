//! The four-axle wagon on the track (CoupledSystem's `vehicle.model = wagon`): static
//! equilibrium at standstill, the refusals, an exact state restore, the reduction to
//! the half-car bogie on the track, the wagon as a co-simulation unit against the
//! monolithic run, and a long run at constant memory.

use wheelflat::sim::{Scenario, Simulation, VehicleSpec, VehicleUnit, VehicleUnitParams};
use wheelflat::vehicle::{CarrierSpec, HalfCarParams};

/// Table 4.4 with the wagon (1.8 m wheelbase, bogie centres 10 m apart, side frames of
/// 180 kg m^2), the flat of the reference run on the leading wheel, 70 km/h, an
/// endless track: [`Scenario::table_4_4_wagon`].
fn wagon_scenario() -> Scenario {
    Scenario::table_4_4_wagon()
}

/// The largest contact force of each wheel `[left, right]` of every wheelset over
/// `duration` (s).
fn peaks(sim: &mut Simulation, duration: f64) -> Vec<[f64; 2]> {
    let n = sim.wheelsets().len();
    let mut m = vec![[f64::MIN; 2]; n];
    let steps = (duration / sim.dt()).round() as usize;
    for _ in 0..steps {
        sim.step().unwrap();
        for (k, mk) in m.iter_mut().enumerate() {
            let c = sim.sample_of(k).unwrap().contact;
            mk[0] = mk[0].max(c[0].force);
            mk[1] = mk[1].max(c[1].force);
        }
    }
    m
}

#[test]
fn a_wagon_at_standstill_stays_in_its_static_equilibrium() {
    // No flats, no speed: the static start is the equilibrium of the wagon, the
    // contacts and the track, so the eight contact forces stay at the static wheel
    // load, an eighth of the wagon's weight (table 4.4: 107.665 kN).
    let mut s = wagon_scenario();
    s.flats = Default::default();
    s.speed = 0.0;
    let mut sim = Simulation::new(&s).unwrap();
    let w = sim.static_load()[0];
    assert!((w / 107_664.75 - 1.0).abs() < 1e-12, "{w}");
    sim.run(0.2, |_| {}).unwrap();
    let mut worst: f64 = 0.0;
    for k in 0..4 {
        for c in sim.sample_of(k).unwrap().contact {
            worst = worst.max((c.force / w - 1.0).abs());
        }
    }
    assert!(worst < 1e-8, "{worst}");
}

#[test]
fn the_wagon_needs_its_four_wheelsets_at_its_offsets() {
    let mut s = wagon_scenario();
    s.trailing.truncate(1);
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(
        e.contains("`wheelsets` = 2") && e.contains("4 with the wagon"),
        "{e}"
    );
    let mut s = wagon_scenario();
    s.trailing[2].offset = 12.0;
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(
        e.contains("`wheelset[4].offset` = 12") && e.contains("11.8 m"),
        "{e}"
    );
}

#[test]
fn a_restored_wagon_state_continues_bit_for_bit() {
    let mut sim = Simulation::new(&wagon_scenario()).unwrap();
    sim.run(0.04, |_| {}).unwrap();
    let saved = sim.state_vector().unwrap();
    let mut first = Vec::new();
    sim.run(0.02, |s| first.push(s.contact[0].force)).unwrap();
    let mut again = Simulation::new(&wagon_scenario()).unwrap();
    again.set_state_vector(&saved).unwrap();
    let mut second = Vec::new();
    again
        .run(0.02, |s| second.push(s.contact[0].force))
        .unwrap();
    assert_eq!(first, second);
    assert_eq!(
        sim.carrier().unwrap().displacements(),
        again.carrier().unwrap().displacements()
    );
}

#[test]
fn the_wagon_with_the_dumbbell_pitch_inertia_is_two_half_cars_on_the_track() {
    // With the car body's pitch inertia M (d/2)^2 its bounce and pitch are the two
    // bolsters' bounces with half its mass each (src/vehicle/wagon.rs): under vertical
    // loads that roll both bogies alike the wagon is two independent half-car bogies.
    // The reference flat rolls only the front bogie, so the match is not exact; the
    // front bogie's wheels then feel the rear bogie only through the car body's roll
    // and the rails 10 m away. Its four peaks are within 1 % of the half-car bogie's on
    // the same track (measured: 0.41 % at most, 0.01 % on the flat wheel), and the
    // wagon's largest peak is the flat wheel's.
    let mut s = wagon_scenario();
    let VehicleSpec::Carrier(CarrierSpec::Wagon(mut w)) = s.vehicle else {
        unreachable!()
    };
    let (m, _, _) = w.body_with_bolsters();
    let hd = 0.5 * w.bogie_distance;
    w.carbody_pitch_inertia = m * hd * hd - 2.0 * w.bogie.bolster_mass * hd * hd;
    s.vehicle = VehicleSpec::Carrier(CarrierSpec::Wagon(w));
    let wagon = peaks(&mut Simulation::new(&s).unwrap(), 0.2);
    let mut h = s.clone();
    let bogie = HalfCarParams {
        carbody_mass: 0.5 * w.carbody_mass,
        ..w.bogie
    };
    h.vehicle = VehicleSpec::Carrier(CarrierSpec::HalfCar(bogie));
    h.trailing.truncate(1);
    let half = peaks(&mut Simulation::new(&h).unwrap(), 0.2);
    for k in 0..2 {
        for side in 0..2 {
            let e = wagon[k][side] / half[k][side] - 1.0;
            assert!(e.abs() < 0.01, "wheelset {} side {side}: {e}", k + 1);
        }
    }
    assert!(wagon[0][0] > 2.5 * 107_664.75, "{wagon:?}");
    let all = wagon.iter().flatten().copied();
    assert_eq!(all.fold(f64::MIN, f64::max), wagon[0][0]);
}

#[test]
fn the_wagon_unit_with_external_wheels_at_the_tracks_step_is_the_monolithic_run() {
    // The vehicle unit (the Wagon FMU's engine) and the track with external wheels,
    // exchanged at every track step in the order of docs/MODEL.md, do the monolithic
    // run's arithmetic: the eight contact forces agree bit for bit through the impact.
    let s = wagon_scenario();
    let VehicleSpec::Carrier(CarrierSpec::Wagon(w)) = s.vehicle else {
        unreachable!()
    };
    let mut mono = Simulation::new(&s).unwrap();
    let mut ext = s.clone();
    ext.vehicle = VehicleSpec::External {
        static_load: [w.static_wheel_load(); 2],
    };
    let mut track = Simulation::new(&ext).unwrap();
    let z = |k: usize| track.sample_of(k).unwrap().wheel_z;
    let mut unit = VehicleUnit::new(&VehicleUnitParams {
        speed: s.speed,
        wheel_radius: s.wheel_radius,
        dt: track.dt(),
        static_wheel_z: z(0),
        axle_box: false,
        model: CarrierSpec::Wagon(w),
        trailing_static_wheel_z: [z(1), z(2), z(3)],
    })
    .unwrap();
    let dt = track.dt();
    for _ in 0..(0.06 / dt).round() as usize {
        for k in 0..4 {
            let wz = unit.wheel_z_of(k).unwrap();
            track.set_wheelset_inputs(k, wz, unit.rotation()).unwrap();
        }
        for k in 0..4 {
            let c = track.sample_of(k).unwrap().contact;
            let m = mono.sample_of(k).unwrap().contact;
            assert_eq!(
                [c[0].force, c[1].force],
                [m[0].force, m[1].force],
                "wheelset {k}"
            );
            unit.set_forces_of(k, [c[0].force, c[1].force]).unwrap();
        }
        track.step().unwrap();
        mono.step().unwrap();
        unit.advance(dt, 1e-12).unwrap();
    }
    assert!(mono.wheelsets().lead().max_force()[0] > 2.5 * 107_664.75);
}

#[test]
fn a_wagon_at_standstill_over_a_dipped_weld_starts_in_its_joint_equilibrium() {
    // A 3 mm dipped weld under the leading left wheel at the start: the wagon is not
    // determinate in twist, so the wheels carry unequal loads at rest (hundreds of
    // newtons off the static load), and the static start solves the track and the wagon
    // together until they agree: standing still, no force moves by more than 1e-6 of
    // the static load over 0.3 s (with the equal loads of a determinate vehicle they
    // moved by 669 N).
    let mut s = wagon_scenario();
    s.flats = Default::default();
    s.speed = 0.0;
    s.rails[0].defect = Some(wheelflat::track::RailDefect {
        position: s.start_position,
        length: 1.0,
        depth: 3e-3,
    });
    let mut sim = Simulation::new(&s).unwrap();
    let w = sim.static_load()[0];
    let forces = |sim: &Simulation| -> Vec<f64> {
        (0..4)
            .flat_map(|k| sim.sample_of(k).unwrap().contact.map(|c| c.force))
            .collect()
    };
    let start = forces(&sim);
    let uneven = start.iter().map(|f| (f - w).abs()).fold(0.0, f64::max);
    assert!(uneven > 100.0, "{start:?}");
    sim.run(0.3, |_| {}).unwrap();
    let moved = forces(&sim)
        .iter()
        .zip(&start)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(moved < 1e-6 * w, "{moved} N");
    // The wagon carries its weight: the loads sum to eight static loads.
    let total: f64 = start.iter().sum();
    assert!((total / (8.0 * w) - 1.0).abs() < 1e-9, "{total}");
}
