//! Supports that lift: rail pads and ballast that carry no tension beyond a preload,
//! and hanging (voided) sleepers with a gap between them and the ballast
//! (`docs/MODEL.md`, "Supports that lift"). The thesis names the sleeper's tendency to
//! lift off the ballast as future work (chapter 6).
//!
//! Every support is the thesis' spring and damper while it carries compression, or
//! tension up to its preload; beyond that it lets go and carries the preload's
//! tension only. A linear support has no limit, so with [`SupportLaw::Linear`] and no
//! gaps the track is the thesis' (and steps through the vectorised loops of
//! `kernels.rs`); otherwise the sleeper loop is this file's, the rail loops the same.

use super::*;

/// How the rail pads and the ballast carry load.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SupportLaw {
    /// Linear springs and dampers that pull as they push (the thesis, 3.6-3.9).
    #[default]
    Linear,
    /// Pads and ballast that carry compression, and tension only up to their preload
    /// ([`Supports::pad_preload`], [`Supports::ballast_preload`]): beyond it the rail
    /// lifts off its pad, or the sleeper's seat off the ballast.
    Tensionless,
}

/// The supports' law and preloads.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Supports {
    /// Linear or tensionless.
    pub law: SupportLaw,
    /// Tension a rail pad carries before the rail lifts off it (N per rail seat, 1 N
    /// to 1 MN; default 20 kN): the fastening's clamping force (toe load) that
    /// compresses the pad at rest (typical clips: 2 x 9 to 12 kN per seat), with the
    /// rail's weight on the seat if it is to count. The track's weight is not in the
    /// model (its displacements are from its rest under that weight), so the preload is
    /// what pulls a lifted rail back: a rail held by nothing would float.
    pub pad_preload: f64,
    /// Tension the ballast under a rail seat carries before the seat lifts off it (N,
    /// 1 N to 1 MN; default 1.7 kN): the weight it carries at rest, half the sleeper's
    /// and a span of rail's, `(m_s / 2 + m a) g` = 1.73 kN on table 4.4's track.
    pub ballast_preload: f64,
}

impl Default for Supports {
    /// Linear supports (the thesis); the preloads a tensionless track would take.
    fn default() -> Self {
        Supports {
            law: SupportLaw::Linear,
            pad_preload: 20e3,
            ballast_preload: 1.7e3,
        }
    }
}

impl Supports {
    /// Checks both preloads (1 N to 1 MN: a support that lets go at no tension at all
    /// leaves a weightless rail or sleeper free once it has).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [
            ("track.pad.preload", self.pad_preload),
            ("track.ballast.preload", self.ballast_preload),
        ] {
            if !(1.0..=1e6).contains(&v) {
                return Err(out_of_range(
                    name,
                    v,
                    "1 N <= value <= 1e6 N (the track's weight is not in the model: the \
                     preloads hold a lifted rail or sleeper down)",
                ));
            }
        }
        Ok(())
    }
}

/// The largest gap under a hanging sleeper (m): voids in service are a few
/// millimetres.
pub const MAX_VOID_GAP: f64 = 0.01;

/// The lift time of a support that carries.
pub(super) const CARRIES: f64 = -1.0;

/// The state of supports that can lift: the gaps, the limits, and how long each
/// support has been lifted.
#[derive(Debug, Clone)]
pub(super) struct Unilateral {
    /// Gap between each sleeper and the ballast at rest (m), per sleeper; 0 on the
    /// ballast (or hanging with no gap: see `hanging`).
    pub(super) gap: Vec<f64>,
    /// Whether each sleeper hangs (its ballast never pulls, whatever its gap).
    pub(super) hanging: Vec<bool>,
    /// The sleepers whose supports can lift (a pad or ballast seat with a finite
    /// limit), in order: the others are the linear track's.
    candidates: Vec<usize>,
    /// The candidates' bounce and roll a step back, saved before the vectorised loop
    /// writes a step on over them (m, rad), in the order of `candidates`.
    zp: Vec<f64>,
    fp: Vec<f64>,
    /// Tension a pad carries before it lets go (N); infinite with linear supports.
    pub(super) pad_limit: f64,
    /// Tension the ballast under each sleeper's seats carries before it lets go (N):
    /// 0 under a hanging sleeper, the ballast preload with tensionless supports,
    /// infinite with linear ones.
    pub(super) ballast_limit: Vec<f64>,
    /// Time each pad has been lifted without a break (s; 0 lifted at the static
    /// start), [`CARRIES`] while it carries: the left rail's seats, then the right
    /// rail's (`2 N_s`).
    pub(super) pad_lifted: Vec<f64>,
    /// Time each ballast seat has been lifted without a break (s), as the pads': the
    /// sleepers' left seats, then their right seats (`2 N_s`).
    pub(super) ballast_lifted: Vec<f64>,
    /// The longest lift of any support since the start (s) and its sleeper (an index
    /// of the track at the time, moved with an endless track's window).
    pub(super) longest: f64,
    pub(super) longest_at: i64,
    /// Step (s), ballast stiffness (N/m), `C_b / (2 dt)` (N s/m / s), `m_s / dt^2`,
    /// `J_s / dt^2`, half the seat distance (m).
    dt: f64,
    kb: f64,
    cbh: f64,
    ms: f64,
    js: f64,
    ls: f64,
}

