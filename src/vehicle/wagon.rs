//! A four-axle freight wagon: the car body in bounce, pitch and roll on the bolsters
//! of two three-piece bogies, each the half-car bogie's side frames (bounce, pitch) and
//! wheelsets (bounce, roll) with their primary and secondary suspensions; nineteen
//! degrees of freedom
//! `d = {z_c, theta_c, phi_c, [z_sfl, theta_sfl, z_sfr, theta_sfr, z_w1, phi_w1, z_w2,
//! phi_w2] of the front bogie, then of the rear bogie}`.
//!
//! The bolsters rest on the car body's centre plates: each moves with the car body at
//! its bogie's centre, `x = +- d / 2` (the front bogie ahead), in bounce and roll, and
//! carries its mass and roll inertia into the car body's. Secondary springs and dampers
//! join the bolster at `-+ L_b / 2` to the side frames' centres; primary ones join each
//! side frame at `+- a / 2` (the wheelbase `a`, the leading wheelset ahead) to the axle
//! boxes at `-+ L_w / 2`, as in the half-car bogie ([`super::HalfCarParams`]). Gravity
//! acts on every body, the contact forces on the eight wheels. Displacements up, roll
//! positive raising the right side, pitch positive raising the front (`docs/MODEL.md`).
//!
//! **The exact reduction.** With the car body's pitch inertia `M (d / 2)^2` (`M` the car
//! body's mass, with the bolsters', a dumbbell with half at each centre plate), the car
//! body's bounce and pitch are the two bolsters' bounces with half the mass each, and
//! the mass matrix decouples: the wagon is two half-car bogies, each carrying half the
//! car body, whose bolsters' roll is tied (one rigid car body, one roll angle). It moves
//! as two independent half-cars under any loads that roll both bogies alike, vertical
//! loads among them; loads that roll one bogie and not the other roll the whole car
//! body, which the pair of half-cars cannot (`tests`: to 1e-9).

use super::HalfCarParams;
use crate::error::{Result, out_of_range};
use nalgebra::{SMatrix, SVector};

/// Degrees of freedom of the wagon.
pub const WAGON_DOFS: usize = 19;
/// A vector over the degrees of freedom.
pub type WagonVector = SVector<f64, WAGON_DOFS>;
/// A matrix over the degrees of freedom.
pub type WagonMatrix = SMatrix<f64, WAGON_DOFS, WAGON_DOFS>;

/// The first degree of freedom of bogie `b` (0 front, 1 rear).
pub const fn bogie_start(b: usize) -> usize {
    3 + 8 * b
}

/// Least distance (m) between the front bogie's trailing wheelset and the rear bogie's
/// leading one.
pub const MIN_BOGIE_GAP: f64 = 1.0;

/// Parameters of the wagon.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WagonParams {
    /// Car-body mass (kg), the bolsters' not included.
    pub carbody_mass: f64,
    /// Car-body pitch inertia about its centre (kg m^2), the bolsters' not included.
    pub carbody_pitch_inertia: f64,
    /// Car-body roll inertia about its centre line (kg m^2), the bolsters' not included.
    pub carbody_roll_inertia: f64,
    /// Distance between the two bogies' centres `d` (m).
    pub bogie_distance: f64,
    /// Each bogie: its bolster, side frames, wheelsets, suspensions and wheelbase, as a
    /// half-car bogie whose `carbody_mass` is unused (the car body is the wagon's).
    pub bogie: HalfCarParams,
}

/// One spring or damper: its constant and the coefficients of its elongation.
struct Link {
    constant: f64,
    a: WagonVector,
}

impl WagonParams {
    /// The wagon of table 4.4: the car body four times the thesis' quarter (80.6 t), each
    /// bogie the half-car bogie of the roll-plane vehicle (`HalfCarParams::from_roll_plane`)
    /// with the wheelbase `wheelbase` (m) and the side frames' pitch inertia
    /// `sideframe_pitch_inertia` (kg m^2), the bogies `bogie_distance` (m) apart. The car
    /// body's inertias are those of a uniform box of the loaded wagon's body, 14 m long,
    /// 2.8 m wide and 2.5 m high: pitch `M (L^2 + h^2) / 12` = 1.36e6 kg m^2, roll
    /// `M (w^2 + h^2) / 12` = 9.47e4 kg m^2 (a stated derivation; a measured wagon's
    /// values replace them).
    pub fn table_4_4(
        p: &super::RollPlaneParams,
        bogie_distance: f64,
        wheelbase: f64,
        sideframe_pitch_inertia: f64,
    ) -> WagonParams {
        let m = 4.0 * p.carbody_mass;
        let (l, w, h) = (14.0, 2.8, 2.5);
        WagonParams {
            carbody_mass: m,
            carbody_pitch_inertia: m * (l * l + h * h) / 12.0,
            carbody_roll_inertia: m * (w * w + h * h) / 12.0,
            bogie_distance,
            bogie: HalfCarParams::from_roll_plane(p, wheelbase, sideframe_pitch_inertia),
        }
    }

