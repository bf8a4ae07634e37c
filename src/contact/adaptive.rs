//! The adaptive radial-spring contact (thesis 2.1-2.8, 2.22-2.24): the integral (2.8)
//! of the compressed radial springs, by the closed form (2.5) where the wheel is round
//! over the whole patch, else by bracketing the sign changes of the integrand and
//! integrating each contact interval by Gauss-Legendre quadrature.

use super::perfect::{perfect_patch_scaled, sin_minus_x};
use super::state::ContactState;
use crate::numerics::{
    LANES, SMALL_ANGLE, SimdLevel, cos_poly, cos_small, gauss_legendre, inlined, refine_root,
    sliver, wrap_angle,
};
use crate::wheel::{FlattedWheel, MAX_FLATS, WheelProfile};
use std::sync::OnceLock;

/// Number of Gauss-Legendre points per contact interval.
const GAUSS_POINTS: usize = LANES;
/// Samples per flat-covered piece used to bracket sign changes. Crossings that fall
/// between two samples of the same sign are found through the curvature bound (see
/// `numerics::sliver`), so the count trades speed, not exactness: 4, 6, 8 and 12 all
/// pass the flat-passage sweep at its 2.1e-8 floor; 8 keeps every search interval
/// narrow enough for one extremum.
const BRACKET_SAMPLES: usize = 8;

/// Nodes and weights of the [`GAUSS_POINTS`]-point Gauss-Legendre rule on [-1, 1].
fn gauss_rule() -> &'static ([f64; GAUSS_POINTS], [f64; GAUSS_POINTS]) {
    static GL: OnceLock<([f64; GAUSS_POINTS], [f64; GAUSS_POINTS])> = OnceLock::new();
    GL.get_or_init(gauss_legendre::<GAUSS_POINTS>)
}

/// Adaptive contact state with radial stiffness `kw` (N/m/rad) for a wheel with profile
/// `wheel` at axle rotation `gamma` (rad) and overlap `overlap` (m), by numerical
/// integration of (2.8) even where the wheel is round; for tests and for checking the
/// closed form (2.5).
pub fn adaptive_numeric(kw: f64, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
    let mut state = ContactState::default();
    adaptive(kw, wheel, gamma, overlap, true, &mut state);
    state
}

/// The adaptive law's state, written into `out`; by quadrature everywhere with
/// `force_numeric`. Each kind of wheel profile has its own integral.
#[inline(always)]
pub(super) fn adaptive(
    kw: f64,
    wheel: &WheelProfile,
    gamma: f64,
    overlap: f64,
    force_numeric: bool,
    out: &mut ContactState,
) {
    match wheel {
        WheelProfile::Flatted(w) => {
            flatted(kw, w, gamma, overlap, force_numeric, out);
        }
    }
}

/// [`adaptive`] and its stiffness `dP / d delta` (N/m, as [`adaptive_stiffness`]) from
/// the same pass, and whether the pass integrated (a flat in the patch: the costly
/// path): the contact's solve in series with the rail's compliance needs all three.
/// The state is [`adaptive`]'s, bit for bit.
#[inline(always)]
pub(super) fn adaptive_and_stiffness(
    kw: f64,
    wheel: &WheelProfile,
    gamma: f64,
    overlap: f64,
    out: &mut ContactState,
) -> (f64, bool) {
    match wheel {
        WheelProfile::Flatted(w) => flatted(kw, w, gamma, overlap, false, out),
    }
}

/// [`adaptive`] for the nominal circle with flats: the closed form (2.5) when no flat
/// reaches into the perfect-wheel patch, else the integral; returns the stiffness
/// `dP / d delta` (N/m, 0 out of contact) and whether it integrated, which
/// [`adaptive`] drops.
#[inline(always)]
fn flatted(
    kw: f64,
    wheel: &FlattedWheel,
    gamma: f64,
    overlap: f64,
    force_numeric: bool,
    out: &mut ContactState,
) -> (f64, bool) {
    let rw = wheel.radius();
    if overlap <= 0.0 || overlap.is_nan() {
        *out = ContactState {
            overlap,
            ..Default::default()
        };
        return (0.0, false);
    }
    let delta = overlap.min(rw);
    let (aw, sin_minus_x_cos_aw, s2) = perfect_patch_scaled(delta * wheel.half_inv_radius());
    let (near, nf) = near_flats(wheel, gamma, aw);
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
        return (2.0 * kw * aw, false);
    }
    let (state, angle) = adaptive_flats(kw, wheel, &near[..nf], overlap, delta, aw, force_numeric);
    *out = state;
    (kw * angle, true)
}

