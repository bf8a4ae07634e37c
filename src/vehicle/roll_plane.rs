//! The thesis' six-degree-of-freedom roll-plane vehicle (3.1-3.3):
//! `d = {z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`, gravity on every body, advanced by
//! central differences with damping as in (3.25).

use super::linear_body::{LinearBody, LinearVehicle, SprungLinearBody};
use super::rail_vehicle::{Axles, Bodies, CarrierModel, RailVehicle, SprungVehicle};
use super::{ExchangeLimits, MAX_AXLES, SideFrameInertia};
use crate::error::{Error, Result, out_of_range};
use crate::limits::{MAX_STATIC_DEFLECTION, check};
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
    /// A wheelset of `wheelset_mass` (kg) and roll inertia `wheelset_inertia` (kg m^2) on
    /// its primary suspension, `primary` = `(K_1` (N/m), `C_1` (N s/m), `L_w` (m)`)`,
    /// under gravity `gravity` (m/s^2), the bodies above it zero: what the track side
    /// carries at the axle-box interface ([`super::PrimaryLink`] uses no more).
    pub fn wheelset_on_primary(
        wheelset_mass: f64,
        wheelset_inertia: f64,
        primary: (f64, f64, f64),
        gravity: f64,
    ) -> RollPlaneParams {
        let (primary_stiffness, primary_damping, primary_spacing) = primary;
        RollPlaneParams {
            carbody_mass: 0.0,
            bolster_mass: 0.0,
            bolster_inertia: 0.0,
            sideframe_mass: 0.0,
            wheelset_mass,
            wheelset_inertia,
            primary_stiffness,
            primary_damping,
            primary_spacing,
            secondary_stiffness: 0.0,
            secondary_damping: 0.0,
            secondary_spacing: 0.0,
            gravity,
        }
    }
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

/// The six-DOF roll-plane vehicle in time under its two contact forces, by central
/// differences with the damping as in (3.25): the generic linear body of
/// [`RollPlaneParams`], a vehicle on one wheelset.
pub type RollPlaneVehicle = LinearBody<RollPlaneParams, 6, 4>;

/// The roll-plane vehicle above its primary suspension (bolster bounce and roll, the
/// two side frames' bounce), under the primary forces at its axle boxes: the partner of
/// the wheelset the track carries ([`super::PrimaryLink`]) at the axle-box interface.
pub type SprungBogie = SprungLinearBody<RollPlaneParams, 6, 4>;

/// `[left, right]` as the leading wheelset of [`Axles`].
fn lead(x: [f64; 2]) -> Axles {
    let mut a = [[0.0; 2]; MAX_AXLES];
    a[0] = x;
    a
}

