//! Angles: wrapping, and cosine and tangent of small angles by polynomials that give the
//! same bits in scalar and vector code.

use std::f64::consts::PI;

/// Wraps an angle (rad) into (-pi, pi].
#[inline]
pub fn wrap_angle(a: f64) -> f64 {
    if a > -PI && a <= PI {
        return a;
    }
    if !a.is_finite() {
        return a;
    }
    let mut r = a.rem_euclid(2.0 * PI);
    if r > PI {
        r -= 2.0 * PI;
    }
    r
}

/// `cos a`: its Taylor polynomial to `a^10` for `|a| <= 0.2` rad (the first omitted
/// term is below 1e-17, under half an ulp of the result), the library cosine
/// otherwise. Contact patches are a few hundredths of a radian wide, so the
/// integrand of (2.8) takes the polynomial.
#[inline]
pub fn cos_small(a: f64) -> f64 {
    if a.abs() <= SMALL_ANGLE {
        cos_poly(a)
    } else {
        a.cos()
    }
}

/// Largest angle (rad) for which [`cos_small`] and [`tan_small`] use their polynomials.
pub const SMALL_ANGLE: f64 = 0.2;

/// The polynomial of [`cos_small`], whatever `a` (valid for `|a| <=` [`SMALL_ANGLE`]).
#[inline(always)]
pub fn cos_poly(a: f64) -> f64 {
    let x = a * a;
    let (x2, c) = (x * x, &COS_TAYLOR);
    // Estrin's scheme: (c0 + c1 x) + x^2 (c2 + c3 x) + x^4 (c4 + c5 x).
    (c[0] + c[1] * x) + (c[2] + c[3] * x) * x2 + (c[4] + c[5] * x) * (x2 * x2)
}

/// `tan a`: its Taylor polynomial to `a^19` for `|a| <= 0.2` rad (the first omitted
/// term is below 1e-18 relative), evaluated by Estrin's scheme: no division, and a
/// dependency chain of five multiply-adds. The library tangent otherwise.
#[inline]
pub fn tan_small(a: f64) -> f64 {
    if a.abs() <= SMALL_ANGLE {
        tan_poly(a)
    } else {
        a.tan()
    }
}

/// The polynomial of [`tan_small`], whatever `a` (valid for `|a| <=` [`SMALL_ANGLE`]).
#[inline(always)]
pub fn tan_poly(a: f64) -> f64 {
    let x = a * a;
    let c = &TAN_TAYLOR;
    let x2 = x * x;
    let x4 = x2 * x2;
    let p03 = (c[0] + c[1] * x) + (c[2] + c[3] * x) * x2;
    let p47 = (c[4] + c[5] * x) + (c[6] + c[7] * x) * x2;
    let p89 = c[8] + c[9] * x;
    a * ((p03 + p47 * x4) + p89 * (x4 * x4))
}

/// The tangent's Taylor coefficients (over `a`) in `a^2`,
/// `(-1)^(n-1) 2^(2n) (2^(2n) - 1) B_(2n) / (2n)!`, `n = 1..=10`.
const TAN_TAYLOR: [f64; 10] = [
    1.0,
    1.0 / 3.0,
    2.0 / 15.0,
    17.0 / 315.0,
    62.0 / 2835.0,
    1382.0 / 155925.0,
    21844.0 / 6081075.0,
    929569.0 / 638512875.0,
    6404582.0 / 10854718875.0,
    443861162.0 / 1856156927625.0,
];

/// `cos a` for `|a| <= pi/2` by its Taylor polynomial to `a^20` (first omitted term
/// below 2e-17), evaluated by Estrin's scheme (a dependency chain of 4
/// multiply-adds instead of Horner's 10).
#[inline]
pub fn cos_half_pi(a: f64) -> f64 {
    let x = a * a;
    let (x2, c) = (x * x, &COS_TAYLOR);
    let x4 = x2 * x2;
    let x8 = x4 * x4;
    let p01 = c[0] + c[1] * x;
    let p23 = c[2] + c[3] * x;
    let p45 = c[4] + c[5] * x;
    let p67 = c[6] + c[7] * x;
    let p89 = c[8] + c[9] * x;
    let p03 = p01 + p23 * x2;
    let p47 = p45 + p67 * x2;
    let p810 = p89 + c[10] * x2;
    (p03 + p47 * x4) + p810 * x8
}

/// `(-1)^k / (2k)!`, `k = 0..=10`: the cosine's Taylor coefficients in `a^2`.
const COS_TAYLOR: [f64; 11] = [
    1.0,
    -1.0 / 2.0,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40320.0,
    -1.0 / 3628800.0,
    1.0 / 479001600.0,
    -1.0 / 87178291200.0,
    1.0 / 20922789888000.0,
    -1.0 / 6402373705728000.0,
    1.0 / 2432902008176640000.0,
];
