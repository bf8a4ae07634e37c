//! The axle-box interface of the roll-plane vehicle: the thesis' six-degree-of-freedom
//! model (3.1-3.3) cut at the primary suspension into
//!
//! * [`WheelsetBody`], the wheelset (bounce `z_w` and roll `phi_w`, mass `m_w`, roll
//!   inertia `J_w`, gravity), driven by the two contact forces from below and the two
//!   primary (axle-box) forces from above; it rides with the track, on the track's
//!   step, so the stiff contact (about 1.5e9 N/m against 1,120 kg) never crosses a
//!   co-simulation interface;
//! * [`SprungBogie`], the bodies above it (bolster bounce and roll, two side frames),
//!   driven by the axle boxes' displacements and velocities through the primary
//!   suspension, whose forces it returns.
//!
//! Joined at every step of the same size they are the monolithic model; exchanged every
//! communication step of a bogie model (about 1 ms) the interface is the soft primary
//! suspension (27 Hz against the side frame), which an explicit exchange carries.
//! Signs: displacements up, roll positive raising the right side, the primary force
//! positive pressing the wheelset down (`docs/MODEL.md`).

use super::RollPlaneParams;
use crate::error::{Result, out_of_range, positive};
use crate::limits::{BODY_DISPLACEMENT_LIMIT, within};
use nalgebra::{Matrix4, Vector4};

/// The wheelset of the roll-plane vehicle on its own: bounce and roll under the contact
/// forces `P` `[left, right]` (N, up on the wheels) and the axle-box forces `F`
/// `[left, right]` (N, down on the axle boxes), both at half the primary spacing `L_w /
/// 2` from the centre, and gravity; advanced by central differences (no damping of its
/// own: the primary dampers are the bogie side's).
#[derive(Debug, Clone)]
pub struct WheelsetBody {
    mass: f64,
    inertia: f64,
    /// Half the primary spacing `L_w / 2` (m): axle boxes and contact points.
    half: f64,
    gravity: f64,
    dt: f64,
    /// `[z_w, phi_w]` at `t_j` (m, rad).
    d: [f64; 2],
    /// `[z_w, phi_w]` at `t_(j-1)`.
    d_prev: [f64; 2],
}

impl WheelsetBody {
    /// The wheelset of `p` (its mass, roll inertia, primary spacing and gravity), at
    /// rest at zero, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`RollPlaneParams::validate`] refuses; `dt` not positive.
    pub fn new(p: &RollPlaneParams, dt: f64) -> Result<WheelsetBody> {
        p.validate()?;
        positive("solver.dt", dt, "s")?;
        Ok(WheelsetBody {
            mass: p.wheelset_mass,
            inertia: p.wheelset_inertia,
            half: 0.5 * p.primary_spacing,
            gravity: p.gravity,
            dt,
            d: [0.0; 2],
            d_prev: [0.0; 2],
        })
    }

    /// The wheel-centre (and axle-box) displacements `[left, right]` (m): `z_w -+ L_w/2
    /// phi_w`.
    #[inline(always)]
    pub fn wheel_z(&self) -> [f64; 2] {
        let [z, phi] = self.d;
        [z - self.half * phi, z + self.half * phi]
    }

    /// The axle boxes' velocities `[left, right]` (m/s), backward differences over the
    /// last step.
    pub fn box_velocity(&self) -> [f64; 2] {
        let v = [
            (self.d[0] - self.d_prev[0]) / self.dt,
            (self.d[1] - self.d_prev[1]) / self.dt,
        ];
        [v[0] - self.half * v[1], v[0] + self.half * v[1]]
    }

    /// Static axle-box loads `[left, right]` (N) that hold the wheelset on the static
    /// contact forces `p` (N): `p - m_w g / 2` each, the roll moments balanced.
    pub fn static_box_force(&self, p: [f64; 2]) -> [f64; 2] {
        let w = 0.5 * self.mass * self.gravity;
        [p[0] - w, p[1] - w]
    }

