//! Wheel-rail normal contact: the seed's adaptive radial-spring model (2.1-2.8,
//! 2.22-2.26) and Hertz point contact (1.3) for comparison.
//!
//! The adaptive force is the integral of the radial springs over the region where
//! they are compressed:
//!
//! `P = K_w * integral of max(0, R(alpha) cos(alpha) - h) d alpha`, `h = R_w - delta_c`,
//!
//! over `|alpha| <= acos(h / R_w)`. With no flat in that range it is the closed form
//! (2.5); otherwise the sign changes of the integrand are bracketed and refined, and
//! every contact interval is integrated by Gauss-Legendre quadrature, so full, partial,
//! asymmetric and split patches are all exact to quadrature accuracy.

use crate::error::{Result, out_of_range, positive};
use crate::numerics::{LANES, SMALL_ANGLE, SimdLevel, cos_poly, cos_small, inlined, wrap_angle};
use crate::wheel::{FlattedWheel, MAX_FLATS, WheelProfile};
use std::sync::OnceLock;

/// Which normal-contact law to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactModel {
    /// The seed's adaptive radial-spring contact (2.8).
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

/// What the contact model reports for one wheel at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactState {
    /// Normal contact force `P` (N), >= 0, pushes the wheel up and the rail down.
    pub force: f64,
    /// Overlap `delta_c = z_rail - z_wheel` (m) (2.7); negative when apart.
    pub overlap: f64,
    /// Front contact angle `alpha_f` (rad), the foremost compressed spring (2.22);
    /// 0 when out of contact.
    pub front_angle: f64,
    /// Rear contact angle `alpha_r` (rad), the rearmost compressed spring (2.22).
    pub rear_angle: f64,
    /// Contact length along the rail between the rear and front contact points (m),
    /// `h (tan alpha_f - tan alpha_r)`.
    pub length: f64,
    /// Number of separate contact intervals (0: loss of contact, 2 or more: split patch).
    pub intervals: u32,
}

impl ContactState {
    /// True when the wheel has lost contact with the rail.
    pub fn lost(&self) -> bool {
        self.intervals == 0
    }
}

/// Radial spring stiffness from a Hertz coefficient and a static load (2.25, 2.26):
/// `delta_0 = (P_0 / C_H)^(2/3)`, `K_w = P_0 / (2 R_w (sin a - a cos a))`, `a = acos((R_w - delta_0)/R_w)`.
pub fn kw_from_hertz(ch: f64, static_load: f64, radius: f64) -> Result<f64> {
    positive("contact.CH", ch, "N/m^1.5")?;
    positive("static wheel load", static_load, "N")?;
    positive("wheel.radius", radius, "m")?;
    let delta0 = (static_load / ch).powf(2.0 / 3.0);
    if delta0 >= radius {
        return Err(out_of_range(
            "contact.CH",
            ch,
            "large enough that the static overlap is below the wheel radius",
        ));
    }
    // The same closed form the adaptive law evaluates, so P(delta_0) = P_0 to rounding.
    Ok(static_load / (2.0 * radius * perfect_patch(delta0, radius).1))
}

/// Perfect-wheel patch angle `alpha_w = acos((R_w - delta)/R_w)` (2.6), computed as
/// `2 asin(sqrt(delta / (2 R_w)))` to keep precision at small overlap.
#[inline]
pub fn patch_angle(delta: f64, radius: f64) -> f64 {
    perfect_patch(delta, radius).0
}

/// Perfect-wheel patch at overlap `delta` (m) on a wheel of radius `radius` (m):
/// the patch angle `alpha_w` (rad), `sin alpha_w - alpha_w cos alpha_w` (the force
/// (2.5) over `2 K_w R_w`) and `s^2 = sin^2(alpha_w / 2) = delta / (2 R_w)`.
///
/// For `s <= 0.05` (overlaps up to about 2.4 mm on a 0.475 m wheel) both are power
/// series in `s^2` times a power of `s`: `alpha_w = 2 asin s = 2 s P(s^2)` and
/// `sin alpha_w - alpha_w cos alpha_w = s^3 Q(s^2)` (the first omitted terms are below
/// 1e-19 relative), so the square root and the polynomials run side by side and the
/// cancellation of the difference never happens. Above, the library functions.
#[inline]
fn perfect_patch(delta: f64, radius: f64) -> (f64, f64, f64) {
    perfect_patch_scaled(delta * (0.5 / radius))
}

/// [`perfect_patch`] of `x = delta / (2 R_w)`.
#[inline]
fn perfect_patch_scaled(x: f64) -> (f64, f64, f64) {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.0025 {
        let s = x.sqrt();
        (
            2.0 * s * estrin7(&ASIN_OVER_S, x),
            s * x * estrin7(&SIN_MINUS_X_COS_OVER_S3, x),
            x,
        )
    } else {
        let a = 2.0 * x.sqrt().asin();
        (a, a.sin() - a * a.cos(), x)
    }
}

/// `c0 + c1 x + ... + c6 x^6` by Estrin's scheme.
#[inline]
fn estrin7(c: &[f64; 7], x: f64) -> f64 {
    let x2 = x * x;
    (c[0] + c[1] * x) + (c[2] + c[3] * x) * x2 + ((c[4] + c[5] * x) + c[6] * x2) * (x2 * x2)
}

