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
use crate::profile::{MAX_FLATS, WheelProfile, cos_small, wrap_angle};
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
    let a = patch_angle(delta0, radius);
    Ok(static_load / (2.0 * radius * sin_minus_x_cos(a)))
}

/// Perfect-wheel patch angle `alpha_w = acos((R_w - delta)/R_w)` (2.6), computed as
/// `2 asin(sqrt(delta / (2 R_w)))` to keep precision at small overlap.
#[inline]
pub fn patch_angle(delta: f64, radius: f64) -> f64 {
    let s = (0.5 * delta / radius).clamp(0.0, 1.0).sqrt();
    2.0 * asin_small(s)
}

/// `asin s` for `s >= 0`: its Taylor polynomial to `s^13` for `s <= 0.05` (overlaps
/// up to about 2.4 mm on a 0.475 m wheel; the first omitted term is below 1e-19), the
/// library arcsine otherwise.
#[inline]
fn asin_small(s: f64) -> f64 {
    if s <= 0.05 {
        let x = s * s;
        s * (1.0
            + x * (1.0 / 6.0
                + x * (3.0 / 40.0
                    + x * (5.0 / 112.0
                        + x * (35.0 / 1152.0 + x * (63.0 / 2816.0 + x * (231.0 / 13312.0)))))))
    } else {
        s.asin()
    }
}

/// `sin a - a cos a`, by its series below 0.1 rad to avoid cancellation.
#[inline]
pub fn sin_minus_x_cos(a: f64) -> f64 {
    if a.abs() < 0.1 {
        let a2 = a * a;
        // a^3/3 - a^5/30 + a^7/840 - a^9/45360 + a^11/3991680
        a * a2
            * (1.0 / 3.0
                + a2 * (-1.0 / 30.0 + a2 * (1.0 / 840.0 + a2 * (-1.0 / 45360.0 + a2 / 3991680.0))))
    } else {
        a.sin() - a * a.cos()
    }
}

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
    2.0 * kw * radius * sin_minus_x_cos(patch_angle(delta, radius))
}

