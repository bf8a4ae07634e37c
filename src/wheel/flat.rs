//! Flat shapes (thesis 2.9-2.21): the haversine (worn) flat and the chord (fresh)
//! flat, their validation and their radius reduction.

use crate::error::{Result, finite, out_of_range};
use crate::limits::MAX_FLAT_DEPTH;
use crate::numerics::{
    LANES, SMALL_ANGLE, cos_half_pi, cos_poly, cos_small, tan_poly, tan_small, wrap_angle,
};
use std::f64::consts::PI;

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
    /// Flat depth `D_f` (m). `None` takes the thesis' default: (2.15) for a
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
    /// Haversine flat: `pi (R_w - D_f) / l_f` (dimensionless), the phase
    /// `u = pi x / l_f - pi/2` of (2.16) per unit of `tan psi`.
    k_tan: f64,
    /// Upper bound of `|f'(psi)| + |f''(psi)|` over the flat (m/rad, m/rad^2): what
    /// the flat adds to the curvature of the contact integrand.
    bend: f64,
}

impl Flat {
    /// Radius reduction `f` (m) at angle `psi` (rad) from the flat centre: (2.16) with
    /// `x = l_f/2 + (R_w - D_f) tan psi` for a haversine flat, `R_w - (R_w - D_f) / cos psi`
    /// (2.12) for a chord flat; zero outside the flat (`|psi| >= half_angle`).
    #[inline]
    pub fn reduction(&self, psi: f64) -> f64 {
        if psi.abs() >= self.half_angle {
            return 0.0;
        }
        match self.shape {
            FlatShape::Haversine => self.haversine_of_tan(tan_small(psi)),
            FlatShape::Chord => self.chord_of_cos(cos_small(psi)),
        }
    }

    /// (2.16) with x = l_f/2 + (R_w - D_f) tan psi along the flat, from `tan psi`:
    /// D/2 (1 - cos(2 pi x / l)) = D sin^2(pi x / l) = D cos^2 u with
    /// u = pi x / l - pi/2 = k_tan tan psi. u is clamped to [-pi/2, pi/2]
    /// (x to [0, l_f]) so that the profile is continuous at the flat ends
    /// (the thesis' x misses 0 by ~1e-5 l_f).
    #[inline(always)]
    fn haversine_of_tan(&self, tan_psi: f64) -> f64 {
        let u = (self.k_tan * tan_psi).clamp(-0.5 * PI, 0.5 * PI);
        let s = cos_half_pi(u);
        self.depth * s * s
    }

    /// (2.12) from `cos psi`.
    #[inline(always)]
    fn chord_of_cos(&self, cos_psi: f64) -> f64 {
        self.radius - (self.radius - self.depth) / cos_psi
    }

    /// [`Flat::reduction`] (m) at [`LANES`] angles `psi` (rad) from the flat centre, the
    /// same bits lane by lane; `None` when a lane inside the flat lies beyond
    /// [`SMALL_ANGLE`].
    #[inline(always)]
    pub(crate) fn reduction_lanes(&self, psi: &[f64; LANES]) -> Option<[f64; LANES]> {
        // Written so that the compiler vectorises it: every lane computes exactly what
        // `reduction` computes, with the polynomials in place of `tan_small` and
        // `cos_small`; beyond SMALL_ANGLE those call the library functions, which do not
        // vectorise, so such a batch is refused and the caller goes point by point.
        let mut out = [0.0; LANES];
        let mut small = true;
        for l in 0..LANES {
            let (p, inside) = (psi[l], psi[l].abs() < self.half_angle);
            small &= !inside || p.abs() <= SMALL_ANGLE;
            let r = match self.shape {
                FlatShape::Haversine => self.haversine_of_tan(tan_poly(p)),
                FlatShape::Chord => self.chord_of_cos(cos_poly(p)),
            };
            out[l] = if inside { r } else { 0.0 };
        }
        small.then_some(out)
    }

    /// Radius reduction (m) at space angle `alpha` (rad) for axle rotation `gamma` (rad):
    /// the flat centre lies at `beta_0 - gamma` (2.17-2.21).
    #[inline]
    pub fn reduction_at(&self, alpha: f64, gamma: f64) -> f64 {
        self.reduction(wrap_angle(alpha + gamma - self.angle))
    }

    /// Upper bound of `|f'| + |f''|` over the flat (m/rad, m/rad^2), `f` the radius
    /// reduction as a function of the angle: with `R_w`, a bound on the second
    /// derivative of the contact integrand, which bounds how far it can rise between
    /// two samples.
    pub fn bend_bound(&self) -> f64 {
        self.bend
    }
}

/// Upper bound of `|f'| + |f''|` of a flat's reduction `f(psi)` (see
/// [`Flat::bend_bound`]), from the derivatives of (2.12) and (2.16) bounded
/// term by term over `|psi| <= h`.
fn bend_bound(shape: FlatShape, radius: f64, depth: f64, k_tan: f64, h: f64) -> f64 {
    let (t, sec) = (h.tan(), 1.0 / h.cos());
    let sec2 = sec * sec;
    match shape {
        FlatShape::Haversine => {
            // f = D cos^2 u, u = k tan psi: f' = -D sin 2u u', f'' = -2D cos 2u u'^2
            // - D sin 2u u'', u' = k sec^2 psi, u'' = 2 k sec^2 psi tan psi.
            let du = k_tan * sec2;
            let d2u = 2.0 * k_tan * sec2 * t;
            depth * du + 2.0 * depth * du * du + depth * d2u
        }
        FlatShape::Chord => {
            // f = R - (R - D) sec psi: f' = -(R - D) sec tan, f'' = -(R - D) sec (sec^2 + tan^2).
            let rd = radius - depth;
            rd * sec * t + rd * sec * (sec2 + t * t)
        }
    }
}

/// The flat `spec` on a wheel of radius `radius` (m), validated; `None` for a flat of
/// zero length and no (or zero) depth. `p` names the flat in errors (`flat.left[1]`).
pub(super) fn validate_flat(radius: f64, spec: &FlatSpec, p: &str) -> Result<Option<Flat>> {
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
    if depth > MAX_FLAT_DEPTH {
        let (name, value) = match depth_given {
            Some(d) => (format!("{p}.depth"), d),
            None => (format!("{p}.length"), length),
        };
        return Err(out_of_range(
            &name,
            value,
            format!(
                "a flat depth <= {MAX_FLAT_DEPTH} m (this one: {} m; wheel flats worn in \
                 service are a few millimetres deep)",
                crate::error::num(depth)
            ),
        ));
    }
    let half_angle = match spec.shape {
        FlatShape::Haversine => length / (2.0 * radius),
        FlatShape::Chord => ((radius - depth) / radius).acos(),
    };
    let k_tan = PI * (radius - depth) / length;
    Ok(Some(Flat {
        shape: spec.shape,
        length,
        depth,
        angle,
        half_angle,
        radius,
        k_tan,
        bend: bend_bound(spec.shape, radius, depth, k_tan, half_angle),
    }))
}