/// `asin(s) / s` in powers of `s^2`: `(2k)! / (4^k (k!)^2 (2k + 1))`.
const ASIN_OVER_S: [f64; 7] = [
    1.0,
    1.0 / 6.0,
    3.0 / 40.0,
    5.0 / 112.0,
    35.0 / 1152.0,
    63.0 / 2816.0,
    231.0 / 13312.0,
];

/// `(sin a - a cos a) / s^3` with `a = 2 asin s`, in powers of `s^2` (series of
/// `2 s sqrt(1 - s^2) - 2 asin(s) (1 - 2 s^2)`, exact rationals).
const SIN_MINUS_X_COS_OVER_S3: [f64; 7] = [
    8.0 / 3.0,
    4.0 / 15.0,
    3.0 / 35.0,
    5.0 / 126.0,
    35.0 / 1584.0,
    63.0 / 4576.0,
    77.0 / 8320.0,
];

/// `sin a - a`, by its series below 0.1 rad.
#[inline]
fn sin_minus_x(a: f64) -> f64 {
    if a.abs() < 0.1 {
        let a2 = a * a;
        -a * a2 * (1.0 / 6.0 + a2 * (-1.0 / 120.0 + a2 * (1.0 / 5040.0 - a2 / 362880.0)))
    } else {
        a.sin() - a
    }
}

/// Perfect-wheel closed form (2.5): `P = 2 K_w R_w (sin a - a cos a)`.
#[inline]
pub fn perfect_wheel_force(kw: f64, radius: f64, delta: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    2.0 * kw * radius * perfect_patch(delta, radius).1
}

/// Number of Gauss-Legendre points per contact interval.
const GAUSS_POINTS: usize = LANES;
/// Samples per flat-covered piece used to bracket sign changes. Crossings that fall
/// between two samples of the same sign are found through the curvature bound (see
/// [`positive_point`]), so the count trades speed, not exactness: 4, 6, 8 and 12 all
/// pass the flat-passage sweep at its 2.1e-8 floor; 8 keeps every search interval
/// narrow enough for one extremum.
const BRACKET_SAMPLES: usize = 8;

fn gauss_legendre() -> &'static ([f64; GAUSS_POINTS], [f64; GAUSS_POINTS]) {
    static GL: OnceLock<([f64; GAUSS_POINTS], [f64; GAUSS_POINTS])> = OnceLock::new();
    GL.get_or_init(|| {
        let n = GAUSS_POINTS;
        let mut x = [0.0; GAUSS_POINTS];
        let mut w = [0.0; GAUSS_POINTS];
        for i in 0..n {
            // Newton on the Legendre polynomial from Tricomi's initial guess.
            let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut dp = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, z);
                for k in 2..=n {
                    let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                    p0 = p1;
                    p1 = p2;
                }
                dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
                let dz = p1 / dp;
                z -= dz;
                if dz.abs() < 1e-16 {
                    break;
                }
            }
            x[i] = z;
            w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
        }
        (x, w)
    })
}

impl ContactLaw {
    /// An adaptive law with radial stiffness `kw` (N/m/rad).
    pub fn adaptive(kw: f64) -> Result<Self> {
        positive("contact.Kw", kw, "N/m/rad")?;
        Ok(ContactLaw {
            model: ContactModel::Adaptive,
            kw,
            ch: 0.0,
        })
    }

    /// A Hertz law with coefficient `ch` (N/m^1.5).
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
    /// scheme ([`crate::track::TrackParams::critical_time_step_with_contact`]).
    pub fn stiffness(&self, wheel: &WheelProfile, gamma: f64, force: f64) -> f64 {
        let d = self.overlap_for_force(wheel, gamma, force);
        let e = 1e-6 * d;
        let p = |x: f64| self.evaluate(wheel, gamma, x).force;
        (p(d + e) - p(d - e)) / (2.0 * e)
    }

    /// Contact state for a wheel with profile `wheel` at axle rotation `gamma` (rad)
    /// and overlap `overlap = z_rail - z_wheel` (m).
    #[inline(always)]
    pub fn evaluate(&self, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
        let mut state = ContactState::default();
        self.evaluate_into(wheel, gamma, overlap, &mut state);
        state
    }

    /// [`ContactLaw::evaluate`] written into `out`, the caller's own place for the
    /// state. The coupled step writes the states where its sample keeps them: a state
    /// built in a temporary and copied at once stalled the copy's wide loads on the
    /// narrow stores that had just built it.
    #[inline(always)]
    pub fn evaluate_into(
        &self,
        wheel: &WheelProfile,
        gamma: f64,
        overlap: f64,
        out: &mut ContactState,
    ) {
        match self.model {
            ContactModel::Adaptive => adaptive(self.kw, wheel, gamma, overlap, false, out),
            ContactModel::Hertz => *out = self.hertz_state(wheel, gamma, overlap),
        }
    }

