//! Several wheelsets on one track, the endless track and a varying speed, against
//! independent references: the linear track's superposition, a 600-span fixed track,
//! the axle's rolling without slip and the static equilibrium at standstill.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use wheelflat::sim::{Scenario, Simulation, TrackState, TrackWindow, TrailingWheelset, kmh};

fn trailing(offset: f64) -> TrailingWheelset {
    TrailingWheelset {
        offset,
        ..Default::default()
    }
}

fn rails(sim: &Simulation) -> Vec<f64> {
    let TrackState::Discrete(t) = sim.track() else {
        unreachable!()
    };
    let mut v = t.rail_z(0);
    v.extend(t.rail_z(1));
    v.extend(t.sleeper_z());
    v
}

#[test]
fn static_deflection_under_a_wagon_is_the_sum_of_each_wheelsets() {
    // Four wheelsets of a wagon (axles 1.8 m apart in each bogie, bogie centres 10 m
    // apart) on a fixed 60-span track: the track is linear, so its static deflection is
    // the sum of each wheelset's alone (each at its place, with the same static load).
    let offsets = [1.8, 10.0, 11.8];
    let mut wagon = Scenario::table_4_4();
    wagon.set_spans(60);
    wagon.start_position = 40.0 * 0.685 + 0.3;
    wagon.trailing = offsets.iter().map(|&d| trailing(d)).collect();
    let all = rails(&Simulation::new(&wagon).unwrap());
    let mut sum = vec![0.0; all.len()];
    for d in [0.0, 1.8, 10.0, 11.8] {
        let mut one = wagon.clone();
        one.trailing.clear();
        one.start_position -= d;
        for (s, x) in sum.iter_mut().zip(rails(&Simulation::new(&one).unwrap())) {
            *s += x;
        }
    }
    let scale = all.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let err = all
        .iter()
        .zip(&sum)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(scale > 1e-3, "{scale}");
    assert!(
        err <= 1e-9 * scale,
        "superposition error {err:e} of {scale:e}"
    );
}

/// Left-wheel force histories (N) of every wheelset over `duration` (s).
fn histories(s: &Scenario, duration: f64) -> Vec<Vec<f64>> {
    let mut sim = Simulation::new(s).unwrap();
    let n = (duration / sim.dt()).round() as usize;
    (0..n)
        .map(|_| {
            sim.step().unwrap();
            sim.wheelsets()
                .iter()
                .map(|w| w.latest().contact[0].force)
                .collect()
        })
        .collect()
}

/// The endless track on its default window against a 600-span fixed track with the
/// wheels started in its middle at the same place relative to the sleepers: peaks
/// within 0.3 %, whole histories within 1 % of the static load.
fn endless_equals_fixed(mut s: Scenario, duration: f64) {
    s.start_position = 10.0 * 0.685;
    let mut fixed = s.clone();
    fixed.set_spans(600);
    fixed.start_position += 290.0 * 0.685;
    s.window = Some(TrackWindow::CONVERGED);
    let load = Simulation::new(&s).unwrap().static_load()[0];
    let (a, b) = (histories(&s, duration), histories(&fixed, duration));
    for k in 0..a[0].len() {
        let peak = |h: &[Vec<f64>]| h.iter().map(|r| r[k]).fold(f64::MIN, f64::max);
        let (pa, pb) = (peak(&a), peak(&b));
        assert!(pb > 1.5 * load, "wheelset {k}: an impact, {pb} N");
        assert!(
            (pa - pb).abs() <= 0.003 * pb,
            "wheelset {k}: peak {pa} N on the window, {pb} N on the fixed track"
        );
        let diff = a
            .iter()
            .zip(&b)
            .fold(0.0f64, |m, (x, y)| m.max((x[k] - y[k]).abs()));
        assert!(
            diff <= 0.01 * load,
            "wheelset {k}: histories differ by {diff} N, static load {load} N"
        );
    }
}

#[test]
fn endless_track_equals_a_long_fixed_track_for_the_reference_flat() {
    endless_equals_fixed(Scenario::table_4_4_flat(), 0.6);
}

#[test]
fn endless_track_equals_a_long_fixed_track_for_a_bogie_with_a_flat_in_front() {
    let mut s = Scenario::table_4_4_flat();
    s.trailing.push(trailing(1.8));
    endless_equals_fixed(s, 0.6);
}

