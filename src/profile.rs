//! Wheel profile: nominal radius with haversine or chord flats (seed eqs. 2.9-2.21).
//!
//! Angles are measured at the wheel centre from the downward vertical (the
//! nominal contact point), positive towards the direction of travel ("front").
//! A flat whose centre sits at wheel angle `beta_0` when the axle rotation angle
//! is zero is found, at axle rotation `gamma`, at the space angle
//! `beta_0 - gamma` (2.17-2.21), wrapped into (-pi, pi].

use crate::error::{Result, finite, out_of_range, positive};
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
    /// Haversine flat: `pi (R_w - D_f) / l_f` (dimensionless), the phase
    /// `u = pi x / l_f - pi/2` of (2.16) per unit of `tan psi`.
    k_tan: f64,
    /// Upper bound of `|f'(psi)| + |f''(psi)|` over the flat (m/rad, m/rad^2): what
    /// the flat adds to the curvature of the contact integrand.
    bend: f64,
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
            FlatShape::Haversine => self.haversine_of_tan(tan_small(psi)),
            FlatShape::Chord => self.chord_of_cos(cos_small(psi)),
        }
    }

    /// (2.16) with x = l_f/2 + (R_w - D_f) tan psi along the flat, from `tan psi`:
    /// D/2 (1 - cos(2 pi x / l)) = D sin^2(pi x / l) = D cos^2 u with
    /// u = pi x / l - pi/2 = k_tan tan psi. u is clamped to [-pi/2, pi/2]
    /// (x to [0, l_f]) so that the profile is continuous at the flat ends
    /// (the seed's x misses 0 by ~1e-5 l_f).
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

    /// [`Flat::reduction`] at [`LANES`] angles at once, written so that the compiler
    /// vectorises it: every lane computes exactly what [`Flat::reduction`] computes,
    /// so the results are the same bits. `None` when a lane inside the flat lies
    /// beyond [`SMALL_ANGLE`] (where [`Flat::reduction`] calls the library functions).
    #[inline(always)]
    pub(crate) fn reduction_lanes(&self, psi: &[f64; LANES]) -> Option<[f64; LANES]> {
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

    /// Radius reduction (m) at space angle `alpha` (rad) for axle rotation `gamma` (rad).
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

/// Most flats one wheel may carry.
pub const MAX_FLATS: usize = 8;

/// A wheel: nominal radius and its flats.
#[derive(Debug, Clone, PartialEq)]
pub struct WheelProfile {
    /// Nominal rolling radius `R_w` (m).
    radius: f64,
    /// `1 / (2 R_w)` (1/m): the contact scales every overlap by it.
    half_inv_radius: f64,
    flats: Vec<Flat>,
}

impl WheelProfile {
    /// A perfect wheel of radius `radius` (m).
    pub fn perfect(radius: f64) -> Result<Self> {
        positive("wheel.radius", radius, "m")?;
        Ok(WheelProfile {
            radius,
            half_inv_radius: 0.5 / radius,
            flats: Vec::new(),
        })
    }

    /// Nominal rolling radius `R_w` (m).
    #[inline]
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// `1 / (2 R_w)` (1/m), kept so that the contact does not divide by the radius
    /// on every evaluation.
    #[inline]
    pub(crate) fn half_inv_radius(&self) -> f64 {
        self.half_inv_radius
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
    fn reduction_lanes_give_the_same_bits_as_reduction() {
        // Haversine and chord flats, angles inside, at the edge of and outside the flat:
        // every lane equals the one-angle evaluation bit for bit; a lane inside the
        // flat beyond SMALL_ANGLE (library functions there) refuses the batch.
        let flats = [
            FlatSpec::haversine(0.1, 0.0015, 0.0),
            FlatSpec::chord(0.08, 0.0),
            FlatSpec::haversine(0.3, 0.004, 0.0),
        ];
        let w = WheelProfile::new(R, &flats, "flat.left").unwrap();
        for fl in w.flats() {
            let h = fl.half_angle;
            for k in 0..200 {
                let psi: [f64; LANES] = std::array::from_fn(|l| {
                    (k as f64 * 0.37 + l as f64 * 0.93).sin() * (1.3 * h).min(SMALL_ANGLE)
                });
                let want = psi.map(|p| fl.reduction(p));
                let got = fl
                    .reduction_lanes(&psi)
                    .expect("all lanes within SMALL_ANGLE");
                for l in 0..LANES {
                    assert_eq!(
                        got[l].to_bits(),
                        want[l].to_bits(),
                        "{:?} psi {}",
                        fl.shape,
                        psi[l]
                    );
                }
                assert!(want.iter().any(|&f| f > 0.0));
            }
            if h > SMALL_ANGLE {
                continue;
            }
            let mut edge = [0.0; LANES];
            edge[0] = h;
            edge[1] = -h;
            edge[2] = h * (1.0 - 1e-15);
            let got = fl.reduction_lanes(&edge).unwrap();
            assert_eq!(
                got.map(f64::to_bits),
                edge.map(|p| fl.reduction(p).to_bits())
            );
        }
        // The 300 mm flat reaches beyond SMALL_ANGLE (half angle 0.316 rad).
        let wide = &w.flats()[2];
        assert!(wide.half_angle > SMALL_ANGLE);
        let mut psi = [0.0; LANES];
        psi[3] = 0.25;
        assert_eq!(wide.reduction_lanes(&psi), None);
        // ... but outside a flat a large angle needs no library function.
        psi[3] = 0.5;
        assert!(wide.reduction_lanes(&psi).is_some());
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
