//! Where TrackContact's displacement inputs are measured from (`inputs.datum`).
//!
//! The static wheel heights (and side-frame displacements) depend on the track: -1.5336
//! mm on the default endless track, -1.3811 mm on the thesis' fixed one (two spans from
//! its end), -1.5973 / -1.6439 mm under a half-car bogie on the endless track. A partner model started at rest on other heights (its
//! start values, its own static state) would hit the rail at its first step. With
//! `inputs.datum = first_step` (the default) the heights the track receives at its first
//! communication step are its static state: each input is moved by the fixed offset
//! `static - first input`, so a partner at rest starts at rest whatever its datum, with
//! no handshake of parameters (which OSP libcosim cannot connect and ecos breaks).
//! `absolute` takes the inputs as they are; the partner then takes the track's
//! `static_wheel_z.*` first. A height the master sets before the first step within 16
//! machine epsilons of its static one (16 to 32 units in the last place) is the
//! partner's rounding of it and moves nothing: no offset.
//!
//! The first step alone cannot tell a partner at rest on heights of 0 from one whose
//! connectors start at 0 (fmpy's `simulate_ssp` starts every connector at 0 and hands
//! the vehicle's heights over only after the first step), but the next inputs can: a
//! partner at rest moves by a step's motion, far less than the static deflection. When
//! an input given between the first and the second step is more than half the static
//! deflection (`|static|`) away from the first step's, the step returns fmi2Warning
//! naming `inputs.datum`, the first-step input and the static height (issue 38, N5);
//! where the first step's input was exactly 0, a connector's initial value and not the
//! partner's rest, the datum is taken again from the new input. A first input other
//! than 0 is the partner's own and is kept: a partner that really moves that far in one
//! step (a long step at an impact) is warned of, not re-measured.
//! Any later force beyond the health bound names the datum's offsets when one is more
//! than half the static deflection ([`InputDatum::explain`]).

use crate::error::{Error, out_of_range};

/// Values of [`InputDatum::state`] per wheelset.
const STATE: usize = 9;

/// The offsets of the displacement inputs of each wheelset `[left, right]` (m), the
/// same for both sides' wheel heights (contact interface) or side frames (axle-box
/// interface), followed until the first step and fixed there; a wheelset whose inputs
/// were not given by then takes the first ones it gets as its static state.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct InputDatum {
    /// Offsets are taken (`inputs.datum = first_step`); otherwise always 0.
    relative: bool,
    /// Per wheelset: inputs were given (before the first step, or since).
    given: Vec<bool>,
    /// Per wheelset: the offsets are fixed.
    fixed: Vec<bool>,
    /// The static displacements the first inputs stand for (m).
    statics: Vec<[f64; 2]>,
    /// Added to each input (m).
    offsets: Vec<[f64; 2]>,
    /// Per wheelset: steps since the offsets were fixed, up to 2 (1: between the first
    /// step and the second, when a move is judged).
    age: Vec<u8>,
    /// Per wheelset and side: the first step's input, when the datum was taken again or
    /// a move from it warned of.
    retaken: Vec<[Option<f64>; 2]>,
    /// The moves not yet warned of: wheelset, side, first input, the input now (m),
    /// whether the datum was taken again.
    pending: Vec<(usize, usize, f64, f64, bool)>,
}

/// The name of displacement input `side` (0 left, 1 right) of wheelset `k` (from 0):
/// a wheel height, or with `axle_box` a side frame's.
pub(super) fn input_name(axle_box: bool, k: usize, side: usize) -> String {
    let what = if axle_box { "sideframe" } else { "wheel" };
    let side = ["left", "right"][side];
    if k == 0 {
        format!("{what}.{side}.z")
    } else {
        format!("wheelset[{}].{what}.{side}.z", k + 1)
    }
}

/// A length in millimetres for a message.
fn mm(z: f64) -> String {
    format!("{:.4} mm", 1e3 * z)
}

impl InputDatum {
    /// The datum of a track whose displacement inputs rest at `statics` (m, one pair
    /// per wheelset); `relative`: `inputs.datum = first_step`.
    pub(super) fn new(relative: bool, statics: Vec<[f64; 2]>) -> InputDatum {
        let n = statics.len();
        InputDatum {
            relative,
            given: vec![false; n],
            fixed: vec![false; n],
            statics,
            offsets: vec![[0.0; 2]; n],
            age: vec![0; n],
            retaken: vec![[None; 2]; n],
            pending: Vec::new(),
        }
    }

