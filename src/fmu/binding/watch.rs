//! What TrackContact sees of its exchange with the vehicle at the contact interface,
//! for the warnings of `fmi2DoStep` ([`crate::fmu::fmi2::Model::step_warning`]):
//!
//! * the communication step against the track's own: the wheel heights are held over a
//!   step (or extrapolated with the derivatives of `fmi2SetRealInputDerivatives`), so
//!   the exchange's error grows with the step (measured on the reference flat, peak of
//!   the leading wheel over 0.3 s: held heights under a sequential master +1.1 % at 2
//!   track steps, +4.2 % at 5, +12 % at 10; under a Jacobi master, OSP libcosim and
//!   ecos, +2.2 %, +7.0 % and +19 %; with the wheel velocities +0.7 % at 5 and +3.3 %
//!   at 10; +1.3, +5.5, +12, +2.4, +8.6, +20, +0.7 and +2.9 % with the rail between
//!   nodes by (3.23));
//! * chatter: a contact force that jumps up and down at every communication point, the
//!   mark of an explicit exchange beyond its stability (10 track steps, Jacobi: peaks
//!   of 615 kN and contact lost 31 % of the time, every force under the health bound);
//! * at the axle boxes, a bouncing exchange: a wheel that lifts off and strikes the rail
//!   at more than twice the static load more often in one turn of the wheel than its
//!   flats explain (one strike a flat, and one more for a weld, a hanging sleeper or a
//!   second bounce), the mark of an axle-box exchange beyond its stability or of a
//!   Jacobi master handing the bogie `primary.*.mean_force` (issue 41: the half-car
//!   bogie at 4 ms bounced every 8 points, 0 to 608 kN, every status fmi2OK);
//! * the axle's rotation against the track's motion: the flats meet the rail where
//!   `wheel.rotation` puts them, so an axle that turns at another rate than the track's
//!   `speed / wheel.radius` (a vehicle at its own speed while the track brakes) hits
//!   the rail at the wrong places.
//!
//! The watch is no part of FMU states: a restored state starts it afresh.

use crate::error::num;

/// Communication steps, in track steps, beyond which the contact exchange's error
/// passes about 1 % on the peak: with held wheel heights, and with their derivatives.
pub(super) const HELD_STEPS: f64 = 1.5;
pub(super) const INTERPOLATED_STEPS: f64 = 5.5;

/// Consecutive communication steps at which a contact force reverses its change by more
/// than [`CHATTER_JUMP`] of the static load: chatter.
const CHATTER_RUN: u32 = 6;
const CHATTER_JUMP: f64 = 0.1;

/// A strike: a contact force over [`STRIKE_HIGH`] times the static load at a
/// communication point after one under [`STRIKE_LOW`] of it (lift-off) since the last.
const STRIKE_LOW: f64 = 0.1;
const STRIKE_HIGH: f64 = 2.0;
/// Strikes a turn of the wheel beyond its flats' that still pass without a warning (a
/// weld, a hanging sleeper, a flat's second bounce).
const STRIKES_SPARE: usize = 1;
/// The strikes are counted over this share of a turn: a flat's strikes a turn apart,
/// seen at communication points, may come up to a step less than a turn apart.
const STRIKE_WINDOW: f64 = 0.9;

/// A contact force that jumps by more than this fraction of the static load when the
/// new wheel heights come in: the exchange does not resolve the contact.
const JUMP_LIMIT: f64 = 0.2;

/// The angle the axle turned may differ from the track's travel over the wheel radius
/// by this fraction (plus [`RATE_FLOOR`] rad/s over the window and the grid's offset)
/// before the watch warns; compared over windows of at least [`RATE_WINDOW`] track
/// steps.
const RATE_TOLERANCE: f64 = 0.01;
const RATE_FLOOR: f64 = 0.05;
const RATE_WINDOW: f64 = 64.0;

/// The name of wheelset `k`'s (0 the leading one) variable `what`: `wheel.rotation`,
/// `wheelset[2].contact.left.force`.
fn named(k: usize, what: &str) -> String {
    if k == 0 {
        what.to_string()
    } else {
        format!("wheelset[{}].{what}", k + 1)
    }
}

