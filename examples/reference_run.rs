//! Runs the reference case (table 4.4, 70 km/h, 100 mm x 1.5 mm flat) for 0.5 s at the
//! seed grid (n = 2, dt = 45 us) or, with `defaults`, at the converged defaults.
fn main() {
    let mut s = wheelflat::sim::Scenario::table_4_4_flat();
    if std::env::args().nth(1).as_deref() != Some("defaults") {
        s.set_nodes_per_span(2);
        s.dt = 45e-6;
    }
    let mut sim = wheelflat::sim::Simulation::new(&s).unwrap();
    let t0 = std::time::Instant::now();
    sim.run(0.5, |_| {}).unwrap();
    let el = t0.elapsed().as_secs_f64();
    println!(
        "{} steps, {:.2} ms per simulated second, peak {:.1} kN",
        sim.steps(),
        el / 0.5 * 1e3,
        sim.max_force()[0] / 1e3
    );
}