    /// Checks every parameter: the bogie's as the half-car's; the car body's mass (a
    /// quarter of it, `vehicle.carbody_mass`), its inertias and the bogie distance in
    /// their ranges ([`crate::limits::check`]); the bogie distance at least the
    /// wheelbase plus [`MIN_BOGIE_GAP`].
    pub fn validate(&self) -> Result<()> {
        self.bogie.validate()?;
        crate::limits::check("vehicle.carbody_mass", 0.25 * self.carbody_mass)?;
        crate::limits::check("vehicle.carbody.pitch_inertia", self.carbody_pitch_inertia)?;
        crate::limits::check("vehicle.carbody.roll_inertia", self.carbody_roll_inertia)?;
        crate::limits::check("vehicle.bogie_distance", self.bogie_distance)?;
        let d = self.bogie_distance;
        // The front bogie's trailing wheelset and the rear bogie's leading one at least
        // a metre apart (more than a wheel's diameter, which the track needs between
        // wheelsets).
        let least = self.bogie.wheelbase + MIN_BOGIE_GAP;
        if d < least {
            return Err(out_of_range(
                "vehicle.bogie_distance",
                d,
                format!(
                    "vehicle.wheelbase + {MIN_BOGIE_GAP} m = {} m <= vehicle.bogie_distance <= \
                     30 m (the bogies' inner wheelsets at least {MIN_BOGIE_GAP} m apart)",
                    crate::error::num(least)
                ),
            ));
        }
        Ok(())
    }

    /// The car body with its bolsters: mass (kg), pitch and roll inertia (kg m^2).
    pub fn body_with_bolsters(&self) -> (f64, f64, f64) {
        let (mb, hd) = (self.bogie.bolster_mass, 0.5 * self.bogie_distance);
        (
            self.carbody_mass + 2.0 * mb,
            self.carbody_pitch_inertia + 2.0 * mb * hd * hd,
            self.carbody_roll_inertia + 2.0 * self.bogie.bolster_inertia,
        )
    }

    /// Diagonal of the mass matrix `M`.
    pub fn mass_diagonal(&self) -> WagonVector {
        let b = &self.bogie;
        let (m, jp, jr) = self.body_with_bolsters();
        let mut d = WagonVector::zeros();
        d[0] = m;
        d[1] = jp;
        d[2] = jr;
        for bogie in 0..2 {
            let s = bogie_start(bogie);
            let per = [
                b.sideframe_mass,
                b.sideframe_pitch_inertia,
                b.sideframe_mass,
                b.sideframe_pitch_inertia,
                b.wheelset_mass,
                b.wheelset_inertia,
                b.wheelset_mass,
                b.wheelset_inertia,
            ];
            for (k, x) in per.into_iter().enumerate() {
                d[s + k] = x;
            }
        }
        d
    }

    /// The suspension elements with the constants `k1` (primary, per axle box) and `k2`
    /// (secondary, per side).
    fn links(&self, k1: f64, k2: f64) -> Vec<Link> {
        let b = &self.bogie;
        let (hb, hw, ha, hd) = (
            0.5 * b.secondary_spacing,
            0.5 * b.primary_spacing,
            0.5 * b.wheelbase,
            0.5 * self.bogie_distance,
        );
        let mut links = Vec::new();
        for (bogie, xb) in [(0usize, hd), (1, -hd)] {
            let s0 = bogie_start(bogie);
            // Secondary, side s (y = -+ L_b/2): the bolster (the car body at the centre
            // plate) at y minus the side frame's centre.
            for (s, y) in [(0usize, -hb), (1, hb)] {
                let mut a = WagonVector::zeros();
                a[0] = 1.0;
                a[1] = xb;
                a[2] = y;
                a[s0 + 2 * s] = -1.0;
                links.push(Link { constant: k2, a });
            }
            // Primary, side s, wheelset i at x = +- a/2 from the bogie's centre.
            for (s, y) in [(0usize, -hw), (1, hw)] {
                for (i, x) in [(0usize, ha), (1, -ha)] {
                    let mut a = WagonVector::zeros();
                    a[s0 + 2 * s] = 1.0;
                    a[s0 + 2 * s + 1] = x;
                    a[s0 + 4 + 2 * i] = -1.0;
                    a[s0 + 5 + 2 * i] = -y;
                    links.push(Link { constant: k1, a });
                }
            }
        }
        links
    }

    fn assemble(&self, k1: f64, k2: f64) -> WagonMatrix {
        let mut m = WagonMatrix::zeros();
        for l in self.links(k1, k2) {
            m += l.a * l.a.transpose() * l.constant;
        }
        m
    }

