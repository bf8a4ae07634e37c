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
//!   communication point, the bogie with the primary force at that point
//!   (`Simulation::primary_force_of`, TrackContact's `primary.*.force`).
//!
//! Printed per vehicle, master and step: each wheel's peak error against the monolithic
//! run (`VehicleSpec::RollPlane`, `CarrierSpec::HalfCar`) and the largest difference of
//! the contact-force histories over the static load, or where it diverged.
//! `cargo run --release --example axle_box_masters [duration_s] [--limits]`: with
//! `--limits`, the largest usable step per master over primary stiffnesses and dampings.
use wheelflat::sim::{
    Scenario, SideFrameSpec, Simulation, TrackWindow, TrailingWheelset, VehicleSpec,
};
use wheelflat::vehicle::{
    Axles, CONTACT_STIFFNESS, CarrierSpec, ExchangeLimits, HalfCarParams, Quad, RollPlaneParams,
    SprungBogie, SprungHalfCar, SprungVehicle,
};

/// `q` as the half-car's wheelsets of a vehicle's [`Axles`].
fn axles(q: Quad) -> Axles {
    [q[0], q[1], [0.0; 2], [0.0; 2]]
}

/// The first two wheelsets of `a`.
fn quad(a: &Axles) -> Quad {
    [a[0], a[1]]
}

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
            Above::HalfCar(b) => b.step(&axles(f)),
        }
    }
    fn side_frames(&self) -> (Quad, Quad) {
        match self {
            Above::RollPlane(b) => {
                let (z, v) = b.side_frames();
                ([z, [0.0; 2]], [v, [0.0; 2]])
            }
            Above::HalfCar(b) => {
                let (z, v) = b.side_frames();
                (quad(&z), quad(&v))
            }
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

/// Outcome of one coupled run: the peak errors (%) per wheel and the largest history
/// difference over the static load (%), or where it failed.
type Outcome = Result<(Vec<f64>, f64), String>;

/// The reference flat case with `k1` (N/m) and `c1` (N s/m) primary suspensions,
/// monolithic: its contact forces at every track step, its static load.
struct Case {
    half_car: bool,
    mono: Scenario,
    cut: Scenario,
    h_params: HalfCarParams,
    p: RollPlaneParams,
    reference: Vec<Quad>,
    load: f64,
    duration: f64,
}

fn record(sim: &Simulation) -> Quad {
    [0, 1].map(|k| {
        sim.sample_of(k)
            .map_or([0.0; 2], |s| [s.contact[0].force, s.contact[1].force])
    })
}

fn peaks(f: &[Quad]) -> Quad {
    [0, 1].map(|k| [0, 1].map(|s| f.iter().map(|q| q[k][s]).fold(f64::MIN, f64::max)))
}

impl Case {
    fn new(half_car: bool, k1: f64, c1: f64, duration: f64) -> Case {
        let mut mono = Scenario::table_4_4_flat();
        mono.window = Some(TrackWindow::CONVERGED);
        let mut p = roll_plane(&mono);
        p.primary_stiffness = k1;
        p.primary_damping = c1;
        mono.vehicle = VehicleSpec::RollPlane(p);
        let (wheelbase, pitch_inertia) = (1.8, 180.0);
        let h_params = HalfCarParams::from_roll_plane(&p, wheelbase, pitch_inertia);
        if half_car {
            mono.vehicle = VehicleSpec::Carrier(CarrierSpec::HalfCar(h_params));
            mono.trailing = vec![TrailingWheelset {
                offset: wheelbase,
                ..Default::default()
            }];
        }
        let mut whole = Simulation::new(&mono).unwrap();
        let steps = (duration / whole.dt()).round() as usize;
        let mut reference = Vec::with_capacity(steps);
        for _ in 0..steps {
            whole.step().unwrap();
            reference.push(record(&whole));
        }
        let mut cut = mono.clone();
        cut.vehicle = VehicleSpec::AxleBox {
            vehicle: p,
            side_frames: if half_car {
                SideFrameSpec::HalfCar {
                    mass: h_params.sideframe_mass,
                    pitch_inertia,
                    bogies: 1,
                }
            } else {
                SideFrameSpec::PerWheelset {
                    mass: p.sideframe_mass,
                }
            },
            static_load: [p.static_wheel_load(); 2],
        };
        Case {
            half_car,
            load: whole.static_load()[0],
            mono,
            cut,
            h_params,
            p,
            reference,
            duration,
        }
    }

    fn wheelsets(&self) -> usize {
        if self.half_car { 2 } else { 1 }
    }

    /// The bogie's critical step (s).
    fn critical(&self) -> f64 {
        if self.half_car {
            self.h_params.critical_time_step()
        } else {
            self.p.critical_time_step()
        }
    }

    /// The cut model at communication step `h` (s) under a Jacobi or sequential master.
    fn run(&self, jacobi: bool, h: f64) -> Outcome {
        let mut sim = Simulation::new(&self.cut).map_err(|e| e.to_string())?;
        let dt = sim.dt();
        let per = (h / dt).round().max(1.0) as u64;
        let h = per as f64 * dt;
        let sub = (h / (5e-4f64).min(0.4 * self.critical())).ceil() as usize;
        let hs = h / sub as f64;
        let boxes: Quad = [0, 1].map(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.1));
        let mut above = if self.half_car {
            let mut b = SprungHalfCar::new(self.h_params, hs).map_err(|e| e.to_string())?;
            b.set_static(&axles(boxes)).unwrap();
            Above::HalfCar(b)
        } else {
            let mut b = SprungBogie::new(self.p, hs).map_err(|e| e.to_string())?;
            b.set_static(boxes[0]).unwrap();
            Above::RollPlane(b)
        };
        let primary = |sim: &Simulation| -> Quad {
            [0, 1].map(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.0))
        };
        let mut f: Vec<Quad> = Vec::with_capacity(self.reference.len());
        for _ in 0..(self.duration / h).round() as usize {
            // A Jacobi master hands the bogie the outputs of the communication point
            // both start from; a sequential one the track's mean of the step just taken.
            let held = [0, 1].map(|k| sim.primary_force_of(k).unwrap_or([0.0; 2]));
            let (zs, vs) = above.side_frames();
            for k in 0..self.wheelsets() {
                sim.set_side_frames_of(k, zs[k], vs[k])
                    .map_err(|e| format!("at {:.3} s: {e}", f.len() as f64 * dt))?;
            }
            for _ in 0..per {
                sim.step()
                    .map_err(|e| format!("at {:.3} s: {e}", f.len() as f64 * dt))?;
                f.push(record(&sim));
            }
            let force = if jacobi { held } else { primary(&sim) };
            for _ in 0..sub {
                above.step(force);
            }
            if above.diverged() {
                return Err(format!(
                    "the bogie diverged at {:.3} s",
                    f.len() as f64 * dt
                ));
            }
        }
        let n = f.len().min(self.reference.len());
        let mut diff: f64 = 0.0;
        for (a, b) in f[..n].iter().zip(&self.reference) {
            for k in 0..self.wheelsets() {
                for s in 0..2 {
                    diff = diff.max((a[k][s] - b[k][s]).abs());
                }
            }
        }
        let (pk, rp) = (peaks(&f), peaks(&self.reference));
        let errs = (0..self.wheelsets())
            .flat_map(|k| [0, 1].map(|s| 100.0 * (pk[k][s] / rp[k][s] - 1.0)))
            .collect();
        Ok((errs, 100.0 * diff / self.load))
    }

    /// The estimated limits ([`wheelflat::vehicle::ExchangeLimits`]) with substeps of at
    /// most 0.5 ms.
    fn estimate(&self) -> ExchangeLimits {
        let sim = Simulation::new(&self.cut).unwrap();
        let boxes: Quad = [0, 1].map(|k| sim.primary_of(k).map_or([0.0; 2], |p| p.1));
        let base = (5e-4f64).min(0.4 * self.critical());
        if self.half_car {
            let mut b = SprungHalfCar::new(self.h_params, base).unwrap();
            b.set_static(&axles(boxes)).unwrap();
            b.exchange_limits(&axles(boxes), base, CONTACT_STIFFNESS)
                .unwrap()
        } else {
            let mut b = SprungBogie::new(self.p, base).unwrap();
            b.set_static(boxes[0]).unwrap();
            b.exchange_limits(boxes[0], base, CONTACT_STIFFNESS)
                .unwrap()
        }
    }

    /// The largest communication step (s) up to 20 ms below which every step of a
    /// geometric scan (ratio 1.1 from 0.1 ms) keeps the run stable: it does not diverge
    /// and its history stays within half the static load.
    fn limit(&self, jacobi: bool) -> f64 {
        let usable = |h: f64| matches!(self.run(jacobi, h), Ok((_, d)) if d < 50.0);
        let mut h = 1e-4;
        while h <= 20e-3 {
            if !usable(h * 1.1) {
                return h;
            }
            h *= 1.1;
        }
        h
    }
}

