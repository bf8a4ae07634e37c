//! Window ends that absorb (issue 29): a graded damping layer over the rails' outer
//! stretch at each end of a track, so that the waves an impact sends along the rails
//! die out there instead of coming back from the fixed ends.
//!
//! Each rail node in a layer of length `L` gets a mass-proportional damping, force per
//! length `-eta(x) m v` on the deflection and `-eta(x) rho I omega` on the rotation
//! (both decay at the same rate), growing with the depth `s` into the layer as
//! `eta(s) = eta_max (s / L)^2`: graded, so that a wave meets no sudden change of
//! impedance to reflect from. The damping is taken as in (3.25), centred:
//! `(1 + gamma) u_(j+1) = 2 u_j - (1 - gamma) u_(j-1) + dt^2 a_j` with
//! `gamma = eta dt / 2`, which is the undamped update `u*` corrected by
//! `u_(j+1) = (u* + gamma u_(j-1)) / (1 + gamma)`: stable for any damping, applied after
//! the vectorised loops to the layer's nodes only. The sleepers keep their own damping.
//!
//! **Measured, and why it is not the default** (`examples/window_reflection.rs`,
//! docs/VALIDATION.md): the layer takes the fast waves (above 1.5 kHz its echo is a
//! third of the same length of plain track's), but a window's error lies in the
//! waves just below the rails' pinned-pinned frequency (about 0.86 to 0.92 kHz on
//! table 4.4), at the edge of the periodic track's pass band, where their group
//! velocity goes to zero. There any damping, however gradual, is a large change of the
//! wave (its wavenumber's imaginary part grows as `eta / c_g`), and the layer reflects
//! as much as the plain track of its length lets through, or more: the adiabatic
//! absorber's limit in a periodic medium near a band edge (Oskooi, Zhang, Avniel and
//! Johnson, Opt. Express 16 (2008) 11376).

use super::*;

/// A graded damping layer at both rail ends of a window ([`Track::set_absorbing_ends`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct AbsorbingEnds {
    /// Length of each layer (m).
    pub length: f64,
    /// Largest damping rate `eta_max` (1/s), at the rail ends.
    pub rate: f64,
    /// Storage slot of each damped node of the left rail (add `S` for the right rail)
    /// and its `gamma = eta dt / 2`.
    nodes: Vec<(usize, f64)>,
    /// The damped nodes' `u_(j-1)` (deflections, then rotations; left rail, then right)
    /// saved before a step.
    saved: Vec<f64>,
}

impl Track {
    /// Puts a graded damping layer of `length` (m) at each end of the rails, the
    /// damping rate growing to `rate` (1/s) at the ends as the square of the depth into
    /// the layer; `length` 0 removes it. The layer's nodes are fixed in the track (a
    /// window's shift moves the state through them).
    ///
    /// Errors: a length that is negative, not finite or more than half the track; a
    /// rate that is negative or not finite.
    pub fn set_absorbing_ends(&mut self, length: f64, rate: f64) -> Result<()> {
        let half = 0.5 * self.params.length();
        if !(length.is_finite() && (0.0..=half).contains(&length)) {
            return Err(out_of_range(
                "track.window.layer",
                length,
                format!("0 to half the track, {} m", crate::error::num(half)),
            ));
        }
        crate::error::non_negative("track.window.layer_rate", rate, "1/s")?;
        if length > 0.0 && self.exact.is_some() {
            return Err(out_of_range(
                "track.window.layer",
                length,
                "0 with exact ends (track.window.exact_memory > 0)".to_string(),
            ));
        }
        if length == 0.0 {
            self.absorbing = None;
            return Ok(());
        }
        let (dx, nk) = (self.params.dx(), self.nk);
        let len = (nk - 1) as f64 * dx;
        let mut nodes = Vec::new();
        // The end nodes themselves are the window's boundary (held at zero on the fixed
        // ends a window has): the layer is the nodes inside.
        for k in 1..nk - 1 {
            let x = k as f64 * dx;
            let depth = (length - x).max(x - (len - length));
            if depth > 0.0 {
                let eta = rate * (depth / length).powi(2);
                nodes.push((self.slot[k], 0.5 * eta * self.dt));
            }
        }
        let saved = vec![0.0; 4 * nodes.len()];
        self.absorbing = Some(Box::new(AbsorbingEnds {
            length,
            rate,
            nodes,
            saved,
        }));
        Ok(())
    }

    /// The layer's length (m) and largest rate (1/s); `None` without one.
    pub fn absorbing_ends(&self) -> Option<(f64, f64)> {
        self.absorbing.as_ref().map(|a| (a.length, a.rate))
    }

