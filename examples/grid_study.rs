//! Grid-convergence study of the peak impact force for the reference case
//! (table 4.4, 70 km/h, 100 mm x 1.5 mm haversine flat on the left wheel, 30 spans):
//! n = 1, 2, 3, 4, 6, 8 nodes per span, each at dt = 0.5 dt_c and dt = 0.25 dt_c, plus
//! the seed's own grid (n = 2, dt = 45 us). Prints a markdown table. The rail between
//! nodes as a beam (the default); `BETWEEN_NODES=linear` for the thesis' (3.23).
use wheelflat::sim::{Scenario, Simulation};
use wheelflat::track::RailBetweenNodes;

fn scenario() -> Scenario {
    let mut s = Scenario::table_4_4_flat();
    if std::env::var("BETWEEN_NODES").as_deref() == Ok("linear") {
        s.set_between_nodes(RailBetweenNodes::Linear);
    }
    s
}

fn peak(n: usize, dt: f64) -> (f64, f64, f64) {
    let mut s = scenario();
    s.set_nodes_per_span(n);
    s.dt = dt;
    let mut sim = Simulation::new(&s).unwrap();
    let mut first = 0.0f64;
    // First impact: the flat reaches the contact after a quarter turn (~0.038 s);
    // the first impact is over by 0.1 s.
    sim.run(0.1, |x| first = first.max(x.contact[0].force))
        .unwrap();
    sim.run(0.7, |_| {}).unwrap();
    (first, sim.max_force()[0], sim.max_force()[1])
}

fn main() {
    println!(
        "| n | dx (mm) | dt (us) | first impact, left (kN) | max over 0.8 s, left (kN) | max, right (kN) |"
    );
    println!("|---|---|---|---|---|---|");
    let (a, b, c) = peak(2, 45e-6);
    #[rustfmt::skip]
    println!("| 2 (seed grid) | 342.5 | 45.00 | {:.1} | {:.1} | {:.1} |", a / 1e3, b / 1e3, c / 1e3);
    let ns: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("n"))
        .collect();
    let ns = if ns.is_empty() {
        vec![1, 2, 3, 4, 6, 8, 12, 16, 24]
    } else {
        ns
    };
    for n in ns {
        let mut s = scenario();
        s.set_nodes_per_span(n);
        let wheelflat::sim::TrackSpec::Discrete(t) = s.track else {
            unreachable!()
        };
        let dtc = t.critical_time_step().0;
        let fr: &[f64] = if std::env::var("DT_FRACTIONS").is_ok() {
            &[0.9, 0.45]
        } else if n <= 8 {
            &[0.5, 0.25]
        } else {
            &[0.5]
        };
        for &f in fr {
            let (a, b, c) = peak(n, f * dtc);
            println!(
                "| {n} | {:.1} | {:.2} | {:.1} | {:.1} | {:.1} |",
                685.0 / n as f64,
                f * dtc * 1e6,
                a / 1e3,
                b / 1e3,
                c / 1e3
            );
        }
    }
}