impl Unilateral {
    pub(super) fn new(p: &TrackParams, ns: usize, dt: f64) -> Self {
        let mut u = Unilateral {
            gap: vec![0.0; ns],
            hanging: vec![false; ns],
            candidates: Vec::new(),
            zp: Vec::new(),
            fp: Vec::new(),
            pad_limit: f64::INFINITY,
            ballast_limit: vec![f64::INFINITY; ns],
            pad_lifted: vec![CARRIES; 2 * ns],
            ballast_lifted: vec![CARRIES; 2 * ns],
            longest: 0.0,
            longest_at: 0,
            dt,
            kb: 0.0,
            cbh: 0.0,
            ms: 0.0,
            js: 0.0,
            ls: 0.5 * p.rail_seat_distance,
        };
        u.set_dt(p, dt);
        u.set_limits(p);
        u
    }

    /// The coefficients of step `dt` (s).
    pub(super) fn set_dt(&mut self, p: &TrackParams, dt: f64) {
        self.dt = dt;
        self.kb = p.ballast_stiffness;
        self.cbh = p.ballast_damping / (2.0 * dt);
        self.ms = p.sleeper_mass / (dt * dt);
        self.js = p.sleeper_inertia / (dt * dt);
    }

    /// The limits from the law and the gaps.
    pub(super) fn set_limits(&mut self, p: &TrackParams) {
        let tensionless = p.supports.law == SupportLaw::Tensionless;
        self.pad_limit = if tensionless {
            p.supports.pad_preload
        } else {
            f64::INFINITY
        };
        for (lim, &h) in self.ballast_limit.iter_mut().zip(&self.hanging) {
            *lim = if h {
                0.0
            } else if tensionless {
                p.supports.ballast_preload
            } else {
                f64::INFINITY
            };
        }
        self.candidates = (0..self.gap.len())
            .filter(|&i| tensionless || self.hanging[i])
            .collect();
        self.zp = vec![0.0; self.candidates.len()];
        self.fp = vec![0.0; self.candidates.len()];
    }

    /// Takes one step of lift (or contact) of a support into its time and the longest.
    #[inline]
    fn lift(time: &mut f64, lifted: bool, dt: f64, longest: &mut (f64, i64), sleeper: usize) {
        if lifted {
            *time = time.max(0.0) + dt;
            if *time > longest.0 {
                *longest = (*time, sleeper as i64);
            }
        } else {
            *time = CARRIES;
        }
    }

    /// The ballast forces under the two seats (N, compression positive) of a sleeper
    /// at `(z, f)` now, `(zp, fp)` a step back and `(zn, pn)` a step on, with its gap
    /// `g` (m): `-K_b (u + g) - C_b du/dt`, the velocity a central difference as in
    /// (3.18).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn ballast_forces(
        &self,
        z: f64,
        f: f64,
        zp: f64,
        fp: f64,
        zn: f64,
        pn: f64,
        g: f64,
    ) -> [f64; 2] {
        [-self.ls, self.ls].map(|arm| {
            let (u, un, up) = (z + arm * f, zn + arm * pn, zp + arm * fp);
            -self.kb * (u + g) - self.cbh * (un - up)
        })
    }

    /// The sleeper's bounce and roll a step on (3.18) with the seats `on` carrying by
    /// spring and damper and the others their limit `lim` (N) of tension: the implicit
    /// damping of the carrying seats couples bounce and roll, a 2 x 2 solve. `fl`, `fr`:
    /// the pad forces on the rails (N, up).
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn solve(
        &self,
        z: f64,
        f: f64,
        zp: f64,
        fp: f64,
        fl: f64,
        fr: f64,
        g: f64,
        lim: f64,
        on: [bool; 2],
    ) -> (f64, f64) {
        let (ms, js, c) = (self.ms, self.js, self.cbh);
        let (mut a11, mut a12, mut a22) = (ms, 0.0, js);
        let mut b1 = ms * (2.0 * z - zp) - (fl + fr);
        let mut b2 = js * (2.0 * f - fp) + self.ls * (fl - fr);
        for (s, arm) in [(0, -self.ls), (1, self.ls)] {
            if on[s] {
                let (u, up) = (z + arm * f, zp + arm * fp);
                a11 += c;
                a12 += c * arm;
                a22 += c * arm * arm;
                let r = -self.kb * (u + g) + c * up;
                b1 += r;
                b2 += arm * r;
            } else {
                b1 -= lim;
                b2 -= arm * lim;
            }
        }
        let det = a11 * a22 - a12 * a12;
        ((b1 * a22 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det)
    }

    /// Supports lifted now: pads, ballast seats.
    pub(super) fn lifted_now(&self) -> (usize, usize) {
        let count = |v: &[f64]| v.iter().filter(|&&t| t >= 0.0).count();
        (count(&self.pad_lifted), count(&self.ballast_lifted))
    }
}

