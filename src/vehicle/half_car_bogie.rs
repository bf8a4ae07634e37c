//! The half-car bogie ([`HalfCarParams`]) in time: [`HalfCarBogie`], the whole bogie
//! driven by the four contact forces, and [`SprungHalfCar`], the bogie above its
//! primary suspension driven by the four primary (axle-box) forces, the partner of a
//! track that carries the wheelsets ([`super::PrimaryLink`]). Both advance by the
//! central differences of the roll-plane vehicle with the damping as in (3.25).

use super::rail_vehicle::{axles, bodies_beyond, wheels_beyond};
use super::{HALF_CAR_DOF_NAMES, HALF_CAR_DOFS, HalfCarParams, HalfCarVector};
use crate::error::{Error, Result, positive};
use crate::numerics::CentralDifference;
use nalgebra::{SMatrix, SVector};

/// Forces or displacements of the four wheels or axle boxes: `[[left, right] of
/// wheelset 1, [left, right] of wheelset 2]`.
pub type Quad = [[f64; 2]; 2];

/// Degrees of freedom above the primary suspension: bolster bounce and roll, the side
/// frames' bounce and pitch.
const SPRUNG_DOFS: usize = 6;

impl HalfCarParams {
    /// Critical step of central differences on the fastest mode (s), `2 / omega_max`.
    pub fn critical_time_step(&self) -> f64 {
        2.0 / self.natural_frequencies()[HALF_CAR_DOFS - 1]
    }

    /// Default step for the bogie on its own (s): 50 steps per shortest natural period,
    /// as the roll-plane vehicle's.
    pub fn default_dt(&self) -> f64 {
        std::f64::consts::TAU / self.natural_frequencies()[HALF_CAR_DOFS - 1] / 50.0
    }

    /// Refuses a step above [`HalfCarParams::critical_time_step`].
    pub fn check_time_step(&self, dt: f64) -> Result<()> {
        crate::numerics::check_critical_step(dt, self.critical_time_step(), "half-car bogie")
    }

    /// Where wheelset `i` (0 leading, 1 trailing) lies along the track from the bogie's
    /// centre (m): `+a/2`, `-a/2`.
    fn axle_x(&self, i: usize) -> f64 {
        if i == 0 {
            0.5 * self.wheelbase
        } else {
            -0.5 * self.wheelbase
        }
    }

    /// The side frames' displacements at the four axle boxes (m) of the state `d` (or
    /// its velocities): `z_sf + x_i theta_sf`.
    fn frames_at_boxes(&self, d: &[f64]) -> Quad {
        [0, 1].map(|i| [0, 1].map(|s| d[2 + 2 * s] + self.axle_x(i) * d[3 + 2 * s]))
    }
}

/// The wheel centres (and axle boxes) `[left, right]` of both wheelsets (m) of the
/// state `d`: `z_w -+ L_w/2 phi_w`.
fn wheels_of(p: &HalfCarParams, d: &HalfCarVector) -> Quad {
    let h = 0.5 * p.primary_spacing;
    [0, 1].map(|i| {
        let (z, phi) = (d[6 + 2 * i], d[7 + 2 * i]);
        [z - h * phi, z + h * phi]
    })
}

/// The primary (bearing) forces at the four axle boxes (N), positive pressing the
/// wheelsets down, of the state `d` moving at `v`: `-(K_1 (z_sf - z_box) + C_1 (v_sf -
/// v_box))`, the side frame taken at the axle (its pitch included).
fn primary_forces(p: &HalfCarParams, d: &HalfCarVector, v: &HalfCarVector) -> Quad {
    let (zf, vf) = (
        p.frames_at_boxes(d.as_slice()),
        p.frames_at_boxes(v.as_slice()),
    );
    let (zb, vb) = (wheels_of(p, d), wheels_of(p, v));
    [0, 1].map(|i| {
        [0, 1].map(|s| {
            -(p.primary_stiffness * (zf[i][s] - zb[i][s])
                + p.primary_damping * (vf[i][s] - vb[i][s]))
        })
    })
}

/// The half-car bogie in time: ten degrees of freedom ([`HALF_CAR_DOF_NAMES`]) under
/// gravity and the four contact forces, by central differences with the damping as in
/// (3.25).
#[derive(Debug, Clone)]
pub struct HalfCarBogie {
    params: HalfCarParams,
    cd: CentralDifference<HALF_CAR_DOFS>,
    gravity: HalfCarVector,
}