/// The contact force's name of wheelset `k`'s wheel on side `s` (0 left, 1 right).
fn force_name(k: usize, s: usize) -> String {
    named(
        k,
        if s == 0 {
            "contact.left.force"
        } else {
            "contact.right.force"
        },
    )
}

/// One wheel's contact forces at the communication points.
#[derive(Debug, Clone, Default)]
struct Wheel {
    force: Option<f64>,
    change: f64,
    run: u32,
    /// Lifted off since the last strike, and the times of the strikes in the last turn
    /// of the wheel (s).
    lifted: bool,
    strikes: std::collections::VecDeque<f64>,
}

/// The rotation input of a wheelset when it was last given: time (s), angle (rad),
/// the track's position then (m).
#[derive(Debug, Clone, Copy)]
struct Rotation {
    time: f64,
    angle: f64,
    position: f64,
}

/// The watch of TrackContact's contact exchange.
#[derive(Debug, Clone, Default)]
pub(super) struct ContactWatch {
    wheels: Vec<[Wheel; 2]>,
    rotations: Vec<Option<Rotation>>,
    /// The axle rate that disagrees with the track's motion, in words.
    rate: Option<String>,
    /// The master has set wheel heights: there is an exchange to watch.
    coupled: bool,
    /// The largest jump of a contact force (N) when new wheel heights came in since the
    /// last step, and the wheel's name.
    jump: Option<(f64, String)>,
}

impl ContactWatch {
    /// A watch of `wheelsets` wheelsets.
    pub(super) fn new(wheelsets: usize) -> ContactWatch {
        ContactWatch {
            wheels: vec![[Wheel::default(), Wheel::default()]; wheelsets],
            rotations: vec![None; wheelsets],
            rate: None,
            coupled: false,
            jump: None,
        }
    }

    /// Wheelset `k`'s contact forces (N) just before and after new wheel heights came
    /// in at a communication point.
    pub(super) fn heights_given(&mut self, k: usize, before: [f64; 2], after: [f64; 2]) {
        for s in 0..2 {
            let d = (after[s] - before[s]).abs();
            if self.jump.as_ref().is_none_or(|(j, _)| d > *j) {
                self.jump = Some((d, force_name(k, s)));
            }
        }
    }

    /// The largest jump of the communication point just past when it passed
    /// [`JUMP_LIMIT`] of the static load `load` (N): the jump (N) and the force's name;
    /// the jump is forgotten.
    pub(super) fn take_jump(&mut self, load: f64) -> Option<(f64, String)> {
        self.jump.take().filter(|(j, _)| *j > JUMP_LIMIT * load)
    }

    /// The master set wheel heights.
    pub(super) fn coupled(&mut self) {
        self.coupled = true;
    }

    /// Whether the master has set wheel heights since the start.
    pub(super) fn is_coupled(&self) -> bool {
        self.coupled
    }

    /// Wheelset `k`'s axle angle `angle` (rad) given when the track is at `time` (s)
    /// and `position` (m), its step `dt` (s), wheel radius `radius` (m): the angle
    /// turned since the last comparison against the track's travel over the radius, once
    /// at least [`RATE_WINDOW`] track steps have passed. The track's time and position
    /// lie on its own grid and the angle on the master's clock (at most a track step
    /// apart); over the window that offset is allowed for, and an angle given modulo a
    /// turn is unwrapped.
    pub(super) fn rotation_given(
        &mut self,
        k: usize,
        (time, position, dt): (f64, f64, f64),
        angle: f64,
        radius: f64,
    ) {
        let Some(slot) = self.rotations.get_mut(k) else {
            return;
        };
        let now = Rotation {
            time,
            angle,
            position,
        };
        let Some(last) = *slot else {
            *slot = Some(now);
            return;
        };
        let span = time - last.time;
        if span < RATE_WINDOW * dt {
            return;
        }
        let rolled = (position - last.position) / radius;
        let turned = angle - last.angle;
        // The nearest multiple of a turn: a partner may wrap its angle.
        let off = turned - rolled;
        let off = off - std::f64::consts::TAU * (off / std::f64::consts::TAU).round();
        let speed = (position - last.position).abs() / span;
        let grid = 2.0 * speed * dt / radius;
        if off.abs() > RATE_TOLERANCE * rolled.abs() + grid + RATE_FLOOR * span {
            let name = named(k, "wheel.rotation");
            self.rate = Some(format!(
                "{name} turned by {} rad from t = {} s to {} s, but the track moved {} m \
                 there, which rolls the axle by {} rad (speed / wheel.radius): the flats \
                 meet the rail where {name} puts them, so they hit it at the wrong places; \
                 give the vehicle the speed the track has (RollPlaneVehicle's and \
                 HalfCarBogie's speed is an input)",
                num(turned),
                num(last.time),
                num(time),
                num(position - last.position),
                num(rolled)
            ));
        } else {
            self.rate = None;
        }
        *slot = Some(now);
    }

