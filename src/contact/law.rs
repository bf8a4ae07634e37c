//! The contact law behind one interface: which law ([`ContactModel`]), its constants
//! ([`ContactLaw`]), the dispatch to each law, and what every law gets from the
//! dispatch: its stiffness and the overlap that carries a force. What a law reports
//! ([`ContactState`]) is in `state.rs`.

use super::state::ContactState;
use super::{adaptive, hertz};
use crate::error::{Result, positive};
use crate::wheel::WheelProfile;

/// Which normal-contact law to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactModel {
    /// The thesis' adaptive radial-spring contact (2.8).
    Adaptive,
    /// Hertz point contact `P = C_H (delta_c - f_0)^(3/2)` (1.3).
    Hertz,
}

/// Contact law with its constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactLaw {
    /// Which law.
    pub model: ContactModel,
    /// Radial spring stiffness `K_w` (N/m/rad), used by the adaptive law.
    pub kw: f64,
    /// Hertz coefficient `C_H` (N/m^1.5), used by the Hertz law.
    pub ch: f64,
}

impl ContactLaw {
    /// An adaptive law with radial stiffness `kw` (N/m/rad) (2.1-2.8).
    ///
    /// # Errors
    /// [`crate::Error::Parameter`] naming `contact.Kw` unless `kw` is finite and positive.
    pub fn adaptive(kw: f64) -> Result<Self> {
        positive("contact.Kw", kw, "N/m/rad")?;
        Ok(ContactLaw {
            model: ContactModel::Adaptive,
            kw,
            ch: 0.0,
        })
    }

    /// A Hertz law with coefficient `ch` (N/m^1.5) (1.3).
    ///
    /// # Errors
    /// [`crate::Error::Parameter`] naming `contact.CH` unless `ch` is finite and positive.
    pub fn hertz(ch: f64) -> Result<Self> {
        positive("contact.CH", ch, "N/m^1.5")?;
        Ok(ContactLaw {
            model: ContactModel::Hertz,
            kw: 0.0,
            ch,
        })
    }

    /// Contact stiffness `dP / d delta` (N/m) at contact force `force` (N) for a wheel
    /// with profile `wheel` at axle rotation `gamma` (rad), by a central difference
    /// (relative step 1e-6) about the overlap that carries the force
    /// ([`ContactLaw::overlap_for_force`]). For the adaptive law on a perfect wheel it is
    /// `2 K_w alpha_w` (differentiating (2.5)); for Hertz `1.5 C_H delta^(1/2)`. The
    /// linearised contact couples the rail under the wheel to the wheel in the explicit
    /// scheme (the track's `critical_time_step_with_contact`).
    pub fn stiffness(&self, wheel: &WheelProfile, gamma: f64, force: f64) -> f64 {
        let d = self.overlap_for_force(wheel, gamma, force);
        let e = 1e-6 * d;
        let p = |x: f64| self.evaluate(wheel, gamma, x).force;
        (p(d + e) - p(d - e)) / (2.0 * e)
    }

    /// Contact stiffness `dP / d delta` (N/m) at the overlap `overlap` (m) for a wheel
    /// with profile `wheel` at axle rotation `gamma` (rad), exact: for the adaptive
    /// law `K_w` times the total angle of the compressed springs (differentiating
    /// (2.8): the integrand vanishes at the contact edges), `2 K_w alpha_w` on a round
    /// wheel; for Hertz `3/2 C_H d^(1/2)` (1.3). 0 out of contact. A wheel moved up by
    /// `dz` changes the force by `-stiffness * dz`.
    pub fn stiffness_at(&self, wheel: &WheelProfile, gamma: f64, overlap: f64) -> f64 {
        match self.model {
            ContactModel::Adaptive => adaptive::adaptive_stiffness(self.kw, wheel, gamma, overlap),
            ContactModel::Hertz => hertz::hertz_stiffness(self.ch, wheel, gamma, overlap),
        }
    }

    /// Contact state for a wheel with profile `wheel` at axle rotation `gamma` (rad)
    /// and overlap `overlap = z_rail - z_wheel` (m) (2.7): for the adaptive law the
    /// integral of the compressed radial springs (2.8; closed form (2.5) where the
    /// wheel is round), for Hertz (1.3) with the radius reduction under the wheel
    /// centre. No contact (zero force, no intervals) when `overlap <= 0` or NaN.
    #[inline(always)]
    pub fn evaluate(&self, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
        let mut state = ContactState::default();
        self.evaluate_into(wheel, gamma, overlap, &mut state);
        state
    }

    /// [`ContactLaw::evaluate`], the state written into `out`.
    #[inline(always)]
    pub(crate) fn evaluate_into(
        &self,
        wheel: &WheelProfile,
        gamma: f64,
        overlap: f64,
        out: &mut ContactState,
    ) {
        // The coupled step writes the states where its sample keeps them: a state built
        // in a temporary and copied at once stalled the copy's wide loads on the narrow
        // stores that had just built it.
        match self.model {
            ContactModel::Adaptive => {
                adaptive::adaptive(self.kw, wheel, gamma, overlap, false, out)
            }
            ContactModel::Hertz => *out = hertz::hertz(self.ch, wheel, gamma, overlap),
        }
    }

