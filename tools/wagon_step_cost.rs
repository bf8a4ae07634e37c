//! Cost of one step of CoupledSystem on the endless track's converged window (or SIDE)
//! with 1 to 4 wheelsets of a four-axle wagon (0, 1.8, 10, 11.8 m), through the C
//! boundary (fmi2DoStep of solver.step, the contact forces read) against the engine's
//! own step of the same scenario, for instruction counting:
//! `valgrind --tool=callgrind target/release/examples/wagon_step_cost engine|fmu WHEELSETS STEPS [SIDE [K]]`
//! (subtract a run of 0 steps). SIDE (m) is the window's length ahead and behind
//! (default: the converged 20 m); 0 runs the fixed 30-span track instead (one wheelset:
//! the others would start behind its end). K makes each fmi2DoStep K steps long
//! (default 1). Without valgrind it prints wall time per step.

use std::hint::black_box;
use std::time::Instant;
use wheelflat::fmu::ffi::*;
use wheelflat::fmu::vars::{COUPLED_SYSTEM, OFFSET_VRS, vr};
use wheelflat::sim::{Scenario, Simulation, TrackWindow, TrailingWheelset};

#[path = "ffi_instance.rs"]
mod ffi_instance;

const WAGON: [f64; 3] = [1.8, 10.0, 11.8];

fn main() {
    let arg = |k: usize| std::env::args().nth(k);
    let which = arg(1).unwrap_or_else(|| "both".into());
    // WHEELSETS "wagon" is the four-axle wagon (`Scenario::table_4_4_wagon`) on its own
    // four wheelsets, a number that many roll-plane vehicles.
    let wagon = arg(2).as_deref() == Some("wagon");
    let wheelsets: usize = if wagon {
        4
    } else {
        arg(2).and_then(|s| s.parse().ok()).unwrap_or(1)
    };
    let n: u64 = arg(3).and_then(|s| s.parse().ok()).unwrap_or(20_000);
    let side: f64 = arg(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or(TrackWindow::CONVERGED.ahead);
    let mut s = if wagon {
        Scenario::table_4_4_wagon()
    } else {
        Scenario::table_4_4_flat()
    };
    s.window = (side > 0.0).then_some(TrackWindow {
        ahead: side,
        behind: side,
        ..TrackWindow::DEFAULT
    });
    s.trailing = WAGON[..wheelsets - 1]
        .iter()
        .map(|&offset| TrailingWheelset {
            offset,
            ..Default::default()
        })
        .collect();
    if which == "engine" || which == "both" {
        let mut e = Simulation::new(&s).unwrap();
        let t0 = Instant::now();
        for _ in 0..n {
            black_box(e.step().as_ref().unwrap());
        }
        let w = t0.elapsed().as_secs_f64() / n as f64;
        println!("engine step, {wheelsets} wheelsets: {:.3} us", w * 1e6);
    }
    if which == "fmu" || which == "both" {
        let mut reals = vec![(vr::TRACK_WINDOW_AHEAD, side)];
        if side > 0.0 {
            reals.push((vr::TRACK_WINDOW_BEHIND, side));
        }
        reals.extend(OFFSET_VRS.iter().copied().zip(WAGON));
        let mut integers = vec![(vr::WHEELSETS, wheelsets as i32)];
        if wagon {
            integers.push((
                vr::VEHICLE_MODEL,
                wheelflat::fmu::vars::enums::vehicle_model::WAGON as i32,
            ));
        }
        let per_call: u64 = arg(5).and_then(|s| s.parse().ok()).unwrap_or(1).max(1);
        let (c, dt) = ffi_instance::initialised(COUPLED_SYSTEM.guid, &reals, &integers);
        let (n, dt) = (n / per_call, dt * per_call as f64);
        let outputs = [vr::CONTACT_LEFT_FORCE, vr::CONTACT_RIGHT_FORCE];
        unsafe {
            let mut p = [0.0; 2];
            let t0 = Instant::now();
            for k in 0..n {
                assert_eq!(fmi2DoStep(c, k as f64 * dt, dt, 1), 0);
                fmi2GetReal(c, outputs.as_ptr(), 2, p.as_mut_ptr());
                black_box(p);
            }
            let w = t0.elapsed().as_secs_f64() / (n * per_call) as f64;
            println!(
                "CoupledSystem step, {wheelsets} wheelsets: {:.3} us",
                w * 1e6
            );
            fmi2FreeInstance(c);
        }
    }
}
