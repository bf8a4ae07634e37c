//! Prints the computed critical time step for the table 4.1 track at n = 1..5, 10
//! (compare with the seed's table 4.2).
fn main() {
    let s = wheelflat::sim::Scenario::table_4_1();
    let wheelflat::sim::TrackSpec::Discrete(mut t) = s.track else {
        unreachable!()
    };
    for n in [1usize, 2, 3, 4, 5, 8, 10] {
        t.nodes_per_span = n;
        let (dt, what) = t.critical_time_step();
        println!("| {n} | {:.1} | {what} |", dt * 1e6);
    }
}