/// [`sleepers_body`] with supports that can lift: the vectorised loop for every
/// sleeper as if all its supports carried, then a scan for the sleepers where that is
/// not so (a pad beyond its limit, a ballast seat beyond its limit with the new
/// positions, a hanging sleeper with a gap), which are done again by
/// [`sleeper_with_limits`] from their saved state a step back. Elsewhere the numbers
/// are the linear loop's, bit for bit. Also counts each support's lift.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn sleepers_unilateral<const FMA: bool>(
    rl: &[f64],
    rr: &[f64],
    rlp: &[f64],
    rrp: &[f64],
    zs: &[f64],
    ph: &[f64],
    zsp: &mut [f64],
    php: &mut [f64],
    pl: &mut [f64],
    pr: &mut [f64],
    c: &SleeperCoeffs,
    u: &mut Unilateral,
) {
    let ns = u.gap.len();
    // The candidates a step back, which the loop overwrites with a step on.
    for (k, &i) in u.candidates.iter().enumerate() {
        u.zp[k] = zsp[i];
        u.fp[k] = php[i];
    }
    sleepers_body::<FMA>(rl, rr, rlp, rrp, zs, ph, zsp, php, pl, pr, c);
    let dt = u.dt;
    let pad_lim = u.pad_limit;
    let mut longest = (u.longest, u.longest_at);
    for k in 0..u.candidates.len() {
        let i = u.candidates[k];
        let (g, lim) = (u.gap[i], u.ballast_limit[i]);
        let pads_carry = pl[i] >= -pad_lim && pr[i] >= -pad_lim;
        let fast = pads_carry && g == 0.0 && {
            let (z, f, zp, fp) = (zs[i], ph[i], u.zp[k], u.fp[k]);
            let force = u.ballast_forces(z, f, zp, fp, zsp[i], php[i], 0.0);
            force[0] >= -lim && force[1] >= -lim
        };
        if fast {
            for a in [&mut u.pad_lifted, &mut u.ballast_lifted] {
                a[i] = CARRIES;
                a[ns + i] = CARRIES;
            }
            continue;
        }
        let lifted = sleeper_with_limits::<FMA>(
            [rl[i], rr[i], rlp[i], rrp[i]],
            [zs[i], ph[i]],
            [u.zp[k], u.fp[k]],
            i,
            zsp,
            php,
            pl,
            pr,
            c,
            u,
        );
        Unilateral::lift(&mut u.pad_lifted[i], lifted[0], dt, &mut longest, i);
        Unilateral::lift(&mut u.pad_lifted[ns + i], lifted[1], dt, &mut longest, i);
        Unilateral::lift(&mut u.ballast_lifted[i], lifted[2], dt, &mut longest, i);
        Unilateral::lift(
            &mut u.ballast_lifted[ns + i],
            lifted[3],
            dt,
            &mut longest,
            i,
        );
    }
    (u.longest, u.longest_at) = longest;
}

/// Sleeper `i` of [`sleepers_unilateral`] again with its supports' limits: the rail
/// over its seats now and a step back `[left, right, left back, right back]` (m), its
/// bounce and roll now and a step back (m, rad): the pad
/// forces (3.9) clamped at the pad's limit, then its update (3.18) with the seats
/// whose ballast carries (found by at most three passes; two seats settle at once but
/// for a seat at its limit to rounding), the others at their limit. Writes the pad
/// forces and the sleeper a step on; returns which of `[left pad, right pad, left
/// ballast, right ballast]` are lifted.
// Inlined, so that it is compiled for the SIMD level with its fused multiply-adds (out
// of line, `mul_add` is a library call).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sleeper_with_limits<const FMA: bool>(
    rail: [f64; 4],
    now: [f64; 2],
    back: [f64; 2],
    i: usize,
    zsp: &mut [f64],
    php: &mut [f64],
    pl: &mut [f64],
    pr: &mut [f64],
    c: &SleeperCoeffs,
    u: &Unilateral,
) -> [bool; 4] {
    let [z, f] = now;
    let [zp, fp] = back;
    let (mut fl, mut fr) = c.pad_forces::<FMA>(rail, now, back);
    let lim = u.pad_limit;
    let (lifted_l, lifted_r) = (fl < -lim, fr < -lim);
    if lifted_l {
        fl = -lim;
    }
    if lifted_r {
        fr = -lim;
    }
    pl[i] = fl;
    pr[i] = fr;
    let (g, lim) = (u.gap[i], u.ballast_limit[i]);
    let mut on = [true, true];
    let (mut zn, mut pn) = if g == 0.0 {
        c.sleeper_update::<FMA>(now, back, fl, fr)
    } else {
        u.solve(z, f, zp, fp, fl, fr, g, lim, on)
    };
    if lim.is_finite() {
        for _ in 0..3 {
            let force = u.ballast_forces(z, f, zp, fp, zn, pn, g);
            let carries = force.map(|x| x >= -lim);
            if carries == on {
                break;
            }
            on = carries;
            (zn, pn) = u.solve(z, f, zp, fp, fl, fr, g, lim, on);
        }
    }
    zsp[i] = zn;
    php[i] = pn;
    [lifted_l, lifted_r, !on[0], !on[1]]
}

