//! Vehicle models and the alternative loads on the track.
//!
//! * [`RollPlaneVehicle`]: the seed's six-degree-of-freedom half-bogie roll-plane model
//!   (3.1-3.3), `d = {z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`, with gravity on every body,
//!   advanced by central differences with damping as in (3.25).
//! * [`LumpedWheels`]: the chapter-2 lumped model's wheel (2.27, first equation), one
//!   per side: half-wheelset mass on the series primary/secondary suspension, loaded by
//!   the wheel load `W`.
//! * [`LumpedTrack`]: the chapter-2 lumped track mass (2.27, second equation), one per rail.
//!
//! Roll angles are positive when they raise the right side (MODEL.md).

use crate::error::{Error, Result, non_negative, out_of_range, positive};
use crate::limits::{
    BODY_DISPLACEMENT_LIMIT, DISPLACEMENT_LIMIT, MAX_STATIC_DEFLECTION, check, within,
};
use nalgebra::{Matrix4, Matrix6, Vector4, Vector6};

/// Parameters of the roll-plane vehicle (table 4.4 names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RollPlaneParams {
    /// Quarter car-body mass carried by the bolster centre (kg); weight `W = m g`.
    pub carbody_mass: f64,
    /// Half-bolster mass `m_b` (kg).
    pub bolster_mass: f64,
    /// Half-bolster roll inertia `J_b` (kg m^2).
    pub bolster_inertia: f64,
    /// Mass of one (half) side frame `m_sfl = m_sfr` (kg).
    pub sideframe_mass: f64,
    /// Wheelset mass `m_w` (kg).
    pub wheelset_mass: f64,
    /// Wheelset roll inertia `J_w` (kg m^2).
    pub wheelset_inertia: f64,
    /// Primary suspension stiffness per side `K_1` (N/m).
    pub primary_stiffness: f64,
    /// Primary suspension damping per side `C_1` (N s/m).
    pub primary_damping: f64,
    /// Lateral distance between the primary suspensions (bearings) `L_w` (m), also the
    /// distance between the two contact points.
    pub primary_spacing: f64,
    /// Secondary suspension stiffness per side `K_2` (N/m).
    pub secondary_stiffness: f64,
    /// Secondary suspension damping per side `C_2` (N s/m).
    pub secondary_damping: f64,
    /// Lateral distance between the secondary suspensions `L_b` (m).
    pub secondary_spacing: f64,
    /// Gravitational acceleration `g` (m/s^2).
    pub gravity: f64,
}