    /// The displacements (m) the track takes for wheelset `k`'s inputs `raw` (m): until
    /// its offsets are fixed the static ones (the offsets follow the inputs; a side the
    /// master set before the first step within the rounding of its static height: the
    /// input as it is), then the inputs moved by the offsets fixed. `set`: the master
    /// set that side's height now; `at_start`: the track has not stepped yet.
    pub(super) fn apply(
        &mut self,
        k: usize,
        raw: [f64; 2],
        set: [bool; 2],
        at_start: bool,
    ) -> [f64; 2] {
        if !self.relative || k >= self.statics.len() {
            return raw;
        }
        if !self.fixed[k] {
            let first = !self.given[k];
            self.given[k] = true;
            // Heights the master set before the first step a few units in the last
            // place off the static ones are the partner's rounding of them (the
            // roll-plane vehicle recomputes each wheel's from its bounce and roll):
            // no offset, the heights as they are, so that a partner started on the
            // published heights runs bit for bit as the monolithic model, which takes
            // its vehicle's rounding too. Inputs left at their start values, or first
            // given after a step, stand for the static state exactly, as before.
            for s in 0..2 {
                if first || set[s] {
                    let d = self.statics[k][s] - raw[s];
                    // 16 machine epsilons of the height: 16 to 32 units in its last place.
                    let rounding = 16.0 * f64::EPSILON * self.statics[k][s].abs().max(raw[s].abs());
                    self.offsets[k][s] = if set[s] && at_start && d.abs() <= rounding {
                        0.0
                    } else {
                        d
                    };
                }
            }
            return [0, 1].map(|s| {
                if self.offsets[k][s] == 0.0 {
                    raw[s]
                } else {
                    self.statics[k][s]
                }
            });
        }
        if self.age[k] == 1 {
            // Between the first step and the second: a move of more than half the static
            // deflection from the first step's input is no partner at rest.
            for s in (0..2).filter(|&s| set[s]) {
                let first = self.first_input(k, s);
                if (raw[s] - first).abs() > 0.5 * self.statics[k][s].abs() {
                    // Only a connector's initial 0 is taken for no input at all.
                    let again = first == 0.0;
                    if again {
                        self.offsets[k][s] = self.statics[k][s] - raw[s];
                    }
                    if self.retaken[k][s].is_none() {
                        self.pending.push((k, s, first, raw[s], again));
                    }
                    self.retaken[k][s] = Some(first);
                }
            }
        }
        [0, 1].map(|s| raw[s] + self.offsets[k][s])
    }

    /// Wheelset `k`'s input on side `s` at the first step (m): kept where the datum was
    /// taken again or a move from it warned of, else what the offset was fixed from.
    fn first_input(&self, k: usize, s: usize) -> f64 {
        self.retaken[k][s].unwrap_or(self.statics[k][s] - self.offsets[k][s])
    }

    /// The warning for the datum taken again since the last call (`axle_box`: the
    /// inputs are side frames'), at time `time` (s); `None` when it was not.
    pub(super) fn take_warning(&mut self, axle_box: bool, time: f64) -> Option<String> {
        if self.pending.is_empty() {
            return None;
        }
        let again = self.pending.iter().any(|p| p.4);
        let moves: Vec<String> = (self.pending.drain(..))
            .map(|(k, s, first, now, _)| {
                format!(
                    "{} = {} at the first step, {} now (static {})",
                    input_name(axle_box, k, s),
                    mm(first),
                    mm(now),
                    mm(self.statics[k][s])
                )
            })
            .collect();
        let what = if again {
            "the first step's inputs of 0 were not the partner's rest (connectors that \
             start at 0, as fmpy's simulate_ssp starts them, before the partner's heights \
             come in): the datum is taken from this step's inputs instead, and the track's \
             first step held its static state. Start the partner's connectors at its \
             static heights, or set inputs.datum = absolute and hand the partner the \
             track's static_wheel_z.* first"
        } else {
            "if the partner was not at rest on its first inputs, start it at rest or set \
             inputs.datum = absolute and hand it the track's static_wheel_z.* first; a \
             partner at rest that moves this far in one step takes too long a \
             communication step"
        };
        Some(format!(
            "at t = {time} s the displacement inputs moved by more than half the static \
             deflection since the first step: {}. With inputs.datum = first_step the first \
             step's inputs stand for the static heights; {what}",
            moves.join("; ")
        ))
    }