impl LinearVehicle<6, 4> for RollPlaneParams {
    const WHAT: &'static str = "vehicle";
    const DOF_NAMES: [&'static str; 6] = BODY_DOFS;
    const WHEELSETS: usize = 1;
    const SPRUNG: [usize; 4] = [0, 1, 2, 3];

    fn validate(&self) -> Result<()> {
        RollPlaneParams::validate(self)
    }
    fn mass_diagonal(&self) -> Vector6<f64> {
        RollPlaneParams::mass_diagonal(self)
    }
    fn stiffness_matrix(&self) -> Matrix6<f64> {
        RollPlaneParams::stiffness_matrix(self)
    }
    fn damping_matrix(&self) -> Matrix6<f64> {
        RollPlaneParams::damping_matrix(self)
    }
    /// (3.1) less the primary suspension, which is the other side's at the axle boxes:
    /// its constants off the side frames' diagonal (the block above the wheelset).
    fn above_primary(&self) -> (Matrix6<f64>, Matrix6<f64>) {
        let (mut k, mut c) = (self.stiffness_matrix(), self.damping_matrix());
        for i in 2..4 {
            k[(i, i)] -= self.primary_stiffness;
            c[(i, i)] -= self.primary_damping;
        }
        (k, c)
    }
    fn gravity_force(&self) -> Vector6<f64> {
        RollPlaneParams::gravity_force(self)
    }
    /// The contact forces `[P_l, P_r]` on the wheelset's bounce and roll (3.1).
    #[inline(always)]
    fn contact_force(&self, p: &Axles) -> Vector6<f64> {
        let [l, r] = p[0];
        let mut f = Vector6::zeros();
        f[4] = l + r;
        f[5] = -(0.5 * self.primary_spacing * (l - r));
        f
    }
    /// (3.2, 3.3): `z_w -+ L_w/2 phi_w`.
    #[inline(always)]
    fn wheels_of(&self, d: &[f64]) -> Axles {
        let h = 0.5 * self.primary_spacing;
        lead([d[4] - h * d[5], d[4] + h * d[5]])
    }
    /// The side frames (no pitch: one over each axle box).
    fn frames_at_boxes(&self, d: &[f64]) -> Axles {
        lead([d[2], d[3]])
    }
    fn add_primary_forces(&self, f: &Axles, g: &mut Vector4<f64>) {
        g[2] += f[0][0];
        g[3] += f[0][1];
    }
    fn primary(&self) -> (f64, f64) {
        (self.primary_stiffness, self.primary_damping)
    }
    /// The wheelset follows the wheels; the bolster and side frames solve their
    /// equations.
    fn static_state(&self, z: &Axles) -> Option<Vector6<f64>> {
        let lw = self.primary_spacing;
        let zw = 0.5 * (z[0][0] + z[0][1]);
        let phw = (z[0][1] - z[0][0]) / lw;
        let k = self.stiffness_matrix();
        let kaa: Matrix4<f64> = k.fixed_view::<4, 4>(0, 0).into();
        let kab = k.fixed_view::<4, 2>(0, 4);
        let g = self.gravity_force();
        let rhs = Vector4::new(g[0], g[1], g[2], g[3]) - kab * nalgebra::Vector2::new(zw, phw);
        let da = kaa
            .lu()
            .solve(&rhs)
            .filter(|d| d.iter().all(|x| x.is_finite()))?;
        Some(Vector6::new(da[0], da[1], da[2], da[3], zw, phw))
    }
    fn static_contact_forces(&self, d: &Vector6<f64>) -> Axles {
        let r = self.stiffness_matrix() * d - self.gravity_force();
        let hw = 0.5 * self.primary_spacing;
        lead([0.5 * (r[4] - r[5] / hw), 0.5 * (r[4] + r[5] / hw)])
    }
    fn bodies(&self, d: &[f64]) -> Bodies {
        let mut b = Bodies::default();
        b.bolster[0] = [d[0], d[1]];
        b.wheelset[0] = [d[4], d[5]];
        b
    }
    /// The side frames of their own mass over each axle box.
    fn exchange_limits(
        &self,
        body: &SprungBogie,
        z: &Axles,
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits> {
        let inertia = SideFrameInertia::single(self.sideframe_mass);
        super::exchange::linear_limits(body, self, inertia, z, base, support)
    }
    /// `p_force F` over the bolster and the side frames, whose forces are gravity only.
    fn step_constant(&self, p_force: &Matrix6<f64>, gravity: &Vector6<f64>) -> Vector6<f64> {
        let mut g = *gravity;
        g[4] = 0.0;
        g[5] = 0.0;
        p_force * g
    }
    /// The contact forces act on the wheelset's bounce and roll only (where they nearly
    /// cancel its weight, so those two entries are formed first): the constant part
    /// and two columns of `p_force`.
    #[inline(always)]
    fn force_share(
        &self,
        p_force: &Matrix6<f64>,
        gravity: &Vector6<f64>,
        constant: &Vector6<f64>,
        p: &Axles,
    ) -> Vector6<f64> {
        let c = self.contact_force(p);
        let (f4, f5) = (gravity[4] + c[4], gravity[5] + c[5]);
        constant + p_force.column(4) * f4 + p_force.column(5) * f5
    }
    fn critical_time_step(&self) -> f64 {
        RollPlaneParams::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        RollPlaneParams::default_dt(self)
    }
    fn check_time_step(&self, dt: f64) -> Result<()> {
        RollPlaneParams::check_time_step(self, dt)
    }
}

impl CarrierModel for RollPlaneParams {
    fn wheelsets(&self) -> usize {
        1
    }
    fn offsets(&self) -> Vec<(f64, &'static str)> {
        Vec::new()
    }
    fn name(&self) -> &'static str {
        "the roll-plane vehicle (vehicle.model = roll_plane)"
    }
    fn validate(&self) -> Result<()> {
        RollPlaneParams::validate(self)
    }
    fn critical_time_step(&self) -> f64 {
        RollPlaneParams::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        RollPlaneParams::default_dt(self)
    }
    fn static_wheel_load(&self) -> f64 {
        RollPlaneParams::static_wheel_load(self)
    }
    fn stiffnesses(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("vehicle.primary.stiffness", self.primary_stiffness),
            ("vehicle.secondary.stiffness", self.secondary_stiffness),
        ]
    }
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>> {
        Ok(Box::new(RollPlaneVehicle::new(*self, dt)?))
    }
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>> {
        Ok(Box::new(SprungBogie::new(*self, dt)?))
    }
}

