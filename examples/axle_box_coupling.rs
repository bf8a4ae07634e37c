//! The axle-box interface against the communication step: the reference flat case
//! (table 4.4, 70 km/h, 100 mm x 1.5 mm flat) with the roll-plane vehicle cut at its
//! primary suspension, the wheelset riding with the track on its step and the bodies
//! above it (`SprungBogie`, 0.5 ms substeps) exchanging primary forces for axle-box
//! motion every `h`, against the monolithic run over 0.8 s: the peak's error and the
//! largest difference of the contact-force history over the static load.
//! `cargo run --release --example axle_box_coupling [--extrapolate]` (the bogie moves the
//! axle boxes along their velocity over its substeps instead of holding them).
use wheelflat::sim::{Scenario, Simulation, VehicleSpec};
use wheelflat::vehicle::SprungBogie;

fn main() {
    let mono = Scenario::table_4_4_flat();
    let VehicleSpec::RollPlane(p) = mono.vehicle else {
        unreachable!()
    };
    let duration = 0.8;
    let mut whole = Simulation::new(&mono).unwrap();
    let mut reference = Vec::new();
    whole
        .run(duration, |s| reference.push(s.contact[0].force))
        .unwrap();
    let peak = |f: &[f64]| f.iter().copied().fold(f64::MIN, f64::max);
    let load = whole.static_load()[0];
    println!("monolithic peak {:.1} kN", peak(&reference) / 1e3);
    println!(
        "| communication step | peak (kN) | peak error (%) | largest history difference / static load (%) |"
    );
    println!("|---|---|---|---|");
    let mut cut = mono.clone();
    cut.vehicle = VehicleSpec::AxleBox(p);
    let extrapolate = std::env::args().any(|a| a == "--extrapolate");
    for h in [0.0, 1e-4, 5e-4, 1e-3, 1.44e-3, 2e-3, 3e-3, 4e-3, 5e-3] {
        let mut sim = Simulation::new(&cut).unwrap();
        let dt = sim.dt();
        let per = (h / dt).round().max(1.0) as u64;
        let h = per as f64 * dt;
        let sub = (h / 5e-4).ceil() as usize;
        let mut bogie = SprungBogie::new(p, h / sub as f64).unwrap();
        bogie
            .set_static(sim.axle_box_motion_of(0).unwrap().0)
            .unwrap();
        let mut f = Vec::new();
        let mut failed = None;
        'run: for _ in 0..(duration / h).round() as usize {
            let (z, v) = sim.axle_box_motion_of(0).unwrap();
            if let Err(e) = sim.set_axle_box_forces_of(0, bogie.primary_forces(z, v)) {
                failed = Some(e.to_string());
                break;
            }
            for _ in 0..per {
                match sim.step() {
                    Ok(s) => f.push(s.contact[0].force),
                    Err(e) => {
                        failed = Some(e.to_string());
                        break 'run;
                    }
                }
            }
            for i in 0..sub {
                // The axle boxes' motion extrapolated along their velocity over the
                // substeps (a zero-order hold of the velocity), or held.
                let tau = if extrapolate {
                    i as f64 * h / sub as f64
                } else {
                    0.0
                };
                bogie.step([z[0] + v[0] * tau, z[1] + v[1] * tau], v);
            }
        }
        let n = f.len().min(reference.len());
        let diff = f[..n]
            .iter()
            .zip(&reference)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let label = if h <= dt * 1.5 {
            format!("{:.1} us (the track's step)", dt * 1e6)
        } else {
            format!("{:.2} ms", h * 1e3)
        };
        match failed {
            Some(e) => println!("| {label} | failed: {e} | | |"),
            None => println!(
                "| {label} | {:.1} | {:+.2} | {:.2} |",
                peak(&f) / 1e3,
                100.0 * (peak(&f) / peak(&reference) - 1.0),
                100.0 * diff / load
            ),
        }
    }
}