impl HalfCarBogie {
    /// The bogie of `params` at rest at zero, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`HalfCarParams::validate`] refuses; `dt` not positive or
    /// above [`HalfCarParams::critical_time_step`].
    pub fn new(params: HalfCarParams, dt: f64) -> Result<HalfCarBogie> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        Ok(HalfCarBogie {
            params,
            cd: CentralDifference::new(
                &params.mass_diagonal(),
                params.stiffness_matrix(),
                params.damping_matrix(),
                dt,
            ),
            gravity: params.gravity_force(),
        })
    }

    /// Parameters.
    pub fn params(&self) -> &HalfCarParams {
        &self.params
    }
    /// Step (s).
    pub fn dt(&self) -> f64 {
        self.cd.dt()
    }
    /// Displacements `d` at `t_j` (m, rad), in the order of [`HALF_CAR_DOF_NAMES`].
    pub fn displacements(&self) -> &HalfCarVector {
        self.cd.d()
    }
    /// Velocities at `t_j`, backward differences over the last step (m/s, rad/s).
    pub fn velocities(&self) -> HalfCarVector {
        self.cd.velocities()
    }

    /// Wheel-centre displacements `[[left, right] of wheelset 1, of wheelset 2]` (m).
    #[inline]
    pub fn wheel_z(&self) -> Quad {
        wheels_of(&self.params, self.cd.d())
    }

    /// Wheel-centre velocities `[[left, right] of wheelset 1, of wheelset 2]` (m/s),
    /// backward differences over the last step.
    pub fn wheel_velocities(&self) -> Quad {
        wheels_of(&self.params, &self.cd.velocities())
    }

    /// The side frames' displacements and velocities at the four axle boxes (m, m/s),
    /// `[[left, right] over wheelset 1, over wheelset 2]` (the pitch included), the
    /// velocities backward differences over the last step.
    pub fn side_frames(&self) -> (Quad, Quad) {
        let v = self.cd.velocities();
        let p = &self.params;
        (
            p.frames_at_boxes(self.cd.d().as_slice()),
            p.frames_at_boxes(v.as_slice()),
        )
    }

    /// Primary suspension (bearing) forces at the four axle boxes (N), positive pressing
    /// the wheelsets down: `-(K_1 (z_sf - z_box) + C_1 (v_sf - v_box))`, the side frame
    /// taken at the axle (its pitch included), the velocities backward differences.
    pub fn bearing_forces(&self) -> Quad {
        primary_forces(&self.params, self.cd.d(), &self.cd.velocities())
    }

    /// Advances one step from `t_j` under the contact forces `p` (N, up on the wheels)
    /// at `t_j`.
    #[inline]
    pub fn step(&mut self, p: Quad) {
        self.cd.advance(self.gravity + self.params.contact_force(p));
    }

    /// Static equilibrium with the wheels held at `z_wheel` (m)
    /// ([`HalfCarParams::static_state`]).
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_wheel: Quad) -> Result<()> {
        let d = self.params.static_state(z_wheel).ok_or_else(not_held)?;
        self.cd.set_state(d, d);
        Ok(())
    }

    /// Changes the step to `dt` (s), keeping the displacements and the
    /// backward-difference velocities.
    ///
    /// Errors: `dt` not positive or above the critical step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        let p = self.params;
        self.cd.change_dt_checked(dt, |h| p.check_time_step(h))
    }

    /// `[dt, d (10), d_prev (10)]`.
    pub fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }

    /// Restores [`HalfCarBogie::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let p = self.params;
        self.cd
            .restore(v, "bogie state length", |h| p.check_time_step(h))
    }

    /// The first value beyond the health bounds: a body beyond
    /// [`crate::limits::BODY_DISPLACEMENT_LIMIT`], a wheel beyond [`crate::limits::DISPLACEMENT_LIMIT`].
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| HALF_CAR_DOF_NAMES[i])
            .or_else(|| wheels_beyond(&axles(self.wheel_z()), 2))
    }
}

fn not_held() -> Error {
    Error::Unsupported(
        "static equilibrium of the half-car bogie: the suspension does not hold the bodies".into(),
    )
}

/// The half-car bogie above its primary suspension: bolster bounce and roll, the side
/// frames' bounce and pitch (the first six of [`HALF_CAR_DOF_NAMES`]), under gravity
/// and the four primary forces (N, positive pressing the axle boxes down, so pushing
/// the side frames up at the axles), which the track side computes
/// ([`super::PrimaryLink`], one per wheelset). Its side frames' motion at the four
/// axle boxes ([`SprungHalfCar::side_frames`]) drives the primary suspensions there.
#[derive(Debug, Clone)]
pub struct SprungHalfCar {
    params: HalfCarParams,
    cd: CentralDifference<SPRUNG_DOFS>,
    gravity: SVector<f64, SPRUNG_DOFS>,
    /// The whole bogie's static state of [`SprungHalfCar::set_static`] (zero before):
    /// the wheelsets' part, which the partner carries, for the outputs.
    rest: HalfCarVector,
}