/// The FMUs' default track (issue 29): the endless track on `TrackWindow::DEFAULT`
/// (10 m a side), against the 600-span fixed track, over the 0.95 s that the thesis'
/// fixed 30-span track lasts from the FMUs' default start (two spans from its end).
/// Measured (`examples/window_study.rs`): the window's peak +0.000 %, its history 1.60 %
/// of the static load; the 30-span track's -0.018 % and 20.8 % (the wheel starts near
/// one fixed end and runs to the other). It costs no more: 31 spans against 30, 5,877
/// against 5,850 instructions a step (callgrind, `wagon_step_cost engine 1 N 10|0`).
#[test]
fn the_default_window_is_closer_to_a_long_track_than_the_fixed_track_it_replaces() {
    let base = Scenario::table_4_4_flat();
    let mut long = base.clone();
    long.set_spans(600);
    long.start_position += 290.0 * 0.685;
    let mut window = base.clone();
    window.window = Some(TrackWindow::DEFAULT);
    let load = Simulation::new(&base).unwrap().static_load()[0];
    let reference = histories(&long, 0.95);
    let errors = |s: &Scenario| {
        let h = histories(s, 0.95);
        let peak = |h: &[Vec<f64>]| h.iter().map(|r| r[0]).fold(f64::MIN, f64::max);
        let diff = h
            .iter()
            .zip(&reference)
            .fold(0.0f64, |m, (x, y)| m.max((x[0] - y[0]).abs()));
        ((peak(&h) / peak(&reference) - 1.0).abs(), diff / load)
    };
    let (peak, history) = errors(&window);
    assert!(peak < 5e-5, "default window: peak off by {peak}");
    assert!(history < 0.02, "default window: history off by {history}");
    let (peak, history) = errors(&base);
    assert!(peak > 1e-4, "fixed 30 spans: peak off by {peak}");
    assert!(history > 0.15, "fixed 30 spans: history off by {history}");
    let spans = |s: &Scenario| Simulation::new(s).unwrap().rail_nodes() / 2 / 8;
    assert!(spans(&window) <= spans(&base) + 1);
}

/// Exact window ends (issue 29, `Track::set_exact_ends`): the reference flat case on a
/// 4 m a side window whose ends remember the whole run equals the 600-span fixed track
/// through the impact (at 0.04 s) and its waves' return from the plain window's ends;
/// the same window with fixed ends is off by a tenth of the static load. Measured:
/// 0.010 % and 9.2 % of the static load; what remains is the static start's (the
/// kernels' sum over the memory is the exterior's static stiffness to about that, so
/// the ends settle by a few newtons' worth from the first step).
#[test]
fn exact_window_ends_equal_a_long_fixed_track_while_they_remember() {
    let mut s = Scenario::table_4_4_flat();
    s.start_position = 10.0 * 0.685;
    let mut long = s.clone();
    long.set_spans(600);
    long.start_position += 290.0 * 0.685;
    let duration = 0.07;
    let load = Simulation::new(&s).unwrap().static_load()[0];
    let reference = histories(&long, duration);
    let error = |memory: f64| {
        let mut w = s.clone();
        w.window = Some(TrackWindow {
            ahead: 4.0,
            behind: 4.0,
            exact_memory: memory,
            ..TrackWindow::DEFAULT
        });
        let h = histories(&w, duration);
        h.iter()
            .zip(&reference)
            .fold(0.0f64, |m, (x, y)| m.max((x[0] - y[0]).abs()))
            / load
    };
    // The kernel fades out over the memory's second half: twice the run.
    let (plain, exact) = (error(0.0), error(2.0 * duration));
    assert!(plain > 0.05, "plain 4 m window: {plain}");
    assert!(exact < 1e-3, "exact 4 m window: {exact}");
}

#[test]
fn the_rear_wheelset_feels_the_front_wheelsets_impact_through_the_rails() {
    // Two wheelsets 1.8 m apart on shared rails, the flat on the front one: the rear
    // wheel's force swings far from its static load (issue 15: 82 to 187 kN), which
    // separate tracks could never show.
    let mut s = Scenario::table_4_4_flat();
    s.trailing.push(trailing(1.8));
    s.window = Some(TrackWindow::CONVERGED);
    let h = histories(&s, 0.6);
    let rear_max = h.iter().map(|r| r[1]).fold(f64::MIN, f64::max);
    let rear_min = h.iter().map(|r| r[1]).fold(f64::MAX, f64::min);
    let load = 107.7e3;
    assert!(
        rear_max > 1.5 * load && rear_min < 0.85 * load,
        "{rear_min} {rear_max}"
    );
}