impl RollPlaneParams {
    /// Checks every parameter.
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
            ("vehicle.secondary.stiffness", self.secondary_stiffness),
            ("vehicle.secondary.damping", self.secondary_damping),
            ("vehicle.secondary.spacing", self.secondary_spacing),
            ("gravity", self.gravity),
        ] {
            check(name, value)?;
        }
        // Static deflection of each stage under its share of the weight, per side.
        let g = self.gravity;
        let secondary = 0.5 * (self.carbody_mass + self.bolster_mass) * g;
        let primary = secondary + self.sideframe_mass * g;
        for (name, k, load) in [
            (
                "vehicle.secondary.stiffness",
                self.secondary_stiffness,
                secondary,
            ),
            ("vehicle.primary.stiffness", self.primary_stiffness, primary),
        ] {
            if load / k > MAX_STATIC_DEFLECTION {
                return Err(out_of_range(
                    name,
                    k,
                    format!(
                        ">= {} N/m: it deflects {} m under its static load of {} N per side \
                         (allowed: up to {MAX_STATIC_DEFLECTION} m)",
                        crate::error::num(load / MAX_STATIC_DEFLECTION),
                        crate::error::num(load / k),
                        crate::error::num(load)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Diagonal of the mass matrix `M`.
    pub fn mass_diagonal(&self) -> Vector6<f64> {
        Vector6::new(
            self.bolster_mass,
            self.bolster_inertia,
            self.sideframe_mass,
            self.sideframe_mass,
            self.wheelset_mass,
            self.wheelset_inertia,
        )
    }

    fn suspension_matrix(k1: f64, k2: f64, lw: f64, lb: f64) -> Matrix6<f64> {
        let (hb, hw) = (0.5 * lb, 0.5 * lw);
        #[rustfmt::skip]
        let m = Matrix6::new(
            2.0 * k2, 0.0,                 -k2,       -k2,       0.0,       0.0,
            0.0,      0.5 * lb * lb * k2,  hb * k2,   -hb * k2,  0.0,       0.0,
            -k2,      hb * k2,             k1 + k2,   0.0,       -k1,       hw * k1,
            -k2,      -hb * k2,            0.0,       k1 + k2,   -k1,       -hw * k1,
            0.0,      0.0,                 -k1,       -k1,       2.0 * k1,  0.0,
            0.0,      0.0,                 hw * k1,   -hw * k1,  0.0,       0.5 * lw * lw * k1,
        );
        m
    }

    /// Stiffness matrix `K` (3.1).
    pub fn stiffness_matrix(&self) -> Matrix6<f64> {
        Self::suspension_matrix(
            self.primary_stiffness,
            self.secondary_stiffness,
            self.primary_spacing,
            self.secondary_spacing,
        )
    }

    /// Damping matrix `C` (3.1).
    pub fn damping_matrix(&self) -> Matrix6<f64> {
        Self::suspension_matrix(
            self.primary_damping,
            self.secondary_damping,
            self.primary_spacing,
            self.secondary_spacing,
        )
    }

    /// Gravity part of `F`: the quarter car body on the bolster and every body's weight.
    pub fn gravity_force(&self) -> Vector6<f64> {
        let g = self.gravity;
        Vector6::new(
            -(self.carbody_mass + self.bolster_mass) * g,
            0.0,
            -self.sideframe_mass * g,
            -self.sideframe_mass * g,
            -self.wheelset_mass * g,
            0.0,
        )
    }

    /// Undamped natural angular frequencies (rad/s), ascending: the square roots of
    /// the eigenvalues of `M^-1 K`, from the symmetric form `M^-1/2 K M^-1/2`.
    pub fn natural_frequencies(&self) -> [f64; 6] {
        let s = self.mass_diagonal().map(|m| 1.0 / m.sqrt());
        let a = Matrix6::from_diagonal(&s) * self.stiffness_matrix() * Matrix6::from_diagonal(&s);
        let mut w: Vec<f64> = a
            .symmetric_eigenvalues()
            .iter()
            .map(|l| l.max(0.0).sqrt())
            .collect();
        w.sort_by(f64::total_cmp);
        [w[0], w[1], w[2], w[3], w[4], w[5]]
    }

    /// Critical step of the undamped central-difference scheme, `2 / omega_max` (s).
    pub fn critical_time_step(&self) -> f64 {
        2.0 / self.natural_frequencies()[5]
    }

    /// Refuses a step above [`RollPlaneParams::critical_time_step`].
    pub fn check_time_step(&self, dt: f64) -> Result<()> {
        let critical = self.critical_time_step();
        if dt > critical {
            return Err(Error::UnstableTimeStep {
                dt,
                critical,
                limit:
                    "vehicle: central differences on the fastest suspension mode (2 / omega_max)"
                        .into(),
            });
        }
        Ok(())
    }

    /// Default step for the vehicle on its own (s): 50 steps per shortest natural
    /// period, so the period error of central differences stays below 0.1 %.
    pub fn default_dt(&self) -> f64 {
        std::f64::consts::TAU / self.natural_frequencies()[5] / 50.0
    }

    /// Static load on each wheel (N): half the weight of everything (the vehicle is
    /// symmetric about the track centre line).
    pub fn static_wheel_load(&self) -> f64 {
        0.5 * self.gravity
            * (self.carbody_mass
                + self.bolster_mass
                + 2.0 * self.sideframe_mass
                + self.wheelset_mass)
    }
}

/// Names of the six degrees of freedom `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`, with
/// their units, for messages.
pub const BODY_DOFS: [&str; 6] = [
    "bolster.z (m)",
    "bolster.roll (rad)",
    "sideframe.left.z (m)",
    "sideframe.right.z (m)",
    "wheelset.z (m)",
    "wheelset.roll (rad)",
];

/// The six-DOF roll-plane vehicle with its central-difference stepper (3.25).
#[derive(Debug, Clone)]
pub struct RollPlaneVehicle {
    params: RollPlaneParams,
    dt: f64,
    /// Displacements at t_j.
    d: Vector6<f64>,
    /// Displacements at t_(j-1).
    d_prev: Vector6<f64>,
    p_cur: Matrix6<f64>,
    p_prev: Matrix6<f64>,
    p_force: Matrix6<f64>,
    /// `p_force * gravity` over the bodies the contact forces do not act on (bolster
    /// and side frames): the step's constant part.
    p_gravity: Vector6<f64>,
    gravity: Vector6<f64>,
}

impl RollPlaneVehicle {
    /// A vehicle at rest with all displacements zero, stepped with `dt` (s).
    pub fn new(params: RollPlaneParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        let mut v = RollPlaneVehicle {
            params,
            dt,
            d: Vector6::zeros(),
            d_prev: Vector6::zeros(),
            p_cur: Matrix6::zeros(),
            p_prev: Matrix6::zeros(),
            p_force: Matrix6::zeros(),
            p_gravity: Vector6::zeros(),
            gravity: params.gravity_force(),
        };
        v.set_coefficients(dt);
        Ok(v)
    }

    /// Update matrices of (3.25) for step `dt` (s).
    fn set_coefficients(&mut self, dt: f64) {
        let params = &self.params;
        let minv = Matrix6::from_diagonal(&params.mass_diagonal().map(|m| 1.0 / m));
        let mc = minv * params.damping_matrix();
        let mk = minv * params.stiffness_matrix();
        let id = Matrix6::<f64>::identity();
        // [I + dt/2 M^-1 C] d+ = dt^2 M^-1 F + [2I - dt^2 M^-1 K] d + [dt/2 M^-1 C - I] d-
        // I + dt/2 M^-1 C is M^-1 (M + dt/2 C) with M + dt/2 C symmetric positive
        // definite, hence regular; the identity fallback is never taken.
        let inv = (id + mc * (0.5 * dt)).try_inverse().unwrap_or(id);
        self.p_cur = inv * (id * 2.0 - mk * (dt * dt));
        self.p_prev = inv * (mc * (0.5 * dt) - id);
        self.p_force = inv * minv * (dt * dt);
        let mut g = self.gravity;
        g[4] = 0.0;
        g[5] = 0.0;
        self.p_gravity = self.p_force * g;
        self.dt = dt;
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Changes the time step to `dt` (s), keeping the displacements at t_j and the
    /// backward-difference velocities (first-order accurate at the switch).
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        self.params.check_time_step(dt)?;
        let ratio = dt / self.dt;
        self.d_prev = self.d - (self.d - self.d_prev) * ratio;
        self.set_coefficients(dt);
        Ok(())
    }

    /// Step, displacements at t_j and at t_(j-1): what [`RollPlaneVehicle::set_state_vector`]
    /// needs to continue exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let mut v = vec![self.dt];
        v.extend(self.d.iter());
        v.extend(self.d_prev.iter());
        v
    }

    /// Restores a state written by [`RollPlaneVehicle::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != 13 {
            return Err(out_of_range(
                "vehicle state length",
                v.len() as f64,
                "13 values",
            ));
        }
        if v[0] != self.dt {
            self.change_dt(v[0])?;
        }
        self.d = Vector6::from_column_slice(&v[1..7]);
        self.d_prev = Vector6::from_column_slice(&v[7..13]);
        Ok(())
    }

    /// Parameters.
    pub fn params(&self) -> &RollPlaneParams {
        &self.params
    }

    /// Displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}` (m, rad) at t_j.
    pub fn displacements(&self) -> &Vector6<f64> {
        &self.d
    }

    /// Displacements at t_(j-1) (m, rad).
    pub fn previous_displacements(&self) -> &Vector6<f64> {
        &self.d_prev
    }

    /// The first displacement (name with unit, value, bound) beyond the health bounds of
    /// [`crate::limits`]: a body at t_j or t_(j-1) beyond
    /// [`BODY_DISPLACEMENT_LIMIT`], a wheel centre beyond [`DISPLACEMENT_LIMIT`]; `None`
    /// when all are within them (and finite).
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        let bodies = self.d.iter().chain(self.d_prev.iter()).enumerate();
        let w = self.wheel_z();
        bodies
            .map(|(i, &x)| (BODY_DOFS[i % 6], x, BODY_DISPLACEMENT_LIMIT))
            .chain([
                ("wheel.left.z (m)", w[0], DISPLACEMENT_LIMIT),
                ("wheel.right.z (m)", w[1], DISPLACEMENT_LIMIT),
            ])
            .find(|&(_, x, limit)| !within(x, limit))
    }

    /// Velocities at t_j by backward difference (m/s, rad/s).
    pub fn velocities(&self) -> Vector6<f64> {
        (self.d - self.d_prev) / self.dt
    }

    /// Sets displacements at t_j and t_(j-1).
    pub fn set_state(&mut self, d: Vector6<f64>, d_prev: Vector6<f64>) {
        self.d = d;
        self.d_prev = d_prev;
    }

    /// Wheel-centre vertical displacements `[left, right]` (m) (3.2, 3.3).
    #[inline]
    pub fn wheel_z(&self) -> [f64; 2] {
        let h = 0.5 * self.params.primary_spacing;
        [self.d[4] - h * self.d[5], self.d[4] + h * self.d[5]]
    }

    /// Generalised force vector `F` for contact forces `[P_l, P_r]` (N).
    #[inline(always)]
    pub fn force(&self, p: [f64; 2]) -> Vector6<f64> {
        let mut f = self.gravity;
        f[4] += p[0] + p[1];
        f[5] -= 0.5 * self.params.primary_spacing * (p[0] - p[1]);
        f
    }

    /// Advances from t_j to t_(j+1) under contact forces `[P_l, P_r]` (N) at t_j.
    #[inline(always)]
    pub fn step(&mut self, p: [f64; 2]) {
        // p_force * force(p), the constant part precomputed: the contact forces act
        // on the wheelset's bounce and roll only (where they nearly cancel its weight,
        // so those two entries are formed first, as in `force`).
        let f = self.force(p);
        let pf = self.p_gravity + self.p_force.column(4) * f[4] + self.p_force.column(5) * f[5];
        let next = self.p_cur * self.d + self.p_prev * self.d_prev + pf;
        self.d_prev = self.d;
        self.d = next;
    }

    /// Primary suspension (bearing) forces `[left, right]` (N): the load the side frame
    /// puts on the wheelset, positive pressing it down.
    pub fn bearing_forces(&self) -> [f64; 2] {
        let p = &self.params;
        let v = self.velocities();
        let h = 0.5 * p.primary_spacing;
        let side = |sf: usize, sgn: f64| {
            let rel = self.d[sf] - (self.d[4] + sgn * h * self.d[5]);
            let relv = v[sf] - (v[4] + sgn * h * v[5]);
            -(p.primary_stiffness * rel + p.primary_damping * relv)
        };
        [side(2, -1.0), side(3, 1.0)]
    }

    /// Static equilibrium with the wheels held at `z_wheel = [left, right]` (m): the
    /// wheelset follows, the bolster and side frames are solved from their equations.
    pub fn set_static(&mut self, z_wheel: [f64; 2]) -> Result<()> {
        let lw = self.params.primary_spacing;
        let zw = 0.5 * (z_wheel[0] + z_wheel[1]);
        let phw = (z_wheel[1] - z_wheel[0]) / lw;
        let k = self.params.stiffness_matrix();
        let kaa: Matrix4<f64> = k.fixed_view::<4, 4>(0, 0).into();
        let kab = k.fixed_view::<4, 2>(0, 4);
        let g = self.gravity;
        let rhs = Vector4::new(g[0], g[1], g[2], g[3]) - kab * nalgebra::Vector2::new(zw, phw);
        let da = kaa
            .lu()
            .solve(&rhs)
            .filter(|d| d.iter().all(|x| x.is_finite()));
        let Some(da) = da else {
            return Err(Error::Unsupported(format!(
                "static equilibrium of the vehicle: the suspension (vehicle.primary.stiffness = {}, \
                 vehicle.secondary.stiffness = {}, vehicle.secondary.spacing = {}) does not hold \
                 the bodies",
                self.params.primary_stiffness,
                self.params.secondary_stiffness,
                self.params.secondary_spacing
            )));
        };
        self.d = Vector6::new(da[0], da[1], da[2], da[3], zw, phw);
        self.d_prev = self.d;
        Ok(())
    }

    /// Residual `F - K d` (N, N m) for contact forces `p`: zero in static equilibrium.
    pub fn static_residual(&self, p: [f64; 2]) -> Vector6<f64> {
        self.force(p) - self.params.stiffness_matrix() * self.d
    }
}