    /// Puts the wheelset at rest with its wheel centres at `z_wheel` `[left, right]` (m).
    pub fn set_static(&mut self, z_wheel: [f64; 2]) {
        self.d = [
            0.5 * (z_wheel[0] + z_wheel[1]),
            (z_wheel[1] - z_wheel[0]) / (2.0 * self.half),
        ];
        self.d_prev = self.d;
    }

    /// Advances one step from `t_j` under the contact forces `p` and the axle-box forces
    /// `f` held over it (N).
    #[inline(always)]
    pub fn step(&mut self, p: [f64; 2], f: [f64; 2]) {
        let up = [p[0] - f[0], p[1] - f[1]];
        let force = up[0] + up[1] - self.mass * self.gravity;
        let moment = self.half * (up[1] - up[0]);
        let h2 = self.dt * self.dt;
        let next = [
            2.0 * self.d[0] - self.d_prev[0] + h2 * force / self.mass,
            2.0 * self.d[1] - self.d_prev[1] + h2 * moment / self.inertia,
        ];
        self.d_prev = self.d;
        self.d = next;
    }

    /// Changes the step to `dt` (s), keeping the displacements and the backward-difference
    /// velocities.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        let r = dt / self.dt;
        for i in 0..2 {
            self.d_prev[i] = self.d[i] - (self.d[i] - self.d_prev[i]) * r;
        }
        self.dt = dt;
        Ok(())
    }

    /// `[dt, z_w, phi_w, z_w prev, phi_w prev]`.
    pub fn state_vector(&self) -> Vec<f64> {
        vec![
            self.dt,
            self.d[0],
            self.d[1],
            self.d_prev[0],
            self.d_prev[1],
        ]
    }

    /// Restores [`WheelsetBody::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != 5 {
            return Err(out_of_range(
                "wheelset state length",
                v.len() as f64,
                "5 values",
            ));
        }
        if v[0] != self.dt {
            self.change_dt(v[0])?;
        }
        self.d = [v[1], v[2]];
        self.d_prev = [v[3], v[4]];
        Ok(())
    }

    /// `[z_w, phi_w]` beyond [`BODY_DISPLACEMENT_LIMIT`], as in the roll-plane vehicle.
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        [
            ("wheelset.z (m)", self.d[0]),
            ("wheelset.roll (rad)", self.d[1]),
        ]
        .into_iter()
        .find(|(_, x)| !within(*x, BODY_DISPLACEMENT_LIMIT))
        .map(|(n, x)| (n, x, BODY_DISPLACEMENT_LIMIT))
    }
}

/// The roll-plane vehicle above its wheelset, `d = {z_b, phi_b, z_sfl, z_sfr}` (the
/// first four of (3.1)), with gravity, driven through the primary suspension by the axle
/// boxes' displacements and velocities `[left, right]` (m, m/s), advanced by the central
/// differences of the whole model with the damping as in (3.25). The primary forces it
/// returns ([`SprungBogie::primary_forces`]) load the wheelset.
#[derive(Debug, Clone)]
pub struct SprungBogie {
    params: RollPlaneParams,
    dt: f64,
    d: Vector4<f64>,
    d_prev: Vector4<f64>,
    p_cur: Matrix4<f64>,
    p_prev: Matrix4<f64>,
    p_force: Matrix4<f64>,
    gravity: Vector4<f64>,
}

