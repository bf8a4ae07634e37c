//! The axle-box interface under the two kinds of master, for both vehicles: the
//! reference flat case (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the leading left
//! wheel, endless track) with the vehicle cut above its primary suspension: the
//! wheelsets and primary suspensions ride with the track on its step
//! (`VehicleSpec::AxleBox`, which moves the side frames on under their own inertia
//! over each step), the bodies above (`SprungBogie`, `SprungHalfCar`, substeps of at
//! most 0.5 ms) take the mean primary forces every communication step `h`:
//!
//! * sequential (Gauss-Seidel, track first): the bogie steps with the mean force of the
//!   step the track has just taken;
//! * Jacobi (OSP libcosim's and ecos' fixed-step algorithms): both step from the same
//!   communication point, the bogie with the mean force of the step before.
//!
//! Printed per vehicle, master and step: each wheel's peak error against the monolithic
//! run (`VehicleSpec::RollPlane`, `VehicleSpec::HalfCar`) and the largest difference of
//! the contact-force histories over the static load, or where it diverged.
//! `cargo run --release --example axle_box_masters [duration_s]`
use wheelflat::sim::{
    Scenario, SideFrameSpec, Simulation, TrackWindow, TrailingWheelset, VehicleSpec,
};
use wheelflat::vehicle::{HalfCarParams, Quad, RollPlaneParams, SprungBogie, SprungHalfCar};

/// The bodies above the primary suspension.
#[allow(clippy::large_enum_variant)]
enum Above {
    RollPlane(SprungBogie),
    HalfCar(SprungHalfCar),
}

impl Above {
    fn step(&mut self, f: Quad) {
        match self {
            Above::RollPlane(b) => b.step(f[0]),
            Above::HalfCar(b) => b.step(f),
        }
    }
    fn side_frames(&self) -> (Quad, Quad) {
        match self {
            Above::RollPlane(b) => {
                let (z, v) = b.side_frames();
                ([z, [0.0; 2]], [v, [0.0; 2]])
            }
            Above::HalfCar(b) => b.side_frames(),
        }
    }
    fn diverged(&self) -> bool {
        match self {
            Above::RollPlane(b) => b.beyond_bounds().is_some(),
            Above::HalfCar(b) => b.beyond_bounds().is_some(),
        }
    }
}

fn roll_plane(s: &Scenario) -> RollPlaneParams {
    match s.vehicle {
        VehicleSpec::RollPlane(p) => p,
        _ => unreachable!("the preset has the roll-plane vehicle"),
    }
}