/// Number of Gauss-Legendre points per contact interval.
const GAUSS_POINTS: usize = 8;
/// Samples per flat-covered piece used to bracket sign changes.
const BRACKET_SAMPLES: usize = 12;

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

    /// Contact state for a wheel with profile `wheel` at axle rotation `gamma` (rad)
    /// and overlap `overlap = z_rail - z_wheel` (m).
    pub fn evaluate(&self, wheel: &WheelProfile, gamma: f64, overlap: f64) -> ContactState {
        match self.model {
            ContactModel::Adaptive => adaptive(self.kw, wheel, gamma, overlap, false),
            ContactModel::Hertz => self.hertz_state(wheel, gamma, overlap),
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
        let a = patch_angle(d, wheel.radius);
        let h = wheel.radius - d;
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
        while self.evaluate(wheel, gamma, hi).force < force && hi < wheel.radius {
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
    adaptive(kw, wheel, gamma, overlap, true)
}

fn adaptive(
    kw: f64,
    wheel: &WheelProfile,
    gamma: f64,
    overlap: f64,
    force_numeric: bool,
) -> ContactState {
    let rw = wheel.radius;
    if overlap <= 0.0 || overlap.is_nan() {
        return ContactState {
            overlap,
            ..Default::default()
        };
    }
    let delta = overlap.min(rw);
    let aw = patch_angle(delta, rw);
    let h = rw - delta;

    // Flat windows (space angles) that reach into [-aw, aw] give the piece edges.
    let mut edges = [0.0f64; 2 * MAX_FLATS + 2];
    let mut ne = 0;
    edges[ne] = -aw;
    ne += 1;
    let mut any = false;
    for fl in wheel.flats() {
        let c = wrap_angle(fl.angle - gamma);
        let (a, b) = (c - fl.half_angle, c + fl.half_angle);
        if b > -aw && a < aw {
            any = true;
            for e in [a, b] {
                if e > -aw && e < aw {
                    edges[ne] = e;
                    ne += 1;
                }
            }
        }
    }
    if !any && !force_numeric {
        // sin(alpha_w) = 2 s sqrt(1 - s^2) with s = sin(alpha_w / 2) = sqrt(delta / 2 R_w).
        let s2 = 0.5 * delta / rw;
        return ContactState {
            force: 2.0 * kw * rw * sin_minus_x_cos(aw),
            overlap,
            front_angle: aw,
            rear_angle: -aw,
            length: 4.0 * rw * (s2 * (1.0 - s2)).sqrt(),
            intervals: 1,
        };
    }
    edges[ne] = aw;
    ne += 1;
    edges[..ne].sort_unstable_by(|a, b| a.total_cmp(b));

    let g = |a: f64| wheel.radius_at(a, gamma) * cos_small(a) - h;
    let several = wheel.flats().len() > 1;
    let covered = |x: f64| {
        wheel
            .flats()
            .iter()
            .any(|fl| wrap_angle(x + gamma - fl.angle).abs() < fl.half_angle)
    };

    // Break points: piece edges, every sign change of g inside flat-covered pieces,
    // and where overlapping flats hand over (the larger reduction wins, so the
    // integrand has a kink there that quadrature must not straddle).
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
        let mut roots = [0.0f64; 5 * BRACKET_SAMPLES + 4];
        let mut nr = 0;
        let dominant = |x: f64| {
            if several {
                wheel.dominant_flat(x, gamma)
            } else {
                None
            }
        };
        let mut top0 = dominant(a);
        for s in 1..=m {
            let x1 = if s == m {
                b
            } else {
                a + (b - a) * s as f64 / m as f64
            };
            let top1 = dominant(x1);
            if let (Some(i), Some(j)) = (top0, top1)
                && i != j
            {
                let (fi, fj) = (&wheel.flats()[i], &wheel.flats()[j]);
                let d = |x: f64| fi.reduction_at(x, gamma) - fj.reduction_at(x, gamma);
                let xc = refine_root(&d, xs[nn - 1], x1);
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
        // Sign changes between samples, then slivers: where the samples show a local
        // maximum of g that is not positive, the true maximum between the neighbours
        // may be, so it is searched for.
        for k in 0..nn - 1 {
            if (gs[k] > 0.0) != (gs[k + 1] > 0.0) {
                roots[nr] = refine_root(&g, xs[k], xs[k + 1]);
                nr += 1;
            }
        }
        for k in 0..nn {
            let left = if k > 0 { gs[k - 1] } else { f64::NEG_INFINITY };
            let right = if k + 1 < nn {
                gs[k + 1]
            } else {
                f64::NEG_INFINITY
            };
            if gs[k] > 0.0 || gs[k] < left || gs[k] < right {
                continue;
            }
            let (lo, hi) = (xs[k.saturating_sub(1)], xs[(k + 1).min(nn - 1)]);
            if let Some((r0, r1)) = sliver(&g, lo, xs[k], hi) {
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
                gauss(&g, a, b)
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

/// Capacity of the break-point list of one evaluation.
const MAX_BREAKS: usize = 4 * MAX_FLATS + 2 * BRACKET_SAMPLES + 8;

/// Root of `g` in `[lo, hi]` (where `g` changes sign) by the Illinois variant of
/// regula falsi (superlinear), ended at 1e-15 rad.
fn refine_root<G: Fn(f64) -> f64>(g: &G, lo: f64, hi: f64) -> f64 {
    let (mut a, mut b) = (lo, hi);
    let (mut fa, mut fb) = (g(a), g(b));
    let mut side = 0i32;
    for _ in 0..100 {
        if (b - a).abs() <= 1e-15 {
            break;
        }
        let denom = fb - fa;
        let mut c = if denom != 0.0 {
            (a * fb - b * fa) / denom
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
        if (fc > 0.0) == (fb > 0.0) {
            b = c;
            fb = fc;
            if side == -1 {
                fa *= 0.5;
            }
            side = -1;
        } else {
            a = c;
            fa = fc;
            if side == 1 {
                fb *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (a + b)
}

/// A point of `[lo, hi]` where `g` is positive, if golden-section search for the
/// maximum of `g` (unimodal there) finds one before the interval shrinks below
/// 1e-13 rad.
fn positive_point<G: Fn(f64) -> f64>(g: &G, lo: f64, hi: f64) -> Option<f64> {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    let (mut a, mut b) = (lo, hi);
    let mut c = b - INV_PHI * (b - a);
    let mut d = a + INV_PHI * (b - a);
    let (mut gc, mut gd) = (g(c), g(d));
    for _ in 0..100 {
        if gc > 0.0 {
            return Some(c);
        }
        if gd > 0.0 {
            return Some(d);
        }
        if b - a < 1e-13 {
            break;
        }
        if gc > gd {
            b = d;
            d = c;
            gd = gc;
            c = b - INV_PHI * (b - a);
            gc = g(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + INV_PHI * (b - a);
            gd = g(d);
        }
    }
    None
}

/// Ends of a contact sliver of `g` around the sample `mid` (where `g <= 0`, as at `lo`
/// and `hi`), or `None` when `g` stays non-positive on `[lo, hi]`. Each end is
/// bracketed between the positive point found and the nearest non-positive sample.
fn sliver<G: Fn(f64) -> f64>(g: &G, lo: f64, mid: f64, hi: f64) -> Option<(f64, f64)> {
    let xp = positive_point(g, lo, hi)?;
    let (left, right) = if xp > mid { (mid, hi) } else { (lo, mid) };
    Some((refine_root(g, left, xp), refine_root(g, xp, right)))
}

fn gauss<G: Fn(f64) -> f64>(g: &G, a: f64, b: f64) -> f64 {
    if b <= a {
        return 0.0;
    }
    let (x, w) = gauss_legendre();
    let c = 0.5 * (a + b);
    let r = 0.5 * (b - a);
    let mut s = 0.0;
    for i in 0..GAUSS_POINTS {
        s += w[i] * g(c + r * x[i]).max(0.0);
    }
    s * r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::{FlatSpec, WheelProfile};

    const R: f64 = 0.475;
    const KW: f64 = 3.3443e10;

    fn brute_force(kw: f64, w: &WheelProfile, gamma: f64, delta: f64, n: usize) -> f64 {
        let aw = patch_angle(delta, w.radius);
        let h = w.radius - delta;
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
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let x = 0.06 * i as f64 / 20_000.0;
            worst = worst.max(((asin_small(x) - x.asin()) / x.asin().max(1e-300)).abs());
        }
        assert!(worst < 3e-16, "{worst:e}");
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
        let peak = |x: f64| 1e-12 - (x - 0.3) * (x - 0.3);
        let xp = positive_point(&peak, 0.0, 1.0).unwrap();
        assert!(peak(xp) > 0.0);
        let below = |x: f64| -1e-12 - (x - 0.3) * (x - 0.3);
        assert_eq!(positive_point(&below, 0.0, 1.0), None);
        // Both ends of the sliver, with the peak left or right of the middle sample.
        let half = 1e-6;
        for mid in [0.2, 0.4] {
            let (r0, r1) = sliver(&peak, 0.0, mid, 1.0).unwrap();
            assert!((r0 - (0.3 - half)).abs() < 1e-9, "mid {mid}: {r0}");
            assert!((r1 - (0.3 + half)).abs() < 1e-9, "mid {mid}: {r1}");
        }
        assert_eq!(sliver(&below, 0.0, 0.4, 1.0), None);
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
}