#[test]
fn an_endless_track_runs_past_any_fixed_length_and_positions_count_along_the_line() {
    let mut s = Scenario::table_4_4();
    s.window = Some(TrackWindow::CONVERGED);
    s.trailing.push(trailing(1.8));
    let mut sim = Simulation::new(&s).unwrap();
    let spans = sim.rail_nodes() / 2 / 8;
    // 3 s at 70 km/h: 58 m, far past the window's 63 spans (43 m); the last second's
    // mean force per wheelset.
    sim.run(2.0, |_| {}).unwrap();
    let mut mean = [0.0; 2];
    let n = (1.0 / sim.dt()).round() as usize;
    for _ in 0..n {
        sim.step().unwrap();
        for (k, m) in mean.iter_mut().enumerate() {
            *m += sim.wheelsets().get(k).unwrap().latest().contact[0].force / n as f64;
        }
    }
    let x = sim.position();
    let expected = s.start_position + s.speed * sim.time();
    assert!((x - expected).abs() < 1e-9, "{x} {expected}");
    assert!(x > spans as f64 * 0.685 + 10.0);
    let rear = sim.sample_of(1).unwrap();
    assert!((rear.position - (x - 1.8)).abs() < 1e-9);
    // Perfect wheels: on average over 28 sleeper passings each wheel carries its
    // static load.
    for (k, m) in mean.iter().enumerate() {
        assert!(
            (m / sim.static_load()[0] - 1.0).abs() < 0.002,
            "wheelset {k}: {m}"
        );
    }
    assert!(sim.time_at_track_end().is_none());
}

/// Impacts of a run whose speed `speed(t)` is set every step: for each pass of the
/// flat's centre through the contact (rotation = pi/2 mod 2 pi), the time, the speed,
/// the time of the largest force within a quarter turn and that force.
fn impacts(sim: &mut Simulation, speed: impl Fn(f64) -> f64, duration: f64) -> Vec<[f64; 4]> {
    let mut out = Vec::new();
    let mut current: Option<[f64; 4]> = None;
    let phase = |g: f64| (g - FRAC_PI_2 + PI).rem_euclid(TAU) - PI;
    let mut last = phase(sim.rotation());
    for _ in 0..(duration / sim.dt()).round() as u64 {
        sim.set_speed(speed(sim.time())).unwrap();
        let s = sim.step().unwrap();
        let p = phase(s.rotation);
        if p.abs() < 0.25 * PI {
            let c = current.get_or_insert([f64::NAN, 0.0, 0.0, 0.0]);
            if last < 0.0 && p >= 0.0 {
                (c[0], c[1]) = (s.time, sim.speed());
            }
            if s.contact[0].force > c[3] {
                (c[2], c[3]) = (s.time, s.contact[0].force);
            }
        } else if let Some(c) = current.take()
            && c[0].is_finite()
        {
            out.push(c);
        }
        last = p;
    }
    out
}

#[test]
fn a_braking_run_hits_where_the_rolling_axle_puts_the_flat_and_stops() {
    // Braking at 1 m/s^2 from 100 km/h for 4 s, then (sped up) at 10 m/s^2 to
    // standstill: every impact peaks within 2 ms of the flat's centre reaching the
    // contact, the rotation is the travelled distance over the radius, and at
    // standstill the wheel rests on its static load.
    let mut s = Scenario::table_4_4_flat();
    s.window = Some(TrackWindow::CONVERGED);
    let v0 = kmh(100.0);
    s.speed = v0;
    let mut sim = Simulation::new(&s).unwrap();
    let speed = |t: f64| {
        if t < 4.0 {
            v0 - t
        } else {
            (v0 - 4.0 - 10.0 * (t - 4.0)).max(0.0)
        }
    };
    let hits = impacts(&mut sim, speed, 7.0);
    let turns = (sim.position() - s.start_position) / (TAU * s.wheel_radius);
    assert!(
        (sim.rotation() - TAU * turns).abs() < 1e-6,
        "rotation {} for {turns} turns",
        sim.rotation()
    );
    // Every turn of the flat brings an impact, as many as the turns passed.
    let passes = ((sim.rotation() - FRAC_PI_2) / TAU).floor() as usize + 1;
    assert!(
        hits.len() + 1 >= passes && hits.len() <= passes,
        "{} {passes}",
        hits.len()
    );
    for h in &hits {
        assert!(
            (h[2] - h[0]).abs() < 2e-3,
            "impact at {} s peaks at {} s",
            h[0],
            h[2]
        );
        assert!(h[3] > 1.3 * sim.static_load()[0], "{h:?}");
    }
    // Impacts weaken as the train slows: the first second's against the last's.
    let fast = hits
        .iter()
        .filter(|h| h[1] > kmh(95.0))
        .map(|h| h[3])
        .fold(0.0, f64::max);
    let slow = hits
        .iter()
        .filter(|h| h[1] < kmh(60.0))
        .map(|h| h[3])
        .fold(0.0, f64::max);
    assert!(fast > 1.2 * slow && slow > 0.0, "{fast} {slow}");
    assert_eq!(sim.speed(), 0.0);
    let x = sim.position();
    sim.run(0.5, |_| {}).unwrap();
    assert_eq!(sim.position(), x);
    let f = sim.sample().contact[0].force;
    assert!((f / sim.static_load()[0] - 1.0).abs() < 0.01, "{f}");
}