    /// Saves the damped nodes' `u_(j-1)` before a step.
    #[cold]
    #[inline(never)]
    pub(super) fn absorbing_save(&mut self) {
        let Some(a) = self.absorbing.as_deref_mut() else {
            return;
        };
        let (sp, m) = (self.sp, a.nodes.len());
        for (i, &(s, _)) in a.nodes.iter().enumerate() {
            a.saved[i] = self.z_prev[s];
            a.saved[m + i] = self.z_prev[s + sp];
            a.saved[2 * m + i] = self.th_prev[s];
            a.saved[3 * m + i] = self.th_prev[s + sp];
        }
    }

    /// Damps the new state (at `t_(j+1)`, in `z`, `th` after the step's swap) of the
    /// layer's nodes: `u = (u* + gamma u_(j-1)) / (1 + gamma)`.
    #[cold]
    #[inline(never)]
    pub(super) fn absorbing_apply(&mut self) {
        let Some(a) = self.absorbing.as_deref() else {
            return;
        };
        let (sp, m) = (self.sp, a.nodes.len());
        for (i, &(s, g)) in a.nodes.iter().enumerate() {
            let r = 1.0 / (1.0 + g);
            self.z[s] = (self.z[s] + g * a.saved[i]) * r;
            self.z[s + sp] = (self.z[s + sp] + g * a.saved[m + i]) * r;
            self.th[s] = (self.th[s] + g * a.saved[2 * m + i]) * r;
            self.th[s + sp] = (self.th[s + sp] + g * a.saved[3 * m + i]) * r;
        }
    }

    /// The layer's `gamma` for a new step `dt` (s).
    pub(super) fn absorbing_rescale(&mut self, dt_old: f64, dt: f64) {
        if let Some(a) = self.absorbing.as_deref_mut() {
            for (_, g) in a.nodes.iter_mut() {
                *g *= dt / dt_old;
            }
        }
    }
}

// The window examples' spectra (a Hann window, one DFT term), for the test below.
#[cfg(test)]
#[path = "../../tools/spectrum.rs"]
mod spectrum;

#[cfg(test)]
mod tests {
    use super::spectrum;
    use crate::track::transparent::tests::{pulse_response, track};

    /// Rail deflection under a 0.1 ms raised-cosine pulse on both rails at mid-span of
    /// span `j` of `spans` spans, with layers of `ell` m at rate `eta` (1/s).
    fn response(spans: usize, j: usize, ell: f64, eta: f64, n: usize) -> (Vec<f64>, f64) {
        let mut t = track(spans);
        t.set_absorbing_ends(ell, eta).unwrap();
        (pulse_response(&mut t, j, n), t.dt())
    }

    /// Energy of `e` (under a Hann window) between `f0` and `f1` (Hz).
    fn band(e: &[f64], dt: f64, f0: f64, f1: f64) -> f64 {
        let w = spectrum::hann(e);
        let df = 1.0 / (w.len() as f64 * dt);
        ((f0 / df).ceil() as usize..(f1 / df) as usize)
            .map(|k| spectrum::power(&w, dt, k as f64 * df))
            .sum()
    }

    #[test]
    fn a_layer_takes_the_fast_waves_but_reflects_the_pinned_pinned_ones() {
        // An end 8 m from the load, with 8 m more of plain track (rate 0) or of layer
        // (300 1/s) beyond it, the other end 150 m away; the echo is the difference
        // from a track with both ends 150 m away, over 0.3 s
        // (`examples/window_reflection.rs` measures it over 0.5 s and more bands).
        let (a, n, far) = (0.685, 20820, 220);
        let (reference, dt) = response(2 * far, far, 0.0, 0.0, n);
        let j = (16.0 / a) as usize;
        let echo = |eta: f64| {
            let u = response(j + far, j, 8.0, eta, n).0;
            let e: Vec<f64> = u.iter().zip(&reference).map(|(x, y)| x - y).collect();
            [(800.0, 1000.0), (1500.0, 3000.0)].map(|(f0, f1)| band(&e, dt, f0, f1))
        };
        let (plain, layer) = (echo(0.0), echo(300.0));
        let r = |k: usize| (layer[k] / plain[k]).sqrt();
        // Measured: 1.5 to 3 kHz, the layer's echo 0.37 of the plain track's; 0.8 to
        // 1 kHz (the pinned-pinned band, where a window's error lies) 0.99.
        assert!(r(1) < 0.5, "1.5-3 kHz: {}", r(1));
        assert!(r(0) > 0.9, "0.8-1 kHz: {}", r(0));
    }
}