    /// Why a force beyond the health bound may be the datum's doing, in words: the
    /// offsets of more than half the static deflection (`axle_box`: the inputs are side
    /// frames'); `None` when there are none or the inputs are absolute.
    pub(super) fn explain(&self, axle_box: bool) -> Option<String> {
        if !self.relative {
            return None;
        }
        let large: Vec<String> = (0..self.offsets.len())
            .flat_map(|k| (0..2).map(move |s| (k, s)))
            .filter(|&(k, s)| {
                self.fixed[k] && self.offsets[k][s].abs() > 0.5 * self.statics[k][s].abs()
            })
            .map(|(k, s)| {
                format!(
                    "{} was {} at the first step, taken for its static {} (offset {})",
                    input_name(axle_box, k, s),
                    mm(self.first_input(k, s)),
                    mm(self.statics[k][s]),
                    mm(self.offsets[k][s])
                )
            })
            .collect();
        (!large.is_empty()).then(|| {
            format!(
                "inputs.datum = first_step moves every input by the offset from its first \
                 step's value to the static height: {}; if the partner was not at rest on \
                 those first inputs, start it at rest or set inputs.datum = absolute",
                large.join("; ")
            )
        })
    }

    /// Whether the inputs are measured from the first step's (`first_step`).
    pub(super) fn is_relative(&self) -> bool {
        self.relative
    }

    /// Whether wheelset `k`'s inputs stand for the static state whatever they are (not
    /// fixed yet, with `first_step`).
    pub(super) fn follows(&self, k: usize) -> bool {
        self.relative && !self.fixed.get(k).copied().unwrap_or(true)
    }

    /// A step is taken: the offsets of every wheelset whose inputs were given stay as
    /// they are.
    pub(super) fn fix(&mut self) {
        for k in 0..self.fixed.len() {
            if self.fixed[k] {
                self.age[k] = (self.age[k] + 1).min(2);
            } else if self.given[k] {
                self.fixed[k] = true;
                self.age[k] = 1;
            }
        }
    }

    /// Values of [`InputDatum::state`].
    pub(super) fn state_len(&self) -> usize {
        STATE * self.offsets.len()
    }

    /// Per wheelset: given (0 or 1), fixed (0 or 1), the offsets `[left, right]` (m),
    /// the steps since fixed (0 to 2), and per side whether the datum was taken again
    /// (0 or 1) and the first step's input then (m, else 0). A re-take not yet warned of is
    /// warned of in the run it happened in, not in a restored one.
    pub(super) fn state(&self) -> Vec<f64> {
        let flag = |b: bool| f64::from(u8::from(b));
        (0..self.offsets.len())
            .flat_map(|k| {
                [
                    flag(self.given[k]),
                    flag(self.fixed[k]),
                    self.offsets[k][0],
                    self.offsets[k][1],
                    f64::from(self.age[k]),
                    flag(self.retaken[k][0].is_some()),
                    self.retaken[k][0].unwrap_or(0.0),
                    flag(self.retaken[k][1].is_some()),
                    self.retaken[k][1].unwrap_or(0.0),
                ]
            })
            .collect()
    }

