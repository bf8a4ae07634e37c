//! One linear vehicle body in time, for every vehicle on several wheelsets: a
//! [`LinearVehicle`] gives the matrices `M` (diagonal), `K`, `C`, gravity, the names of
//! its degrees of freedom and how its wheels and axle boxes sit on them; [`LinearBody`]
//! advances the whole vehicle under the contact forces and [`SprungLinearBody`] the
//! bodies above its primary suspension under the primary forces, both by the central
//! differences of the roll-plane vehicle with the damping as in (3.25), and both stand
//! behind [`RailVehicle`] and [`SprungVehicle`]. A new vehicle kind writes its matrices
//! and maps once, in its own file, and gets the stepping, the step checks, the state
//! vectors and the health checks from here.

use super::rail_vehicle::{Axles, Bodies, RailVehicle, SprungVehicle};
use super::{ExchangeLimits, MAX_AXLES};
use crate::error::{Error, Result, positive};
use crate::limits::{BODY_DISPLACEMENT_LIMIT, DISPLACEMENT_LIMIT, within};
use crate::numerics::{CentralDifference, check_critical_step};
use nalgebra::{SMatrix, SVector};

/// A linear vehicle of `N` degrees of freedom, `S` of them above its primary suspension
/// ([`LinearVehicle::SPRUNG`]): its parameters and how its bodies meet the wheels and the
/// axle boxes.
pub trait LinearVehicle<const N: usize, const S: usize>:
    Copy + std::fmt::Debug + Send + Sync + 'static
{
    /// The vehicle in a few words, for the errors ("half-car bogie").
    const WHAT: &'static str;
    /// Names of the degrees of freedom in the order of `d`, as the health checks name
    /// them ("carbody.z (m)").
    const DOF_NAMES: [&'static str; N];
    /// Number of wheelsets.
    const WHEELSETS: usize;
    /// The degrees of freedom above the primary suspension, indices into `d` in the
    /// order of [`SprungLinearBody`]'s state (the others are the wheelsets').
    const SPRUNG: [usize; S];

    /// Checks every parameter, naming the variables.
    ///
    /// Errors: a parameter outside its physical range.
    fn validate(&self) -> Result<()>;
    /// Diagonal of the mass matrix `M` (kg, kg m^2).
    fn mass_diagonal(&self) -> SVector<f64, N>;
    /// Stiffness matrix `K` (N/m, N m/rad).
    fn stiffness_matrix(&self) -> SMatrix<f64, N, N>;
    /// Damping matrix `C` (N s/m, N m s/rad).
    fn damping_matrix(&self) -> SMatrix<f64, N, N>;
    /// `K` and `C` of the suspension above the axle boxes only (the primary suspension
    /// is the partner's when the vehicle couples at its axle boxes).
    fn above_primary(&self) -> (SMatrix<f64, N, N>, SMatrix<f64, N, N>);
    /// Gravity on every body (N), down.
    fn gravity_force(&self) -> SVector<f64, N>;
    /// The generalised force of the contact forces `p` (N, up on the wheels).
    fn contact_force(&self, p: &Axles) -> SVector<f64, N>;
    /// The wheel centres (and axle boxes) `[left, right]` of every wheelset (m) of the
    /// displacements `d` (or velocities).
    fn wheels_of(&self, d: &[f64]) -> Axles;
    /// The upper ends of the primary suspension above every axle box (m) of `d` (or of
    /// the velocities): the side frames at the axles, or the car body there.
    fn frames_at_boxes(&self, d: &[f64]) -> Axles;
    /// Adds the primary forces `f` (N, pressing the axle boxes down, so pushing the
    /// bodies above up) to the generalised force `g` of the bodies above.
    fn add_primary_forces(&self, f: &Axles, g: &mut SVector<f64, S>);
    /// Primary stiffness and damping per axle box `(K_1, C_1)` (N/m, N s/m).
    fn primary(&self) -> (f64, f64);
    /// The static state with the wheels held at `z` (m); `None` when the suspension
    /// does not hold the bodies.
    fn static_state(&self, z: &Axles) -> Option<SVector<f64, N>>;
    /// The bodies' motion of the displacements `d`, as the outputs give it.
    fn bodies(&self, d: &[f64]) -> Bodies;
    /// The exchange's stable steps of the bodies above the primary suspension `body`
    /// at rest on `z` (m) ([`SprungVehicle::exchange_limits`]).
    ///
    /// Errors: a parameter [`super::PrimaryLink::new`] refuses.
    fn exchange_limits(
        &self,
        body: &SprungLinearBody<Self, N, S>,
        z: &Axles,
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits>;

    /// The force's share of a step, `P_f (F_gravity + F_contact(p))` (`P_f` the
    /// update's `dt^2 [I + dt/2 M^-1 C]^-1 M^-1`), `constant` the part that stays the
    /// same from step to step ([`LinearVehicle::step_constant`]). By default the
    /// product in full; a vehicle whose contact forces act on a few degrees of freedom
    /// forms it from those columns of `P_f` (the roll-plane vehicle: its wheelset's).
    #[inline(always)]
    fn force_share(
        &self,
        p_force: &SMatrix<f64, N, N>,
        gravity: &SVector<f64, N>,
        _constant: &SVector<f64, N>,
        p: &Axles,
    ) -> SVector<f64, N> {
        crate::numerics::mat_vec_dispatched(p_force, &(gravity + self.contact_force(p)))
    }
    /// The part of [`LinearVehicle::force_share`] that stays the same from step to step
    /// for the update's `p_force` and the gravity `gravity` (zero by default, unused).
    fn step_constant(
        &self,
        _p_force: &SMatrix<f64, N, N>,
        _gravity: &SVector<f64, N>,
    ) -> SVector<f64, N> {
        SVector::zeros()
    }

    /// Undamped natural frequencies (rad/s), ascending: the square roots of the
    /// eigenvalues of `M^-1 K`.
    fn natural_frequencies(&self) -> [f64; N] {
        crate::numerics::natural_frequencies(&self.mass_diagonal(), &self.stiffness_matrix())
    }
    /// Critical step of central differences on the fastest mode (s), `2 / omega_max`.
    fn critical_time_step(&self) -> f64 {
        2.0 / self.natural_frequencies()[N - 1]
    }
    /// Default step for the vehicle on its own (s): 50 steps per shortest natural
    /// period, as the roll-plane vehicle's.
    fn default_dt(&self) -> f64 {
        std::f64::consts::TAU / self.natural_frequencies()[N - 1] / 50.0
    }
    /// Refuses a step above [`LinearVehicle::critical_time_step`].
    ///
    /// Errors: `dt` above the critical step.
    fn check_time_step(&self, dt: f64) -> Result<()> {
        check_critical_step(dt, self.critical_time_step(), Self::WHAT)
    }
    /// The primary forces at every axle box (N), pressing the wheelsets down, of the
    /// state `d` moving at `v`: `-(K_1 (z_top - z_box) + C_1 (v_top - v_box))`.
    fn primary_forces(&self, d: &[f64], v: &[f64]) -> Axles {
        let (zf, vf, zb, vb) = (
            self.frames_at_boxes(d),
            self.frames_at_boxes(v),
            self.wheels_of(d),
            self.wheels_of(v),
        );
        let (k1, c1) = self.primary();
        let mut f = [[0.0; 2]; MAX_AXLES];
        for (w, fw) in f.iter_mut().enumerate().take(Self::WHEELSETS) {
            *fw = [0, 1].map(|s| -(k1 * (zf[w][s] - zb[w][s]) + c1 * (vf[w][s] - vb[w][s])));
        }
        f
    }
    /// The contact forces (N) that hold the static state `d`: the wheelsets' rows of
    /// `K d - F_gravity`, split between the two wheels of each.
    fn static_contact_forces(&self, d: &SVector<f64, N>) -> Axles;
}

/// The error of a suspension that does not hold the bodies of `what`.
fn not_held(what: &str) -> Error {
    Error::Unsupported(format!(
        "static equilibrium of the {what}: the suspension does not hold the bodies"
    ))
}

/// The first value of `d` or `d_prev` beyond [`BODY_DISPLACEMENT_LIMIT`], named by
/// `names`.
fn bodies_beyond<const M: usize>(
    cd: &CentralDifference<M>,
    names: impl Fn(usize) -> &'static str,
) -> Option<(&'static str, f64, f64)> {
    cd.d()
        .iter()
        .chain(cd.d_prev().iter())
        .enumerate()
        .map(|(i, &x)| (names(i % M), x, BODY_DISPLACEMENT_LIMIT))
        .find(|&(_, x, l)| !within(x, l))
}

/// The first wheel centre of the first `wheelsets` of `z` (m) beyond
/// [`DISPLACEMENT_LIMIT`], named as the FMUs name it.
pub(super) fn wheels_beyond(z: &Axles, wheelsets: usize) -> Option<(&'static str, f64, f64)> {
    const WHEELS: [&str; 2 * MAX_AXLES] = [
        "wheel.left.z (m)",
        "wheel.right.z (m)",
        "wheelset[2].wheel.left.z (m)",
        "wheelset[2].wheel.right.z (m)",
        "wheelset[3].wheel.left.z (m)",
        "wheelset[3].wheel.right.z (m)",
        "wheelset[4].wheel.left.z (m)",
        "wheelset[4].wheel.right.z (m)",
    ];
    WHEELS
        .into_iter()
        .zip(z.iter().take(wheelsets).flatten())
        .map(|(n, &x)| (n, x, DISPLACEMENT_LIMIT))
        .find(|&(_, x, l)| !within(x, l))
}

/// What building either body refuses: a parameter [`LinearVehicle::validate`] refuses;
/// `dt` (s) not positive or above [`LinearVehicle::critical_time_step`].
fn check_new<P: LinearVehicle<N, S>, const N: usize, const S: usize>(
    params: &P,
    dt: f64,
) -> Result<()> {
    params.validate()?;
    positive("solver.dt", dt, "s")?;
    params.check_time_step(dt)
}

/// Changes the step of either body's stepper `cd` to `dt` (s), checked against the
/// whole vehicle's critical step.
fn change_dt_of<P: LinearVehicle<N, S>, const N: usize, const S: usize, const M: usize>(
    cd: &mut CentralDifference<M>,
    params: &P,
    dt: f64,
) -> Result<()> {
    cd.change_dt_checked(dt, |h| params.check_time_step(h))
}

/// Restores either body's stepper `cd` from its state vector `v`, the length refused
/// naming the vehicle.
fn restore_of<P: LinearVehicle<N, S>, const N: usize, const S: usize, const M: usize>(
    cd: &mut CentralDifference<M>,
    params: &P,
    v: &[f64],
) -> Result<()> {
    let what = format!("{} state length", P::WHAT);
    cd.restore(v, &what, |h| params.check_time_step(h))
}

/// A linear vehicle in time: its `N` degrees of freedom under gravity and the contact
/// forces of its wheels.
#[derive(Debug, Clone)]
pub struct LinearBody<P: LinearVehicle<N, S>, const N: usize, const S: usize> {
    params: P,
    cd: CentralDifference<N>,
    gravity: SVector<f64, N>,
    /// [`LinearVehicle::step_constant`] for the step in use.
    constant: SVector<f64, N>,
}

impl<P: LinearVehicle<N, S>, const N: usize, const S: usize> LinearBody<P, N, S> {
    /// The vehicle of `params` at rest at zero, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`LinearVehicle::validate`] refuses; `dt` not positive or
    /// above [`LinearVehicle::critical_time_step`].
    pub fn new(params: P, dt: f64) -> Result<Self> {
        check_new(&params, dt)?;
        let mut body = LinearBody {
            params,
            cd: CentralDifference::new(
                &params.mass_diagonal(),
                params.stiffness_matrix(),
                params.damping_matrix(),
                dt,
            ),
            gravity: params.gravity_force(),
            constant: SVector::zeros(),
        };
        body.set_constant();
        Ok(body)
    }

    /// [`LinearVehicle::step_constant`] for the step in use.
    fn set_constant(&mut self) {
        self.constant = self.params.step_constant(self.cd.p_force(), &self.gravity);
    }

    /// Parameters.
    pub fn params(&self) -> &P {
        &self.params
    }
    /// Displacements `d` at `t_j` (m, rad), in the order of [`LinearVehicle::DOF_NAMES`].
    pub fn displacements(&self) -> &SVector<f64, N> {
        self.cd.d()
    }
    /// Displacements at `t_(j-1)` (m, rad).
    pub fn previous_displacements(&self) -> &SVector<f64, N> {
        self.cd.d_prev()
    }
    /// Velocities at `t_j`, backward differences over the last step (m/s, rad/s).
    pub fn velocities(&self) -> SVector<f64, N> {
        self.cd.velocities()
    }
    /// Sets the displacements at `t_j` and `t_(j-1)` (m, rad).
    pub fn set_state(&mut self, d: SVector<f64, N>, d_prev: SVector<f64, N>) {
        self.cd.set_state(d, d_prev);
    }
}

impl<P: LinearVehicle<N, S>, const N: usize, const S: usize> RailVehicle for LinearBody<P, N, S> {
    fn wheelsets(&self) -> usize {
        P::WHEELSETS
    }
    fn dt(&self) -> f64 {
        self.cd.dt()
    }
    fn critical_time_step(&self) -> f64 {
        self.params.critical_time_step()
    }
    fn wheel_z(&self) -> Axles {
        self.params.wheels_of(self.cd.d().as_slice())
    }
    fn wheel_velocities(&self) -> Axles {
        self.params.wheels_of(self.cd.velocities().as_slice())
    }
    fn bearing_forces(&self) -> Axles {
        let v = self.cd.velocities();
        self.params
            .primary_forces(self.cd.d().as_slice(), v.as_slice())
    }
    fn side_frames(&self) -> (Axles, Axles) {
        let v = self.cd.velocities();
        (
            self.params.frames_at_boxes(self.cd.d().as_slice()),
            self.params.frames_at_boxes(v.as_slice()),
        )
    }
    fn displacements(&self) -> &[f64] {
        self.cd.d().as_slice()
    }
    fn bodies(&self) -> Bodies {
        self.params.bodies(self.cd.d().as_slice())
    }
    #[inline(always)]
    fn step(&mut self, p: &Axles) {
        let pf = self
            .params
            .force_share(self.cd.p_force(), &self.gravity, &self.constant, p);
        self.cd.advance_premultiplied(pf);
    }
    fn set_static(&mut self, z: &Axles) -> Result<Axles> {
        let d = self
            .params
            .static_state(z)
            .ok_or_else(|| not_held(P::WHAT))?;
        self.cd.set_state(d, d);
        Ok(self.params.static_contact_forces(&d))
    }
    fn change_dt(&mut self, dt: f64) -> Result<()> {
        change_dt_of(&mut self.cd, &self.params, dt)?;
        self.set_constant();
        Ok(())
    }
    fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        restore_of(&mut self.cd, &self.params, v)?;
        self.set_constant();
        Ok(())
    }
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| P::DOF_NAMES[i])
            .or_else(|| wheels_beyond(&RailVehicle::wheel_z(self), P::WHEELSETS))
    }
    fn clone_box(&self) -> Box<dyn RailVehicle> {
        Box::new(self.clone())
    }
}

