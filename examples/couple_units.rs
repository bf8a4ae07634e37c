//! Coupling the two co-simulation units in Rust, as a master couples the TrackContact and
//! RollPlaneVehicle FMUs: the track with external wheels, the vehicle driven by the
//! contact forces, exchanged every communication step in the order of the thesis'
//! coupled step (vehicle outputs -> track inputs -> track outputs -> vehicle inputs ->
//! both step). At a communication step equal to the track's step this is the
//! monolithic solver's arithmetic: the peak is the 306.4 kN of `first_run`.
//!
//! `cargo run --release --example couple_units [steps_per_exchange]`

use wheelflat::sim::{Scenario, Simulation, VehicleSpec, VehicleUnit, VehicleUnitParams};
use wheelflat::vehicle::CarrierSpec;

fn main() -> Result<(), wheelflat::Error> {
    let per_exchange: u64 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let scenario = Scenario::table_4_4_flat();
    let VehicleSpec::RollPlane(vehicle) = scenario.vehicle else {
        unreachable!("table 4.4 has the roll-plane vehicle")
    };
    // Static handshake: the vehicle's static wheel loads preload the track, whose
    // static wheel heights the vehicle then rests on.
    let w = vehicle.static_wheel_load();
    let mut track_scenario = scenario.clone();
    track_scenario.vehicle = VehicleSpec::External {
        static_load: [w, w],
    };
    let mut track = Simulation::new(&track_scenario)?;
    let mut car = VehicleUnit::new(&VehicleUnitParams {
        speed: scenario.speed,
        wheel_radius: scenario.wheel_radius,
        dt: 0.0,
        static_wheel_z: track.wheel_z(),
        axle_box: false,
        model: CarrierSpec::RollPlane(vehicle),
        trailing_static_wheel_z: [[0.0; 2]; 3],
    })?;
    let h = per_exchange as f64 * track.dt();
    let revolution = std::f64::consts::TAU * scenario.wheel_radius / scenario.speed;
    let mut peak = [0.0f64; 2];
    for _ in 0..(revolution / h) as usize {
        track.set_wheel_inputs(car.wheel_z(), car.rotation())?;
        let c = track.sample().contact;
        let forces = [c[0].force, c[1].force];
        car.set_forces(forces)?;
        peak = [peak[0].max(forces[0]), peak[1].max(forces[1])];
        track.advance_steps(per_exchange)?;
        car.advance(h, 0.0)?;
    }
    println!(
        "communication step {:.2} us: peak contact force left {:.1} kN, right {:.1} kN",
        h * 1e6,
        peak[0] / 1e3,
        peak[1] / 1e3
    );
    Ok(())
}