    /// Stiffness matrix `K` (symmetric, from the twenty springs).
    pub fn stiffness_matrix(&self) -> WagonMatrix {
        self.assemble(self.bogie.primary_stiffness, self.bogie.secondary_stiffness)
    }

    /// Damping matrix `C`.
    pub fn damping_matrix(&self) -> WagonMatrix {
        self.assemble(self.bogie.primary_damping, self.bogie.secondary_damping)
    }

    /// Gravity on every body (N): the weights, down; inertias carry none.
    pub fn gravity_force(&self) -> WagonVector {
        let m = self.mass_diagonal();
        let mut f = WagonVector::zeros();
        f[0] = -m[0] * self.bogie.gravity;
        for bogie in 0..2 {
            let s = bogie_start(bogie);
            for k in [0, 2, 4, 6] {
                f[s + k] = -m[s + k] * self.bogie.gravity;
            }
        }
        f
    }

    /// The generalised force of the contact forces `p[b][i]` `[left, right]` (N, up on
    /// the wheels) of wheelset `i` (0 leading) of bogie `b` (0 front).
    pub fn contact_force(&self, p: [[[f64; 2]; 2]; 2]) -> WagonVector {
        let hw = 0.5 * self.bogie.primary_spacing;
        let mut f = WagonVector::zeros();
        for (bogie, pb) in p.iter().enumerate() {
            let s = bogie_start(bogie);
            for (i, [l, r]) in pb.iter().enumerate() {
                f[s + 4 + 2 * i] = l + r;
                f[s + 5 + 2 * i] = hw * (r - l);
            }
        }
        f
    }

    /// Undamped natural frequencies (rad/s), ascending: the square roots of the
    /// eigenvalues of `M^-1 K` (through the symmetric `M^-1/2 K M^-1/2`).
    pub fn natural_frequencies(&self) -> [f64; WAGON_DOFS] {
        crate::numerics::natural_frequencies(&self.mass_diagonal(), &self.stiffness_matrix())
    }

    /// Static contact force on each of the eight wheels (N): an eighth of the weight.
    pub fn static_wheel_load(&self) -> f64 {
        -self.gravity_force().sum() / 8.0
    }

    /// The degrees of freedom the wheels do not hold: the car body's and the side
    /// frames'.
    fn free() -> [usize; 11] {
        let (f, r) = (bogie_start(0), bogie_start(1));
        [0, 1, 2, f, f + 1, f + 2, f + 3, r, r + 1, r + 2, r + 3]
    }

    /// The static state with the wheels held at `z_wheel[b][i]` `[left, right]` (m): the
    /// wheelsets follow; the car body and the side frames solve `K d = F` for the free
    /// degrees of freedom, `F` the gravity and `extra` (N, generalised). `None` when
    /// the suspension does not hold them.
    pub fn static_state_under(
        &self,
        z_wheel: [[[f64; 2]; 2]; 2],
        extra: &WagonVector,
    ) -> Option<WagonVector> {
        let hw = 0.5 * self.bogie.primary_spacing;
        let mut d = WagonVector::zeros();
        for (bogie, zb) in z_wheel.iter().enumerate() {
            let s = bogie_start(bogie);
            for (i, [l, r]) in zb.iter().enumerate() {
                d[s + 4 + 2 * i] = 0.5 * (l + r);
                d[s + 5 + 2 * i] = (r - l) / (2.0 * hw);
            }
        }
        let free = Self::free();
        let k = self.stiffness_matrix();
        let f = self.gravity_force() + extra - k * d;
        let kff = SMatrix::<f64, 11, 11>::from_fn(|i, j| k[(free[i], free[j])]);
        let rhs = SVector::<f64, 11>::from_fn(|i, _| f[free[i]]);
        let x = kff.lu().solve(&rhs)?;
        for (i, &k) in free.iter().enumerate() {
            d[k] = x[i];
        }
        d.iter().all(|x| x.is_finite()).then_some(d)
    }

    /// [`WagonParams::static_state_under`] gravity alone.
    pub fn static_state(&self, z_wheel: [[[f64; 2]; 2]; 2]) -> Option<WagonVector> {
        self.static_state_under(z_wheel, &WagonVector::zeros())
    }

    /// The contact forces `[b][i]` `[left, right]` (N) that hold the static state `d`:
    /// the wheelsets' rows of `K d - F_gravity`, split between the two wheels.
    pub fn static_contact_forces(&self, d: &WagonVector) -> [[[f64; 2]; 2]; 2] {
        let r = self.stiffness_matrix() * d - self.gravity_force();
        let hw = 0.5 * self.bogie.primary_spacing;
        [0, 1].map(|bogie| {
            let s = bogie_start(bogie);
            [0, 1].map(|i| {
                let (f, m) = (r[s + 4 + 2 * i], r[s + 5 + 2 * i]);
                [0.5 * (f - m / hw), 0.5 * (f + m / hw)]
            })
        })
    }
}