    /// Restores [`InputDatum::state`].
    ///
    /// Errors: a wrong length, a flag that is not 0 or 1, an offset beyond 1 m or not
    /// finite.
    pub(super) fn restore(&mut self, v: &[f64]) -> Result<(), Error> {
        let flag = |x: f64| x == 0.0 || x == 1.0;
        let metres = |x: &f64| x.is_finite() && x.abs() <= 1.0;
        let ok = v.len() == self.state_len()
            && v.chunks(STATE).all(|c| {
                flag(c[0])
                    && flag(c[1])
                    && c[2..4].iter().all(metres)
                    && [0.0, 1.0, 2.0].contains(&c[4])
                    && flag(c[5])
                    && metres(&c[6])
                    && flag(c[7])
                    && metres(&c[8])
            });
        if !ok {
            return Err(out_of_range(
                "state: input datum",
                v.len() as f64,
                format!(
                    "{} values: per wheelset two flags 0 or 1, offsets within 1 m, steps 0 to \
                     2, per side a flag 0 or 1 and a first input within 1 m",
                    self.state_len()
                ),
            ));
        }
        for (k, c) in v.chunks(STATE).enumerate() {
            self.given[k] = c[0] == 1.0;
            self.fixed[k] = c[1] == 1.0;
            self.offsets[k] = [c[2], c[3]];
            self.age[k] = c[4] as u8;
            self.retaken[k] = [(c[5], c[6]), (c[7], c[8])].map(|(f, x)| (f == 1.0).then_some(x));
        }
        self.pending.clear();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_inputs_stand_for_the_static_state_and_later_ones_move_from_it() {
        let mut d = InputDatum::new(true, vec![[-1.5e-3, -1.6e-3]]);
        // Before the first step every input stands for the static state.
        assert_eq!(
            d.apply(0, [-1.38e-3, -1.38e-3], [true; 2], true),
            [-1.5e-3, -1.6e-3]
        );
        assert_eq!(
            d.apply(0, [-1.40e-3, -1.38e-3], [true; 2], true),
            [-1.5e-3, -1.6e-3]
        );
        d.fix();
        // After it, the change since the last input before the step.
        let z = d.apply(0, [-1.50e-3, -1.28e-3], [true; 2], false);
        assert!((z[0] - (-1.5e-3 - 0.1e-3)).abs() < 1e-15, "{z:?}");
        assert!((z[1] - (-1.6e-3 + 0.1e-3)).abs() < 1e-15, "{z:?}");
        // The state continues exactly.
        let mut e = InputDatum::new(true, vec![[-1.5e-3, -1.6e-3]]);
        e.restore(&d.state()).unwrap();
        assert_eq!(e.apply(0, [-1.50e-3, -1.28e-3], [true; 2], false), z);
        assert!(e.restore(&[2.0, 0.0, 0.0, 0.0]).is_err());
        assert!(e.restore(&[1.0, 0.0]).is_err());
    }

    #[test]
    fn a_wheelset_first_given_after_the_first_step_starts_from_its_static_state() {
        let mut d = InputDatum::new(true, vec![[-1.5e-3; 2], [-1.6e-3; 2]]);
        d.apply(0, [-1.38e-3; 2], [true; 2], true);
        d.fix();
        // Wheelset 2 was not given before the first step: its first input stands for the
        // static state, and it moves from there after the next step.
        assert!(d.follows(1) && !d.follows(0));
        assert_eq!(d.apply(1, [-1.0e-3; 2], [true; 2], false), [-1.6e-3; 2]);
        d.fix();
        let z = d.apply(1, [-0.9e-3; 2], [true; 2], false);
        assert!((z[0] - -1.5e-3).abs() < 1e-15, "{z:?}");
    }

    #[test]
    fn absolute_inputs_are_taken_as_they_are() {
        let mut d = InputDatum::new(false, vec![[-1.5e-3; 2]]);
        assert_eq!(
            d.apply(0, [-1.38e-3, 0.2], [true; 2], true),
            [-1.38e-3, 0.2]
        );
    }

    #[test]
    fn a_partners_rounding_of_the_static_heights_is_no_offset_at_the_start() {
        // The default endless track's two static heights differ in the last place; the
        // roll-plane vehicle gives both back rounded alike. Before the first step such
        // heights are taken as they are (as the monolithic model takes them); a
        // wheelset first given them after a step keeps its static state exactly.
        let statics = [-0.0015336282039686896, -0.0015336282039686894];
        let rounded = [-0.0015336282039686896; 2];
        let mut d = InputDatum::new(true, vec![statics; 2]);
        assert_eq!(d.apply(0, rounded, [true; 2], true), rounded);
        // Inputs left at their start values stand for the static state exactly.
        assert_eq!(d.apply(1, rounded, [false; 2], true), statics);
        d.fix();
        assert_eq!(d.apply(0, rounded, [true; 2], false), rounded);
        assert_eq!(d.apply(1, rounded, [true; 2], false), statics);
        // A real offset (a partner on another datum) is one, from 64 units in the last
        // place on.
        let mut e = InputDatum::new(true, vec![statics]);
        assert_eq!(e.apply(0, [-1.5e-3; 2], [true; 2], true), statics);
        let off = statics.map(|z| z * (1.0 + 64.0 * f64::EPSILON));
        assert_eq!(e.apply(0, off, [true; 2], true), statics);
        // A side the master did not set keeps its static height exactly.
        let mut f = InputDatum::new(true, vec![statics]);
        assert_eq!(
            f.apply(0, rounded, [true, false], true),
            [rounded[0], statics[1]]
        );
    }

    #[test]
    fn a_move_of_more_than_half_the_static_deflection_after_the_first_step_takes_the_datum_again() {
        // fmpy's simulate_ssp: connectors at 0 for the first step, the partner's heights
        // at rest from the second on (issue 38, N5).
        let statics = [-1.5e-3, -1.6e-3];
        let mut d = InputDatum::new(true, vec![statics]);
        assert_eq!(d.apply(0, [0.0; 2], [true; 2], true), statics);
        d.fix();
        assert!(d.explain(false).is_some(), "0 taken for -1.5 mm is named");
        // Half the static deflection and less is a move: the offsets stay.
        let z = d.apply(0, [-0.74e-3, 0.0], [true, false], false);
        assert!((z[0] - (-1.5e-3 - 0.74e-3)).abs() < 1e-15, "{z:?}");
        assert_eq!(d.take_warning(false, 0.1), None);
        // The partner's rest comes in: the datum is taken from it.
        let rest = [-1.52e-3, -1.61e-3];
        assert_eq!(d.apply(0, rest, [true; 2], false), statics);
        let w = d.take_warning(false, 2e-5).unwrap();
        for part in [
            "t = 0.00002 s",
            "wheel.left.z = 0.0000 mm at the first step, -1.5200 mm now (static -1.5000 mm)",
            "wheel.right.z = 0.0000 mm at the first step, -1.6100 mm now (static -1.6000 mm)",
            "inputs.datum = first_step",
            "inputs.datum = absolute",
        ] {
            assert!(w.contains(part), "{part}: {w}");
        }
        assert_eq!(d.take_warning(false, 3e-5), None, "warned once");
        assert_eq!(d.explain(false), None, "the offsets are small again");
        // The state carries it; after the second step nothing is taken again.
        let mut e = InputDatum::new(true, vec![[0.0; 2]]);
        e.restore(&d.state()).unwrap();
        assert_eq!(e.state(), d.state());
        d.fix();
        let z = d.apply(0, [0.0; 2], [true; 2], false);
        assert!((z[0] - (-1.5e-3 + 1.52e-3)).abs() < 1e-15, "{z:?}");
        assert_eq!(d.take_warning(true, 1.0), None);
        // A first step on 0 that nothing took again is named by a later error.
        let mut f = InputDatum::new(true, vec![statics]);
        f.apply(0, [0.0; 2], [true; 2], true);
        f.fix();
        f.fix();
        f.apply(0, [-1.0e-3; 2], [true; 2], false);
        assert_eq!(f.take_warning(true, 1.0), None);
        let named = f.explain(true).unwrap();
        assert!(
            named.contains(
                "sideframe.left.z was 0.0000 mm at the first step, taken for its static \
                 -1.5000 mm (offset -1.5000 mm)"
            ),
            "{named}"
        );
        // A first input other than 0 is the partner's own: a move of more than half the
        // static deflection after it is warned of, and the offsets stay (a partner that
        // really moves, at too long a step).
        let mut g = InputDatum::new(true, vec![statics]);
        g.apply(0, [-1.0e-3; 2], [true; 2], true);
        g.fix();
        let z = g.apply(0, [-2.0e-3, -1.0e-3], [true; 2], false);
        assert!((z[0] - (-1.5e-3 - 1.0e-3)).abs() < 1e-15, "{z:?}");
        let w = g.take_warning(false, 5e-3).unwrap();
        assert!(
            w.contains("wheel.left.z = -1.0000 mm at the first step, -2.0000 mm now")
                && w.contains("too long a communication step")
                && !w.contains("right"),
            "{w}"
        );
        // Absolute inputs are never moved.
        let mut a = InputDatum::new(false, vec![statics]);
        a.apply(0, [0.0; 2], [true; 2], true);
        a.fix();
        assert_eq!(a.apply(0, rest, [true; 2], false), rest);
        assert_eq!((a.take_warning(false, 0.0), a.explain(false)), (None, None));
    }
}
