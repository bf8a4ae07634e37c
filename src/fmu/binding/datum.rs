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

use crate::error::{Error, out_of_range};

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
        [0, 1].map(|s| raw[s] + self.offsets[k][s])
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
        for (f, g) in self.fixed.iter_mut().zip(&self.given) {
            *f |= *g;
        }
    }

    /// Values of [`InputDatum::state`].
    pub(super) fn state_len(&self) -> usize {
        4 * self.offsets.len()
    }

    /// Per wheelset: given (0 or 1), fixed (0 or 1), the offsets `[left, right]` (m).
    pub(super) fn state(&self) -> Vec<f64> {
        let flag = |b: bool| f64::from(u8::from(b));
        (0..self.offsets.len())
            .flat_map(|k| {
                [
                    flag(self.given[k]),
                    flag(self.fixed[k]),
                    self.offsets[k][0],
                    self.offsets[k][1],
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
        let ok = v.len() == self.state_len()
            && v.chunks(4).all(|c| {
                flag(c[0]) && flag(c[1]) && c[2..].iter().all(|x| x.is_finite() && x.abs() <= 1.0)
            });
        if !ok {
            return Err(out_of_range(
                "state: input datum",
                v.len() as f64,
                format!(
                    "{} values: per wheelset two flags 0 or 1, then offsets within 1 m",
                    self.state_len()
                ),
            ));
        }
        for (k, c) in v.chunks(4).enumerate() {
            self.given[k] = c[0] == 1.0;
            self.fixed[k] = c[1] == 1.0;
            self.offsets[k] = [c[2], c[3]];
        }
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
        let mut e = InputDatum::new(true, vec![[0.0; 2]]);
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
}