/// One central-difference step of `m z'' + c z' + k (z - z_ref) = f`, `[m, c, k] = mck`,
/// with the damping velocity centred as in (3.25); returns `z_(j+1)`.
#[inline]
fn sdof_step(mck: [f64; 3], dt: f64, z: f64, z_prev: f64, z_ref: f64, f: f64) -> f64 {
    let [m, c, k] = mck;
    let a = m / (dt * dt);
    let b = c / (2.0 * dt);
    (f - k * (z - z_ref) + a * (2.0 * z - z_prev) + b * z_prev) / (a + b)
}

/// Chapter-2 lumped wheel (2.27), one per side:
/// `m_w z'' + C z' + K (z - z_0) = -W + P`, with `z_0` the static position so that the
/// static contact force is exactly `W` (the suspension preload carries the body).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedWheelParams {
    /// Half-wheelset mass `m_w` (kg).
    pub mass: f64,
    /// Suspension stiffness `K` (N/m): primary and secondary in series.
    pub stiffness: f64,
    /// Suspension damping `C` (N s/m): primary and secondary in series.
    pub damping: f64,
    /// Static wheel load `W` (N).
    pub load: f64,
}

impl LumpedWheelParams {
    /// Checks every parameter.
    pub fn validate(&self) -> Result<()> {
        positive("vehicle.wheel.mass", self.mass, "kg")?;
        non_negative("vehicle.suspension.stiffness", self.stiffness, "N/m")?;
        non_negative("vehicle.suspension.damping", self.damping, "N s/m")?;
        non_negative("vehicle.wheel.load", self.load, "N")?;
        Ok(())
    }
}