fn main() {
    let duration: f64 = std::env::args()
        .nth(1)
        .map_or(0.6, |a| a.parse().expect("a duration in seconds"));
    for half_car in [false, true] {
        let mut mono = Scenario::table_4_4_flat();
        mono.window = Some(TrackWindow::DEFAULT);
        let p = roll_plane(&mono);
        let wheelbase = 1.8;
        let pitch_inertia = 180.0;
        let h_params = HalfCarParams::from_roll_plane(&p, wheelbase, pitch_inertia);
        if half_car {
            mono.vehicle = VehicleSpec::HalfCar(h_params);
            mono.trailing = vec![TrailingWheelset {
                offset: wheelbase,
                ..Default::default()
            }];
        }
        let wheelsets = if half_car { 2 } else { 1 };
        let mut whole = Simulation::new(&mono).unwrap();
        let mut reference: Vec<Quad> = Vec::new();
        let record = |sim: &Simulation| -> Quad {
            [0, 1].map(|k| {
                sim.sample_of(k)
                    .map_or([0.0; 2], |s| [s.contact[0].force, s.contact[1].force])
            })
        };
        let steps = (duration / whole.dt()).round() as usize;
        for _ in 0..steps {
            whole.step().unwrap();
            reference.push(record(&whole));
        }
        let load = whole.static_load()[0];
        let peaks = |f: &[Quad]| -> Quad {
            [0, 1].map(|k| [0, 1].map(|s| f.iter().map(|q| q[k][s]).fold(f64::MIN, f64::max)))
        };
        let ref_peaks = peaks(&reference);
        println!(
            "{}: monolithic peaks {} kN",
            if half_car {
                "half-car bogie"
            } else {
                "roll-plane vehicle"
            },
            (0..wheelsets)
                .flat_map(|k| ref_peaks[k].map(|x| format!("{:.2}", x / 1e3)))
                .collect::<Vec<_>>()
                .join(" / ")
        );
        println!("| master | step | peak errors (%) | history / static load (%) |");
        println!("|---|---|---|---|");
        let mut cut = mono.clone();
        cut.vehicle = VehicleSpec::AxleBox {
            vehicle: p,
            side_frames: if half_car {
                SideFrameSpec::HalfCar {
                    mass: h_params.sideframe_mass,
                    pitch_inertia,
                }
            } else {
                SideFrameSpec::PerWheelset {
                    mass: p.sideframe_mass,
                }
            },
            static_load: [p.static_wheel_load(); 2],
        };
        for jacobi in [false, true] {
            for h in [0.5e-3, 1e-3, 2e-3, 3e-3, 4e-3, 6e-3] {
                let mut sim = Simulation::new(&cut).unwrap();
                let dt = sim.dt();
                let per = (h / dt).round().max(1.0) as u64;
                let h = per as f64 * dt;
                let sub = (h / 5e-4).ceil() as usize;
                let hs = h / sub as f64;
                let boxes: Quad = [0, 1].map(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.1));
                let mut above = if half_car {
                    let mut b = SprungHalfCar::new(h_params, hs).unwrap();
                    b.set_static(boxes).unwrap();
                    Above::HalfCar(b)
                } else {
                    let mut b = SprungBogie::new(p, hs).unwrap();
                    b.set_static(boxes[0]).unwrap();
                    Above::RollPlane(b)
                };
                let mut f: Vec<Quad> = Vec::new();
                let mut failed = None;
                let primary = |sim: &Simulation| -> Quad {
                    [0, 1].map(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.0))
                };
                'run: for _ in 0..(duration / h).round() as usize {
                    // What the bogie takes: a Jacobi master hands it the outputs of the
                    // communication point both start from.
                    let held = primary(&sim);
                    let (zs, vs) = above.side_frames();
                    for k in 0..wheelsets {
                        sim.set_side_frames_of(k, zs[k], vs[k]).unwrap();
                    }
                    for _ in 0..per {
                        if let Err(e) = sim.step() {
                            failed = Some(format!("{e}"));
                            break 'run;
                        }
                        f.push(record(&sim));
                    }
                    let force = if jacobi { held } else { primary(&sim) };
                    for _ in 0..sub {
                        above.step(force);
                    }
                    if above.diverged() {
                        failed = Some("the bogie diverged".into());
                        break;
                    }
                }
                let master = if jacobi { "Jacobi" } else { "sequential" };
                let n = f.len().min(reference.len());
                let mut diff: f64 = 0.0;
                for (a, b) in f[..n].iter().zip(&reference) {
                    for k in 0..wheelsets {
                        for s in 0..2 {
                            diff = diff.max((a[k][s] - b[k][s]).abs());
                        }
                    }
                }
                match failed {
                    Some(e) => println!(
                        "| {master} | {:.1} ms | unstable at {:.3} s: {} | |",
                        h * 1e3,
                        n as f64 * dt,
                        &e[..e.len().min(70)]
                    ),
                    None => {
                        let pk = peaks(&f);
                        let errs: Vec<String> = (0..wheelsets)
                            .flat_map(|k| {
                                [0, 1].map(|s| {
                                    format!("{:+.2}", 100.0 * (pk[k][s] / ref_peaks[k][s] - 1.0))
                                })
                            })
                            .collect();
                        println!(
                            "| {master} | {:.1} ms | {} | {:.2} |",
                            h * 1e3,
                            errs.join(" / "),
                            100.0 * diff / load
                        )
                    }
                }
            }
        }
    }
}
