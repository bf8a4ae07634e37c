//! Supports that lift: the hanging sleeper against an exact linear solve, tensionless
//! supports against the linear track while they carry, the limits held, the step's
//! stability and the state.

use super::*;

/// Table 4.4's track at the converged grid, `spans` long, with `supports`.
fn track(spans: usize, supports: Supports) -> Track {
    let crate::sim::TrackSpec::Discrete(mut p) = crate::sim::Scenario::table_4_4().track else {
        unreachable!("table 4.4 has the discrete track")
    };
    p.spans = spans;
    p.supports = supports;
    Track::new(p, 1e-5).unwrap()
}

/// Tensionless supports that let go at the least tension allowed (1 N).
const TENSIONLESS: Supports = Supports {
    law: SupportLaw::Tensionless,
    pad_preload: 1.0,
    ballast_preload: 1.0,
};

/// A wheelset's static load (N per rail) at `x` (m).
fn wheelset(x: f64, force: f64) -> [PointLoad; 2] {
    [0, 1].map(|rail| PointLoad {
        rail,
        position: x,
        force,
    })
}

#[test]
fn a_hanging_sleeper_with_an_open_gap_is_a_track_without_its_ballast() {
    // Sleeper 12 of 30 hangs 5 mm above the ballast, more than the rail over it
    // deflects under a wheelset's 107.66 kN a rail one span away: the static state
    // is that of a track whose sleeper 12 has no ballast, solved here densely and
    // independently (nalgebra's LU of the linear track's stiffness matrix less that
    // sleeper's ballast).
    let (x, p, void) = (11.0 * 0.685, 107_664.75, 12);
    let mut t = track(30, Supports::default());
    let mut gaps = vec![None; 31];
    gaps[void] = Some(0.005);
    t.set_sleeper_gaps(&gaps).unwrap();
    t.set_static(&wheelset(x, p)).unwrap();

    let reference = track(30, Supports::default());
    let (nk, ns) = (reference.nk, reference.ns);
    let mut k = reference.stiffness_matrix();
    let kb = reference.params.ballast_stiffness;
    let ls = 0.5 * reference.params.rail_seat_distance;
    k[(4 * nk + void, 4 * nk + void)] -= 2.0 * kb;
    k[(4 * nk + ns + void, 4 * nk + ns + void)] -= 2.0 * ls * ls * kb;
    let mut f = DVector::<f64>::zeros(k.nrows());
    let (kk, w) = reference.locate(x);
    for rail in 0..2 {
        f[rail * nk + kk] -= (1.0 - w) * p;
        f[rail * nk + kk + 1] -= w * p;
    }
    let exact = k.lu().solve(&f).unwrap();
    let z = t
        .rail_z(0)
        .into_iter()
        .chain(t.rail_z(1))
        .collect::<Vec<_>>();
    let scale = exact
        .iter()
        .take(2 * nk)
        .fold(0.0f64, |m, v| m.max(v.abs()));
    for (i, (a, b)) in z.iter().zip(exact.iter()).enumerate() {
        assert!((a - b).abs() <= 1e-9 * scale, "node {i}: {a} against {b}");
    }
    // The sleeper hangs: its seats stay above the ballast by part of the gap, and
    // the ballast carries nothing there.
    let seat = t.support_response(0, void as f64 * 0.685);
    assert!(seat.seat_displacement > -0.005 && seat.seat_displacement < -1e-4);
    assert_eq!(seat.ballast_force, 0.0);
    // Its neighbour carries more than on the intact track (3 % here).
    let mut intact = track(30, Supports::default());
    intact.set_static(&wheelset(x, p)).unwrap();
    let (a, b) = (
        t.support_response(0, 11.0 * 0.685).rail_seat_force,
        intact.support_response(0, 11.0 * 0.685).rail_seat_force,
    );
    assert!(a > 1.02 * b, "{a} against {b}");

    // A smaller gap closes: the ballast then carries the sleeper by what the seat
    // has moved beyond the gap, K_b (u + g), and the solve agrees with the same
    // linear track loaded by the gap's offset.
    let mut closed = track(30, Supports::default());
    gaps[void] = Some(2e-4);
    closed.set_sleeper_gaps(&gaps).unwrap();
    closed.set_static(&wheelset(x, p)).unwrap();
    let s = closed.support_response(0, void as f64 * 0.685);
    assert!(s.seat_displacement < -2e-4);
    let expect = -kb * (s.seat_displacement + 2e-4);
    assert!((s.ballast_force - expect).abs() < 1e-9 * p && s.ballast_force > 0.0);
}

