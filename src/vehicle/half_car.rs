//! The thesis' half-car bogie (its figure 1.10 and future work): one bogie of a freight
//! wagon in bounce, roll and pitch, ten degrees of freedom
//! `d = {z_b, phi_b, z_sfl, theta_sfl, z_sfr, theta_sfr, z_w1, phi_w1, z_w2, phi_w2}`:
//! the bolster with its share of the car body (bounce, roll), the two side frames
//! (bounce, pitch), the leading (1) and trailing (2) wheelsets (bounce, roll). Secondary
//! springs and dampers join the bolster at `-+ L_b / 2` to the side frames' centres;
//! primary ones join each side frame at `+- a / 2` along the track (the wheelbase `a`)
//! to the axle boxes at `-+ L_w / 2`. Gravity acts on every body, the contact forces on
//! the four wheels (below the axle boxes). Displacements up, roll positive raising the
//! right side, pitch positive raising the front (`docs/MODEL.md`).
//!
//! Cut fore and aft through the bogie's centre, with both wheelsets moving alike and
//! the side frames not pitching, it is twice the roll-plane vehicle of (3.1-3.3):
//! [`HalfCarParams::from_roll_plane`] builds the half-car whose in-phase modes are the
//! roll-plane vehicle's. One difference is deliberate: the thesis' roll-plane vehicle
//! carries the car body as a weight on the bolster, not as a mass; here the car body's
//! share is part of the bolster's mass (its roll inertia is in `bolster_inertia`), so
//! the in-phase modes are those of the roll-plane vehicle with the car body's mass on
//! its bolster. Without the rails under the wheels the bogie has four rigid modes
//! (bounce, roll, pitch and warp).

use super::RollPlaneParams;
use crate::error::{Result, out_of_range};
use crate::limits::check;
use nalgebra::{SMatrix, SVector};

/// Degrees of freedom of the half-car bogie.
pub const HALF_CAR_DOFS: usize = 10;
/// A vector over the degrees of freedom.
pub type HalfCarVector = SVector<f64, HALF_CAR_DOFS>;
/// A matrix over the degrees of freedom.
pub type HalfCarMatrix = SMatrix<f64, HALF_CAR_DOFS, HALF_CAR_DOFS>;

/// Names of the degrees of freedom, in the order of `d`.
pub const HALF_CAR_DOF_NAMES: [&str; HALF_CAR_DOFS] = [
    "bolster.z (m)",
    "bolster.roll (rad)",
    "sideframe.left.z (m)",
    "sideframe.left.pitch (rad)",
    "sideframe.right.z (m)",
    "sideframe.right.pitch (rad)",
    "wheelset[1].z (m)",
    "wheelset[1].roll (rad)",
    "wheelset[2].z (m)",
    "wheelset[2].roll (rad)",
];

/// Parameters of the half-car bogie (table 4.4 names, for a whole bogie).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfCarParams {
    /// Car-body mass carried by the bolster centre (kg): half the car body.
    pub carbody_mass: f64,
    /// Bolster mass (kg).
    pub bolster_mass: f64,
    /// Roll inertia of the bolster with its car-body share (kg m^2).
    pub bolster_inertia: f64,
    /// Mass of one side frame (kg).
    pub sideframe_mass: f64,
    /// Pitch inertia of one side frame about its centre (kg m^2).
    pub sideframe_pitch_inertia: f64,
    /// Mass of one wheelset (kg).
    pub wheelset_mass: f64,
    /// Roll inertia of one wheelset (kg m^2).
    pub wheelset_inertia: f64,
    /// Primary stiffness per axle box `K_1` (N/m).
    pub primary_stiffness: f64,
    /// Primary damping per axle box `C_1` (N s/m).
    pub primary_damping: f64,
    /// Lateral distance between the axle boxes (and the contact points) `L_w` (m).
    pub primary_spacing: f64,
    /// Secondary stiffness per side `K_2` (N/m).
    pub secondary_stiffness: f64,
    /// Secondary damping per side `C_2` (N s/m).
    pub secondary_damping: f64,
    /// Lateral distance between the secondary suspensions `L_b` (m).
    pub secondary_spacing: f64,
    /// Wheelbase `a` (m): the distance between the two wheelsets (a freight bogie's is
    /// about 1.8 m).
    pub wheelbase: f64,
    /// Gravitational acceleration `g` (m/s^2).
    pub gravity: f64,
}

/// One spring or damper: its constant and the coefficients of its elongation over the
/// degrees of freedom (`K += k a a^T`).
struct Link {
    constant: f64,
    a: HalfCarVector,
}