    /// The rotation rate's disagreement with the track's motion, if the last one showed
    /// it.
    pub(super) fn rate_warning(&self) -> Option<String> {
        self.rate.clone()
    }

    /// The contact forces `forces` (N, per wheelset `[left, right]`) at a communication
    /// point, with the static load `load` (N): a wheel whose force has reversed its
    /// change by more than a tenth of the static load at each of the last
    /// [`CHATTER_RUN`] points chatters; its name, if any.
    pub(super) fn forces_at_point(
        &mut self,
        forces: impl IntoIterator<Item = [f64; 2]>,
        load: f64,
    ) -> Option<String> {
        let mut chatter = None;
        for (k, (w, f)) in self.wheels.iter_mut().zip(forces).enumerate() {
            for s in 0..2 {
                let wheel = &mut w[s];
                if let Some(before) = wheel.force {
                    let change = f[s] - before;
                    let big = change.abs() > CHATTER_JUMP * load;
                    wheel.run = if big && change * wheel.change < 0.0 {
                        wheel.run + 1
                    } else {
                        0
                    };
                    wheel.change = change;
                }
                wheel.force = Some(f[s]);
                if wheel.run >= CHATTER_RUN && chatter.is_none() {
                    chatter = Some(force_name(k, s));
                }
            }
        }
        chatter
    }

    /// The contact forces `forces` (N, per wheelset `[left, right]`) at the
    /// communication point `time` (s) of the axle-box exchange, with the static load
    /// `load` (N), the time of a turn of the wheel `turn` (s, `2 pi R_w / V`), and each
    /// wheel's flats `flats` (per wheelset `[left, right]`): a wheel that struck the rail
    /// (a force over twice the static load after lift-off) more often within
    /// [`STRIKE_WINDOW`] of a turn than its flats and [`STRIKES_SPARE`] explain bounces;
    /// (its name, the strikes, the window (s)), if any.
    pub(super) fn strikes_at_point(
        &mut self,
        time: f64,
        forces: impl IntoIterator<Item = ([f64; 2], [usize; 2])>,
        load: f64,
        turn: f64,
    ) -> Option<(String, usize, f64)> {
        let mut bouncing = None;
        for (k, (w, (f, flats))) in self.wheels.iter_mut().zip(forces).enumerate() {
            for s in 0..2 {
                let wheel = &mut w[s];
                if f[s] < STRIKE_LOW * load {
                    wheel.lifted = true;
                } else if f[s] > STRIKE_HIGH * load && wheel.lifted {
                    wheel.lifted = false;
                    wheel.strikes.push_back(time);
                }
                while wheel
                    .strikes
                    .front()
                    .is_some_and(|t| *t <= time - STRIKE_WINDOW * turn)
                {
                    wheel.strikes.pop_front();
                }
                let n = wheel.strikes.len();
                if n > flats[s] + STRIKES_SPARE && bouncing.is_none() {
                    bouncing = Some((force_name(k, s), n, STRIKE_WINDOW * turn));
                }
            }
        }
        bouncing
    }

