//! The braking run: table 4.4's wagon with the reference flat (100 mm x 1.5 mm on the
//! left wheel) on the endless track, braking from 100 km/h to standstill at 1 m/s^2,
//! then standing 1 s. The speed is set at every step (`Simulation::set_speed`); the
//! axle rolls without slip, so the flat meets the rail whenever the rotation passes
//! pi/2 (mod 2 pi). Prints every impact (time, speed, peak force, the peak's delay
//! after the flat's centre reached the contact, the place along the span) and, for
//! comparison, the impacts of constant-speed runs at 100, 80, 60, 40 and 20 km/h
//! (each impact of 1 s, as the place along the span changes).
//! `cargo run --release --example braking_run [DECELERATION]`
use std::f64::consts::{FRAC_PI_2, TAU};
use wheelflat::sim::{Scenario, Simulation, TrackWindow, kmh};

/// Peak force of each impact (the largest left-wheel force while the flat is within a
/// quarter turn of the contact): (time of the flat's centre at the contact (s), speed
/// (m/s), peak (N), peak time (s), position (m)).
fn impacts(sim: &mut Simulation, speed: impl Fn(f64) -> f64, duration: f64) -> Vec<[f64; 5]> {
    let mut out = Vec::new();
    let mut current: Option<[f64; 5]> = None;
    let mut last_gamma = sim.rotation();
    let n = (duration / sim.dt()).round() as u64;
    for _ in 0..n {
        let v = speed(sim.time());
        sim.set_speed(v).unwrap();
        let s = sim.step().unwrap();
        // Angle of the flat's centre from the contact, in (-pi, pi].
        let phase =
            |g: f64| (g - FRAC_PI_2 + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI;
        let (p0, p1) = (phase(last_gamma), phase(s.rotation));
        last_gamma = s.rotation;
        let near = p1.abs() < 0.25 * std::f64::consts::PI;
        if near {
            let c = current.get_or_insert([f64::NAN, v, 0.0, 0.0, s.position]);
            if p0 < 0.0 && p1 >= 0.0 {
                c[0] = s.time;
                c[1] = v;
                c[4] = s.position;
            }
            if s.contact[0].force > c[2] {
                c[2] = s.contact[0].force;
                c[3] = s.time;
            }
        } else if let Some(c) = current.take()
            && c[0].is_finite()
        {
            out.push(c);
        }
    }
    out
}

fn main() {
    let decel: f64 = std::env::args()
        .nth(1)
        .map_or(1.0, |a| a.parse().expect("DECELERATION (m/s^2)"));
    let mut s = Scenario::table_4_4_flat();
    s.window = Some(TrackWindow::CONVERGED);
    let v0 = kmh(100.0);
    s.speed = v0;
    let mut sim = Simulation::new(&s).unwrap();
    let stop = v0 / decel;
    let a = 0.685;
    let hits = impacts(&mut sim, |t| (v0 - decel * t).max(0.0), stop + 1.0);
    println!(
        "braking from 100 km/h at {decel} m/s^2: {} impacts, standstill at {stop:.2} s, position {:.2} m",
        hits.len(),
        sim.position()
    );
    println!("| time (s) | speed (km/h) | peak (kN) | delay (ms) | place in the span (-) |");
    println!("|---|---|---|---|---|");
    for h in &hits {
        println!(
            "| {:.3} | {:.1} | {:.1} | {:.2} | {:.2} |",
            h[0],
            h[1] * 3.6,
            h[2] / 1e3,
            (h[3] - h[0]) * 1e3,
            (h[4] / a).rem_euclid(1.0)
        );
    }
    let after = sim.sample();
    println!(
        "at standstill, 1 s later: force {:.1} kN (static {:.1} kN), speed {} m/s",
        after.contact[0].force / 1e3,
        sim.static_load()[0] / 1e3,
        sim.speed()
    );
    println!("\nconstant speed, every impact of 1 s:");
    println!(
        "| speed (km/h) | impacts | smallest peak (kN) | largest peak (kN) | braking run's peaks within 5 km/h (kN) |"
    );
    println!("|---|---|---|---|---|");
    for kmh_v in [100.0, 80.0, 60.0, 40.0, 20.0] {
        let mut c = s.clone();
        c.speed = kmh(kmh_v);
        let mut sim = Simulation::new(&c).unwrap();
        let v = c.speed;
        let hits_c = impacts(&mut sim, |_| v, 1.0);
        let peaks: Vec<f64> = hits_c.iter().map(|h| h[2]).collect();
        let lo = peaks.iter().copied().fold(f64::MAX, f64::min);
        let hi = peaks.iter().copied().fold(f64::MIN, f64::max);
        let near: Vec<String> = hits
            .iter()
            .filter(|h| (h[1] * 3.6 - kmh_v).abs() <= 5.0)
            .map(|h| format!("{:.0}", h[2] / 1e3))
            .collect();
        println!(
            "| {kmh_v} | {} | {:.1} | {:.1} | {} |",
            peaks.len(),
            lo / 1e3,
            hi / 1e3,
            near.join(", ")
        );
    }
}