    fn hertz_state(&self, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
        let f0 = wheel.reduction(0.0, gamma);
        let d = overlap - f0;
        if d <= 0.0 {
            return ContactState {
                overlap,
                ..Default::default()
            };
        }
        // The Hertz law knows no patch; report the geometric overlap patch of a
        // circle of the nominal radius pressed in by d.
        let a = patch_angle(d, wheel.radius());
        let h = wheel.radius() - d;
        ContactState {
            force: self.ch * d * d.sqrt(),
            overlap,
            front_angle: a,
            rear_angle: -a,
            length: 2.0 * h * a.tan(),
            intervals: 1,
        }
    }

    /// Overlap (m) at which this law carries `force` (N) for the wheel at axle
    /// rotation `gamma` (inverse of [`ContactLaw::evaluate`], by bisection).
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

/// Adaptive force by numerical integration even for a perfect wheel; for tests and
/// for checking the closed form.
pub fn adaptive_numeric(kw: f64, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
    let mut state = ContactState::default();
    adaptive(kw, wheel, gamma, overlap, true, &mut state);
    state
}

/// The adaptive law's state, written into `out`; by quadrature everywhere with
/// `force_numeric`. Each kind of wheel profile has its own integral.
#[inline(always)]
fn adaptive(
    kw: f64,
    wheel: &WheelProfile,
    gamma: f64,
    overlap: f64,
    force_numeric: bool,
    out: &mut ContactState,
) {
    match wheel {
        WheelProfile::Flatted(w) => flatted(kw, w, gamma, overlap, force_numeric, out),
    }
}

/// [`adaptive`] for the nominal circle with flats: the closed form (2.5) when no flat
/// reaches into the perfect-wheel patch, else the integral.
#[inline(always)]
fn flatted(
    kw: f64,
    wheel: &FlattedWheel,
    gamma: f64,
    overlap: f64,
    force_numeric: bool,
    out: &mut ContactState,
) {
    let rw = wheel.radius();
    if overlap <= 0.0 || overlap.is_nan() {
        *out = ContactState {
            overlap,
            ..Default::default()
        };
        return;
    }
    let delta = overlap.min(rw);
    let (aw, sin_minus_x_cos_aw, s2) = perfect_patch_scaled(delta * wheel.half_inv_radius());
    // Flats whose window (space angles) reaches into [-aw, aw], with their centres.
    let mut near = [(0.0f64, 0usize); MAX_FLATS];
    let mut nf = 0;
    for (i, fl) in wheel.flats().iter().enumerate() {
        let c = wrap_angle(fl.angle - gamma);
        if c + fl.half_angle > -aw && c - fl.half_angle < aw {
            near[nf] = (c, i);
            nf += 1;
        }
    }
    if nf == 0 && !force_numeric {
        // sin(alpha_w) = 2 s sqrt(1 - s^2) with s = sin(alpha_w / 2) = sqrt(delta / 2 R_w).
        *out = ContactState {
            force: 2.0 * kw * rw * sin_minus_x_cos_aw,
            overlap,
            front_angle: aw,
            rear_angle: -aw,
            length: 4.0 * rw * (s2 * (1.0 - s2)).sqrt(),
            intervals: 1,
        };
        return;
    }
    *out = adaptive_flats(kw, wheel, &near[..nf], overlap, delta, aw, force_numeric);
}

/// The adaptive integral when flats reach into the patch `[-aw, aw]` (rad) at overlap
/// `delta` (m) (or always, with `force_numeric`). `near`: those flats, as (centre
/// space angle, index in the wheel's flats); their windows lie within `pi` of the
/// patch, so a space angle `x` sits at `x - centre` from a flat's centre, unwrapped.
///
/// Compiled once per instruction set (AVX-512, AVX2, baseline: the widest this CPU
/// has) and dispatched here:
/// the integrand is evaluated [`LANES`] points at a time where it can be, and those
/// evaluations vectorise. No FMA at any level, so every level gives the same bits.
#[inline(never)]
fn adaptive_flats(
    kw: f64,
    wheel: &FlattedWheel,
    near: &[(f64, usize)],
    overlap: f64,
    delta: f64,
    aw: f64,
    force_numeric: bool,
) -> ContactState {
    SimdLevel::detect().run(
        #[inline(always)]
        || adaptive_flats_body(kw, wheel, near, overlap, delta, aw, force_numeric),
    )
}

/// [`adaptive_flats`], inlined into each instruction set's copy.
#[inline(always)]
fn adaptive_flats_body(
    kw: f64,
    wheel: &FlattedWheel,
    near: &[(f64, usize)],
    overlap: f64,
    delta: f64,
    aw: f64,
    force_numeric: bool,
) -> ContactState {
    let rw = wheel.radius();
    let h = rw - delta;
    let flats = wheel.flats();
    // The closures are marked `#[inline(always)]` (through `inlined`, as attributes on
    // closures are allowed only in argument position) so that they are compiled into
    // each instruction set's copy of this function, not once for the baseline.
    let reduction_of = inlined(
        #[inline(always)]
        |j: usize, x: f64| {
            let (c, i) = near[j];
            flats[i].reduction(x - c)
        },
    );
    let g = inlined(
        #[inline(always)]
        |x: f64| {
            let mut f = 0.0f64;
            for j in 0..near.len() {
                f = f.max(reduction_of(j, x));
            }
            (rw - f) * cos_small(x) - h
        },
    );
    // `g` at LANES points at once, vectorised, the same bits as `g` point by point.
    let g_lanes = inlined(
        #[inline(always)]
        |xs: &[f64; LANES]| -> [f64; LANES] {
            let mut f = [0.0f64; LANES];
            let mut small = xs.iter().fold(true, |ok, x| ok & (x.abs() <= SMALL_ANGLE));
            for &(c, i) in near {
                match flats[i].reduction_lanes(&xs.map(|x| x - c)) {
                    Some(r) => (0..LANES).for_each(|l| f[l] = f[l].max(r[l])),
                    None => small = false,
                }
            }
            if small {
                std::array::from_fn(|l| (rw - f[l]) * cos_poly(xs[l]) - h)
            } else {
                xs.map(g)
            }
        },
    );
    let covered = |x: f64| {
        near.iter()
            .any(|&(c, i)| (x - c).abs() < flats[i].half_angle)
    };
    // Where overlapping flats hand over, the larger reduction wins: the flat that
    // shapes the wheel at x (an index into `near`).
    let several = near.len() > 1;
    let dominant = |x: f64| {
        if !several {
            return None;
        }
        let (mut best, mut f) = (None, 0.0f64);
        for j in 0..near.len() {
            let r = reduction_of(j, x);
            if r > f {
                f = r;
                best = Some(j);
            }
        }
        best
    };
    // |g''| <= R_w + 2 max(|f'| + |f''|) (the flats' `bend_bound`): between samples d
    // apart g rises at most `rise d^2` above the larger end value (plus rounding).
    let bend = near
        .iter()
        .map(|&(_, i)| flats[i].bend_bound())
        .fold(0.0, f64::max);
    let rise = (rw + 2.0 * bend) / 8.0;

    // Piece edges: the patch ends and the flat window edges inside the patch.
    let mut edges = [0.0f64; 2 * MAX_FLATS + 2];
    let mut ne = 0;
    edges[ne] = -aw;
    ne += 1;
    for &(c, i) in near {
        let ha = flats[i].half_angle;
        for e in [c - ha, c + ha] {
            if e > -aw && e < aw {
                edges[ne] = e;
                ne += 1;
            }
        }
    }
    edges[ne] = aw;
    ne += 1;
    edges[..ne].sort_unstable_by(|a, b| a.total_cmp(b));

    // Break points: piece edges, every sign change of g inside flat-covered pieces,
    // the ends of contact slivers between samples, and where overlapping flats hand
    // over (a kink that quadrature must not straddle).
    let mut brk = [0.0f64; MAX_BREAKS];
    let mut nb = 0;
    for p in 0..ne - 1 {
        let (a, b) = (edges[p], edges[p + 1]);
        if nb < MAX_BREAKS {
            brk[nb] = a;
            nb += 1;
        }
        if b <= a || (!force_numeric && !covered(0.5 * (a + b))) {
            continue;
        }
        // Samples of g, with the hand-over points of overlapping flats inserted.
        let m = BRACKET_SAMPLES;
        let mut xs = [0.0f64; 2 * BRACKET_SAMPLES + 2];
        let mut gs = [0.0f64; 2 * BRACKET_SAMPLES + 2];
        xs[0] = a;
        gs[0] = g(a);
        let mut nn = 1;
        let mut roots = [0.0f64; 4 * BRACKET_SAMPLES + 4];
        let mut nr = 0;
        // Sample positions after `a`, the last one `b`.
        let x_samples: [f64; BRACKET_SAMPLES] = std::array::from_fn(|k| {
            let s = k + 1;
            if s == m {
                b
            } else {
                a + (b - a) * s as f64 / m as f64
            }
        });
        if !several {
            // One flat: no hand-over points; the samples at once.
            xs[1..=m].copy_from_slice(&x_samples);
            gs[1..=m].copy_from_slice(&g_lanes(&x_samples));
            nn = m + 1;
        } else {
            let mut top0 = dominant(a);
            for &x1 in &x_samples {
                let top1 = dominant(x1);
                if let (Some(i), Some(j)) = (top0, top1)
                    && i != j
                {
                    let d = inlined(
                        #[inline(always)]
                        |x: f64| reduction_of(i, x) - reduction_of(j, x),
                    );
                    let (x0, x1) = (xs[nn - 1], x1);
                    let xc = refine_root(&d, x0, d(x0), x1, d(x1));
                    roots[nr] = xc;
                    nr += 1;
                    xs[nn] = xc;
                    gs[nn] = g(xc);
                    nn += 1;
                }
                xs[nn] = x1;
                gs[nn] = g(x1);
                nn += 1;
                top0 = top1;
            }
        }
        // Between two samples: a sign change is a contact end. Two non-positive ends
        // may still hide a sliver of contact, two positive ends a gap, where the
        // curvature bound lets g cross zero in between; these are searched for.
        let neg_g = inlined(
            #[inline(always)]
            |x: f64| -g(x),
        );
        for k in 0..nn - 1 {
            let (g0, g1) = (gs[k], gs[k + 1]);
            let d = xs[k + 1] - xs[k];
            let slack = rise * d * d + ROUNDING;
            let pair = if (g0 > 0.0) != (g1 > 0.0) {
                roots[nr] = refine_root(&g, xs[k], g0, xs[k + 1], g1);
                nr += 1;
                None
            } else if g0 <= 0.0 {
                if g0.max(g1) + slack > 0.0 {
                    sliver(&g, xs[k], g0, xs[k + 1], g1, rise)
                } else {
                    None
                }
            } else if g0.min(g1) - slack <= 0.0 {
                sliver(&neg_g, xs[k], -g0, xs[k + 1], -g1, rise)
            } else {
                None
            };
            if let Some((r0, r1)) = pair {
                roots[nr] = r0;
                roots[nr + 1] = r1;
                nr += 2;
            }
        }
        roots[..nr].sort_unstable_by(|a, b| a.total_cmp(b));
        for &r in &roots[..nr] {
            if nb < MAX_BREAKS {
                brk[nb] = r;
                nb += 1;
            }
        }
    }
    if nb < MAX_BREAKS {
        brk[nb] = aw;
        nb += 1;
    }

    let mut integral = 0.0;
    let mut front = 0.0;
    let mut rear = 0.0;
    let mut intervals = 0u32;
    let mut in_contact = false;
    for i in 0..nb - 1 {
        let (a, b) = (brk[i], brk[i + 1]);
        if b <= a {
            continue;
        }
        let mid = 0.5 * (a + b);
        let nominal = !force_numeric && !covered(mid);
        let inside = nominal || g(mid) > 0.0;
        if inside {
            integral += if nominal {
                // R = R_w here: integral of R_w cos(alpha) - h, written without cancellation.
                rw * (sin_minus_x(b) - sin_minus_x(a)) + delta * (b - a)
            } else {
                gauss(&g_lanes, a, b)
            };
            if !in_contact {
                intervals += 1;
                if intervals == 1 {
                    rear = a;
                }
            }
            front = b;
        }
        in_contact = inside;
    }
    if intervals == 0 {
        return ContactState {
            overlap,
            ..Default::default()
        };
    }
    ContactState {
        force: kw * integral,
        overlap,
        front_angle: front,
        rear_angle: rear,
        length: h * (front.tan() - rear.tan()),
        intervals,
    }
}

/// Rounding allowance (m) in the curvature test for slivers: far above the rounding
/// of one evaluation of the integrand (about 1e-16 R_w).
const ROUNDING: f64 = 1e-15;

/// Capacity of the break-point list of one evaluation.
const MAX_BREAKS: usize = 4 * MAX_FLATS + 2 * BRACKET_SAMPLES + 8;

/// Root of `g` in `[lo, hi]` (where `g` changes sign; `glo`, `ghi` its values there)
/// by the Anderson-Bjorck variant of regula falsi (order about 1.7; the end kept
/// twice has its value scaled by `1 - g(c)/g(b)`, or halved as in Illinois when that
/// is not positive), ended at 1e-15 rad. The bracket `[a, b]` may be reversed; `b`
/// is always the newest point.
#[inline(always)]
fn refine_root<G: Fn(f64) -> f64>(g: &G, lo: f64, glo: f64, hi: f64, ghi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    let (mut fa, mut fb) = (glo, ghi);
    for _ in 0..100 {
        if (b - a).abs() <= 1e-15 {
            break;
        }
        let denom = fb - fa;
        let mut c = if denom != 0.0 {
            b - fb * (b - a) / denom
        } else {
            0.5 * (a + b)
        };
        if !(c > a.min(b) && c < a.max(b)) {
            c = 0.5 * (a + b);
        }
        let fc = g(c);
        if fc == 0.0 {
            return c;
        }
        if (fc > 0.0) != (fb > 0.0) {
            // The root lies between b and c: b becomes the kept end.
            (a, fa) = (b, fb);
        } else {
            // a is kept again: scale its value down.
            let m = 1.0 - fc / fb;
            fa *= if m > 0.0 { m } else { 0.5 };
        }
        (b, fb) = (c, fc);
    }
    0.5 * (a + b)
}

/// A point of `[lo, hi]` where `g` is positive, and `g` there, if golden-section search for the
/// maximum of `g` (unimodal there) finds one; `None` once the values found and the
/// curvature bound (`g` rises at most `rise w^2` above the larger end value of an
/// interval `w` wide) show that `g` stays non-positive, or the interval is below
/// 1e-13 rad. `glo`, `ghi`: `g` at the ends.
#[inline(always)]
fn positive_point<G: Fn(f64) -> f64>(
    g: &G,
    lo: f64,
    glo: f64,
    hi: f64,
    ghi: f64,
    rise: f64,
) -> Option<(f64, f64)> {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let (mut a, mut b, mut ga, mut gb) = (lo, hi, glo, ghi);
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    for _ in 0..200 {
        if gc > 0.0 {
            return Some((c, gc));
        }
        if gd > 0.0 {
            return Some((d, gd));
        }
        let w = (c - a).max(d - c).max(b - d);
        if b - a < 1e-13 || ga.max(gb).max(gc).max(gd) + rise * w * w + ROUNDING <= 0.0 {
            break;
        }
        if gc > gd {
            (b, gb) = (d, gd);
            (d, gd) = (c, gc);
            c = b - INV_PHI * (b - a);
            gc = g(c);
        } else {
            (a, ga) = (c, gc);
            (c, gc) = (d, gd);
            d = a + INV_PHI * (b - a);
            gd = g(d);
        }
    }
    None
}

/// Ends of a contact sliver of `g` between `lo` and `hi`, where `g` is non-positive
/// (`glo`, `ghi`), or `None` when `g` stays non-positive there (see
/// [`positive_point`]). Each end is bracketed between the positive point found and
/// the nearer end of the interval.
#[inline(always)]
fn sliver<G: Fn(f64) -> f64>(
    g: &G,
    lo: f64,
    glo: f64,
    hi: f64,
    ghi: f64,
    rise: f64,
) -> Option<(f64, f64)> {
    let (xp, gp) = positive_point(g, lo, glo, hi, ghi, rise)?;
    Some((
        refine_root(g, lo, glo, xp, gp),
        refine_root(g, xp, gp, hi, ghi),
    ))
}

/// Gauss-Legendre integral of `max(g, 0)` over `[a, b]`, `g_lanes` evaluating `g` at
/// all points at once.
#[inline(always)]
fn gauss<G: Fn(&[f64; LANES]) -> [f64; LANES]>(g_lanes: &G, a: f64, b: f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let (x, w) = gauss_legendre();
    let c = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let gx = g_lanes(&std::array::from_fn(|i| c + r * x[i]));
    let mut s = 0.0;
    for i in 0..GAUSS_POINTS {
        s += w[i] * gx[i].max(0.0);
    }
    s * r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wheel::{FlatSpec, WheelProfile};

    const R: f64 = 0.475;
    const KW: f64 = 3.3443e10;

    fn brute_force(kw: f64, w: &WheelProfile, gamma: f64, delta: f64, n: usize) -> f64 {
        let aw = patch_angle(delta, w.radius());
        let h = w.radius() - delta;
        let da = 2.0 * aw / n as f64;
        let mut s = 0.0;
        for i in 0..n {
            let a = -aw + (i as f64 + 0.5) * da;
            s += (w.radius_at(a, gamma) * a.cos() - h).max(0.0);
        }
        kw * s * da
    }

    #[test]
    fn integral_equals_closed_form_for_perfect_wheel() {
        let w = WheelProfile::perfect(R).unwrap();
        for delta in [1e-7, 1e-6, 3e-5, 1e-4, 5e-4, 2e-3] {
            let closed = perfect_wheel_force(KW, R, delta);
            let num = adaptive_numeric(KW, &w, 0.0, delta).force;
            let fast = ContactLaw::adaptive(KW)
                .unwrap()
                .evaluate(&w, 0.0, delta)
                .force;
            // Independent form of (2.5) with the textbook acos.
            let a = ((R - delta) / R).acos();
            let textbook = 2.0 * KW * R * (a.sin() - a * a.cos());
            assert!(
                ((num - closed) / closed).abs() < 1e-9,
                "{delta}: {num} vs {closed}"
            );
            assert_eq!(fast, closed);
            assert!(((textbook - closed) / closed).abs() < 1e-6);
        }
    }

    #[test]
    fn small_overlap_law_is_hertz_like() {
        for delta in [1e-7, 1e-6, 1e-5, 1e-4] {
            let p = perfect_wheel_force(KW, R, delta);
            let law = 4.0 * 2f64.sqrt() / 3.0 * KW / R.sqrt() * delta.powf(1.5);
            assert!(((p - law) / law).abs() < 0.01, "{delta}: {p} vs {law}");
        }
    }

    #[test]
    fn kw_calibration_reproduces_static_load() {
        let (ch, p0) = (0.87e11, 82e3);
        let kw = kw_from_hertz(ch, p0, 0.4572).unwrap();
        let d0 = (p0 / ch).powf(2.0 / 3.0);
        let p = perfect_wheel_force(kw, 0.4572, d0);
        assert!(((p - p0) / p0).abs() < 1e-12);
        // Small-angle limit: K_w = 3 C_H sqrt(R) / (4 sqrt 2).
        let approx = 3.0 * ch * 0.4572f64.sqrt() / (4.0 * 2f64.sqrt());
        assert!(((kw - approx) / approx).abs() < 1e-3);
    }

    #[test]
    fn short_flat_inside_patch_splits_it_and_matches_brute_force() {
        // 8 mm x 0.3 mm flat, slightly off centre, inside a ~19 mm patch.
        let w = WheelProfile::new(R, &[FlatSpec::haversine(0.008, 0.0003, 0.002)], "f").unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        let delta = 1e-4;
        let st = law.evaluate(&w, 0.0, delta);
        assert_eq!(st.intervals, 2, "{st:?}");
        let bf = brute_force(KW, &w, 0.0, delta, 100_000);
        assert!(
            ((st.force - bf) / bf).abs() < 1e-6,
            "{} vs {}",
            st.force,
            bf
        );
        // The patch keeps its perfect-wheel ends.
        let aw = patch_angle(delta, R);
        assert!((st.front_angle - aw).abs() < 1e-12 && (st.rear_angle + aw).abs() < 1e-12);
        assert!(st.force < perfect_wheel_force(KW, R, delta));
    }

    #[test]
    fn partial_and_asymmetric_contact_match_brute_force() {
        let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        for (gamma, delta) in [
            (-0.09, 2e-4),
            (-0.1, 1e-3),
            (0.05, 1.6e-3),
            (0.0, 1.8e-3),
            (0.11, 3e-4),
        ] {
            let st = law.evaluate(&w, gamma, delta);
            let bf = brute_force(KW, &w, gamma, delta, 200_000);
            if bf == 0.0 {
                assert_eq!(st.force, 0.0);
                assert!(st.lost());
                continue;
            }
            assert!(
                ((st.force - bf) / bf).abs() < 1e-6,
                "{gamma} {delta}: {} vs {}",
                st.force,
                bf
            );
            // Extreme contact points satisfy R(alpha) cos(alpha) = h (2.22).
            let h = R - delta;
            for a in [st.front_angle, st.rear_angle] {
                let aw = patch_angle(delta, R);
                if (a.abs() - aw).abs() > 1e-12 {
                    assert!((w.radius_at(a, gamma) * a.cos() - h).abs() < 1e-12);
                }
            }
        }
        // Flat entering from the front: the front edge recedes, the rear stays at -alpha_w.
        let delta = 2e-4;
        let aw = patch_angle(delta, R);
        let st = law.evaluate(&w, -0.095, delta);
        assert!(
            st.front_angle < aw - 1e-6 && (st.rear_angle + aw).abs() < 1e-12,
            "{st:?}"
        );
    }

    #[test]
    fn flat_passage_sweep_matches_brute_force() {
        // Every axle angle across the passage of a haversine flat, a chord flat and a
        // pair of overlapping flats, at light, static and heavy overlap: the adaptive
        // integral against a 200,000-point midpoint sum of the radial springs.
        let wheels = [
            WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap(),
            WheelProfile::new(R, &[FlatSpec::chord(0.06, 0.0)], "f").unwrap(),
            WheelProfile::new(
                R,
                &[
                    FlatSpec::haversine(0.05, 0.0004, 0.0),
                    FlatSpec::haversine(0.03, 0.0006, 0.03),
                ],
                "f",
            )
            .unwrap(),
        ];
        let law = ContactLaw::adaptive(KW).unwrap();
        let mut worst: f64 = 0.0;
        let mut evaluated = 0;
        for w in &wheels {
            for delta in [5e-5, 1.5e-4, 6e-4] {
                for i in 0..=40 {
                    let gamma = -0.16 + 0.32 * i as f64 / 40.0;
                    let st = law.evaluate(w, gamma, delta);
                    let bf = brute_force(KW, w, gamma, delta, 200_000);
                    let scale = perfect_wheel_force(KW, R, delta);
                    worst = worst.max((st.force - bf).abs() / scale);
                    evaluated += 1;
                }
            }
        }
        assert_eq!(evaluated, 3 * 3 * 41);
        // The midpoint sum itself is good to about 1e-8 of the perfect-wheel force.
        assert!(
            worst < 1e-7,
            "worst error {worst:e} of the perfect-wheel force"
        );
    }

    #[test]
    fn small_angle_cosine_is_the_cosine() {
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let a = -0.25 + 0.5 * i as f64 / 20_000.0;
            worst = worst.max((cos_small(a) - a.cos()).abs());
        }
        assert!(worst <= 2.3e-16, "{worst:e}");
    }

