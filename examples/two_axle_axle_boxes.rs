//! What TrackContact carries above the two-axle wagon's axle boxes (issue 39): the
//! reference flat case (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the leading left
//! wheel, the converged endless track) with the two-axle wagon cut above its axle boxes
//! (`VehicleSpec::AxleBox`: the track carries the wheelsets with their suspension
//! springs and dampers), its car body (`SprungTwoAxleWagon`, substeps of at most 0.5 ms)
//! taking the primary forces every communication step `h` under a sequential master
//! (track first, the mean force of the step) and a Jacobi one (both from the same point,
//! the force at that point), with nothing above the axle boxes
//! (`SideFrameSpec::Nothing`, the upper ends moving on at their input velocity) and with
//! the car body's effective mass at each axle box carried as a side frame of that mass.
//!
//! Printed: each wheel's peak error against the monolithic run
//! (`CarrierSpec::TwoAxle`) and the largest difference of the contact-force histories
//! over the static load.
//! `cargo run --release --example two_axle_axle_boxes [duration_s]`.
use wheelflat::sim::{
    Scenario, SideFrameSpec, Simulation, TrackWindow, TrailingWheelset, VehicleSpec,
};
use wheelflat::vehicle::{
    Axles, CarrierSpec, RollPlaneParams, SprungTwoAxleWagon, SprungVehicle, TwoAxleParams,
    WHEELBASE_RANGE,
};

fn record(sim: &Simulation) -> [[f64; 2]; 2] {
    [0, 1].map(|k| {
        sim.sample_of(k)
            .map_or([0.0; 2], |s| [s.contact[0].force, s.contact[1].force])
    })
}

fn main() {
    let duration: f64 = std::env::args()
        .nth(1)
        .map_or(0.6, |a| a.parse().expect("a duration in seconds"));
    let mut mono = Scenario::table_4_4_flat();
    mono.window = Some(TrackWindow::CONVERGED);
    let VehicleSpec::RollPlane(p) = mono.vehicle else {
        unreachable!("the preset has the roll-plane vehicle")
    };
    let wagon = TwoAxleParams::table_4_4(&p, (1_358_110.0, 94_642.0), 9.0);
    assert!(wagon.wheelbase >= WHEELBASE_RANGE.0);
    mono.vehicle = VehicleSpec::Carrier(CarrierSpec::TwoAxle(wagon));
    mono.trailing = vec![TrailingWheelset {
        offset: wagon.wheelbase,
        ..Default::default()
    }];
    let mut whole = Simulation::new(&mono).unwrap();
    let steps = (duration / whole.dt()).round() as usize;
    let reference: Vec<_> = (0..steps)
        .map(|_| {
            whole.step().unwrap();
            record(&whole)
        })
        .collect();
    let load = whole.static_load()[0];
    let wheelset: RollPlaneParams = wagon.wheelset();
    let carried = [
        (
            "nothing",
            SideFrameSpec::Nothing {
                wheelsets: 2,
                wheelbase: WHEELBASE_RANGE,
                vehicle: "two_axle",
            },
        ),
        (
            "the effective mass",
            SideFrameSpec::PerWheelset {
                mass: wagon.effective_mass(),
            },
        ),
    ];
    println!(
        "two-axle wagon, {duration} s; effective mass at each axle box {:.0} kg",
        wagon.effective_mass()
    );
    println!(
        "| above the axle boxes | master | h (ms) | peak errors (%) | largest difference (% of the static load) |"
    );
    println!("|---|---|---|---|---|");
    for (what, side_frames) in carried {
        let mut cut = mono.clone();
        cut.vehicle = VehicleSpec::AxleBox {
            vehicle: wheelset,
            side_frames,
            static_load: [wagon.static_wheel_load(); 2],
        };
        for jacobi in [false, true] {
            for h in [1e-3, 2e-3] {
                let mut sim = Simulation::new(&cut).unwrap();
                let dt = sim.dt();
                let per = (h / dt).round().max(1.0) as u64;
                let h = per as f64 * dt;
                let sub = (h / 5e-4).ceil() as usize;
                let boxes: Axles =
                    std::array::from_fn(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.1));
                let mut above = SprungTwoAxleWagon::new(wagon, h / sub as f64).unwrap();
                SprungVehicle::set_static(&mut above, &boxes).unwrap();
                let mut f = Vec::with_capacity(steps);
                for _ in 0..(duration / h).round() as usize {
                    let held: Axles =
                        std::array::from_fn(|k| sim.primary_force_of(k).unwrap_or([0.0; 2]));
                    let (zs, vs) = above.side_frames();
                    for k in 0..2 {
                        sim.set_side_frames_of(k, zs[k], vs[k]).unwrap();
                    }
                    for _ in 0..per {
                        sim.step().unwrap();
                        f.push(record(&sim));
                    }
                    let mean: Axles =
                        std::array::from_fn(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.0));
                    for _ in 0..sub {
                        SprungVehicle::step(&mut above, if jacobi { &held } else { &mean });
                    }
                }
                let n = f.len().min(reference.len());
                let peak = |x: &[[[f64; 2]; 2]], k: usize, s: usize| {
                    x[..n].iter().map(|q| q[k][s]).fold(f64::MIN, f64::max)
                };
                let errors: Vec<String> = (0..2)
                    .flat_map(|k| [0, 1].map(|s| (k, s)))
                    .map(|(k, s)| {
                        format!(
                            "{:+.2}",
                            100.0 * (peak(&f, k, s) / peak(&reference, k, s) - 1.0)
                        )
                    })
                    .collect();
                let diff = f[..n]
                    .iter()
                    .zip(&reference)
                    .flat_map(|(a, b)| {
                        (0..4).map(move |i| (a[i / 2][i % 2] - b[i / 2][i % 2]).abs())
                    })
                    .fold(0.0, f64::max);
                println!(
                    "| {what} | {} | {} | {} | {:.2} |",
                    if jacobi { "Jacobi" } else { "sequential" },
                    h * 1e3,
                    errors.join(", "),
                    100.0 * diff / load
                );
            }
        }
    }
}