/// A linear vehicle above its primary suspension: its first `S` degrees of freedom
/// under gravity and the primary forces at its axle boxes (N, pressing the axle boxes
/// down), which the track side computes ([`super::PrimaryLink`]).
#[derive(Debug, Clone)]
pub struct SprungLinearBody<P: LinearVehicle<N, S>, const N: usize, const S: usize> {
    params: P,
    cd: CentralDifference<S>,
    gravity: SVector<f64, S>,
    /// The whole vehicle's static state of `set_static` (zero before): the wheelsets'
    /// part, which the partner carries, for the outputs.
    rest: SVector<f64, N>,
}

impl<P: LinearVehicle<N, S>, const N: usize, const S: usize> SprungLinearBody<P, N, S> {
    /// The bodies of `params` above the primary suspension, stepped with `dt` (s).
    ///
    /// Errors: as [`LinearBody::new`] (the step is checked against the whole vehicle's
    /// critical step).
    pub fn new(params: P, dt: f64) -> Result<Self> {
        check_new(&params, dt)?;
        let (k, c) = params.above_primary();
        let (m, g) = (params.mass_diagonal(), params.gravity_force());
        let sub = |a: SMatrix<f64, N, N>| {
            SMatrix::<f64, S, S>::from_fn(|i, j| a[(P::SPRUNG[i], P::SPRUNG[j])])
        };
        Ok(SprungLinearBody {
            params,
            cd: CentralDifference::new(
                &SVector::from_fn(|i, _| m[P::SPRUNG[i]]),
                sub(k),
                sub(c),
                dt,
            ),
            gravity: SVector::from_fn(|i, _| g[P::SPRUNG[i]]),
            rest: SVector::zeros(),
        })
    }