/// Two independent lumped wheels (left, right).
#[derive(Debug, Clone)]
pub struct LumpedWheels {
    /// Parameters (same for both sides).
    pub params: LumpedWheelParams,
    dt: f64,
    z: [f64; 2],
    z_prev: [f64; 2],
    z0: [f64; 2],
}

impl LumpedWheels {
    /// Wheels at rest at zero, stepped with `dt` (s).
    pub fn new(params: LumpedWheelParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        Ok(LumpedWheels {
            params,
            dt,
            z: [0.0; 2],
            z_prev: [0.0; 2],
            z0: [0.0; 2],
        })
    }
    /// Wheel-centre displacements (m).
    pub fn wheel_z(&self) -> [f64; 2] {
        self.z
    }
    /// Static equilibrium at wheel positions `z` (m) with contact force `W`.
    pub fn set_static(&mut self, z: [f64; 2]) {
        self.z = z;
        self.z_prev = z;
        self.z0 = z;
    }
    /// Advances one step under contact forces `p` (N).
    pub fn step(&mut self, p: [f64; 2]) {
        let q = &self.params;
        for i in 0..2 {
            let (z, zp) = (self.z[i], self.z_prev[i]);
            let f = -q.load + p[i];
            self.z[i] = sdof_step(
                [q.mass, q.damping, q.stiffness],
                self.dt,
                z,
                zp,
                self.z0[i],
                f,
            );
            self.z_prev[i] = z;
        }
    }
}

