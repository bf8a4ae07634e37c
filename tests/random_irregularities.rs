//! Random rail profiles and roughness in the coupled engine (issue 44): the endless
//! track reads the drawn profile where its window is, the ramp starts the run at rest,
//! the same seed draws the same run and another seed another, and the roughness reaches
//! the contact through its filter.

use std::sync::Arc;
use wheelflat::contact::{RoughnessSpectrum, hertz_half_length};
use wheelflat::sim::{RandomIrregularities, Roughness, Scenario, Simulation, TrackWindow};
use wheelflat::track::{ProfileSpec, TrackSpectrum};

/// Table 4.4 with perfect wheels at 70 km/h from 35 m on the endless track, FRA class 4
/// (1.5 to 30 m).
fn case(seed: u64) -> Scenario {
    let mut s = Scenario::table_4_4();
    s.speed = 70.0 / 3.6;
    s.start_position = 35.0;
    s.window = Some(TrackWindow::DEFAULT);
    s.random = RandomIrregularities {
        profile: Some(ProfileSpec {
            spectrum: TrackSpectrum::Fra(4),
            seed,
            band: (1.5, 30.0),
            cross_level: false,
            ramp: 2.0,
        }),
        roughness: None,
    };
    s
}

/// The left wheel's contact forces and the overlap's shift under it, over `duration`.
fn run(s: &Scenario, duration: f64) -> (Vec<f64>, Vec<[f64; 2]>, f64) {
    let mut sim = Simulation::new(s).unwrap();
    let (mut f, mut h) = (Vec::new(), Vec::new());
    while sim.time() < duration {
        f.push(sim.step().unwrap().contact[0].force);
        h.push(sim.irregularity(0));
    }
    (f, h, sim.static_load()[0])
}

#[test]
fn the_endless_track_reads_the_drawn_profile_where_its_window_is() {
    // Two windows of different lengths and a fixed 120-span track: the same rail under
    // the wheel at every step, bit for bit, and the same forces to the window's
    // accuracy (0.6 % of the static load, docs/VALIDATION.md).
    let mut fixed = case(7);
    fixed.window = None;
    fixed.set_spans(120);
    let mut short = fixed.clone();
    short.window = Some(TrackWindow::DEFAULT);
    let mut long = fixed.clone();
    long.window = Some(TrackWindow::CONVERGED);
    let (ff, hf, load) = run(&fixed, 0.3);
    let (fs, hs, _) = run(&short, 0.3);
    let (fl, hl, _) = run(&long, 0.3);
    assert_eq!(hf, hs);
    assert_eq!(hf, hl);
    // The profile is felt: it moved the overlap by millimetres over the run.
    let span = hf.iter().map(|h| h[0]).fold(0.0f64, |m, h| m.max(h.abs()));
    assert!(span > 1e-3, "{span}");
    for other in [&fs, &fl] {
        let worst = ff
            .iter()
            .zip(other)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(worst < 0.006 * load, "{worst}");
    }
}

#[test]
fn the_ramp_starts_the_run_at_rest_and_seeds_draw_their_own_rails() {
    // Over the first 2 m (0.1 s at 70 km/h) the profile grows from nothing: the first
    // step is the ideal rail's, bit for bit.
    let ideal = {
        let mut s = case(1);
        s.random = RandomIrregularities::default();
        s
    };
    let (fi, _, load) = run(&ideal, 0.2);
    let (f1, h1, _) = run(&case(1), 0.2);
    let at_rest = Simulation::new(&case(1)).unwrap();
    assert_eq!(at_rest.irregularity(0), [0.0, 0.0]);
    let (f1b, _, _) = run(&case(1), 0.2);
    let (f2, h2, _) = run(&case(2), 0.2);
    // The first step's travel, 1e-5 s, lifts the rail by less than a nanometre.
    assert!(h1[0].iter().all(|h| h.abs() < 1e-9), "{:?}", h1[0]);
    assert!((fi[0] - f1[0]).abs() < 1e-6 * load);
    assert_eq!(f1, f1b);
    assert_ne!(h1, h2);
    // Beyond the ramp the seeds' rails differ and move the force.
    let differ = f1
        .iter()
        .zip(&f2)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(differ > 0.01 * load, "{differ}");
    let (ls, rs) = (h1.iter().map(|h| h[0]), h1.iter().map(|h| h[1]));
    assert!(
        ls.zip(rs).any(|(l, r)| l != r),
        "the rails are drawn independently"
    );
}

#[test]
fn rail_roughness_reaches_the_contact_through_the_patch() {
    // The ISO 3095 limit on both rails, no profile: at every step the overlap shifts by
    // the drawn roughness averaged over the Hertz patch under the static load, each
    // term `a cos(k x + phi)` seen as `a sin(k a_p) / (k a_p) cos(k x + phi)`.
    let iso = Arc::new(RoughnessSpectrum::iso3095());
    let mut s = case(1);
    s.random = RandomIrregularities {
        profile: None,
        roughness: Some(Roughness {
            rail: Some(iso.clone()),
            wheel: None,
            seed: 3,
            patch_length: 0.0,
        }),
    };
    let mut sim = Simulation::new(&s).unwrap();
    // Without a drawn profile the roughness is there from the start, where the static
    // start stands the wheels on it: the first step's force is the static load's, to
    // the roughness's own change over one step's travel (0.3 mm).
    let static_load = sim.static_load()[0];
    let first = Simulation::new(&s).unwrap().step().unwrap().contact[0].force;
    assert!(
        (first - static_load).abs() < 0.01 * static_load,
        "{first} {static_load}"
    );
    let half = hertz_half_length(s.wheel_radius, sim.static_load()[0], s.hertz_coefficient);
    assert!((0.004..0.01).contains(&half), "{half}");
    let raw = iso.rail(3, 0, 0.0);
    let (mut worst, mut rms) = (0.0f64, 0.0);
    let n = 2000;
    for _ in 0..n {
        sim.step().unwrap();
        let x = sim.position();
        let expected: f64 = raw
            .terms()
            .map(|(k, a, p)| a * (k * half).sin() / (k * half) * (k * x + p).cos())
            .sum();
        let h = sim.irregularity(0)[0];
        worst = worst.max((h - expected).abs());
        rms += h * h / n as f64;
    }
    assert!(worst < 1e-12, "{worst}");
    // Micrometres: the limit's 11.7 um RMS, less what the patch takes out.
    let rms = rms.sqrt();
    assert!(rms > 1e-6 && rms < iso.rms(), "{rms}");
}