/// The roll-plane vehicle's own terms: one wheelset, `[left, right]`.
impl RollPlaneVehicle {
    /// Time step (s).
    pub fn dt(&self) -> f64 {
        RailVehicle::dt(self)
    }
    /// Changes the time step to `dt` (s), keeping the displacements at t_j and the
    /// backward-difference velocities (first-order accurate at the switch).
    ///
    /// Errors: `dt` not positive or above the critical step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        RailVehicle::change_dt(self, dt)
    }
    /// Step, displacements at t_j and at t_(j-1): what
    /// [`RollPlaneVehicle::set_state_vector`] needs to continue exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        RailVehicle::state_vector(self)
    }
    /// Restores a state written by [`RollPlaneVehicle::state_vector`].
    ///
    /// Errors: a wrong length, a step the vehicle refuses.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        RailVehicle::set_state_vector(self, v)
    }
    /// The first displacement (name with unit, value, bound) beyond the health bounds of
    /// [`crate::limits`]: a body at t_j or t_(j-1) beyond
    /// [`crate::limits::BODY_DISPLACEMENT_LIMIT`], a wheel centre beyond
    /// [`crate::limits::DISPLACEMENT_LIMIT`]; `None` when all are within them.
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        RailVehicle::beyond_bounds(self)
    }
    /// Wheel-centre vertical displacements `[left, right]` (m) (3.2, 3.3).
    #[inline(always)]
    pub fn wheel_z(&self) -> [f64; 2] {
        self.params().wheels_of(self.displacements().as_slice())[0]
    }
    /// Generalised force vector `F` for contact forces `[P_l, P_r]` (N).
    pub fn force(&self, p: [f64; 2]) -> Vector6<f64> {
        self.params().gravity_force() + self.params().contact_force(&lead(p))
    }
    /// Advances from t_j to t_(j+1) under contact forces `[P_l, P_r]` (N) at t_j.
    #[inline(always)]
    pub fn step(&mut self, p: [f64; 2]) {
        RailVehicle::step(self, &lead(p))
    }
    /// Primary suspension (bearing) forces `[left, right]` (N): the load the side frame
    /// puts on the wheelset, positive pressing it down.
    pub fn bearing_forces(&self) -> [f64; 2] {
        RailVehicle::bearing_forces(self)[0]
    }
    /// Static equilibrium with the wheels held at `z_wheel = [left, right]` (m): the
    /// wheelset follows, the bolster and side frames are solved from their equations.
    ///
    /// Errors: a suspension that does not hold the bodies (naming its stiffnesses).
    pub fn set_static(&mut self, z_wheel: [f64; 2]) -> Result<()> {
        let p = *self.params();
        RailVehicle::set_static(self, &lead(z_wheel)).map_err(|_| {
            Error::Unsupported(format!(
                "static equilibrium of the vehicle: the suspension (vehicle.primary.stiffness = \
                 {}, vehicle.secondary.stiffness = {}, vehicle.secondary.spacing = {}) does not \
                 hold the bodies",
                p.primary_stiffness, p.secondary_stiffness, p.secondary_spacing
            ))
        })?;
        Ok(())
    }
    /// Residual `F - K d` (N, N m) for contact forces `p`: zero in static equilibrium.
    pub fn static_residual(&self, p: [f64; 2]) -> Vector6<f64> {
        self.force(p) - self.params().stiffness_matrix() * self.displacements()
    }
}

/// The roll-plane vehicle above its axle boxes in its own terms: one wheelset,
/// `[left, right]`.
impl SprungBogie {
    /// Advances one step under the primary forces `f` `[left, right]` (N, pressing the
    /// axle boxes down, so pushing the side frames up) held over it.
    pub fn step(&mut self, f: [f64; 2]) {
        SprungVehicle::step(self, &lead(f))
    }
    /// The side frames' displacements and velocities `[left, right]` (m, m/s), the
    /// velocities backward differences over the last step.
    pub fn side_frames(&self) -> ([f64; 2], [f64; 2]) {
        let (z, v) = SprungVehicle::side_frames(self);
        (z[0], v[0])
    }
    /// The primary forces `[left, right]` (N, pressing the axle boxes down) of the side
    /// frames now against axle boxes at `z_box` moving at `v_box` (m, m/s).
    pub fn primary_forces(&self, z_box: [f64; 2], v_box: [f64; 2]) -> [f64; 2] {
        let (k1, c1) = (
            self.params().primary_stiffness,
            self.params().primary_damping,
        );
        let (d, v) = self.side_frames();
        [
            -(k1 * (d[0] - z_box[0]) + c1 * (v[0] - v_box[0])),
            -(k1 * (d[1] - z_box[1]) + c1 * (v[1] - v_box[1])),
        ]
    }
    /// Static equilibrium with the axle boxes at `z_box` `[left, right]` (m).
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_box: [f64; 2]) -> Result<()> {
        SprungVehicle::set_static(self, &lead(z_box)).map(|_| ())
    }
    /// [`ExchangeLimits`] of this bogie at rest with its axle boxes at `z_box` (m), its
    /// substeps at most `base` (s), its wheelset on contact springs of `support` (N/m
    /// per wheel, [`super::CONTACT_STIFFNESS`]), side frames of their own mass.
    ///
    /// Errors: a parameter [`super::PrimaryLink::new`] refuses.
    pub fn exchange_limits(
        &self,
        z_box: [f64; 2],
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits> {
        SprungVehicle::exchange_limits(self, &lead(z_box), base, support)
    }
    /// Changes the step to `dt` (s).
    ///
    /// Errors: `dt` not positive or above the critical step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        SprungVehicle::change_dt(self, dt)
    }
    /// `[dt, d (4), d_prev (4)]`.
    pub fn state_vector(&self) -> Vec<f64> {
        SprungVehicle::state_vector(self)
    }
    /// Restores [`SprungBogie::state_vector`].
    ///
    /// Errors: a wrong length, a step the vehicle refuses.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        SprungVehicle::set_state_vector(self, v)
    }
    /// A body beyond [`crate::limits::BODY_DISPLACEMENT_LIMIT`].
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        SprungVehicle::beyond_bounds(self)
    }
}