#[test]
fn a_constant_speed_set_every_step_changes_no_bit() {
    let s = Scenario::table_4_4_flat();
    let mut a = Simulation::new(&s).unwrap();
    let mut b = Simulation::new(&s).unwrap();
    for _ in 0..3000 {
        b.set_speed(s.speed).unwrap();
        assert_eq!(a.step().unwrap(), b.step().unwrap());
    }
}

#[test]
fn bad_wheelset_window_and_speed_values_are_refused_by_name() {
    let name = |s: &Scenario| match Simulation::new(s) {
        Err(wheelflat::Error::Parameter { name, .. }) => name,
        other => panic!("{other:?}"),
    };
    let mut s = Scenario::table_4_4();
    s.trailing = vec![trailing(1.8), trailing(1.0)];
    assert_eq!(name(&s), "wheelset[3].offset");
    s.trailing = vec![trailing(-1.0)];
    assert_eq!(name(&s), "wheelset[2].offset");
    s.trailing = (1..5).map(|k| trailing(k as f64)).collect();
    assert_eq!(name(&s), "wheelsets");
    s.trailing = vec![trailing(30.0)];
    assert_eq!(name(&s), "start_position");
    // A flat of a trailing wheelset is named with its wheelset.
    let mut t = trailing(1.8);
    t.flats[0].push(wheelflat::wheel::FlatSpec::haversine(0.1, 0.05, 0.0));
    s.trailing = vec![t];
    assert!(
        name(&s).starts_with("wheelset[2].flat.left[1]"),
        "{}",
        name(&s)
    );
    s.trailing.clear();
    s.window = Some(TrackWindow {
        ahead: 0.1,
        behind: 20.0,
        ..TrackWindow::DEFAULT
    });
    assert_eq!(name(&s), "track.window.ahead");
    s.window = Some(TrackWindow {
        ahead: 20.0,
        behind: f64::NAN,
        ..TrackWindow::DEFAULT
    });
    assert_eq!(name(&s), "track.window.behind");
    // A window too long for the rail's segments is named by the window (breaker, issue
    // 29: it was blamed on track.spans, which the endless track sets itself); 64 nodes
    // a span allow 1,561 spans, 1,069.285 m (named to the millimetre below).
    s.window = Some(TrackWindow {
        ahead: 1000.0,
        behind: 1000.0,
        ..TrackWindow::DEFAULT
    });
    s.set_nodes_per_span(64);
    match Simulation::new(&s) {
        Err(wheelflat::Error::Parameter { name, allowed, .. }) => {
            assert_eq!(name, "track.window.ahead");
            assert!(
                allowed.contains("track.window.behind <= 1069.284 m"),
                "{allowed}"
            );
        }
        other => panic!("{other:?}"),
    }
    // The longest window it names, to the millimetre below, is accepted and two
    // millimetres more are not (breaker, issue 29: at 0.1 m spacing the named
    // 156.10000000000002 m was itself refused when split 78.05 + 78.05 m).
    if let wheelflat::sim::TrackSpec::Discrete(p) = &mut s.track {
        p.sleeper_spacing = 0.1;
    }
    let dt = s.dt;
    s.dt = 0.0;
    let most = match Simulation::new(&s) {
        Err(wheelflat::Error::Parameter { allowed, .. }) => {
            let at = allowed.find("<= ").unwrap() + 3;
            let v = &allowed[at..];
            v[..v.find(' ').unwrap()].parse::<f64>().unwrap()
        }
        other => panic!("{other:?}"),
    };
    assert_eq!(most, 156.099);
    let side = |sum: f64| {
        Some(TrackWindow {
            ahead: sum - 20.0,
            behind: 20.0,
            ..TrackWindow::DEFAULT
        })
    };
    s.window = side(most);
    Simulation::new(&s).unwrap();
    s.window = side(most + 2e-3);
    assert_eq!(name(&s), "track.window.ahead");
    s.track = Scenario::table_4_4().track;
    s.dt = dt;
    s.window = None;
    s.set_nodes_per_span(8);
    // Exact ends (breaker, issue 29): a memory shorter than a step was taken as none,
    // and a layer, voided sleepers or tensionless supports went with them silently.
    let exact = |m: f64| {
        Some(TrackWindow {
            exact_memory: m,
            ..TrackWindow::DEFAULT
        })
    };
    for m in [1e-7, 5e-4, -0.01, 1.5, f64::NAN] {
        s.window = exact(m);
        assert_eq!(name(&s), "track.window.exact_memory", "{m}");
    }
    s.window = Some(TrackWindow {
        layer: 1.0,
        layer_rate: 300.0,
        exact_memory: 0.01,
        ..TrackWindow::DEFAULT
    });
    assert_eq!(name(&s), "track.window.exact_memory");
    s.window = exact(0.01);
    s.voids = Some(wheelflat::sim::VoidedSleepers {
        position: 6.85,
        sleepers: 3,
        gap: 5e-4,
    });
    assert_eq!(name(&s), "track.window.exact_memory");
    s.voids = None;
    // A moving window needs the fixed rail ends: refused when built, not mid-run.
    s.window = Some(TrackWindow::DEFAULT);
    if let wheelflat::sim::TrackSpec::Discrete(p) = &mut s.track {
        p.ends = wheelflat::track::RailEnds::Pinned;
    }
    assert!(matches!(
        Simulation::new(&s),
        Err(wheelflat::Error::Unsupported(_))
    ));
    let mut sim = Simulation::new(&Scenario::table_4_4()).unwrap();
    for v in [-1.0, f64::NAN, 1e3] {
        match sim.set_speed(v) {
            Err(wheelflat::Error::Parameter { name, .. }) => assert_eq!(name, "speed"),
            other => panic!("{v}: {other:?}"),
        }
    }
}

