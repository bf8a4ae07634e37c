//! The half-car bogie on the track (CoupledSystem's `vehicle.model = half_car`):
//! static equilibrium at standstill, the refusals, an exact state restore, and the
//! impact against the roll-plane vehicle.

use wheelflat::sim::{Scenario, Simulation, TrackWindow, TrailingWheelset, VehicleSpec};
use wheelflat::vehicle::{CarrierSpec, HalfCarParams, RollPlaneParams};

fn roll_plane(s: &Scenario) -> RollPlaneParams {
    match s.vehicle {
        VehicleSpec::RollPlane(p) => p,
        _ => unreachable!("the preset has the roll-plane vehicle"),
    }
}

/// Table 4.4 with the half-car bogie (1.8 m wheelbase, side frames of 90 kg m^2), the
/// flat of the reference run on the leading wheelset, an endless track.
fn half_car_scenario() -> Scenario {
    let mut s = Scenario::table_4_4_flat();
    let p = roll_plane(&s);
    s.vehicle = VehicleSpec::Carrier(CarrierSpec::HalfCar(HalfCarParams::from_roll_plane(
        &p, 1.8, 90.0,
    )));
    s.trailing = vec![TrailingWheelset {
        offset: 1.8,
        ..Default::default()
    }];
    s.window = Some(TrackWindow::CONVERGED);
    s
}

#[test]
fn a_half_car_at_standstill_stays_in_its_static_equilibrium() {
    // No flats, no speed: the static start is the equilibrium of bogie, contact and
    // track, so the four contact forces stay at the static wheel load.
    let mut s = half_car_scenario();
    s.flats = Default::default();
    s.speed = 0.0;
    let mut sim = Simulation::new(&s).unwrap();
    let w = sim.static_load()[0];
    let mut worst: f64 = 0.0;
    sim.run(0.1, |_| {}).unwrap();
    for k in 0..2 {
        let f = sim.sample_of(k).unwrap().contact;
        for c in f {
            worst = worst.max((c.force / w - 1.0).abs());
        }
    }
    assert!(worst < 1e-6, "{worst}");
}

#[test]
fn the_half_car_needs_its_two_wheelsets_at_its_wheelbase() {
    let mut s = half_car_scenario();
    s.trailing.clear();
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(
        e.contains("`wheelsets` = 1") && e.contains("half_car"),
        "{e}"
    );
    let mut s = half_car_scenario();
    s.trailing[0].offset = 2.0;
    let e = Simulation::new(&s).unwrap_err().to_string();
    assert!(
        e.contains("`wheelset[2].offset` = 2") && e.contains("1.8 m"),
        "{e}"
    );
}

#[test]
fn a_restored_half_car_state_continues_bit_for_bit() {
    let mut sim = Simulation::new(&half_car_scenario()).unwrap();
    sim.run(0.05, |_| {}).unwrap();
    let saved = sim.state_vector().unwrap();
    let mut first = Vec::new();
    sim.run(0.05, |s| first.push(s.contact[0].force)).unwrap();
    let mut again = Simulation::new(&half_car_scenario()).unwrap();
    again.set_state_vector(&saved).unwrap();
    let mut second = Vec::new();
    again
        .run(0.05, |s| second.push(s.contact[0].force))
        .unwrap();
    assert_eq!(first, second);
    let b = sim.carrier().unwrap().displacements();
    assert_eq!(b, again.carrier().unwrap().displacements());
}

#[test]
fn the_half_cars_impact_is_near_the_roll_plane_vehicles() {
    // The flat's impact is set by the wheelset's unsprung mass and the track; the
    // bodies above the primary suspension barely take part (thesis 4.3). The half-car
    // bogie's peak stays within 3 % of the roll-plane vehicle's.
    let peak = |s: &Scenario| {
        let mut sim = Simulation::new(s).unwrap();
        let mut m: f64 = 0.0;
        sim.run(0.3, |x| m = m.max(x.contact[0].force)).unwrap();
        m
    };
    let hc = peak(&half_car_scenario());
    let mut rp = half_car_scenario();
    rp.vehicle = Scenario::table_4_4_flat().vehicle;
    rp.trailing.clear();
    let r = peak(&rp);
    assert!(r > 2.5e5, "{r}");
    assert!((hc / r - 1.0).abs() < 0.03, "half car {hc}, roll plane {r}");
}
