//! The thesis' six-degree-of-freedom roll-plane vehicle (3.1-3.3):
//! `d = {z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`, gravity on every body, advanced by
//! central differences with damping as in (3.25).

use crate::error::{Error, Result, out_of_range, positive};
use crate::limits::{
    BODY_DISPLACEMENT_LIMIT, DISPLACEMENT_LIMIT, MAX_STATIC_DEFLECTION, check, within,
};
use crate::numerics::CentralDifference;
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
        crate::numerics::natural_frequencies(&self.mass_diagonal(), &self.stiffness_matrix())
    }

    /// Critical step of the undamped central-difference scheme, `2 / omega_max` (s).
    pub fn critical_time_step(&self) -> f64 {
        2.0 / self.natural_frequencies()[5]
    }

    /// Refuses a step above [`RollPlaneParams::critical_time_step`].
    pub fn check_time_step(&self, dt: f64) -> Result<()> {
        crate::numerics::check_critical_step(dt, self.critical_time_step(), "vehicle")
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
    /// The bodies' displacements at t_j and t_(j-1) and the update of (3.25).
    cd: CentralDifference<6>,
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
        let cd = CentralDifference::new(
            &params.mass_diagonal(),
            params.stiffness_matrix(),
            params.damping_matrix(),
            dt,
        );
        let mut v = RollPlaneVehicle {
            params,
            cd,
            p_gravity: Vector6::zeros(),
            gravity: params.gravity_force(),
        };
        v.set_p_gravity();
        Ok(v)
    }

    /// The step's constant part for the update matrices in use.
    fn set_p_gravity(&mut self) {
        let mut g = self.gravity;
        g[4] = 0.0;
        g[5] = 0.0;
        self.p_gravity = self.cd.p_force() * g;
    }

    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.cd.dt()
    }

    /// Changes the time step to `dt` (s), keeping the displacements at t_j and the
    /// backward-difference velocities (first-order accurate at the switch).
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        self.params.check_time_step(dt)?;
        self.cd.change_dt(dt);
        self.set_p_gravity();
        Ok(())
    }

    /// Step, displacements at t_j and at t_(j-1): what [`RollPlaneVehicle::set_state_vector`]
    /// needs to continue exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }

    /// Restores a state written by [`RollPlaneVehicle::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let len = CentralDifference::<6>::STATE_LEN;
        if v.len() != len {
            return Err(out_of_range(
                "vehicle state length",
                v.len() as f64,
                format!("{len} values"),
            ));
        }
        if v[0] != self.dt() {
            self.change_dt(v[0])?;
        }
        self.cd.set_displacements_from(v);
        Ok(())
    }

    /// Parameters.
    pub fn params(&self) -> &RollPlaneParams {
        &self.params
    }

    /// Displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}` (m, rad) at t_j.
    pub fn displacements(&self) -> &Vector6<f64> {
        self.cd.d()
    }

    /// Displacements at t_(j-1) (m, rad).
    pub fn previous_displacements(&self) -> &Vector6<f64> {
        self.cd.d_prev()
    }

    /// The first displacement (name with unit, value, bound) beyond the health bounds of
    /// [`crate::limits`]: a body at t_j or t_(j-1) beyond
    /// [`BODY_DISPLACEMENT_LIMIT`], a wheel centre beyond [`DISPLACEMENT_LIMIT`]; `None`
    /// when all are within them (and finite).
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        let bodies = self
            .cd
            .d()
            .iter()
            .chain(self.cd.d_prev().iter())
            .enumerate();
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
        self.cd.velocities()
    }

    /// Sets displacements at t_j and t_(j-1).
    pub fn set_state(&mut self, d: Vector6<f64>, d_prev: Vector6<f64>) {
        self.cd.set_state(d, d_prev);
    }

    /// Wheel-centre vertical displacements `[left, right]` (m) (3.2, 3.3).
    #[inline]
    pub fn wheel_z(&self) -> [f64; 2] {
        let h = 0.5 * self.params.primary_spacing;
        let d = self.cd.d();
        [d[4] - h * d[5], d[4] + h * d[5]]
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
        let p_force = self.cd.p_force();
        let pf = self.p_gravity + p_force.column(4) * f[4] + p_force.column(5) * f[5];
        self.cd.advance_premultiplied(pf);
    }

    /// Primary suspension (bearing) forces `[left, right]` (N): the load the side frame
    /// puts on the wheelset, positive pressing it down.
    pub fn bearing_forces(&self) -> [f64; 2] {
        let p = &self.params;
        let v = self.velocities();
        let h = 0.5 * p.primary_spacing;
        let side = |sf: usize, sgn: f64| {
            let d = self.cd.d();
            let rel = d[sf] - (d[4] + sgn * h * d[5]);
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
        let d = Vector6::new(da[0], da[1], da[2], da[3], zw, phw);
        self.cd.set_state(d, d);
        Ok(())
    }

    /// Residual `F - K d` (N, N m) for contact forces `p`: zero in static equilibrium.
    pub fn static_residual(&self, p: [f64; 2]) -> Vector6<f64> {
        self.force(p) - self.params.stiffness_matrix() * self.cd.d()
    }
}
