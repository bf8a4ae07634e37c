//! Wheel profile: nominal radius with haversine or chord flats (seed eqs. 2.9-2.21).
//!
//! Angles are measured at the wheel centre from the downward vertical (the
//! nominal contact point), positive towards the direction of travel ("front").
//! A flat whose centre sits at wheel angle `beta_0` when the axle rotation angle
//! is zero is found, at axle rotation `gamma`, at the space angle
//! `beta_0 - gamma` (2.17-2.21), wrapped into (-pi, pi].

use crate::error::{Result, finite, out_of_range, positive};
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
    if a.abs() <= 0.2 {
        let x = a * a;
        1.0 + x
            * (-1.0 / 2.0
                + x * (1.0 / 24.0 + x * (-1.0 / 720.0 + x * (1.0 / 40320.0 - x / 3628800.0))))
    } else {
        a.cos()
    }
}

/// `tan a`: the quotient of the sine and cosine Taylor polynomials for
/// `|a| <= 0.2` rad (both exact to well under an ulp there), the library tangent
/// otherwise.
#[inline]
pub fn tan_small(a: f64) -> f64 {
    if a.abs() <= 0.2 {
        let x = a * a;
        let sin = a
            * (1.0
                + x * (-1.0 / 6.0
                    + x * (1.0 / 120.0
                        + x * (-1.0 / 5040.0 + x * (1.0 / 362880.0 - x / 39916800.0)))));
        sin / cos_small(a)
    } else {
        a.tan()
    }
}

/// `cos a` for `|a| <= pi/2` by its Taylor polynomial to `a^20` (first omitted term
/// below 2e-17).
#[inline]
fn cos_half_pi(a: f64) -> f64 {
    let x = a * a;
    // Coefficients (-1)^k / (2k)!, k = 0..=10, by Horner's rule from the top.
    const C: [f64; 11] = [
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
    let mut r = C[10];
    for c in C[..10].iter().rev() {
        r = r * x + c;
    }
    r
}

/// Shape of a flat.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlatShape {
    /// Rounded (worn) flat, radius reduction `f = D/2 (1 - cos(2 pi x / l))` (2.14, 2.16).
    Haversine,
    /// Fresh flat: a straight chord, `R = (R_w - D) / cos(beta - beta_c)` (2.12).
    Chord,
}

/// A flat as the user specifies it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlatSpec {
    /// Flat length `l_f` (m).
    pub length: f64,
    /// Flat depth `D_f` (m). `None` takes the seed's default: (2.15) for a
    /// haversine flat, (2.13) for a chord flat.
    pub depth: Option<f64>,
    /// Wheel angle of the flat centre at zero axle rotation, `beta_0` (rad).
    pub angle: f64,
    /// Shape of the flat.
    pub shape: FlatShape,
}

impl FlatSpec {
    /// A haversine flat of given length and depth (m) at `angle` (rad).
    pub fn haversine(length: f64, depth: f64, angle: f64) -> Self {
        FlatSpec {
            length,
            depth: Some(depth),
            angle,
            shape: FlatShape::Haversine,
        }
    }
    /// A chord flat of given length (m) at `angle` (rad); depth from (2.13).
    pub fn chord(length: f64, angle: f64) -> Self {
        FlatSpec {
            length,
            depth: None,
            angle,
            shape: FlatShape::Chord,
        }
    }
}

/// A validated flat on a wheel of known radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Flat {
    /// Shape of the flat.
    pub shape: FlatShape,
    /// Length `l_f` (m).
    pub length: f64,
    /// Depth `D_f` (m).
    pub depth: f64,
    /// Centre angle at zero axle rotation, `beta_0` (rad).
    pub angle: f64,
    /// Half-angle of the flat seen from the wheel centre (rad): `l_f/(2 R_w)` (2.9)
    /// for a haversine flat, `acos((R_w - D_f)/R_w)` for a chord flat.
    pub half_angle: f64,
    radius: f64,
}

impl Flat {
    /// Radius reduction `f` (m) at angle `psi` (rad) from the flat centre;
    /// zero outside the flat.
    #[inline]
    pub fn reduction(&self, psi: f64) -> f64 {
        if psi.abs() >= self.half_angle {
            return 0.0;
        }
        match self.shape {
            FlatShape::Haversine => {
                // (2.16); x is clamped to [0, l_f] so that the profile is
                // continuous at the flat ends (the seed's x misses 0 by ~1e-5 l_f).
                let x = (0.5 * self.length + (self.radius - self.depth) * tan_small(psi))
                    .clamp(0.0, self.length);
                // D/2 (1 - cos(2 pi x / l)) = D sin^2(pi x / l), with
                // sin(pi x / l) = cos(pi x / l - pi/2) and the argument in [-pi/2, pi/2].
                let s = cos_half_pi(PI * x / self.length - 0.5 * PI);
                self.depth * s * s
            }
            FlatShape::Chord => self.radius - (self.radius - self.depth) / cos_small(psi),
        }
    }

    /// Radius reduction (m) at space angle `alpha` (rad) for axle rotation `gamma` (rad).
    #[inline]
    pub fn reduction_at(&self, alpha: f64, gamma: f64) -> f64 {
        self.reduction(wrap_angle(alpha + gamma - self.angle))
    }
}

