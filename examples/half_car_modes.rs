//! The half-car bogie of table 4.4 (1.8 m wheelbase, side frames of 180 kg m^2 in
//! pitch): its natural frequencies from the symmetric eigenproblem against the general
//! eigenvalues of M^-1 K, its static wheel loads, and the roll-plane vehicle's elastic
//! modes (with the car body's mass on its bolster) among them.
//!
//!     cargo run --release --example half_car_modes

use std::f64::consts::TAU;
use wheelflat::sim::{Scenario, VehicleSpec};
use wheelflat::vehicle::{HALF_CAR_DOFS, HalfCarMatrix, HalfCarParams};

fn main() {
    let VehicleSpec::RollPlane(rp) = Scenario::table_4_4().vehicle else {
        unreachable!("table 4.4 has the roll-plane vehicle")
    };
    let p = HalfCarParams::from_roll_plane(&rp, 1.8, 180.0);
    let minv = HalfCarMatrix::from_diagonal(&p.mass_diagonal().map(|m| 1.0 / m));
    let mut general: Vec<f64> = (minv * p.stiffness_matrix())
        .complex_eigenvalues()
        .iter()
        .map(|c| c.re.max(0.0).sqrt())
        .collect();
    general.sort_by(f64::total_cmp);
    let mut massive = rp;
    massive.bolster_mass += massive.carbody_mass;
    massive.carbody_mass = 0.0;
    let roll_plane = massive.natural_frequencies();
    println!("mode  symmetric (Hz)  eig(M^-1 K) (Hz)  roll-plane vehicle (Hz)");
    for (i, w) in p.natural_frequencies().iter().enumerate() {
        let same = roll_plane
            .iter()
            .find(|&&x| x > 1e-6 && (x - w).abs() <= 1e-9 * w)
            .map_or(String::new(), |x| format!("{:.4}", x / TAU));
        println!(
            "{:4}  {:14.4}  {:16.4}  {same}",
            i + 1,
            w / TAU,
            general[i] / TAU
        );
    }
    assert_eq!(general.len(), HALF_CAR_DOFS);
    let d = p.static_state([[0.0; 2]; 2]).expect("a static state");
    let f = p.static_contact_forces(&d);
    println!(
        "static wheel loads (kN): {:.3} {:.3} / {:.3} {:.3}; a quarter of the weight: {:.3}",
        f[0][0] / 1e3,
        f[0][1] / 1e3,
        f[1][0] / 1e3,
        f[1][1] / 1e3,
        p.static_wheel_load() / 1e3
    );
    println!(
        "critical step {:.2} us, default step {:.2} us",
        p.critical_time_step() * 1e6,
        p.default_dt() * 1e6
    );
}