impl SprungBogie {
    /// The bodies of `params` above the wheelset, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`RollPlaneParams::validate`] refuses; `dt` not positive or
    /// above the whole vehicle's critical step.
    pub fn new(params: RollPlaneParams, dt: f64) -> Result<SprungBogie> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        let g = params.gravity_force();
        let mut b = SprungBogie {
            params,
            dt,
            d: Vector4::zeros(),
            d_prev: Vector4::zeros(),
            p_cur: Matrix4::zeros(),
            p_prev: Matrix4::zeros(),
            p_force: Matrix4::zeros(),
            gravity: Vector4::new(g[0], g[1], g[2], g[3]),
        };
        b.set_coefficients(dt);
        Ok(b)
    }

    fn set_coefficients(&mut self, dt: f64) {
        let p = &self.params;
        let m = p.mass_diagonal();
        let minv = Matrix4::from_diagonal(&Vector4::new(
            1.0 / m[0],
            1.0 / m[1],
            1.0 / m[2],
            1.0 / m[3],
        ));
        let k: Matrix4<f64> = p.stiffness_matrix().fixed_view::<4, 4>(0, 0).into();
        let c: Matrix4<f64> = p.damping_matrix().fixed_view::<4, 4>(0, 0).into();
        let id = Matrix4::<f64>::identity();
        // As the whole vehicle (`RollPlaneVehicle`): M + dt/2 C is symmetric positive
        // definite, so the inverse exists.
        let inv = (id + minv * c * (0.5 * dt)).try_inverse().unwrap_or(id);
        self.p_cur = inv * (id * 2.0 - minv * k * (dt * dt));
        self.p_prev = inv * (minv * c * (0.5 * dt) - id);
        self.p_force = inv * minv * (dt * dt);
        self.dt = dt;
    }

    /// Step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// `{z_b, phi_b, z_sfl, z_sfr}` at `t_j` (m, rad).
    pub fn displacements(&self) -> &Vector4<f64> {
        &self.d
    }

    /// The primary suspension's force on the side frames `[left, right]`' equations from
    /// the axle boxes at `z_box` (m) moving at `v_box` (m/s): `K_1 z_box + C_1 v_box`
    /// up on each side frame (the part of `-K d - C v` of (3.1) that the wheelset's
    /// motion contributes).
    fn box_drive(&self, z_box: [f64; 2], v_box: [f64; 2]) -> Vector4<f64> {
        let (k1, c1) = (self.params.primary_stiffness, self.params.primary_damping);
        Vector4::new(
            0.0,
            0.0,
            k1 * z_box[0] + c1 * v_box[0],
            k1 * z_box[1] + c1 * v_box[1],
        )
    }

    /// Advances one step from `t_j` with the axle boxes at `z_box` (m) moving at `v_box`
    /// (m/s), held over the step.
    pub fn step(&mut self, z_box: [f64; 2], v_box: [f64; 2]) {
        let f = self.gravity + self.box_drive(z_box, v_box);
        let next = self.p_cur * self.d + self.p_prev * self.d_prev + self.p_force * f;
        self.d_prev = self.d;
        self.d = next;
    }

    /// Primary suspension forces `[left, right]` (N), positive pressing the axle boxes
    /// down: `-(K_1 (z_sf - z_box) + C_1 (v_sf - v_box))`, the side frames' velocities
    /// backward differences over the last step.
    pub fn primary_forces(&self, z_box: [f64; 2], v_box: [f64; 2]) -> [f64; 2] {
        let (k1, c1) = (self.params.primary_stiffness, self.params.primary_damping);
        let v = (self.d - self.d_prev) / self.dt;
        [
            -(k1 * (self.d[2] - z_box[0]) + c1 * (v[2] - v_box[0])),
            -(k1 * (self.d[3] - z_box[1]) + c1 * (v[3] - v_box[1])),
        ]
    }

    /// Static equilibrium with the axle boxes held at `z_box` (m).
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_box: [f64; 2]) -> Result<()> {
        let k: Matrix4<f64> = self
            .params
            .stiffness_matrix()
            .fixed_view::<4, 4>(0, 0)
            .into();
        let rhs = self.gravity + self.box_drive(z_box, [0.0; 2]);
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
        self.d = d;
        self.d_prev = d;
        Ok(())
    }
}