    #[test]
    fn small_arcsine_is_the_arcsine() {
        // The series patch angle 2 s P(s^2) against the library arcsine, across the
        // switch to the library at s = 0.05.
        let mut worst: f64 = 0.0;
        for i in 1..=20_000 {
            let s = 0.06 * i as f64 / 20_000.0;
            let (a, _, x) = perfect_patch(2.0 * R * s * s, R);
            let want = 2.0 * x.sqrt().asin();
            worst = worst.max(((a - want) / want).abs());
        }
        assert!(worst < 6e-16, "{worst:e}");
        // The series s^3 Q(s^2) for sin a - a cos a against its alternating Taylor
        // series in a (no cancellation), summed to convergence in f64.
        let mut worst: f64 = 0.0;
        for i in 1..=2_000 {
            let s = 0.05 * i as f64 / 2_000.0;
            let (a, got, _) = perfect_patch(2.0 * R * s * s, R);
            // sum over n >= 1 of (-1)^(n+1) 2n a^(2n+1) / (2n+1)!
            let (mut term, mut want) = (a * a * a / 3.0, 0.0);
            for n in 1..30 {
                want += term;
                let n = n as f64;
                term *= -a * a * (2.0 * n + 2.0) / (2.0 * n * (2.0 * n + 2.0) * (2.0 * n + 3.0));
            }
            worst = worst.max(((got - want) / want).abs());
        }
        // The reference starts from the rounded angle (2 ulp), an error that the
        // cube-like growth of sin a - a cos a triples.
        assert!(worst < 2e-15, "sin a - a cos a: {worst:e}");
        // Perfect-wheel patch length from the identity against the direct sine.
        let law = ContactLaw::adaptive(KW).unwrap();
        let w = WheelProfile::perfect(R).unwrap();
        for delta in [1e-6, 1e-4, 2e-3, 0.01] {
            let st = law.evaluate(&w, 0.0, delta);
            let direct = 2.0 * R * ((R - delta) / R).acos().sin();
            assert!(((st.length - direct) / direct).abs() < 1e-9, "{delta}");
        }
    }

