//! Cost of the flat-in-patch contact (the adaptive integral) over the calls the
//! issue's reference case makes (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left
//! wheel, n = 2, dt = 45 us, 0.8 s): the run is recorded, the calls in which the flat
//! reaches into the patch are replayed in a loop, and the fastest of five rounds is
//! printed with the share of steps that make such a call.
//! `cargo run --release --example flat_path_cost`

use std::hint::black_box;
use std::time::Instant;
use wheelflat::sim::{Scenario, Simulation};
use wheelflat::wheel::WheelProfile;

fn main() {
    let mut s = Scenario::table_4_4_flat();
    s.set_nodes_per_span(2);
    s.dt = 45e-6;
    let mut sim = Simulation::new(&s).unwrap();
    let law = *sim.contact_law();
    let flat = WheelProfile::new(s.wheel_radius, &s.flats[0], "flat.left").unwrap();
    let perfect = WheelProfile::perfect(s.wheel_radius).unwrap();
    let steps = (0.8 / sim.dt()).round() as usize;
    let mut calls = Vec::new();
    for _ in 0..steps {
        let x = sim.step().unwrap();
        let (gamma, overlap) = (
            x.rotation.rem_euclid(std::f64::consts::TAU),
            x.contact[0].overlap,
        );
        // A call takes the flat path when the flat changes the result.
        if law.evaluate(&flat, gamma, overlap) != law.evaluate(&perfect, gamma, overlap) {
            calls.push((gamma, overlap));
        }
    }
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        for _ in 0..20 {
            for &(gamma, overlap) in &calls {
                black_box(law.evaluate(black_box(&flat), black_box(gamma), black_box(overlap)));
            }
        }
        best = best.min(t0.elapsed().as_secs_f64() / (20 * calls.len()) as f64);
    }
    println!(
        "{} of {steps} steps ({:.1} %) evaluate the flat in the patch: {:.0} ns per call, \
         {:.1} ns per step on average",
        calls.len(),
        100.0 * calls.len() as f64 / steps as f64,
        best * 1e9,
        best * 1e9 * calls.len() as f64 / steps as f64
    );
}