impl SprungHalfCar {
    /// The bodies of `params` above the primary suspension, stepped with `dt` (s).
    ///
    /// Errors: as [`HalfCarBogie::new`] (the step is checked against the whole bogie's
    /// critical step).
    pub fn new(params: HalfCarParams, dt: f64) -> Result<SprungHalfCar> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        // The secondary suspension only: the primary is the other side's.
        let mut above = params;
        above.primary_stiffness = 0.0;
        above.primary_damping = 0.0;
        let k: SMatrix<f64, 6, 6> = above.stiffness_matrix().fixed_view::<6, 6>(0, 0).into();
        let c: SMatrix<f64, 6, 6> = above.damping_matrix().fixed_view::<6, 6>(0, 0).into();
        let m = params.mass_diagonal().fixed_rows::<6>(0).into_owned();
        Ok(SprungHalfCar {
            params,
            cd: CentralDifference::new(&m, k, c, dt),
            gravity: params.gravity_force().fixed_rows::<6>(0).into_owned(),
            rest: HalfCarVector::zeros(),
        })
    }

    /// Parameters.
    pub fn params(&self) -> &HalfCarParams {
        &self.params
    }

    /// Step (s).
    pub fn dt(&self) -> f64 {
        self.cd.dt()
    }
    /// The whole bogie's displacements (m, rad), in the order of
    /// [`HALF_CAR_DOF_NAMES`]: these bodies' now, the wheelsets' at rest
    /// ([`SprungHalfCar::set_static`]).
    pub fn whole_displacements(&self) -> HalfCarVector {
        let mut d = self.rest;
        d.fixed_rows_mut::<6>(0).copy_from(self.cd.d());
        d
    }

    /// `{z_b, phi_b, z_sfl, theta_sfl, z_sfr, theta_sfr}` at `t_j` (m, rad).
    pub fn displacements(&self) -> &SVector<f64, SPRUNG_DOFS> {
        self.cd.d()
    }

    /// The side frames' displacements and velocities at the four axle boxes (m, m/s),
    /// `[[left, right] over wheelset 1, over wheelset 2]`, the velocities backward
    /// differences over the last step.
    pub fn side_frames(&self) -> (Quad, Quad) {
        let v = self.cd.velocities();
        (
            self.params.frames_at_boxes(self.cd.d().as_slice()),
            self.params.frames_at_boxes(v.as_slice()),
        )
    }

    /// Advances one step from `t_j` under the primary forces `f` (N) held over it.
    pub fn step(&mut self, f: Quad) {
        let mut g = self.gravity;
        for (i, fi) in f.iter().enumerate() {
            let x = self.params.axle_x(i);
            for (s, &fs) in fi.iter().enumerate() {
                g[2 + 2 * s] += fs;
                g[3 + 2 * s] += x * fs;
            }
        }
        self.cd.advance(g);
    }

    /// Static equilibrium with the axle boxes (wheels) held at `z_wheel` (m), as the
    /// whole bogie's ([`HalfCarParams::static_state`]); returns the static primary
    /// forces (N), pressing the axle boxes down.
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_wheel: Quad) -> Result<Quad> {
        let d = self.params.static_state(z_wheel).ok_or_else(not_held)?;
        let top = d.fixed_rows::<6>(0).into_owned();
        self.cd.set_state(top, top);
        self.rest = d;
        // At rest: the springs alone.
        Ok(primary_forces(&self.params, &d, &HalfCarVector::zeros()))
    }

    /// Changes the step to `dt` (s), as [`HalfCarBogie::change_dt`].
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        let p = self.params;
        self.cd.change_dt_checked(dt, |h| p.check_time_step(h))
    }

    /// `[dt, d (6), d_prev (6)]`.
    pub fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }

    /// Restores [`SprungHalfCar::state_vector`].
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let p = self.params;
        self.cd
            .restore(v, "bogie state length", |h| p.check_time_step(h))
    }

    /// A body beyond [`crate::limits::BODY_DISPLACEMENT_LIMIT`].
    pub fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| HALF_CAR_DOF_NAMES[i])
    }
}