fn main() {
    let duration: f64 = std::env::args()
        .nth(1)
        .map_or(0.6, |a| a.parse().expect("a duration in seconds"));
    let limits = std::env::args().any(|a| a == "--limits");
    // `--at K1 C1 h`: one case, both vehicles and masters (N/m, N s/m, s).
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--at") {
        let x: Vec<f64> = args[i + 1..i + 4]
            .iter()
            .map(|a| a.parse().unwrap())
            .collect();
        for half_car in [false, true] {
            let case = Case::new(half_car, x[0], x[1], duration);
            let e = case.estimate();
            for jacobi in [false, true] {
                println!(
                    "half_car {half_car} jacobi {jacobi} h {} ms: {:?} (estimated limit {:.2} ms)",
                    x[2] * 1e3,
                    case.run(jacobi, x[2]),
                    if jacobi { e.jacobi } else { e.sequential } * 1e3
                );
            }
        }
        return;
    }
    let d = roll_plane(&Scenario::table_4_4_flat());
    for half_car in [false, true] {
        let name = if half_car {
            "half-car bogie"
        } else {
            "roll-plane vehicle"
        };
        if limits {
            println!("{name}: largest stable communication step (ms), {duration} s");
            println!(
                "| K_1 (MN/m) | C_1 (kN s/m) | sequential: measured / estimated | Jacobi: measured / estimated |"
            );
            println!("|---|---|---|---|");
            for k1 in [d.primary_stiffness, 1e8, 7.88e8, 1e10] {
                for c1 in [0.0, d.primary_damping, 1e6] {
                    let case = Case::new(half_car, k1, c1, duration);
                    let e = case.estimate();
                    println!(
                        "| {} | {} | {:.2} / {:.2} | {:.2} / {:.2} |",
                        k1 / 1e6,
                        c1 / 1e3,
                        case.limit(false) * 1e3,
                        e.sequential * 1e3,
                        case.limit(true) * 1e3,
                        e.jacobi * 1e3
                    );
                }
            }
            continue;
        }
        let case = Case::new(half_car, d.primary_stiffness, d.primary_damping, duration);
        let rp = peaks(&case.reference);
        let _ = &case.mono;
        println!(
            "{name}: monolithic peaks {} kN",
            (0..case.wheelsets())
                .flat_map(|k| rp[k].map(|x| format!("{:.2}", x / 1e3)))
                .collect::<Vec<_>>()
                .join(" / ")
        );
        println!("| master | step | peak errors (%) | history / static load (%) |");
        println!("|---|---|---|---|");
        for jacobi in [false, true] {
            let master = if jacobi { "Jacobi" } else { "sequential" };
            for h in [0.1e-3, 0.2e-3, 0.5e-3, 1e-3, 2e-3, 3e-3, 4e-3, 6e-3] {
                match case.run(jacobi, h) {
                    Err(e) => println!(
                        "| {master} | {:.1} ms | unstable {} | |",
                        h * 1e3,
                        &e[..e.len().min(80)]
                    ),
                    Ok((errs, diff)) => println!(
                        "| {master} | {:.1} ms | {} | {diff:.2} |",
                        h * 1e3,
                        errs.iter()
                            .map(|e| format!("{e:+.2}"))
                            .collect::<Vec<_>>()
                            .join(" / ")
                    ),
                }
            }
        }
    }
}
