//! The perfect wheel's closed form (thesis 2.5, 2.6): the patch angle and the force of
//! the radial springs of a round wheel, and the integral of the springs over part of a
//! round stretch of the patch.

/// Perfect-wheel patch angle `alpha_w = acos((R_w - delta)/R_w)` (rad) (2.6) at overlap
/// `delta` (m) on a wheel of radius `radius` (m), computed as
/// `2 asin(sqrt(delta / (2 R_w)))` to keep precision at small overlap. `delta` is taken
/// as 0 when negative and as `2 R_w` above it (`alpha_w` from 0 to `pi`).
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
/// 1e-19 relative), so the difference never cancels. Above, the library functions.
#[inline]
pub(super) fn perfect_patch(delta: f64, radius: f64) -> (f64, f64, f64) {
    perfect_patch_scaled(delta * (0.5 / radius))
}

/// [`perfect_patch`] of `x = delta / (2 R_w)`.
#[inline]
pub(super) fn perfect_patch_scaled(x: f64) -> (f64, f64, f64) {
    // Below the switch the square root and the polynomials run side by side.
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
pub(super) fn sin_minus_x(a: f64) -> f64 {
    if a.abs() < 0.1 {
        let a2 = a * a;
        -a * a2 * (1.0 / 6.0 + a2 * (-1.0 / 120.0 + a2 * (1.0 / 5040.0 - a2 / 362880.0)))
    } else {
        a.sin() - a
    }
}

/// Perfect-wheel closed form (2.5): the force `P = 2 K_w R_w (sin a - a cos a)` (N) of
/// the radial springs of stiffness `kw` (N/m/rad) on a round wheel of radius `radius` (m)
/// at overlap `delta` (m), `a` the patch angle (2.6); 0 when `delta <= 0`.
#[inline]
pub fn perfect_wheel_force(kw: f64, radius: f64, delta: f64) -> f64 {
    if delta <= 0.0 {
        return 0.0;
    }
    2.0 * kw * radius * perfect_patch(delta, radius).1
}