#[test]
fn the_shortest_exact_memory_accepted_holds_where_shorter_ones_grew() {
    // The third breaker (issue 29): memories of 64 to 69 steps were accepted and grew
    // without bound after 0.5 to 1.6 s on a 4 m window; 69 steps is now refused by
    // name, and the shortest memory accepted (128 steps) holds for 2 s, standing and at
    // 70 km/h, with the rail under the wheel at its static sag.
    for speed in [0.0, 70.0 / 3.6] {
        let mut s = Scenario::table_4_4();
        s.start_position = 6.85;
        s.speed = speed;
        let dt = Simulation::new(&s).unwrap().dt();
        let window = |steps: f64| {
            Some(TrackWindow {
                ahead: 4.0,
                behind: 4.0,
                exact_memory: steps * dt,
                ..TrackWindow::DEFAULT
            })
        };
        s.window = window(69.0);
        match Simulation::new(&s) {
            Err(wheelflat::Error::Parameter { name, allowed, .. }) => {
                assert_eq!(name, "track.window.exact_memory");
                assert!(allowed.contains("128 steps"), "{allowed}");
            }
            other => panic!("{:?}", other.map(|_| ())),
        }
        s.window = window(128.0);
        let mut sim = Simulation::new(&s).unwrap();
        let (mut low, mut high) = (f64::MAX, f64::MIN);
        sim.run(2.0, |x| {
            low = low.min(x.rail_z[0]);
            high = high.max(x.rail_z[0]);
        })
        .unwrap();
        // Perfect wheels on a smooth track: the rail under the wheel stays at its static
        // sag (1.4 mm, table 4.4) but for the sleeper passing (tens of micrometres).
        assert!((-1.6e-3..-1.2e-3).contains(&low), "{speed} m/s: {low} m");
        assert!(high - low < 1e-4, "{speed} m/s: {low} to {high} m");
    }
}
