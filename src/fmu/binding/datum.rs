//! Where TrackContact's displacement inputs are measured from (`inputs.datum`).
//!
//! The static wheel heights (and side-frame displacements) depend on the track: -1.3811
//! mm on the default fixed track, -1.5336 mm on the endless one, -1.5973 / -1.6428 mm
//! under a half-car bogie there. A partner model started at rest on other heights (its
//! start values, its own static state) would hit the rail at its first step. With
//! `inputs.datum = first_step` (the default) the heights the track receives at its first
//! communication step are its static state: each input is moved by the fixed offset
//! `static - first input`, so a partner at rest starts at rest whatever its datum, with
//! no handshake of parameters (which OSP libcosim cannot connect and ecos breaks).
//! `absolute` takes the inputs as they are; the partner then takes the track's
//! `static_wheel_z.*` first.

use crate::error::{Error, out_of_range};

/// The offsets of the displacement inputs of each wheelset `[left, right]` (m), the
/// same for both sides' wheel heights (contact interface) or side frames (axle-box
/// interface), followed until the first step and fixed there.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct InputDatum {
    /// Offsets are taken (`inputs.datum = first_step`); otherwise always 0.
    relative: bool,
    /// The first step was taken: the offsets are fixed.
    fixed: bool,
    /// The static displacements the first inputs stand for (m).
    statics: Vec<[f64; 2]>,
    /// Added to each input (m).
    offsets: Vec<[f64; 2]>,
}

impl InputDatum {
    /// The datum of a track whose displacement inputs rest at `statics` (m, one pair
    /// per wheelset); `relative`: `inputs.datum = first_step`.
    pub(super) fn new(relative: bool, statics: Vec<[f64; 2]>) -> InputDatum {
        let offsets = vec![[0.0; 2]; statics.len()];
        InputDatum {
            relative,
            fixed: false,
            statics,
            offsets,
        }
    }

    /// The displacements (m) the track takes for wheelset `k`'s inputs `raw` (m): before
    /// the first step the static ones (the offsets follow the inputs), after it the
    /// inputs moved by the offsets fixed then.
    pub(super) fn apply(&mut self, k: usize, raw: [f64; 2]) -> [f64; 2] {
        if !self.relative || k >= self.statics.len() {
            return raw;
        }
        if !self.fixed {
            self.offsets[k] = [0, 1].map(|s| self.statics[k][s] - raw[s]);
            return self.statics[k];
        }
        [0, 1].map(|s| raw[s] + self.offsets[k][s])
    }

    /// Whether the inputs stand for the static state whatever they are (before the first
    /// step, with `first_step`).
    pub(super) fn follows(&self) -> bool {
        self.relative && !self.fixed
    }

    /// The first step is taken: the offsets stay as they are.
    pub(super) fn fix(&mut self) {
        self.fixed = true;
    }

    /// Values of [`InputDatum::state`].
    pub(super) fn state_len(&self) -> usize {
        1 + 2 * self.offsets.len()
    }

    /// `[fixed (0 or 1), offsets (2 per wheelset)]`.
    pub(super) fn state(&self) -> Vec<f64> {
        let mut v = vec![f64::from(u8::from(self.fixed))];
        v.extend(self.offsets.iter().flatten());
        v
    }

    /// Restores [`InputDatum::state`].
    ///
    /// Errors: a wrong length, a flag that is not 0 or 1, an offset beyond 1 m or not
    /// finite.
    pub(super) fn restore(&mut self, v: &[f64]) -> Result<(), Error> {
        if v.len() != self.state_len()
            || !(v[0] == 0.0 || v[0] == 1.0)
            || v[1..].iter().any(|x| x.is_nan() || x.abs() > 1.0)
        {
            return Err(out_of_range(
                "state: input datum",
                v.len() as f64,
                format!(
                    "{} values: a flag 0 or 1, then offsets within 1 m",
                    self.state_len()
                ),
            ));
        }
        self.fixed = v[0] == 1.0;
        for (o, pair) in self.offsets.iter_mut().zip(v[1..].chunks(2)) {
            *o = [pair[0], pair[1]];
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
        assert_eq!(d.apply(0, [-1.38e-3, -1.38e-3]), [-1.5e-3, -1.6e-3]);
        assert_eq!(d.apply(0, [-1.40e-3, -1.38e-3]), [-1.5e-3, -1.6e-3]);
        d.fix();
        // After it, the change since the last input before the step.
        let z = d.apply(0, [-1.50e-3, -1.28e-3]);
        assert!((z[0] - (-1.5e-3 - 0.1e-3)).abs() < 1e-15, "{z:?}");
        assert!((z[1] - (-1.6e-3 + 0.1e-3)).abs() < 1e-15, "{z:?}");
        // The state continues exactly.
        let mut e = InputDatum::new(true, vec![[0.0; 2]]);
        e.restore(&d.state()).unwrap();
        assert_eq!(e.apply(0, [-1.50e-3, -1.28e-3]), z);
        assert!(e.restore(&[2.0, 0.0, 0.0]).is_err());
        assert!(e.restore(&[1.0, 0.0]).is_err());
    }

    #[test]
    fn absolute_inputs_are_taken_as_they_are() {
        let mut d = InputDatum::new(false, vec![[-1.5e-3; 2]]);
        assert_eq!(d.apply(0, [-1.38e-3, 0.2]), [-1.38e-3, 0.2]);
    }
}