#[test]
fn tensionless_supports_step_as_the_linear_track_until_one_lets_go() {
    // A wheelset's load dropped on the track at rest: the rails swing, and some time
    // after the start a support ahead goes into tension. Until then the tensionless
    // track's numbers are the linear track's, bit for bit; after it they differ and
    // no pad or ballast seat carries tension.
    let loads = wheelset(10.0 * 0.685 + 0.2, 150e3);
    let mut linear = track(20, Supports::default());
    let mut lifting = track(20, TENSIONLESS);
    let mut first_lift = None;
    for step in 0..4000 {
        linear.step(&loads);
        lifting.step(&loads);
        let (pads, ballast) = lifting.lifted_supports();
        if pads + ballast > 0 {
            first_lift.get_or_insert(step);
        }
        if first_lift.is_none() {
            assert_eq!(linear.to_nodes(&linear.z), lifting.to_nodes(&lifting.z));
            assert_eq!(linear.sleeper_z(), lifting.sleeper_z());
            assert_eq!(linear.sleeper_roll(), lifting.sleeper_roll());
        }
        for rail in 0..2 {
            assert!(lifting.pad_forces(rail).iter().all(|&f| f >= -1.0));
        }
    }
    let first = first_lift.expect("a support lets go");
    assert!(first >= 1, "{first}");
    let lin_min = (0..2)
        .flat_map(|r| linear.pad_forces(r).to_vec())
        .fold(f64::INFINITY, f64::min);
    assert!(lin_min < -100.0, "the linear pads pull: {lin_min}");
    assert_ne!(linear.to_nodes(&linear.z), lifting.to_nodes(&lifting.z));
    let (longest, at) = lifting.longest_lift();
    assert!(longest > 0.0 && (0..=20).contains(&at), "{longest} {at}");
}

#[test]
fn preloads_are_the_tension_a_support_carries_and_compression_is_unchanged() {
    // With preloads above any tension the run reaches, nothing lets go and the
    // tensionless track is the linear one bit for bit; with a 2 kN pad preload the
    // pads pull with 2 kN at most.
    let loads = wheelset(10.0 * 0.685 + 0.2, 150e3);
    let strong = Supports {
        pad_preload: 1e6,
        ballast_preload: 1e6,
        ..TENSIONLESS
    };
    let some = Supports {
        pad_preload: 2e3,
        ballast_preload: 1.7e3,
        ..TENSIONLESS
    };
    let mut linear = track(20, Supports::default());
    let mut held = track(20, strong);
    let mut preloaded = track(20, some);
    let mut pulled = 0.0f64;
    for _ in 0..4000 {
        linear.step(&loads);
        held.step(&loads);
        preloaded.step(&loads);
        for rail in 0..2 {
            let m = preloaded
                .pad_forces(rail)
                .iter()
                .fold(0.0f64, |m, &f| m.min(f));
            assert!(m >= -2e3, "{m}");
            pulled = pulled.min(m);
        }
    }
    assert_eq!(
        linear.state_vector(),
        held.state_vector()[..linear.state_len()]
    );
    assert_eq!(held.lifted_supports(), (0, 0));
    assert_eq!(pulled, -2e3, "some pad reaches its preload");
}