/// The flats whose window (space angles) reaches into the patch `[-aw, aw]` (rad) at
/// axle rotation `gamma` (rad), as (centre space angle, index in the wheel's flats), and
/// their number.
#[inline(always)]
fn near_flats(wheel: &FlattedWheel, gamma: f64, aw: f64) -> ([(f64, usize); MAX_FLATS], usize) {
    let mut near = [(0.0f64, 0usize); MAX_FLATS];
    let mut nf = 0;
    for (i, fl) in wheel.flats().iter().enumerate() {
        let c = wrap_angle(fl.angle - gamma);
        if c + fl.half_angle > -aw && c - fl.half_angle < aw {
            near[nf] = (c, i);
            nf += 1;
        }
    }
    (near, nf)
}

/// The contact stiffness `dP / d delta` (N/m) of the adaptive law, exact: with
/// `P = K_w * integral of max(0, R(alpha) cos(alpha) - h) d alpha` and `h = R_w -
/// delta`, the integrand vanishes at every contact edge, so the edges' motion adds
/// nothing and `dP / d delta = K_w * (the total angle of the compressed springs)`, the
/// sum of the contact intervals' widths (`2 K_w alpha_w` on a round wheel, from (2.5)).
/// 0 out of contact. The intervals are found as [`adaptive`] finds them: this is
/// [`adaptive_and_stiffness`]'s stiffness, the state left aside.
pub fn adaptive_stiffness(kw: f64, wheel: &WheelProfile, gamma: f64, overlap: f64) -> f64 {
    adaptive_and_stiffness(kw, wheel, gamma, overlap, &mut ContactState::default()).0
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
/// Returns the state and the total angle of the compressed springs (rad).
#[inline(never)]
fn adaptive_flats(
    kw: f64,
    wheel: &FlattedWheel,
    near: &[(f64, usize)],
    overlap: f64,
    delta: f64,
    aw: f64,
    force_numeric: bool,
) -> (ContactState, f64) {
    SimdLevel::detect().run(
        #[inline(always)]
        || adaptive_flats_body(kw, wheel, near, overlap, delta, aw, force_numeric),
    )
}

/// [`adaptive_flats`], inlined into each instruction set's copy; with the total angle
/// of the compressed springs (rad), the stiffness's (the contact's series solve and
/// [`adaptive_stiffness`] use it; [`adaptive`] drops it).
#[inline(always)]
fn adaptive_flats_body(
    kw: f64,
    wheel: &FlattedWheel,
    near: &[(f64, usize)],
    overlap: f64,
    delta: f64,
    aw: f64,
    force_numeric: bool,
) -> (ContactState, f64) {
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
                    sliver(&g, xs[k], g0, xs[k + 1], g1, rise, ROUNDING)
                } else {
                    None
                }
            } else if g0.min(g1) - slack <= 0.0 {
                sliver(&neg_g, xs[k], -g0, xs[k + 1], -g1, rise, ROUNDING)
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
    let mut measure = 0.0;
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
            measure += b - a;
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
        return (
            ContactState {
                overlap,
                ..Default::default()
            },
            0.0,
        );
    }
    (
        ContactState {
            force: kw * integral,
            overlap,
            front_angle: front,
            rear_angle: rear,
            length: h * (front.tan() - rear.tan()),
            intervals,
        },
        measure,
    )
}

/// Rounding allowance (m) in the curvature test for slivers: far above the rounding
/// of one evaluation of the integrand (about 1e-16 R_w).
const ROUNDING: f64 = 1e-15;

/// Capacity of the break-point list of one evaluation.
const MAX_BREAKS: usize = 4 * MAX_FLATS + 2 * BRACKET_SAMPLES + 8;

/// Gauss-Legendre integral of `max(g, 0)` over `[a, b]`, `g_lanes` evaluating `g` at
/// all points at once.
#[inline(always)]
fn gauss<G: Fn(&[f64; LANES]) -> [f64; LANES]>(g_lanes: &G, a: f64, b: f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let (x, w) = gauss_rule();
    let c = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let gx = g_lanes(&std::array::from_fn(|i| c + r * x[i]));
    let mut s = 0.0;
    for i in 0..GAUSS_POINTS {
        s += w[i] * gx[i].max(0.0);
    }
    s * r
}