    /// [`ContactLaw::evaluate_into`] and the stiffness `dP / d delta` (N/m,
    /// [`ContactLaw::stiffness_at`]) at that overlap, from one pass of the law, and
    /// whether the pass was a costly one (the adaptive integral with a flat in the
    /// patch; closed forms are not).
    #[inline(always)]
    fn evaluate_with_stiffness_into(
        &self,
        wheel: &WheelProfile,
        gamma: f64,
        overlap: f64,
        out: &mut ContactState,
    ) -> (f64, bool) {
        match self.model {
            ContactModel::Adaptive => {
                adaptive::adaptive_and_stiffness(self.kw, wheel, gamma, overlap, out)
            }
            ContactModel::Hertz => {
                *out = hertz::hertz(self.ch, wheel, gamma, overlap);
                (
                    hertz::hertz_stiffness(self.ch, wheel, gamma, overlap),
                    false,
                )
            }
        }
    }

    /// The contact state with a compliance `compliance` `c` (m/N) in series on the
    /// rail's side (the rail under a load between nodes, `Track::shear_compliance`):
    /// the force `P` that solves `P = P_law(overlap - c P)`, and the law's state at the
    /// overlap `overlap - c P` that carries it. `g(P) = P - P_law(overlap - c P)` rises
    /// with slope `1 + c k >= 1` (`k` the law's stiffness), so the root is unique, in
    /// `[0, P_law(overlap)]`. Newton's method from `guess` (N; the force of the step
    /// before), each step one pass of the law with its stiffness: it stops once
    /// `|g| <= 1e-9 |P| + 1e-6 N`, or, where the pass was a costly one (a flat in the
    /// patch), once a step moves the overlap by at most 1e-5 of itself, when the state
    /// is carried to the new overlap along the stiffness
    /// (`force` and `overlap` set from the step; the law's curvature, `3/8` of the
    /// square of that relative move for Hertz-like laws, leaves an error below 4e-11
    /// of the force, 4 uN at the static load, so that a finite difference of the
    /// forces over 1e-8 m of wheel height still gives the stiffness to 1e-6; the
    /// patch's angles and length are those of the last pass, 1e-7 rad off): one costly
    /// pass a step while the force changes by less than about 10 kN a step; closed
    /// forms converge in two or three. At most 30 steps (one that leaves
    /// the bracket is bisected). `compliance <= 0` is [`ContactLaw::evaluate_into`]
    /// itself, bit for bit. Returns the force `P` (N) the rail's deflection takes:
    /// `c P` is how far the rail under the wheel lies below the nodes'
    /// [`crate::track::Track::rail_z_at`].
    #[inline(always)]
    pub(crate) fn evaluate_in_series_into(
        &self,
        wheel: &WheelProfile,
        gamma: f64,
        overlap: f64,
        compliance: f64,
        guess: f64,
        out: &mut ContactState,
    ) -> f64 {
        if compliance.is_nan() || compliance <= 0.0 {
            self.evaluate_into(wheel, gamma, overlap, out);
            return out.force;
        }
        let (mut lo, mut hi) = (0.0, f64::INFINITY);
        let mut p = if guess.is_finite() {
            guess.max(0.0)
        } else {
            0.0
        };
        for _ in 0..30 {
            let d = overlap - compliance * p;
            let (k, costly) = self.evaluate_with_stiffness_into(wheel, gamma, d, out);
            let g = p - out.force;
            if g.abs() <= 1e-9 * p.abs() + 1e-6 || !g.is_finite() {
                return p;
            }
            if g > 0.0 {
                hi = p;
            } else {
                lo = p;
            }
            let next = p - g / (1.0 + compliance * k);
            if next > lo && next < hi {
                let moved = compliance * (next - p);
                if costly && out.force > 0.0 && moved.abs() <= 1e-5 * d {
                    // Carried along the stiffness: P_law(d - moved) = force - k moved.
                    out.force = next;
                    out.overlap = overlap - compliance * next;
                    return next;
                }
                p = next;
            } else if hi.is_finite() {
                p = 0.5 * (lo + hi);
            } else {
                p = out.force;
            }
        }
        self.evaluate_into(wheel, gamma, overlap - compliance * p, out);
        p
    }

    /// Overlap (m) at which this law carries `force` (N) for the wheel at axle
    /// rotation `gamma` (rad): the inverse of [`ContactLaw::evaluate`], by bisection to
    /// 1e-16 relative; 0 for `force <= 0`.
    pub fn overlap_for_force(&self, wheel: &WheelProfile, gamma: f64, force: f64) -> f64 {
        if force <= 0.0 {
            return 0.0;
        }
        let mut lo = 0.0;
        let mut hi = 1e-4;
        while self.evaluate(wheel, gamma, hi).force < force && hi < wheel.radius() {
            lo = hi;
            hi *= 2.0;
        }
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if self.evaluate(wheel, gamma, mid).force < force {
                lo = mid;
            } else {
                hi = mid;
            }
            if hi - lo <= 1e-16 * hi {
                break;
            }
        }
        0.5 * (lo + hi)
    }
}