/// Most flats one wheel may carry.
pub const MAX_FLATS: usize = 8;

/// A wheel: nominal radius and its flats.
#[derive(Debug, Clone, PartialEq)]
pub struct WheelProfile {
    /// Nominal rolling radius `R_w` (m).
    pub radius: f64,
    flats: Vec<Flat>,
}

impl WheelProfile {
    /// A perfect wheel of radius `radius` (m).
    pub fn perfect(radius: f64) -> Result<Self> {
        positive("wheel.radius", radius, "m")?;
        Ok(WheelProfile {
            radius,
            flats: Vec::new(),
        })
    }

    /// A wheel with flats; `name` prefixes parameter names in errors
    /// (e.g. `flat.left`). A flat of zero length and no (or zero) depth is no flat.
    pub fn new(radius: f64, flats: &[FlatSpec], name: &str) -> Result<Self> {
        let mut w = Self::perfect(radius)?;
        for (k, spec) in flats.iter().enumerate() {
            let p = format!("{name}[{}]", k + 1);
            if let Some(flat) = validate_flat(radius, spec, &p)? {
                if w.flats.len() == MAX_FLATS {
                    return Err(out_of_range(
                        &format!("{p}.length"),
                        spec.length,
                        format!("at most {MAX_FLATS} flats per wheel"),
                    ));
                }
                w.flats.push(flat);
            }
        }
        Ok(w)
    }

    /// The validated flats.
    pub fn flats(&self) -> &[Flat] {
        &self.flats
    }

    /// Radius reduction (m) at space angle `alpha` (rad) for axle rotation `gamma` (rad).
    /// Where flats overlap, the larger reduction wins.
    #[inline]
    pub fn reduction(&self, alpha: f64, gamma: f64) -> f64 {
        let mut f = 0.0f64;
        for fl in &self.flats {
            f = f.max(fl.reduction_at(alpha, gamma));
        }
        f
    }

    /// Index of the flat whose reduction is largest (and positive) at space angle
    /// `alpha` (rad) for axle rotation `gamma` (rad): the flat that shapes the wheel
    /// there.
    pub fn dominant_flat(&self, alpha: f64, gamma: f64) -> Option<usize> {
        let mut best = None;
        let mut f = 0.0f64;
        for (i, fl) in self.flats.iter().enumerate() {
            let r = fl.reduction_at(alpha, gamma);
            if r > f {
                f = r;
                best = Some(i);
            }
        }
        best
    }

    /// Instantaneous radius `R_i` (m) at space angle `alpha` for axle rotation `gamma` (2.18).
    #[inline]
    pub fn radius_at(&self, alpha: f64, gamma: f64) -> f64 {
        self.radius - self.reduction(alpha, gamma)
    }
}