    /// Forgets what was seen (a restored FMU state).
    pub(super) fn restart(&mut self) {
        let coupled = self.coupled;
        *self = ContactWatch::new(self.wheels.len());
        self.coupled = coupled;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wheel_that_strikes_more_often_than_its_flats_bounces_and_a_flats_impacts_do_not() {
        let (load, turn) = (100e3, 0.1535);
        let mut w = ContactWatch::new(1);
        // One flat on the left wheel: lift-off and a strike of 2.8 times the load, with a
        // second, smaller bounce, once a turn, at 1 ms communication points.
        let mut t = 0.0;
        for _ in 0..5 {
            for i in 0..153 {
                let p = match i {
                    40 => 0.0,
                    41 => 2.8 * load,
                    42 => 0.0,
                    43 => 2.1 * load,
                    _ => load,
                };
                assert_eq!(
                    w.strikes_at_point(t, [([p, load], [1, 0])], load, turn),
                    None,
                    "t = {t}"
                );
                t += 1e-3;
            }
        }
        // Lift-off for 5 points and 300 to 600 kN, every 8 points (the half-car bogie at
        // 4 ms under a Jacobi master fed the mean force): named within one turn.
        let mut named = None;
        for i in 0..40 {
            let p = if i % 8 < 5 {
                0.0
            } else {
                3e5 + 1e5 * f64::from(i % 3)
            };
            named = named.or(w.strikes_at_point(t, [([p, load], [1, 0])], load, turn));
            t += 4e-3;
        }
        let (name, n, _) = named.expect("a bouncing wheel");
        assert_eq!((name.as_str(), n), ("contact.left.force", 3));
        // The right wheel, with no flat, bounces at its second strike in a turn.
        let mut w = ContactWatch::new(1);
        let mut seen = Vec::new();
        for (i, p) in [0.0, 3e5, load, 0.0, 2.5e5].iter().enumerate() {
            seen.push(w.strikes_at_point(i as f64 * 1e-3, [([load, *p], [1, 0])], load, turn));
        }
        assert_eq!(seen[..4], [None, None, None, None]);
        assert_eq!(seen[4].as_ref().map(|s| s.1), Some(2));
    }

    #[test]
    fn a_force_that_reverses_at_every_point_chatters_and_a_ringing_one_does_not() {
        let load = 1e5;
        let mut w = ContactWatch::new(1);
        // Up and down by 30 kN at every point: chatter from the sixth reversal on.
        let mut seen = Vec::new();
        for n in 0..10 {
            let f = if n % 2 == 0 { 1.2e5 } else { 0.9e5 };
            seen.push(w.forces_at_point([[f, load]], load).is_some());
        }
        assert_eq!(
            seen,
            [
                false, false, false, false, false, false, false, true, true, true
            ]
        );
        // An impact that rings at 7 points per period (1 kHz at 10 track steps): none.
        let mut w = ContactWatch::new(1);
        for n in 0..200 {
            let f = load + 2e5 * (std::f64::consts::TAU * n as f64 / 7.0).sin();
            assert!(w.forces_at_point([[f, load]], load).is_none(), "{n}");
        }
    }

    #[test]
    fn an_axle_that_turns_at_another_rate_than_the_track_rolls_is_named() {
        let mut w = ContactWatch::new(1);
        let (r, dt) = (0.42, 1e-3);
        // The track brakes from 19.44 m/s to 10 m/s, the axle keeps turning at 19.44 / r.
        w.rotation_given(0, (0.0, 0.0, dt), 0.0, r);
        // Within the window: nothing compared yet.
        w.rotation_given(0, (0.05, 0.5, dt), 0.05 * 19.44 / r, r);
        assert!(w.rate_warning().is_none());
        w.rotation_given(0, (0.1, 1.0, dt), 0.1 * 19.44 / r, r);
        let m = w.rate_warning().unwrap();
        assert!(m.starts_with("wheel.rotation turned by 4.628"), "{m}");
        assert!(
            m.contains("moved 1 m") && m.contains("axle by 2.380"),
            "{m}"
        );
        // Rolling as the track moves, its angle given modulo a turn and the track's time
        // and position half a step off the master's: no warning.
        let a = (0.1 * 19.44 / r + 1.0 / r) % std::f64::consts::TAU;
        w.rotation_given(0, (0.2 + 0.5 * dt, 2.0 + 0.005, dt), a, r);
        assert!(w.rate_warning().is_none(), "{:?}", w.rate_warning());
    }
}
