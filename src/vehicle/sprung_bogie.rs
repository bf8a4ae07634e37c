//! The roll-plane vehicle above its primary suspension ([`SprungBogie`]), the partner of
//! the wheelset the track carries ([`super::WheelsetBody`], [`super::PrimaryLink`]) at
//! the axle-box interface (`axle_box.rs`).

use super::RollPlaneParams;
use crate::error::{Result, positive};
use crate::limits::{BODY_DISPLACEMENT_LIMIT, within};
use crate::numerics::CentralDifference;
use nalgebra::{Matrix4, Vector4};

/// The roll-plane vehicle above its primary suspension, `d = {z_b, phi_b, z_sfl,
/// z_sfr}` (the first four of (3.1)), with gravity, driven by the primary forces
/// `[left, right]` (N, pressing the axle boxes down, so pushing the side frames up) that
/// its partner ([`super::PrimaryLink`]) computes, and advanced by the central differences of
/// the whole model with the damping as in (3.25). Its side frames' motion
/// ([`SprungBogie::side_frames`]) drives the primary suspension on the other side.
#[derive(Debug, Clone)]
pub struct SprungBogie {
    params: RollPlaneParams,
    /// The bodies' displacements and the update of (3.25) without the primary
    /// suspension.
    cd: CentralDifference<4>,
    gravity: Vector4<f64>,
}

impl SprungBogie {
    /// The bodies of `params` above the primary suspension, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`RollPlaneParams::validate`] refuses; `dt` not positive or
    /// above the whole vehicle's critical step.
    pub fn new(params: RollPlaneParams, dt: f64) -> Result<SprungBogie> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        let g = params.gravity_force();
        let m = params.mass_diagonal();
        // The first four rows and columns of (3.1), less the primary suspension,
        // which is the other side's.
        let mut k: Matrix4<f64> = params.stiffness_matrix().fixed_view::<4, 4>(0, 0).into();
        let mut c: Matrix4<f64> = params.damping_matrix().fixed_view::<4, 4>(0, 0).into();
        for i in 2..4 {
            k[(i, i)] -= params.primary_stiffness;
            c[(i, i)] -= params.primary_damping;
        }
        Ok(SprungBogie {
            params,
            cd: CentralDifference::new(&Vector4::new(m[0], m[1], m[2], m[3]), k, c, dt),
            gravity: Vector4::new(g[0], g[1], g[2], g[3]),
        })
    }

    /// Step (s).
    pub fn dt(&self) -> f64 {
        self.cd.dt()
    }

    /// Parameters.
    pub fn params(&self) -> &RollPlaneParams {
        &self.params
    }

    /// Changes the step to `dt` (s), keeping the displacements and the
    /// backward-difference velocities, as [`super::RollPlaneVehicle::change_dt`].
    ///
    /// Errors: `dt` not positive or above the whole vehicle's critical step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        let p = self.params;
        self.cd.change_dt_checked(dt, |h| p.check_time_step(h))
    }

    /// `[dt, d (4), d_prev (4)]`.
    pub fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }

    /// Restores [`SprungBogie::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let p = self.params;
        self.cd
            .restore(v, "bogie state length", |h| p.check_time_step(h))
    }

    /// A displacement beyond [`BODY_DISPLACEMENT_LIMIT`], named as the roll-plane
    /// vehicle's.
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        self.cd
            .d()
            .iter()
            .chain(self.cd.d_prev().iter())
            .enumerate()
            .map(|(i, &x)| (super::BODY_DOFS[i % 4], x, BODY_DISPLACEMENT_LIMIT))
            .find(|&(_, x, l)| !within(x, l))
    }

    /// Advances one step from `t_j` under the primary forces `f` `[left, right]` (N)
    /// held over it.
    pub fn step(&mut self, f: [f64; 2]) {
        self.cd
            .advance(self.gravity + Vector4::new(0.0, 0.0, f[0], f[1]));
    }

    /// The side frames' displacements and velocities `[left, right]` (m, m/s) at `t_j`,
    /// the velocities backward differences over the last step.
    pub fn side_frames(&self) -> ([f64; 2], [f64; 2]) {
        let (d, v) = (self.cd.d(), self.cd.velocities());
        ([d[2], d[3]], [v[2], v[3]])
    }

    /// `{z_b, phi_b, z_sfl, z_sfr}` at `t_j` (m, rad).
    pub fn displacements(&self) -> &Vector4<f64> {
        self.cd.d()
    }

    /// Primary suspension forces `[left, right]` (N), positive pressing the axle boxes
    /// down: `-(K_1 (z_sf - z_box) + C_1 (v_sf - v_box))`, the side frames' velocities
    /// backward differences over the last step.
    pub fn primary_forces(&self, z_box: [f64; 2], v_box: [f64; 2]) -> [f64; 2] {
        let (k1, c1) = (self.params.primary_stiffness, self.params.primary_damping);
        let (d, v) = self.side_frames();
        [
            -(k1 * (d[0] - z_box[0]) + c1 * (v[0] - v_box[0])),
            -(k1 * (d[1] - z_box[1]) + c1 * (v[1] - v_box[1])),
        ]
    }

    /// Static equilibrium with the axle boxes held at `z_box` (m): the bodies on their
    /// secondary springs and on the primary springs to the axle boxes, `K d = F_gravity
    /// + K_1 z_box` over the first four rows of (3.1).
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_box: [f64; 2]) -> Result<()> {
        let k: Matrix4<f64> = self
            .params
            .stiffness_matrix()
            .fixed_view::<4, 4>(0, 0)
            .into();
        let k1 = self.params.primary_stiffness;
        let rhs = self.gravity + Vector4::new(0.0, 0.0, k1 * z_box[0], k1 * z_box[1]);
        let d = k
            .lu()
            .solve(&rhs)
            .filter(|d| d.iter().all(|x| x.is_finite()))
            .ok_or_else(|| {
                crate::error::Error::Unsupported(
                    "static equilibrium of the bogie: the suspension does not hold the bodies"
                        .into(),
                )
            })?;
        self.cd.set_state(d, d);
        Ok(())
    }
}