fn validate_flat(radius: f64, spec: &FlatSpec, p: &str) -> Result<Option<Flat>> {
    let length = finite(&format!("{p}.length"), spec.length, "m")?;
    let angle = finite(&format!("{p}.angle"), spec.angle, "rad")?;
    if length < 0.0 {
        return Err(out_of_range(&format!("{p}.length"), length, ">= 0 m"));
    }
    let depth_given = match spec.depth {
        Some(d) => Some(finite(&format!("{p}.depth"), d, "m")?),
        None => None,
    };
    if length == 0.0 {
        return match depth_given {
            None => Ok(None),
            Some(0.0) => Ok(None),
            Some(d) => Err(out_of_range(
                &format!("{p}.depth"),
                d,
                "0 m when the flat length is 0 (a flat needs both length and depth)",
            )),
        };
    }
    let quarter = 0.5 * PI * radius;
    if length > quarter {
        return Err(out_of_range(
            &format!("{p}.length"),
            length,
            format!("0 < length <= a quarter of the circumference, {quarter:.4} m"),
        ));
    }
    let chord_depth = radius - (radius * radius - 0.25 * length * length).sqrt(); // (2.13)
    let depth = match (depth_given, spec.shape) {
        (Some(d), _) if d <= 0.0 => {
            return Err(out_of_range(
                &format!("{p}.depth"),
                d,
                format!("> 0 m when the flat length is {length} m"),
            ));
        }
        (Some(d), _) if d >= radius => {
            return Err(out_of_range(
                &format!("{p}.depth"),
                d,
                format!("0 < depth < wheel radius {radius} m"),
            ));
        }
        (Some(d), FlatShape::Chord) if ((d - chord_depth) / chord_depth).abs() > 0.02 => {
            return Err(out_of_range(
                &format!("{p}.depth"),
                d,
                format!(
                    "within 2% of the chord depth {chord_depth:.6e} m that a {length} m chord \
                     flat has on a {radius} m wheel (2.13); give depth 0/None to use it"
                ),
            ));
        }
        (Some(d), _) => d,
        (None, FlatShape::Haversine) => length * length / (16.0 * radius), // (2.15)
        (None, FlatShape::Chord) => chord_depth,
    };
    let half_angle = match spec.shape {
        FlatShape::Haversine => length / (2.0 * radius),
        FlatShape::Chord => ((radius - depth) / radius).acos(),
    };
    Ok(Some(Flat {
        shape: spec.shape,
        length,
        depth,
        angle,
        half_angle,
        radius,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    const R: f64 = 0.475;

    #[test]
    fn haversine_depth_at_centre_and_zero_at_edges() {
        let w =
            WheelProfile::new(R, &[FlatSpec::haversine(0.1, 0.0015, 0.3)], "flat.left").unwrap();
        // Centre of the flat lies at space angle 0.3 - gamma.
        assert!((w.reduction(0.3, 0.0) - 0.0015).abs() < 1e-15);
        assert!((w.reduction(0.0, 0.3) - 0.0015).abs() < 1e-15);
        let phi = 0.1 / (2.0 * R);
        assert!(w.reduction(0.3 + phi * 0.9999999, 0.0) < 1e-9);
        assert_eq!(w.reduction(0.3 + phi * 1.01, 0.0), 0.0);
        // Profile is continuous at both ends (clamping of x).
        assert!(w.reduction(0.3 - phi + 1e-12, 0.0) < 1e-12);
    }

    #[test]
    fn default_depths_follow_seed() {
        let h = WheelProfile::new(
            R,
            &[FlatSpec {
                length: 0.1,
                depth: None,
                angle: 0.0,
                shape: FlatShape::Haversine,
            }],
            "f",
        )
        .unwrap();
        assert!((h.flats()[0].depth - 0.01 / (16.0 * R)).abs() < 1e-15);
        let c = WheelProfile::new(R, &[FlatSpec::chord(0.1, 0.0)], "f").unwrap();
        let d = R - (R * R - 0.0025f64).sqrt();
        assert!((c.flats()[0].depth - d).abs() < 1e-15);
        // A chord flat is a straight line: R cos(psi) = R_w - D across it.
        for psi in [-0.1, -0.05, 0.0, 0.07] {
            let r = c.radius_at(psi, 0.0);
            assert!((r * psi.cos() - (R - d)).abs() < 1e-14);
        }
        // and meets the circle at its ends: chord length equals l_f.
        let half = c.flats()[0].half_angle;
        assert!((2.0 * R * half.sin() - 0.1).abs() < 1e-12);
    }

    #[test]
    fn bad_flats_are_refused_with_names() {
        let cases = [
            (FlatSpec::haversine(0.1, 0.0, 0.0), "flat.left[1].depth"),
            (FlatSpec::haversine(0.0, 0.001, 0.0), "flat.left[1].depth"),
            (FlatSpec::haversine(0.8, 0.001, 0.0), "flat.left[1].length"),
            (FlatSpec::haversine(0.1, 0.5, 0.0), "flat.left[1].depth"),
            (FlatSpec::haversine(-0.1, 0.001, 0.0), "flat.left[1].length"),
            (
                FlatSpec::haversine(0.1, f64::NAN, 0.0),
                "flat.left[1].depth",
            ),
            (
                FlatSpec {
                    length: 0.1,
                    depth: Some(0.0015),
                    angle: 0.0,
                    shape: FlatShape::Chord,
                },
                "flat.left[1].depth",
            ),
        ];
        for (spec, name) in cases {
            match WheelProfile::new(R, &[spec], "flat.left") {
                Err(Error::Parameter { name: n, .. }) => assert_eq!(n, name, "{spec:?}"),
                other => panic!("{spec:?} gave {other:?}"),
            }
        }
        // Zero length and zero depth is "no flat".
        let w = WheelProfile::new(R, &[FlatSpec::haversine(0.0, 0.0, 1.0)], "f").unwrap();
        assert!(w.flats().is_empty());
    }

    #[test]
    fn overlapping_flats_take_larger_reduction() {
        let w = WheelProfile::new(
            R,
            &[
                FlatSpec::haversine(0.1, 0.001, 0.0),
                FlatSpec::haversine(0.05, 0.002, 0.02),
            ],
            "f",
        )
        .unwrap();
        assert!((w.reduction(0.02, 0.0) - 0.002).abs() < 1e-15);
        assert!((w.reduction(-0.05, 0.0) - w.flats()[0].reduction(-0.05)).abs() < 1e-15);
    }

    #[test]
    fn polynomial_trig_matches_library() {
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let a = -0.25 + 0.5 * i as f64 / 20_000.0;
            worst = worst.max(((tan_small(a) - a.tan()) / a.tan().abs().max(1e-300)).abs());
        }
        assert!(worst < 5e-16, "tan: {worst:e}");
        let mut worst: f64 = 0.0;
        for i in 0..=20_000 {
            let a = -0.5 * PI + PI * i as f64 / 20_000.0;
            worst = worst.max((cos_half_pi(a) - a.cos()).abs());
        }
        assert!(worst < 5e-16, "cos: {worst:e}");
    }

    #[test]
    fn wrap_is_into_half_open_interval() {
        assert!((wrap_angle(3.0 * PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(-PI) - PI).abs() < 1e-12);
        assert!((wrap_angle(0.1 - 4.0 * PI) - 0.1).abs() < 1e-12);
    }
}
