//! Engine benchmarks: cost per simulated second of the reference case
//! (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left wheel, 30 spans), at the
//! seed's grid (n = 2, dt = 45 us) and at the converged defaults; scaling with spans
//! and n; contact evaluation with and without a flat in the patch.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};

#[path = "../tools/ffi_instance.rs"]
mod ffi_instance;
use std::hint::black_box;
use wheelflat::contact::ContactLaw;
use wheelflat::sim::{Scenario, Simulation, TrackWindow, TrailingWheelset};
use wheelflat::wheel::{FlatSpec, WheelProfile};

/// Simulated time per benchmark iteration of the scaling and FMU groups (s).
const SIM_TIME: f64 = 0.1;

/// Simulated time per iteration of the reference case (s): five passages of the flat
/// through the patch (at 0.038 s and every 0.154 s after), 6.25 per second against
/// 6.5 in a long run, so that the time per simulated second weighs the flat-in-patch
/// contact as a long run does (a 0.1 s window holds one passage, 10 per second).
const REFERENCE_TIME: f64 = 0.8;

fn run(sim: &Simulation) -> f64 {
    run_for(sim, SIM_TIME)
}

fn run_for(sim: &Simulation, time: f64) -> f64 {
    let mut s = sim.clone();
    let n = (time / s.dt()).round() as u64;
    for _ in 0..n {
        // The sample is kept where step returns it (no copy into black_box).
        black_box(s.step().as_ref().unwrap());
    }
    s.max_force()[0]
}

fn reference(c: &mut Criterion) {
    let mut g = c.benchmark_group("reference_case_per_0.8s");
    g.sample_size(20);
    let mut seed = Scenario::table_4_4_flat();
    seed.set_nodes_per_span(2);
    seed.dt = 45e-6;
    let sim = Simulation::new(&seed).unwrap();
    g.bench_function("seed_grid_n2_dt45us", |b| {
        b.iter(|| run_for(&sim, REFERENCE_TIME))
    });
    // The same case over the first 0.1 s only (one passage of the flat).
    g.bench_function("seed_grid_n2_dt45us_first_0.1s", |b| {
        b.iter(|| run_for(&sim, 0.1))
    });
    let sim = Simulation::new(&Scenario::table_4_4_flat()).unwrap();
    g.sample_size(10);
    g.bench_function("converged_defaults", |b| {
        b.iter(|| run_for(&sim, REFERENCE_TIME))
    });
    g.finish();
}

fn scaling(c: &mut Criterion) {
    let mut g = c.benchmark_group("scaling_per_0.1s");
    g.sample_size(10);
    for spans in [20usize, 30, 60, 120] {
        let mut s = Scenario::table_4_4_flat();
        s.set_nodes_per_span(2);
        s.set_spans(spans);
        s.dt = 40e-6;
        let sim = Simulation::new(&s).unwrap();
        g.bench_with_input(
            BenchmarkId::new("spans_n2_dt40us", spans),
            &sim,
            |b, sim| b.iter(|| run(sim)),
        );
    }
    for n in [1usize, 2, 4, 8] {
        let mut s = Scenario::table_4_4_flat();
        s.set_nodes_per_span(n);
        s.dt = 10e-6;
        let sim = Simulation::new(&s).unwrap();
        g.bench_with_input(BenchmarkId::new("n_30spans_dt10us", n), &sim, |b, sim| {
            b.iter(|| run(sim))
        });
    }
    g.finish();
}

fn contact(c: &mut Criterion) {
    let mut g = c.benchmark_group("contact_evaluation");
    let law = ContactLaw::adaptive(3.3443e10).unwrap();
    let w = WheelProfile::new(0.475, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
    g.bench_function("no_flat_in_patch", |b| {
        b.iter(|| law.evaluate(black_box(&w), black_box(2.0), black_box(1e-4)))
    });
    g.bench_function("flat_in_patch", |b| {
        b.iter(|| law.evaluate(black_box(&w), black_box(0.1), black_box(3e-4)))
    });
    g.finish();
}

/// TrackContact through its C functions, at communication step = dt (set the wheel
/// inputs, read the contact forces, step: what a master does each step), against the
/// engine stepping the same track with the same held wheels.
fn fmu_step(c: &mut Criterion) {
    use wheelflat::fmu::ffi::*;
    use wheelflat::fmu::vars::{TRACK_CONTACT, vr};
    use wheelflat::sim::VehicleSpec;

    let mut g = c.benchmark_group("track_contact_per_0.1s");
    g.sample_size(10);
    // The engine: the default scenario with external wheels held at rest.
    let mut s = Scenario::table_4_4_flat();
    s.vehicle = VehicleSpec::External {
        static_load: [107_664.75; 2],
    };
    let sim = Simulation::new(&s).unwrap();
    let (z, dt) = (sim.wheel_z(), sim.dt());
    let n = (SIM_TIME / dt).round() as u64;
    g.bench_function("engine_step", |b| {
        b.iter(|| {
            let mut e = sim.clone();
            for k in 0..n {
                e.set_wheel_inputs(z, e.rotation()).unwrap();
                // The sample is kept where step returns it (no copy into black_box).
                black_box(e.step().as_ref().unwrap());
                black_box(k);
            }
        })
    });
    // The FMU.
    let (comp, _) = ffi_instance::initialised(
        TRACK_CONTACT.guid,
        // The thesis' fixed track, as the engine's (the FMUs' default is the endless).
        &[(vr::TRACK_WINDOW_AHEAD, 0.0)],
        &[],
    );
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    unsafe {
        assert_eq!(fmi2GetFMUstate(comp, &mut state), 0);
    }
    let inputs = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z, vr::WHEEL_ROTATION];
    let outputs = [vr::CONTACT_LEFT_FORCE, vr::CONTACT_RIGHT_FORCE];
    g.bench_function("fmi2_set_get_dostep", |b| {
        b.iter(|| unsafe {
            assert_eq!(fmi2SetFMUstate(comp, state), 0);
            let mut p = [0.0; 2];
            for k in 0..n {
                let t = k as f64 * dt;
                let u = [z[0], z[1], s.speed * t / s.wheel_radius];
                fmi2SetReal(comp, inputs.as_ptr(), 3, u.as_ptr());
                fmi2GetReal(comp, outputs.as_ptr(), 2, p.as_mut_ptr());
                black_box(p);
                fmi2DoStep(comp, t, dt, 1);
            }
        })
    });
    unsafe {
        fmi2FreeFMUstate(comp, &mut state);
        fmi2FreeInstance(comp);
    }
    g.finish();
}

