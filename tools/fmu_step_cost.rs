//! Cost of one TrackContact communication step at comm step = dt (set wheel inputs,
//! read the forces, fmi2DoStep) against the engine's own step on the same track, for
//! instruction counting: `valgrind --tool=callgrind target/release/examples/fmu_step_cost engine|fmu [steps]`.
//! Without valgrind it prints wall time per step.

use std::hint::black_box;
use std::time::Instant;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{TRACK_CONTACT, vr};
use wheelflat::sim::{Scenario, Simulation, VehicleSpec};

#[path = "ffi_instance.rs"]
mod ffi_instance;

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "both".into());
    let n: u64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let mut s = Scenario::table_4_4_flat();
    s.vehicle = VehicleSpec::External {
        static_load: [107_664.75; 2],
    };
    let sim = Simulation::new(&s).unwrap();
    let (z, dt) = (sim.wheel_z(), sim.dt());
    if which == "engine" || which == "both" {
        let mut e = sim.clone();
        let t0 = Instant::now();
        for _ in 0..n {
            e.set_wheel_inputs(z, e.rotation()).unwrap();
            // The sample is kept where step returns it (no copy into black_box).
            black_box(e.step().as_ref().unwrap());
        }
        let w = t0.elapsed().as_secs_f64() / n as f64;
        println!("engine step: {:.3} us", w * 1e6);
    }
    if which == "fmu" || which == "both" {
        let (c, _) = ffi_instance::initialised(
            TRACK_CONTACT.guid,
            // The thesis' fixed track, as the engine's (the FMUs' default is the endless).
            &[(vr::TRACK_WINDOW_AHEAD, 0.0)],
            &[],
        );
        let inputs = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z, vr::WHEEL_ROTATION];
        let outputs = [vr::CONTACT_LEFT_FORCE, vr::CONTACT_RIGHT_FORCE];
        unsafe {
            let mut p = [0.0; 2];
            let t0 = Instant::now();
            for k in 0..n {
                let t = k as f64 * dt;
                let u = [z[0], z[1], s.speed * t / s.wheel_radius];
                fmi2SetReal(c, inputs.as_ptr(), 3, u.as_ptr());
                fmi2GetReal(c, outputs.as_ptr(), 2, p.as_mut_ptr());
                black_box(p);
                assert_eq!(fmi2DoStep(c, t, dt, 1), 0);
            }
            let w = t0.elapsed().as_secs_f64() / n as f64;
            println!("fmu step (set, get, doStep): {:.3} us", w * 1e6);
            fmi2FreeInstance(c);
        }
    }
}
