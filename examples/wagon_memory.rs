//! A four-axle wagon (wheelsets 0, 1.8, 10 and 11.8 m behind the leading one, the
//! reference flat on the leading wheelset's left wheel) on the endless track at the
//! converged grid and the converged window (20 m a side), 60 s at 70 km/h: the peak resident memory
//! (VmHWM) and the wall time at 1, 10 and 60 s of simulated time. Memory stays constant
//! because the window moves with the wagon. Linux only (reads /proc/self/status).
//! The wagon is the whole car body on two half-car bogies (`vehicle.model = wagon`);
//! with the argument `roll_plane`, a roll-plane vehicle on each wheelset; with `one`,
//! the reference flat case alone (one wheelset) on the FMUs' default window (10 m a
//! side, issue 29).
//! `cargo run --release --example wagon_memory [roll_plane|one]`
use std::time::Instant;
use wheelflat::sim::{Scenario, Simulation, TrackWindow};

fn peak_rss_kib() -> u64 {
    let s = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    s.lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_default();
    let mut s = Scenario::table_4_4_wagon();
    match which.as_str() {
        "one" => {
            s = Scenario::table_4_4_flat();
            s.window = Some(TrackWindow::DEFAULT);
        }
        "roll_plane" => s.vehicle = Scenario::table_4_4_flat().vehicle,
        _ => {}
    }
    let before = peak_rss_kib();
    let mut sim = Simulation::new(&s).unwrap();
    println!(
        "{} wheelsets, window of {} spans; peak RSS before building: {before} KiB",
        sim.wheelsets().len(),
        sim.rail_nodes() / 2 / 8
    );
    println!(
        "| simulated (s) | position (m) | peak RSS (KiB) | wall (s) | largest force of each wheelset's left wheel (kN) |"
    );
    println!("|---|---|---|---|---|");
    let t0 = Instant::now();
    let mut done = 0.0;
    for mark in [1.0, 10.0, 60.0] {
        sim.run(mark - done, |_| {}).unwrap();
        done = mark;
        let w = sim.wheelsets();
        println!(
            "| {mark} | {:.1} | {} | {:.3} | {} |",
            sim.position(),
            peak_rss_kib(),
            t0.elapsed().as_secs_f64(),
            (0..w.len())
                .map(|k| format!("{:.1}", w.get(k).unwrap().max_force()[0] / 1e3))
                .collect::<Vec<_>>()
                .join(" / ")
        );
    }
    println!("\nlargest contact forces over the run (kN):\n");
    println!("| wheelset | left | right |");
    println!("|---|---|---|");
    for (k, w) in sim.wheelsets().iter().enumerate() {
        let m = w.max_force();
        println!("| {} | {:.1} | {:.1} |", k + 1, m[0] / 1e3, m[1] / 1e3);
    }
}
