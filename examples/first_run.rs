//! A first program with the engine: the thesis' table 4.4 freight wheelset at 70 km/h
//! with a 100 mm x 1.5 mm flat on the left wheel, on the converged default grid, run for
//! one revolution of the wheel. Prints the static load, the peak contact force per wheel
//! and when the left one occurred.
//!
//! `cargo run --release --example first_run`

use wheelflat::sim::{Scenario, Simulation};

fn main() -> Result<(), wheelflat::Error> {
    let scenario = Scenario::table_4_4_flat();
    // Builds track, vehicle and contact, checks every parameter and solves the static
    // equilibrium of the whole system.
    let mut sim = Simulation::new(&scenario)?;
    let revolution = std::f64::consts::TAU * scenario.wheel_radius / scenario.speed;
    let (mut peak, mut at) = ([0.0f64; 2], 0.0);
    sim.run(revolution, |sample| {
        if sample.contact[0].force > peak[0] {
            at = sample.time;
        }
        for (p, c) in peak.iter_mut().zip(&sample.contact) {
            *p = p.max(c.force);
        }
    })?;
    println!(
        "static wheel load {:.1} kN, step {:.2} us",
        sim.static_load()[0] / 1e3,
        sim.dt() * 1e6
    );
    println!(
        "peak contact force: left {:.1} kN at t = {:.2} ms, right {:.1} kN",
        peak[0] / 1e3,
        at * 1e3,
        peak[1] / 1e3
    );
    Ok(())
}
