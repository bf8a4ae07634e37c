//! Bit-exact hashes of every sample of the three reference runs (the check that a
//! restructure or a speed change leaves every result unchanged): the seed grid through
//! 0.8 s, the converged defaults through 0.3 s, and three flats (two haversine on the
//! left wheel, a chord on the right) through 0.3 s. Each line is an FNV-1a hash over the
//! bits of every field of every sample (time, position, rotation, wheel and rail
//! displacements, every field of both contact states).
//!
//! Each run twice: with the rail between nodes as a beam (the default since issue 27)
//! and as the thesis' linear interpolation (3.23) (`-linear`), which gives the bits
//! every run gave before issue 27 (ca87e4a538843d11, fd1aed06ca0dd1f1,
//! e173932efd4e3ca6).
//!
//! With them, the wagon on the default window through 0.1 s (`wagon`, issue 42).
//!
//! `cargo run --release --example sample_hash [seed|defaults|flats][-linear]|wagon`
//! (all seven without an argument; one of them for counting its instructions under
//! callgrind).

use wheelflat::sim::{Sample, Scenario, Simulation};
use wheelflat::track::RailBetweenNodes;
use wheelflat::wheel::FlatSpec;

/// FNV-1a over the bits of `f64`s.
struct Fnv(u64);

impl Fnv {
    fn add(&mut self, x: f64) {
        for b in x.to_bits().to_le_bytes() {
            self.0 ^= b as u64;
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn sample(&mut self, s: &Sample) {
        for x in [s.time, s.position, s.rotation] {
            self.add(x);
        }
        for i in 0..2 {
            let c = &s.contact[i];
            for x in [
                s.wheel_z[i],
                s.rail_z[i],
                c.force,
                c.overlap,
                c.front_angle,
                c.rear_angle,
                c.length,
                c.intervals as f64,
            ] {
                self.add(x);
            }
        }
    }
}

/// The hash of every sample of `s` over `duration` (s), and the steps taken.
fn hash_run(s: &Scenario, duration: f64) -> (u64, u64) {
    let mut sim = Simulation::new(s).unwrap();
    let mut h = Fnv(0xcbf2_9ce4_8422_2325);
    h.sample(&sim.sample());
    let n = (duration / sim.dt()).round() as u64;
    for _ in 0..n {
        h.sample(&sim.step().unwrap());
    }
    (h.0, n)
}

/// The reference runs `only` names (all seven with `None`), in order: their names, the
/// sample hashes and the steps taken (`tests/reference_hashes.rs` holds them to the
/// recorded bits).
pub fn hashes(only: Option<&str>) -> Vec<(String, u64, u64)> {
    let mut out = Vec::new();
    let mut run = |key: &str, name: &str, s: &Scenario, duration: f64| {
        if only.is_none_or(|o| o == key) {
            let (h, n) = hash_run(s, duration);
            out.push((name.to_string(), h, n));
        }
        let key = format!("{key}-linear");
        if only.is_none_or(|o| o == key) {
            let mut linear = s.clone();
            linear.set_between_nodes(RailBetweenNodes::Linear);
            let (h, n) = hash_run(&linear, duration);
            out.push((format!("{name}, linear (3.23)"), h, n));
        }
    };
    let mut seed = Scenario::table_4_4_flat();
    seed.set_nodes_per_span(2);
    seed.dt = 45e-6;
    run("seed", "seed grid (n = 2, dt = 45 us), 0.8 s", &seed, 0.8);
    let defaults = Scenario::table_4_4_flat();
    run("defaults", "converged defaults, 0.3 s", &defaults, 0.3);
    let mut flats = Scenario::table_4_4_flat();
    // As the runner's `--flat left:100:1.5:90 --flat left:60:0.8:250
    // --flat right:80:0:120:chord` builds them (mm and degrees).
    let (mm, deg) = (|x: f64| x * 1e-3, |a: f64| a.to_radians());
    flats.flats[0].push(FlatSpec::haversine(mm(100.0), mm(1.5), deg(90.0)));
    flats.flats[0].push(FlatSpec::haversine(mm(60.0), mm(0.8), deg(250.0)));
    flats.flats[1].push(FlatSpec::chord(mm(80.0), deg(120.0)));
    run("flats", "three more flats, 0.3 s", &flats, 0.3);
    // The wagon on the default window (issue 42: the work its wheelsets share is
    // restructured for speed, its results not): the leading wheelset's samples.
    if only.is_none_or(|o| o == "wagon") {
        let mut wagon = Scenario::table_4_4_wagon();
        wagon.window = Some(wheelflat::sim::TrackWindow::DEFAULT);
        let (h, n) = hash_run(&wagon, 0.1);
        out.push(("the wagon, default window, 0.1 s".to_string(), h, n));
    }
    out
}

#[allow(dead_code)]
fn main() {
    let only = std::env::args().nth(1);
    for (name, h, n) in hashes(only.as_deref()) {
        println!("{name}: {n} steps, sample hash {h:016x}");
    }
}
