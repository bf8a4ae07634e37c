//! Cost of issue 27's options on the converged default (table 4.4's reference flat,
//! n = 8, 70 km/h, fixed 30-span track), for instruction counting:
//! `valgrind --tool=callgrind target/release/examples/options_cost OPTION [steps]`,
//! minus the same with 0 steps, divided by the steps. OPTION: `none`, `tensionless`
//! (pads 20 kN, ballast 1.7 kN preloads), `voids` (three hanging sleepers, 0.3 mm, at
//! 8 m), `profile` (a measured left rail, 2 mm dip in a 1,001-point table), `weld`
//! (the dipped weld of rail.defect.*), `roundness` (a 629-point out-of-roundness on the
//! left wheel), `half_car` (the half-car bogie on two wheelsets, endless track),
//! `wagon` (the wagon on four, endless track). Without valgrind it prints the wall
//! time per step.

use std::f64::consts::TAU;
use std::hint::black_box;
use std::sync::Arc;
use std::time::Instant;
use wheelflat::numerics::Table;
use wheelflat::sim::{
    Scenario, Simulation, TrackWindow, TrailingWheelset, VehicleSpec, VoidedSleepers,
};
use wheelflat::track::{RailDefect, SupportLaw, Supports};
use wheelflat::vehicle::{CarrierSpec, HalfCarParams};
use wheelflat::wheel::OutOfRoundness;

fn main() {
    let option = std::env::args().nth(1).unwrap_or_else(|| "none".into());
    let n: u64 = std::env::args()
        .nth(2)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20_000);
    let mut s = Scenario::table_4_4_flat();
    match option.as_str() {
        "none" => {}
        "tensionless" => s.set_supports(Supports {
            law: SupportLaw::Tensionless,
            pad_preload: 20e3,
            ballast_preload: 1.7e3,
        }),
        "voids" => {
            s.voids = Some(VoidedSleepers {
                position: 8.2,
                sleepers: 3,
                gap: 3e-4,
            })
        }
        "profile" => {
            let (x, h): (Vec<f64>, Vec<f64>) = (0..=1000)
                .map(|i| {
                    let x = 0.02 * i as f64;
                    (
                        x,
                        -1e-3 * (1.0 + (TAU * (x - 8.5)).cos()) * f64::from((x - 8.5).abs() < 0.5),
                    )
                })
                .unzip();
            s.rails[0].measured = Some(Arc::new(Table::new(x, h, "profile").unwrap()));
        }
        "weld" => {
            s.rails[0].defect = Some(RailDefect {
                position: 8.5,
                length: 1.0,
                depth: 1e-3,
            })
        }
        "roundness" => {
            let (b, r): (Vec<f64>, Vec<f64>) = (0..629)
                .map(|i| {
                    let b = 0.01 * i as f64;
                    (b, 5e-5 * (8.0 * b).sin())
                })
                .unzip();
            s.roundness[0] = Some(Arc::new(
                OutOfRoundness::new(Table::new(b, r, "w").unwrap(), "w").unwrap(),
            ));
        }
        "half_car" => {
            let VehicleSpec::RollPlane(p) = s.vehicle else {
                unreachable!()
            };
            s.vehicle = VehicleSpec::Carrier(CarrierSpec::HalfCar(HalfCarParams::from_roll_plane(
                &p, 1.8, 180.0,
            )));
            s.trailing = vec![TrailingWheelset {
                offset: 1.8,
                ..Default::default()
            }];
            s.window = Some(TrackWindow::CONVERGED);
        }
        "wagon" => s = Scenario::table_4_4_wagon(),
        other => panic!("unknown option {other}"),
    }
    let mut sim = Simulation::new(&s).unwrap();
    let t0 = Instant::now();
    for _ in 0..n {
        black_box(sim.step().unwrap());
    }
    if n > 0 {
        println!(
            "{option}: {:.1} ns per step",
            t0.elapsed().as_secs_f64() * 1e9 / n as f64
        );
    }
}