/// Chapter-2 lumped track (2.27): `m_t z'' + C_t z' + K_t z = -P`, one mass per rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LumpedTrackParams {
    /// Track mass `m_t` (kg).
    pub mass: f64,
    /// Support stiffness `K_t` (N/m).
    pub stiffness: f64,
    /// Support damping `C_t` (N s/m).
    pub damping: f64,
}

/// Two lumped track masses (left, right rail).
#[derive(Debug, Clone)]
pub struct LumpedTrack {
    /// Parameters.
    pub params: LumpedTrackParams,
    dt: f64,
    z: [f64; 2],
    z_prev: [f64; 2],
}

impl LumpedTrack {
    /// Track at rest, stepped with `dt` (s).
    pub fn new(params: LumpedTrackParams, dt: f64) -> Result<Self> {
        positive("track.lumped.mass", params.mass, "kg")?;
        positive("track.lumped.stiffness", params.stiffness, "N/m")?;
        non_negative("track.lumped.damping", params.damping, "N s/m")?;
        positive("solver.dt", dt, "s")?;
        Ok(LumpedTrack {
            params,
            dt,
            z: [0.0; 2],
            z_prev: [0.0; 2],
        })
    }
    /// Rail displacement (m).
    pub fn rail_z(&self) -> [f64; 2] {
        self.z
    }
    /// Static equilibrium under loads `p` (N).
    pub fn set_static(&mut self, p: [f64; 2]) {
        for i in 0..2 {
            self.z[i] = -p[i] / self.params.stiffness;
        }
        self.z_prev = self.z;
    }
    /// Advances one step under contact forces `p` (N).
    pub fn step(&mut self, p: [f64; 2]) {
        let q = &self.params;
        let dt = self.dt;
        for i in 0..2 {
            let a = q.mass / (dt * dt);
            let b = q.damping / (2.0 * dt);
            let rhs = -p[i] - q.stiffness * self.z[i]
                + a * (2.0 * self.z[i] - self.z_prev[i])
                + b * self.z_prev[i];
            let next = rhs / (a + b);
            self.z_prev[i] = self.z[i];
            self.z[i] = next;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, SymmetricEigen};

    /// Table 4.4 vehicle, from the preset.
    fn table_4_4() -> RollPlaneParams {
        match crate::sim::Scenario::table_4_4().vehicle {
            crate::sim::VehicleSpec::RollPlane(p) => p,
            _ => unreachable!("table 4.4 has the roll-plane vehicle"),
        }
    }

    #[test]
    fn static_wheel_load_is_seeds_107_6_kn() {
        let w = table_4_4().static_wheel_load();
        assert!((w - 107.6e3).abs() < 0.1e3, "{w}");
    }

    #[test]
    fn static_state_has_zero_residual() {
        let p = table_4_4();
        let mut v = RollPlaneVehicle::new(p, 45e-6).unwrap();
        v.set_static([-1e-3, -1.2e-3]).unwrap();
        let w = p.static_wheel_load();
        // Unequal wheel heights and equal loads: the wheelset rolls, nothing accelerates.
        let r = v.static_residual([w, w]);
        assert!(r.norm() < 1e-6, "{r}");
        let before = *v.displacements();
        for _ in 0..1000 {
            v.step([w, w]);
        }
        let drift = (v.displacements() - before).norm();
        assert!(drift < 1e-12, "{drift:e}");
        let b = v.bearing_forces();
        let upper = w - 0.5 * p.wheelset_mass * p.gravity;
        assert!(
            (b[0] - upper).abs() < 1e-6 && (b[1] - upper).abs() < 1e-6,
            "{b:?}"
        );
    }

    /// Spectrum magnitude of `sig` at frequency f (Hz), Hann-windowed.
    fn dft_mag(sig: &[f64], dt: f64, f: f64) -> f64 {
        let n = sig.len();
        let (mut re, mut im) = (0.0, 0.0);
        for (i, s) in sig.iter().enumerate() {
            let w = 0.5 - 0.5 * (2.0 * std::f64::consts::PI * i as f64 / n as f64).cos();
            let ph = 2.0 * std::f64::consts::PI * f * i as f64 * dt;
            re += w * s * ph.cos();
            im += w * s * ph.sin();
        }
        (re * re + im * im).sqrt()
    }

    #[test]
    fn free_decay_frequencies_match_eigenvalues_of_m_inv_k() {
        let mut p = table_4_4();
        p.primary_damping = 0.0;
        p.secondary_damping = 0.0;
        p.gravity = 0.0;
        // Eigenvalues of M^-1 K via the symmetric form M^-1/2 K M^-1/2.
        let m = p.mass_diagonal();
        let k = p.stiffness_matrix();
        let ks = DMatrix::from_fn(6, 6, |i, j| k[(i, j)] / (m[i] * m[j]).sqrt());
        let mut freqs: Vec<f64> = SymmetricEigen::new(ks)
            .eigenvalues
            .iter()
            .filter(|l| **l > 1e-6)
            .map(|l| l.sqrt() / (2.0 * std::f64::consts::PI))
            .collect();
        freqs.sort_by(|a, b| a.total_cmp(b));
        assert_eq!(freqs.len(), 4, "two rigid-body modes of the free vehicle");
        // Free decay from an arbitrary initial displacement.
        let dt = 1e-4;
        let mut v = RollPlaneVehicle::new(p, dt).unwrap();
        let d0 = Vector6::new(1e-3, 2e-3, -1.5e-3, 0.7e-3, 0.4e-3, -1e-3);
        v.set_state(d0, d0);
        let mut hist: Vec<Vector6<f64>> = Vec::new();
        for _ in 0..200_000 {
            v.step([0.0, 0.0]);
            hist.push(*v.displacements());
        }
        // Every eigenfrequency appears as a local spectral peak in some coordinate;
        // locate it by golden-section search near the eigenvalue and compare.
        for f in freqs {
            let mut best = (0.0, 0.0);
            for c in 0..6 {
                let sig: Vec<f64> = hist.iter().map(|d| d[c]).collect();
                let mag = dft_mag(&sig, dt, f);
                if mag > best.0 {
                    best = (mag, c as f64);
                }
            }
            let sig: Vec<f64> = hist.iter().map(|d| d[best.1 as usize]).collect();
            let (mut lo, mut hi) = (0.97 * f, 1.03 * f);
            for _ in 0..60 {
                let a = hi - 0.618 * (hi - lo);
                let b = lo + 0.618 * (hi - lo);
                if dft_mag(&sig, dt, a) > dft_mag(&sig, dt, b) {
                    hi = b;
                } else {
                    lo = a;
                }
            }
            let peak = 0.5 * (lo + hi);
            // Central differences shift omega by (omega dt)^2 / 24: far below 0.1 %.
            assert!(((peak - f) / f).abs() < 1e-3, "peak {peak} vs eigen {f}");
        }
    }

    #[test]
    fn bad_vehicle_parameters_are_refused() {
        let mut p = table_4_4();
        p.wheelset_mass = -1.0;
        let e = RollPlaneVehicle::new(p, 1e-5).unwrap_err().to_string();
        assert!(
            e.contains("vehicle.wheelset.mass") && e.contains("-1"),
            "{e}"
        );
        let mut p = table_4_4();
        p.primary_damping = f64::NAN;
        let e = RollPlaneVehicle::new(p, 1e-5).unwrap_err().to_string();
        assert!(e.contains("vehicle.primary.damping"), "{e}");
    }
}