impl HalfCarParams {
    /// The half-car bogie that is twice the roll-plane vehicle `p` cut fore and aft:
    /// the car-body share, bolster, bolster inertia and side frames doubled (the
    /// roll-plane vehicle carries half a bogie), the secondary suspension doubled per
    /// side, the primary per axle box and the wheelsets as they are; the side frames'
    /// pitch inertia `sideframe_pitch_inertia` (kg m^2) and the wheelbase `wheelbase`
    /// (m) added.
    pub fn from_roll_plane(
        p: &RollPlaneParams,
        wheelbase: f64,
        sideframe_pitch_inertia: f64,
    ) -> HalfCarParams {
        HalfCarParams {
            carbody_mass: 2.0 * p.carbody_mass,
            bolster_mass: 2.0 * p.bolster_mass,
            bolster_inertia: 2.0 * p.bolster_inertia,
            sideframe_mass: 2.0 * p.sideframe_mass,
            sideframe_pitch_inertia,
            wheelset_mass: p.wheelset_mass,
            wheelset_inertia: p.wheelset_inertia,
            primary_stiffness: p.primary_stiffness,
            primary_damping: p.primary_damping,
            primary_spacing: p.primary_spacing,
            secondary_stiffness: 2.0 * p.secondary_stiffness,
            secondary_damping: 2.0 * p.secondary_damping,
            secondary_spacing: p.secondary_spacing,
            wheelbase,
            gravity: p.gravity,
        }
    }

    /// Checks every parameter against its physical range (named as the FMU
    /// variables); the wheelbase between 1 and 5 m (more than a wheel's diameter, which
    /// the track needs between wheelsets), the side frames' pitch inertia
    /// between 1 and 1e5 kg m^2.
    pub fn validate(&self) -> Result<()> {
        for (name, value) in [
            ("vehicle.carbody_mass", self.carbody_mass),
            ("vehicle.bolster.mass", self.bolster_mass),
            ("vehicle.bolster.inertia", self.bolster_inertia),
            ("vehicle.sideframe.mass", self.sideframe_mass),
            ("vehicle.wheelset.mass", self.wheelset_mass),
            ("vehicle.wheelset.inertia", self.wheelset_inertia),
            ("vehicle.primary.stiffness", self.primary_stiffness),
            ("vehicle.primary.damping", self.primary_damping),
            ("vehicle.primary.spacing", self.primary_spacing),
            ("vehicle.secondary.damping", self.secondary_damping),
            ("vehicle.secondary.spacing", self.secondary_spacing),
            ("gravity", self.gravity),
            ("vehicle.wheelbase", self.wheelbase),
            (
                "vehicle.sideframe.pitch_inertia",
                self.sideframe_pitch_inertia,
            ),
        ] {
            check(name, value)?;
        }
        // Two sides' secondary springs: twice the roll-plane vehicle's range.
        let (name, v, lo, hi) = (
            "vehicle.secondary.stiffness",
            self.secondary_stiffness,
            1e4,
            2e10,
        );
        if !(v >= lo && v <= hi) {
            return Err(out_of_range(name, v, format!("{lo} <= {name} <= {hi}")));
        }
        Ok(())
    }

    /// Diagonal of the mass matrix `M`.
    pub fn mass_diagonal(&self) -> HalfCarVector {
        let (msf, jsf) = (self.sideframe_mass, self.sideframe_pitch_inertia);
        let (mw, jw) = (self.wheelset_mass, self.wheelset_inertia);
        HalfCarVector::from_column_slice(&[
            self.bolster_mass + self.carbody_mass,
            self.bolster_inertia,
            msf,
            jsf,
            msf,
            jsf,
            mw,
            jw,
            mw,
            jw,
        ])
    }

    /// The suspension elements with the constants `k1` (primary, per axle box) and `k2`
    /// (secondary, per side).
    fn links(&self, k1: f64, k2: f64) -> Vec<Link> {
        let (hb, hw, ha) = (
            0.5 * self.secondary_spacing,
            0.5 * self.primary_spacing,
            0.5 * self.wheelbase,
        );
        let mut links = Vec::new();
        // Secondary, side s (y = -+ L_b/2): bolster at y minus the side frame's centre.
        for (s, y) in [(0usize, -hb), (1, hb)] {
            let mut a = HalfCarVector::zeros();
            a[0] = 1.0;
            a[1] = y;
            a[2 + 2 * s] = -1.0;
            links.push(Link { constant: k2, a });
        }
        // Primary, side s, wheelset i at x = +- a/2: the side frame at x minus the
        // wheelset's axle box at y = -+ L_w/2.
        for (s, y) in [(0usize, -hw), (1, hw)] {
            for (i, x) in [(0usize, ha), (1, -ha)] {
                let mut a = HalfCarVector::zeros();
                a[2 + 2 * s] = 1.0;
                a[3 + 2 * s] = x;
                a[6 + 2 * i] = -1.0;
                a[7 + 2 * i] = -y;
                links.push(Link { constant: k1, a });
            }
        }
        links
    }