/// A four-axle wagon's wheelsets behind the leading one (m): two bogies with 1.8 m
/// wheelbases, their centres 10 m apart.
const WAGON: [f64; 3] = [1.8, 10.0, 11.8];

/// The reference flat case on the endless track with `wheelsets` wheelsets of the
/// wagon and window sides `side` (m).
fn endless(wheelsets: usize, side: f64) -> Simulation {
    let mut s = Scenario::table_4_4_flat();
    s.window = Some(TrackWindow {
        ahead: side,
        behind: side,
        ..TrackWindow::DEFAULT
    });
    s.trailing = WAGON[..wheelsets - 1]
        .iter()
        .map(|&offset| TrailingWheelset {
            offset,
            ..Default::default()
        })
        .collect();
    Simulation::new(&s).unwrap()
}

/// Cost per simulated second (one iteration = 1 s) on the endless track: the converged
/// window with 1 to 4 wheelsets, and one wheelset on windows of 8 to 30 m a side (10 m:
/// the FMUs' default).
fn endless_track(c: &mut Criterion) {
    let mut g = c.benchmark_group("endless_track_per_1s");
    g.sample_size(10);
    let side = TrackWindow::CONVERGED.ahead;
    for w in 1..=4 {
        let sim = endless(w, side);
        g.bench_with_input(
            BenchmarkId::new("wheelsets_converged_window", w),
            &sim,
            |b, sim| b.iter(|| run_for(sim, 1.0)),
        );
    }
    // The whole wagon (vehicle.model = wagon): the car body on two half-car bogies over
    // the same four wheelsets.
    let wagon = Simulation::new(&Scenario::table_4_4_wagon()).unwrap();
    g.bench_with_input(
        BenchmarkId::new("wagon_vehicle_converged_window", 4),
        &wagon,
        |b, sim| b.iter(|| run_for(sim, 1.0)),
    );
    for side in [8.0, 10.0, 12.0, 30.0] {
        let sim = endless(1, side);
        g.bench_with_input(
            BenchmarkId::new("one_wheelset_window_side_m", side),
            &sim,
            |b, sim| b.iter(|| run_for(sim, 1.0)),
        );
    }
    // The same through the C boundary: CoupledSystem on the converged window with 1 and 4
    // wheelsets, one fmi2DoStep of solver.step per step (its overhead over the engine).
    for w in [1usize, 4] {
        let comp = coupled_system_on_window(w);
        g.bench_with_input(
            BenchmarkId::new("coupled_system_fmu_wheelsets", w),
            &comp,
            |b, comp| b.iter(|| fmu_run(comp.0, comp.1, comp.2, 1.0)),
        );
    }
    g.finish();
}

/// An initialised CoupledSystem instance on the converged window with `wheelsets`
/// wheelsets (the wagon's), its FMU state there, and its step (s).
fn coupled_system_on_window(
    wheelsets: usize,
) -> (
    wheelflat::fmu::ffi::fmi2Component,
    wheelflat::fmu::ffi::fmi2FMUstate,
    f64,
) {
    use wheelflat::fmu::ffi::*;
    use wheelflat::fmu::vars::{COUPLED_SYSTEM, OFFSET_VRS, vr};
    let mut reals = vec![
        (vr::TRACK_WINDOW_AHEAD, TrackWindow::CONVERGED.ahead),
        (vr::TRACK_WINDOW_BEHIND, TrackWindow::CONVERGED.behind),
    ];
    reals.extend(OFFSET_VRS.iter().copied().zip(WAGON));
    let (comp, dt) = ffi_instance::initialised(
        COUPLED_SYSTEM.guid,
        &reals,
        &[(vr::WHEELSETS, wheelsets as i32)],
    );
    let mut state: fmi2FMUstate = std::ptr::null_mut();
    unsafe {
        assert_eq!(fmi2GetFMUstate(comp, &mut state), 0);
    }
    (comp, state, dt)
}

/// `time` (s) of fmi2DoStep calls of `dt` from the FMU state `state`, the contact
/// forces read after each.
fn fmu_run(
    comp: wheelflat::fmu::ffi::fmi2Component,
    state: wheelflat::fmu::ffi::fmi2FMUstate,
    dt: f64,
    time: f64,
) {
    use wheelflat::fmu::ffi::*;
    use wheelflat::fmu::vars::vr;
    let outputs = [vr::CONTACT_LEFT_FORCE, vr::CONTACT_RIGHT_FORCE];
    unsafe {
        assert_eq!(fmi2SetFMUstate(comp, state), 0);
        let mut p = [0.0; 2];
        for k in 0..(time / dt).round() as u64 {
            fmi2DoStep(comp, k as f64 * dt, dt, 1);
            fmi2GetReal(comp, outputs.as_ptr(), 2, p.as_mut_ptr());
            black_box(p);
        }
    }
}

criterion_group!(
    benches,
    reference,
    scaling,
    contact,
    fmu_step,
    endless_track
);
criterion_main!(benches);