impl Track {
    /// The hanging (voided) sleepers: per sleeper (`gaps.len()` =
    /// [`TrackParams::spans`] + 1) `None` on the ballast, or `Some(g)`, the gap (m, 0 or
    /// more) between it and the ballast at rest: it hangs from the rails until it has
    /// moved down by its gap, and its ballast never pulls (with `g = 0` it rests on
    /// the ballast without being held down). From this call on the track steps through the loop of supports
    /// that can lift, which gives the linear loop's numbers bit for bit where no
    /// support can lift (all zeros with linear supports: the thesis' track).
    ///
    /// Errors: a gap below 0, above 0.05 m or not finite (named `track.void.gap`), or
    /// the wrong count.
    pub fn set_sleeper_gaps(&mut self, gaps: &[Option<f64>]) -> Result<()> {
        if self.exact.is_some() && gaps.iter().any(Option::is_some) {
            return Err(Error::Unsupported(
                "hanging sleepers (track.void.*) with exact ends: the track beyond the ends \
                 must be linear"
                    .into(),
            ));
        }
        if gaps.len() != self.ns {
            return Err(out_of_range(
                "sleeper gaps",
                gaps.len() as f64,
                format!("one per sleeper: {}", self.ns),
            ));
        }
        for &g in gaps.iter().flatten() {
            if !(0.0..=MAX_VOID_GAP).contains(&g) {
                return Err(out_of_range(
                    "track.void.gap",
                    g,
                    format!("0 m <= gap <= {MAX_VOID_GAP} m"),
                ));
            }
        }
        let (p, ns, dt) = (self.params, self.ns, self.dt);
        let u = self
            .unilateral
            .get_or_insert_with(|| Box::new(Unilateral::new(&p, ns, dt)));
        for (i, g) in gaps.iter().enumerate() {
            u.gap[i] = g.unwrap_or(0.0);
            u.hanging[i] = g.is_some();
        }
        u.set_limits(&p);
        Ok(())
    }

    /// Whether a support can lift (tensionless supports or a gap under a sleeper).
    pub fn supports_can_lift(&self) -> bool {
        self.unilateral.is_some()
    }

    /// Supports lifted now: rail pads (of both rails), ballast seats (two per sleeper).
    pub fn lifted_supports(&self) -> (usize, usize) {
        self.unilateral.as_ref().map_or((0, 0), |u| u.lifted_now())
    }

    /// The longest lift of any support (pad or ballast seat) since the start (s) and
    /// its sleeper's index in the track as it is now (below 0 when an endless track's
    /// window has left it behind); `(0, 0)` when none has lifted.
    pub fn longest_lift(&self) -> (f64, i64) {
        self.unilateral
            .as_ref()
            .map_or((0.0, 0), |u| (u.longest, u.longest_at))
    }

    /// Whether the pad of `rail` (0 left, 1 right) on sleeper `i` and the ballast under
    /// that seat are lifted now.
    pub fn lifted(&self, rail: usize, i: usize) -> (bool, bool) {
        self.unilateral.as_ref().map_or((false, false), |u| {
            let at = rail.min(1) * self.ns + i;
            (u.pad_lifted[at] >= 0.0, u.ballast_lifted[at] >= 0.0)
        })
    }

    /// How long the pad of `rail` (0 left, 1 right) on sleeper `i` and the ballast
    /// under that seat have been lifted without a break (s); 0 while they carry.
    pub fn lift_times(&self, rail: usize, i: usize) -> (f64, f64) {
        self.unilateral.as_ref().map_or((0.0, 0.0), |u| {
            let at = rail.min(1) * self.ns + i;
            (u.pad_lifted[at].max(0.0), u.ballast_lifted[at].max(0.0))
        })
    }
}