#[test]
fn lifting_supports_are_stable_at_the_linear_tracks_critical_step() {
    // Letting go only takes springs away, and a hanging sleeper's ballast is a spring
    // that comes and goes: the linear track's critical step bounds the lifting
    // track's. A wheelset's 200 kN put on and taken off every 5 ms for 0.2 s (the rail
    // jumps off its pads as it rebounds) over a hanging sleeper: at 0.999 of the
    // critical step the rail under the load follows the run at a quarter of it to
    // 2.0 % of its largest deflection (the load switches and the samples fall up to
    // a step apart); an unstable step would grow without bound.
    let supports = Supports {
        pad_preload: 2e3,
        ballast_preload: 1.7e3,
        ..TENSIONLESS
    };
    let p = *track(12, supports).params();
    let x = 6.0 * 0.685 + 0.1;
    let run = |fraction: f64| {
        let dt = fraction * p.critical_time_step().0;
        let mut t = Track::new(p, dt).unwrap();
        let mut gaps = vec![None; 13];
        gaps[6] = Some(1e-4);
        t.set_sleeper_gaps(&gaps).unwrap();
        let mut at_ms = Vec::new();
        let (mut time, mut next) = (0.0, 0.0);
        while time < 0.2 {
            let force = if ((time / 0.005) as usize).is_multiple_of(2) {
                200e3
            } else {
                0.0
            };
            t.step(&wheelset(x, force));
            time += dt;
            if time >= next {
                at_ms.push(t.rail_z_at(0, x));
                next += 1e-3;
            }
        }
        (at_ms, t.longest_lift().0)
    };
    let (coarse, lifted) = run(0.999);
    let (fine, _) = run(0.25);
    let scale = fine.iter().fold(0.0f64, |m, z| m.max(z.abs()));
    assert!(scale > 1e-3 && lifted > 1e-3, "{scale} {lifted}");
    let worst = coarse
        .iter()
        .zip(&fine)
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(worst < 0.03 * scale, "{worst} of {scale}");
}

#[test]
fn the_state_of_lifting_supports_restores_bit_for_bit_and_moves_with_the_window() {
    let loads = wheelset(10.0 * 0.685 + 0.2, 150e3);
    let mut a = track(20, TENSIONLESS);
    let mut gaps = vec![None; 21];
    gaps[12] = Some(3e-4);
    a.set_sleeper_gaps(&gaps).unwrap();
    for _ in 0..1500 {
        a.step(&loads);
    }
    let saved = a.state_vector();
    assert_eq!(saved.len(), a.state_len());
    let mut b = track(20, TENSIONLESS);
    b.set_sleeper_gaps(&gaps).unwrap();
    b.set_state_vector(&saved).unwrap();
    for _ in 0..1500 {
        a.step(&loads);
        b.step(&loads);
    }
    assert_eq!(a.state_vector(), b.state_vector());
    // A shift by 3 spans moves the lift times and the longest lift's sleeper with
    // the track.
    let before = (a.lift_times(0, 12), a.longest_lift());
    a.shift_spans(3).unwrap();
    assert_eq!(a.lift_times(0, 9), before.0);
    assert_eq!(a.longest_lift().1, before.1.1 - 3);
}

#[test]
fn a_sleeper_hanging_with_no_gap_rests_on_ballast_that_never_pulls() {
    // Gap 0: the sleeper touches the ballast at rest, which carries it as before while
    // pressed and lets go instead of pulling: the run is the linear track's until the
    // ballast under it would pull, and its seat forces never go below 0 after.
    let loads = wheelset(10.0 * 0.685 + 0.2, 150e3);
    let mut linear = track(20, Supports::default());
    let mut hanging = track(20, Supports::default());
    let mut gaps = vec![None; 21];
    gaps[12] = Some(0.0);
    hanging.set_sleeper_gaps(&gaps).unwrap();
    let mut lifted = false;
    for _ in 0..4000 {
        linear.step(&loads);
        hanging.step(&loads);
        for rail in 0..2 {
            let b = hanging.support_response(rail, 12.0 * 0.685).ballast_force;
            assert!(b >= 0.0, "{b}");
            lifted |= hanging.lift_times(rail, 12).1 > 0.0;
        }
    }
    assert!(lifted, "the ballast under it lets go");
    assert_ne!(linear.sleeper_z(), hanging.sleeper_z());
}
