//! Engine benchmarks: cost per simulated second of the reference case
//! (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left wheel, 30 spans), at the
//! seed's grid (n = 2, dt = 45 us) and at the converged defaults; scaling with spans
//! and n; contact evaluation with and without a flat in the patch.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use wheelflat::contact::ContactLaw;
use wheelflat::params::Scenario;
use wheelflat::profile::{FlatSpec, WheelProfile};
use wheelflat::solver::Simulation;

/// Simulated time per benchmark iteration (s); figures are scaled to 1 s.
const SIM_TIME: f64 = 0.1;

fn run(sim: &Simulation) -> f64 {
    let mut s = sim.clone();
    let n = (SIM_TIME / s.dt()).round() as u64;
    for _ in 0..n {
        black_box(s.step().unwrap());
    }
    s.max_force()[0]
}

fn reference(c: &mut Criterion) {
    let mut g = c.benchmark_group("reference_case_per_0.1s");
    g.sample_size(20);
    let mut seed = Scenario::table_4_4_flat();
    seed.set_nodes_per_span(2);
    seed.dt = 45e-6;
    let sim = Simulation::new(&seed).unwrap();
    g.bench_function("seed_grid_n2_dt45us", |b| b.iter(|| run(&sim)));
    let sim = Simulation::new(&Scenario::table_4_4_flat()).unwrap();
    g.bench_function("converged_defaults", |b| b.iter(|| run(&sim)));
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

criterion_group!(benches, reference, scaling, contact);
criterion_main!(benches);