    #[test]
    fn sliver_search_finds_a_narrow_positive_peak() {
        // A peak 1e-12 high and 2e-6 wide at 0.3 that no sample grid would catch.
        // |g''| = 2: g rises at most w^2 / 4 above the chord of an interval w wide.
        let rise = 0.25;
        let peak = |x: f64| 1e-12 - (x - 0.3) * (x - 0.3);
        let (xp, gp) = positive_point(&peak, 0.0, peak(0.0), 1.0, peak(1.0), rise).unwrap();
        assert!(peak(xp) > 0.0 && gp == peak(xp));
        let below = |x: f64| -1e-12 - (x - 0.3) * (x - 0.3);
        assert_eq!(
            positive_point(&below, 0.0, below(0.0), 1.0, below(1.0), rise),
            None
        );
        // Both ends of the sliver, the peak near either end of the interval.
        let half = 1e-6;
        for (lo, hi) in [(0.0, 1.0), (0.25, 0.31), (0.29, 0.9)] {
            let (r0, r1) = sliver(&peak, lo, peak(lo), hi, peak(hi), rise).unwrap();
            assert!((r0 - (0.3 - half)).abs() < 1e-9, "[{lo}, {hi}]: {r0}");
            assert!((r1 - (0.3 + half)).abs() < 1e-9, "[{lo}, {hi}]: {r1}");
        }
        assert_eq!(sliver(&below, 0.0, below(0.0), 1.0, below(1.0), rise), None);
        // A gap: g positive at both ends, below zero over 2e-6 around 0.3; searched
        // for as a sliver of -g.
        let dip = |x: f64| -peak(x);
        let (r0, r1) = sliver(&|x| -dip(x), 0.0, -dip(0.0), 1.0, -dip(1.0), rise).unwrap();
        assert!((r0 - (0.3 - half)).abs() < 1e-9 && (r1 - (0.3 + half)).abs() < 1e-9);
        // A maximum well below zero is dismissed by the curvature bound in a few
        // evaluations instead of a search down to 1e-13.
        let count = std::cell::Cell::new(0);
        let deep = |x: f64| {
            count.set(count.get() + 1);
            -1e-6 - (x - 0.3) * (x - 0.3)
        };
        assert_eq!(
            positive_point(&deep, 0.29, deep(0.29), 0.32, deep(0.32), rise),
            None
        );
        assert!(count.get() < 12, "{} evaluations", count.get());
    }