    fn assemble(&self, k1: f64, k2: f64) -> HalfCarMatrix {
        let mut m = HalfCarMatrix::zeros();
        for l in self.links(k1, k2) {
            m += l.a * l.a.transpose() * l.constant;
        }
        m
    }

    /// Stiffness matrix `K` (symmetric, assembled from the ten springs).
    pub fn stiffness_matrix(&self) -> HalfCarMatrix {
        self.assemble(self.primary_stiffness, self.secondary_stiffness)
    }

    /// Damping matrix `C`.
    pub fn damping_matrix(&self) -> HalfCarMatrix {
        self.assemble(self.primary_damping, self.secondary_damping)
    }

    /// Gravity on every body (N): the weights, down.
    pub fn gravity_force(&self) -> HalfCarVector {
        let g = self.gravity;
        let mut f = -self.mass_diagonal() * g;
        // Inertias carry no weight.
        for i in [1, 3, 5, 7, 9] {
            f[i] = 0.0;
        }
        f
    }

    /// The generalised force of the contact forces `p` `[[left, right] of wheelset 1,
    /// [left, right] of wheelset 2]` (N, up on the wheels), at `-+ L_w / 2`.
    pub fn contact_force(&self, p: [[f64; 2]; 2]) -> HalfCarVector {
        let hw = 0.5 * self.primary_spacing;
        let mut f = HalfCarVector::zeros();
        for (i, [l, r]) in p.iter().enumerate() {
            f[6 + 2 * i] = l + r;
            f[7 + 2 * i] = hw * (r - l);
        }
        f
    }

    /// Undamped natural frequencies (rad/s), ascending: the square roots of the
    /// eigenvalues of `M^-1 K` (through the symmetric `M^-1/2 K M^-1/2`).
    pub fn natural_frequencies(&self) -> [f64; HALF_CAR_DOFS] {
        crate::numerics::natural_frequencies(&self.mass_diagonal(), &self.stiffness_matrix())
    }

    /// Static contact force on each of the four wheels (N): a quarter of the bogie's
    /// weight with its car-body share.
    pub fn static_wheel_load(&self) -> f64 {
        0.25 * self.gravity
            * (self.carbody_mass
                + self.bolster_mass
                + 2.0 * self.sideframe_mass
                + 2.0 * self.wheelset_mass)
    }

    /// The static state with the four wheels held at `z_wheel` `[[left, right] of
    /// wheelset 1, of wheelset 2]` (m): the wheelsets follow, the bolster and side
    /// frames solve `K d = F_gravity` for the free degrees of freedom. `None` when the
    /// suspension does not hold them.
    pub fn static_state(&self, z_wheel: [[f64; 2]; 2]) -> Option<HalfCarVector> {
        let hw = 0.5 * self.primary_spacing;
        let mut d = HalfCarVector::zeros();
        for (i, [l, r]) in z_wheel.iter().enumerate() {
            d[6 + 2 * i] = 0.5 * (l + r);
            d[7 + 2 * i] = (r - l) / (2.0 * hw);
        }
        let k = self.stiffness_matrix();
        let kaa = k.fixed_view::<6, 6>(0, 0).into_owned();
        let kab = k.fixed_view::<6, 4>(0, 6);
        let g = self.gravity_force();
        let rhs = g.fixed_rows::<6>(0) - kab * d.fixed_rows::<4>(6);
        let free = kaa.lu().solve(&rhs)?;
        d.fixed_rows_mut::<6>(0).copy_from(&free);
        d.iter().all(|x| x.is_finite()).then_some(d)
    }

    /// The contact forces `[[left, right]; 2]` (N) that hold the static state `d`: the
    /// wheelsets' rows of `K d - F_gravity`, split between the two wheels.
    pub fn static_contact_forces(&self, d: &HalfCarVector) -> [[f64; 2]; 2] {
        let r = self.stiffness_matrix() * d - self.gravity_force();
        let hw = 0.5 * self.primary_spacing;
        [0, 1].map(|i| {
            let (f, m) = (r[6 + 2 * i], r[7 + 2 * i]);
            [0.5 * (f - m / hw), 0.5 * (f + m / hw)]
        })
    }
}