    /// Parameters.
    pub fn params(&self) -> &P {
        &self.params
    }
    /// Step (s).
    pub fn dt(&self) -> f64 {
        self.cd.dt()
    }
    /// The bodies' displacements at `t_j` (m, rad), in the order of
    /// [`LinearVehicle::SPRUNG`].
    pub fn displacements(&self) -> &SVector<f64, S> {
        self.cd.d()
    }
    /// The whole vehicle's vector with these bodies' values of `x` and the wheelsets'
    /// of `rest`.
    fn whole(&self, x: &SVector<f64, S>, rest: SVector<f64, N>) -> SVector<f64, N> {
        let mut d = rest;
        for (i, &k) in P::SPRUNG.iter().enumerate() {
            d[k] = x[i];
        }
        d
    }
    /// The whole vehicle's displacements (m, rad): these bodies' now, the wheelsets' at
    /// rest ([`SprungVehicle::set_static`]).
    pub fn whole_displacements(&self) -> SVector<f64, N> {
        self.whole(self.cd.d(), self.rest)
    }
}

impl<P: LinearVehicle<N, S>, const N: usize, const S: usize> SprungVehicle
    for SprungLinearBody<P, N, S>
{
    fn wheelsets(&self) -> usize {
        P::WHEELSETS
    }
    fn critical_time_step(&self) -> f64 {
        self.params.critical_time_step()
    }
    fn side_frames(&self) -> (Axles, Axles) {
        let zero = SVector::zeros();
        let (d, v) = (
            self.whole(self.cd.d(), zero),
            self.whole(&self.cd.velocities(), zero),
        );
        (
            self.params.frames_at_boxes(d.as_slice()),
            self.params.frames_at_boxes(v.as_slice()),
        )
    }
    fn bodies(&self) -> Bodies {
        self.params.bodies(self.whole_displacements().as_slice())
    }
    fn step(&mut self, f: &Axles) {
        let mut g = self.gravity;
        self.params.add_primary_forces(f, &mut g);
        self.cd.advance(g);
    }
    fn set_static(&mut self, z: &Axles) -> Result<Axles> {
        let d = self
            .params
            .static_state(z)
            .ok_or_else(|| not_held(P::WHAT))?;
        let top = SVector::from_fn(|i, _| d[P::SPRUNG[i]]);
        self.cd.set_state(top, top);
        self.rest = d;
        // At rest: the springs alone.
        Ok(self
            .params
            .primary_forces(d.as_slice(), SVector::<f64, N>::zeros().as_slice()))
    }
    fn change_dt(&mut self, dt: f64) -> Result<()> {
        change_dt_of(&mut self.cd, &self.params, dt)
    }
    fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        restore_of(&mut self.cd, &self.params, v)
    }
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| P::DOF_NAMES[P::SPRUNG[i]])
    }
    fn exchange_limits(&self, z: &Axles, base: f64, support: f64) -> Result<ExchangeLimits> {
        self.params.exchange_limits(self, z, base, support)
    }
    fn clone_box(&self) -> Box<dyn SprungVehicle> {
        Box::new(self.clone())
    }
}

impl<P: LinearVehicle<N, S>, const N: usize, const S: usize> SprungLinearBody<P, N, S> {
    /// Sets the displacements of [`SprungVehicle::state_vector`] `v` (the step
    /// unchanged), for the exchange's estimate.
    pub(super) fn set_integrator_displacements(&mut self, v: &[f64]) {
        self.cd.set_displacements_from(v)
    }
    /// Changes the substep to `dt` (s), unchecked (below the critical step).
    pub(super) fn set_substep(&mut self, dt: f64) {
        self.cd.change_dt(dt)
    }
}