    #[test]
    fn force_is_continuous_as_flat_enters_patch() {
        let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        let delta = 2e-4;
        let aw = patch_angle(delta, R);
        let phi = 0.1 / (2.0 * R);
        // flat rear edge at space angle -gamma - phi... front edge reaches +aw when gamma = -(aw + phi)
        let g0 = -(aw + phi);
        let a = law.evaluate(&w, g0 - 1e-9, delta).force;
        let b = law.evaluate(&w, g0 + 1e-9, delta).force;
        assert!(((a - b) / a).abs() < 1e-8, "{a} {b}");
    }

    #[test]
    fn full_loss_of_contact_inside_deep_flat() {
        let w = WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.0)], "f").unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        let st = law.evaluate(&w, 0.0, 1e-3);
        assert!(st.lost() && st.force == 0.0);
        let hz = ContactLaw::hertz(0.85e11).unwrap();
        assert_eq!(hz.evaluate(&w, 0.0, 1e-3).force, 0.0);
        let st = hz.evaluate(&w, 0.0, 1.6e-3);
        assert!((st.force - 0.85e11 * (1e-4f64).powf(1.5)).abs() < 1e-3);
    }

    #[test]
    fn inverse_overlap() {
        let w = WheelProfile::perfect(R).unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        let d = law.overlap_for_force(&w, 0.0, 107.6e3);
        assert!((law.evaluate(&w, 0.0, d).force - 107.6e3).abs() < 1e-6);
    }

    #[test]
    fn contact_stiffness_is_the_derivative_of_the_closed_forms() {
        // Adaptive, perfect wheel: differentiating (2.5) gives 2 K_w alpha_w with
        // cos alpha_w = (R_w - delta) / R_w; Hertz: 1.5 C_H delta^(1/2).
        let w = WheelProfile::perfect(R).unwrap();
        let law = ContactLaw::adaptive(KW).unwrap();
        for p in [50e3, 107.7e3, 430e3, 2.15e6] {
            let d = law.overlap_for_force(&w, 0.0, p);
            let alpha = ((R - d) / R).acos();
            let k = law.stiffness(&w, 0.0, p);
            assert!((k / (2.0 * KW * alpha) - 1.0).abs() < 1e-6, "{p}: {k}");
        }
        let hertz = ContactLaw::hertz(8.5e10).unwrap();
        let d = hertz.overlap_for_force(&w, 0.0, 107.7e3);
        let k = hertz.stiffness(&w, 0.0, 107.7e3);
        assert!((k / (1.5 * 8.5e10 * d.sqrt()) - 1.0).abs() < 1e-6, "{k}");
    }
}
