//! The wagon ([`WagonParams`]) in time: [`Wagon`], the whole wagon driven by the eight
//! contact forces, and [`SprungWagon`], the wagon above its primary suspensions driven
//! by the eight primary (axle-box) forces, the partner of a track that carries the four
//! wheelsets ([`super::PrimaryLink`]). Both advance by the central differences of the
//! roll-plane vehicle with the damping as in (3.25), as the half-car bogie does, and
//! both stand behind [`RailVehicle`] and [`SprungVehicle`].

use super::rail_vehicle::{
    Axles, Bodies, CarrierModel, RailVehicle, SprungVehicle, bodies_beyond, wheels_beyond,
};
use super::{ExchangeLimits, WAGON_DOFS, WagonParams, WagonVector, bogie_start};
use crate::error::{Error, Result, positive};
use crate::numerics::{CentralDifference, check_critical_step};
use nalgebra::{SMatrix, SVector};

/// Forces or displacements of the eight wheels: `[b][i]` `[left, right]` of wheelset
/// `i` (0 leading) of bogie `b` (0 front).
pub type Octet = [[[f64; 2]; 2]; 2];

/// Names of the wagon's degrees of freedom, in the order of `d` (`super::wagon`), for
/// the health checks.
pub const WAGON_DOF_NAMES: [&str; WAGON_DOFS] = [
    "carbody.z (m)",
    "carbody.pitch (rad)",
    "carbody.roll (rad)",
    "front bogie sideframe.left.z (m)",
    "front bogie sideframe.left.pitch (rad)",
    "front bogie sideframe.right.z (m)",
    "front bogie sideframe.right.pitch (rad)",
    "wheelset.z (m)",
    "wheelset.roll (rad)",
    "wheelset[2].z (m)",
    "wheelset[2].roll (rad)",
    "rear bogie sideframe.left.z (m)",
    "rear bogie sideframe.left.pitch (rad)",
    "rear bogie sideframe.right.z (m)",
    "rear bogie sideframe.right.pitch (rad)",
    "wheelset[3].z (m)",
    "wheelset[3].roll (rad)",
    "wheelset[4].z (m)",
    "wheelset[4].roll (rad)",
];

/// Degrees of freedom above the primary suspensions: the car body's three, each
/// bogie's side frames' four.
const SPRUNG_DOFS: usize = 11;

/// The wagon's degrees of freedom above the primary suspensions, in the order of
/// [`SprungWagon`]'s state.
const SPRUNG: [usize; SPRUNG_DOFS] = [0, 1, 2, 3, 4, 5, 6, 11, 12, 13, 14];

impl WagonParams {
    /// Critical step of central differences on the fastest mode (s), `2 / omega_max`.
    pub fn critical_time_step(&self) -> f64 {
        2.0 / self.natural_frequencies()[WAGON_DOFS - 1]
    }

    /// Default step for the wagon on its own (s): 50 steps per shortest natural period,
    /// as the half-car bogie's.
    pub fn default_dt(&self) -> f64 {
        std::f64::consts::TAU / self.natural_frequencies()[WAGON_DOFS - 1] / 50.0
    }

    /// Refuses a step above [`WagonParams::critical_time_step`].
    pub fn check_time_step(&self, dt: f64) -> Result<()> {
        check_critical_step(dt, self.critical_time_step(), "wagon")
    }

    /// Where wheelset `i` of a bogie (0 leading) lies from the bogie's centre (m).
    fn axle_x(&self, i: usize) -> f64 {
        if i == 0 {
            0.5 * self.bogie.wheelbase
        } else {
            -0.5 * self.bogie.wheelbase
        }
    }

    /// The side frames at the eight axle boxes of the state `d` (or its velocities),
    /// wheelset by wheelset from the leading one: `z_sf + x_i theta_sf`.
    fn frames_at_boxes(&self, d: &[f64]) -> Axles {
        let mut a = [[0.0; 2]; 4];
        for (w, aw) in a.iter_mut().enumerate() {
            let (s0, x) = (bogie_start(w / 2), self.axle_x(w % 2));
            *aw = [0, 1].map(|s| d[s0 + 2 * s] + x * d[s0 + 2 * s + 1]);
        }
        a
    }

    /// The wheel centres of the state `d` (or its velocities), wheelset by wheelset:
    /// `z_w -+ L_w/2 phi_w`.
    fn wheels_of(&self, d: &[f64]) -> Axles {
        let h = 0.5 * self.bogie.primary_spacing;
        let mut a = [[0.0; 2]; 4];
        for (w, aw) in a.iter_mut().enumerate() {
            let j = bogie_start(w / 2) + 4 + 2 * (w % 2);
            *aw = [d[j] - h * d[j + 1], d[j] + h * d[j + 1]];
        }
        a
    }

    /// The primary forces at the eight axle boxes (N), pressing the wheelsets down, of
    /// the state `d` moving at `v`: `-(K_1 (z_sf - z_box) + C_1 (v_sf - v_box))`.
    fn primary_forces(&self, d: &[f64], v: &[f64]) -> Axles {
        let (zf, vf, zb, vb) = (
            self.frames_at_boxes(d),
            self.frames_at_boxes(v),
            self.wheels_of(d),
            self.wheels_of(v),
        );
        let (k1, c1) = (self.bogie.primary_stiffness, self.bogie.primary_damping);
        let mut f = [[0.0; 2]; 4];
        for (w, fw) in f.iter_mut().enumerate() {
            *fw = [0, 1].map(|s| -(k1 * (zf[w][s] - zb[w][s]) + c1 * (vf[w][s] - vb[w][s])));
        }
        f
    }
}

impl WagonParams {
    /// The bodies of the displacements `d` (in the order of [`WAGON_DOF_NAMES`]): each
    /// bolster moves with the car body at its centre plate, `x = +- d / 2`.
    pub fn bodies(&self, d: &[f64]) -> Bodies {
        let hd = 0.5 * self.bogie_distance;
        let mut b = Bodies {
            carbody: [d[0], d[1], d[2]],
            ..Bodies::default()
        };
        for w in 0..4 {
            let (s0, x) = (bogie_start(w / 2), if w < 2 { hd } else { -hd });
            b.bolster[w] = [d[0] + x * d[1], d[2]];
            b.sideframe_pitch[w] = [d[s0 + 1], d[s0 + 3]];
            let j = s0 + 4 + 2 * (w % 2);
            b.wheelset[w] = [d[j], d[j + 1]];
        }
        b
    }
}

impl CarrierModel for WagonParams {
    fn wheelsets(&self) -> usize {
        4
    }
    fn offsets(&self) -> Vec<(f64, &'static str)> {
        let (a, d) = (self.bogie.wheelbase, self.bogie_distance);
        vec![
            (a, "the wheelbase"),
            (d, "the bogie centre distance"),
            (
                d + a,
                "wheelset[3].offset + wheelset[2].offset, the rear bogie's trailing wheelset \
                 a wheelbase behind its leading one",
            ),
        ]
    }
    fn name(&self) -> &'static str {
        "the wagon (vehicle.model = wagon)"
    }
    fn validate(&self) -> Result<()> {
        WagonParams::validate(self)
    }
    fn critical_time_step(&self) -> f64 {
        WagonParams::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        WagonParams::default_dt(self)
    }
    fn static_wheel_load(&self) -> f64 {
        WagonParams::static_wheel_load(self)
    }
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>> {
        Ok(Box::new(Wagon::new(*self, dt)?))
    }
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>> {
        Ok(Box::new(SprungWagon::new(*self, dt)?))
    }
}

/// `a` as `[b][i]`.
fn octet(a: &Axles) -> Octet {
    [[a[0], a[1]], [a[2], a[3]]]
}

/// `o` wheelset by wheelset.
fn flat(o: Octet) -> Axles {
    [o[0][0], o[0][1], o[1][0], o[1][1]]
}

fn not_held() -> Error {
    Error::Unsupported(
        "static equilibrium of the wagon: the suspension does not hold the bodies".into(),
    )
}

/// The wagon in time: nineteen degrees of freedom under gravity and the eight contact
/// forces, by the central differences of the roll-plane vehicle with the damping as in
/// (3.25) (the half-car bogie's scheme).
#[derive(Debug, Clone)]
pub struct Wagon {
    params: WagonParams,
    cd: CentralDifference<WAGON_DOFS>,
    gravity: WagonVector,
}

impl Wagon {
    /// The wagon of `params` at rest at zero, stepped with `dt` (s).
    ///
    /// Errors: a parameter [`WagonParams::validate`] refuses; `dt` not positive or above
    /// [`WagonParams::critical_time_step`].
    pub fn new(params: WagonParams, dt: f64) -> Result<Wagon> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        Ok(Wagon {
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
    pub fn params(&self) -> &WagonParams {
        &self.params
    }

    /// Displacements `d` at `t_j` (m, rad), in the order of [`WAGON_DOF_NAMES`].
    pub fn displacements(&self) -> &WagonVector {
        self.cd.d()
    }

    /// Wheel-centre displacements `[b][i]` `[left, right]` (m): `z_w -+ L_w/2 phi_w`.
    pub fn wheel_z(&self) -> Octet {
        octet(&self.params.wheels_of(self.cd.d().as_slice()))
    }

    /// Advances one step from `t_j` under the contact forces `p` (N, up on the wheels)
    /// at `t_j`.
    pub fn step(&mut self, p: Octet) {
        self.cd.advance(self.gravity + self.params.contact_force(p));
    }

    /// Static equilibrium with the wheels held at `z_wheel` (m)
    /// ([`WagonParams::static_state`]).
    ///
    /// Errors: a suspension that does not hold the bodies.
    pub fn set_static(&mut self, z_wheel: Octet) -> Result<()> {
        let d = self.params.static_state(z_wheel).ok_or_else(not_held)?;
        self.cd.set_state(d, d);
        Ok(())
    }
}

impl RailVehicle for Wagon {
    fn wheelsets(&self) -> usize {
        4
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
    #[inline]
    fn step(&mut self, p: &Axles) {
        Wagon::step(self, octet(p))
    }
    fn set_static(&mut self, z: &Axles) -> Result<Axles> {
        Wagon::set_static(self, octet(z))?;
        Ok(flat(self.params.static_contact_forces(self.cd.d())))
    }
    fn change_dt(&mut self, dt: f64) -> Result<()> {
        let p = self.params;
        self.cd.change_dt_checked(dt, |h| p.check_time_step(h))
    }
    fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let p = self.params;
        self.cd
            .restore(v, "wagon state length", |h| p.check_time_step(h))
    }
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| WAGON_DOF_NAMES[i])
            .or_else(|| wheels_beyond(&RailVehicle::wheel_z(self), 4))
    }
    fn clone_box(&self) -> Box<dyn RailVehicle> {
        Box::new(self.clone())
    }
}

/// The wagon above its primary suspensions: the car body (bounce, pitch, roll) with
/// the bolsters, and each bogie's side frames (bounce, pitch), under gravity and the
/// eight primary forces (N, positive pressing the axle boxes down, so pushing the side
/// frames up at the axles), which the track side computes ([`super::PrimaryLink`], one
/// per wheelset, the side frames shared by each bogie's two wheelsets).
#[derive(Debug, Clone)]
pub struct SprungWagon {
    params: WagonParams,
    cd: CentralDifference<SPRUNG_DOFS>,
    gravity: SVector<f64, SPRUNG_DOFS>,
    /// The whole wagon's static state of `set_static` (zero before): the wheelsets'
    /// part, which the partner carries, for the outputs.
    rest: WagonVector,
}

impl SprungWagon {
    /// The bodies of `params` above the primary suspensions, stepped with `dt` (s).
    ///
    /// Errors: as [`Wagon::new`] (the step is checked against the whole wagon's
    /// critical step).
    pub fn new(params: WagonParams, dt: f64) -> Result<SprungWagon> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        params.check_time_step(dt)?;
        // The secondary suspension only: the primary is the other side's.
        let mut above = params;
        above.bogie.primary_stiffness = 0.0;
        above.bogie.primary_damping = 0.0;
        let sub = |m: nalgebra::SMatrix<f64, WAGON_DOFS, WAGON_DOFS>| {
            SMatrix::<f64, SPRUNG_DOFS, SPRUNG_DOFS>::from_fn(|i, j| m[(SPRUNG[i], SPRUNG[j])])
        };
        let (m, g) = (params.mass_diagonal(), params.gravity_force());
        Ok(SprungWagon {
            params,
            cd: CentralDifference::new(
                &SVector::from_fn(|i, _| m[SPRUNG[i]]),
                sub(above.stiffness_matrix()),
                sub(above.damping_matrix()),
                dt,
            ),
            gravity: SVector::from_fn(|i, _| g[SPRUNG[i]]),
            rest: WagonVector::zeros(),
        })
    }

    /// The whole wagon's vector with these bodies' values of `x` (the others zero).
    fn whole(x: &SVector<f64, SPRUNG_DOFS>) -> WagonVector {
        let mut d = WagonVector::zeros();
        for (i, &k) in SPRUNG.iter().enumerate() {
            d[k] = x[i];
        }
        d
    }
}

impl SprungVehicle for SprungWagon {
    fn wheelsets(&self) -> usize {
        4
    }
    fn critical_time_step(&self) -> f64 {
        self.params.critical_time_step()
    }
    fn side_frames(&self) -> (Axles, Axles) {
        let (d, v) = (Self::whole(self.cd.d()), Self::whole(&self.cd.velocities()));
        (
            self.params.frames_at_boxes(d.as_slice()),
            self.params.frames_at_boxes(v.as_slice()),
        )
    }
    fn bodies(&self) -> Bodies {
        let mut d = self.rest;
        for (i, &k) in SPRUNG.iter().enumerate() {
            d[k] = self.cd.d()[i];
        }
        self.params.bodies(d.as_slice())
    }
    fn step(&mut self, f: &Axles) {
        let mut g = self.gravity;
        for (w, fw) in f.iter().enumerate() {
            // Bogie w / 2's side frames start at 3 + 4 (w / 2) here.
            let (s0, x) = (3 + 4 * (w / 2), self.params.axle_x(w % 2));
            for (s, &fs) in fw.iter().enumerate() {
                g[s0 + 2 * s] += fs;
                g[s0 + 2 * s + 1] += x * fs;
            }
        }
        self.cd.advance(g);
    }
    fn set_static(&mut self, z: &Axles) -> Result<Axles> {
        let d = self.params.static_state(octet(z)).ok_or_else(not_held)?;
        let top = SVector::from_fn(|i, _| d[SPRUNG[i]]);
        self.cd.set_state(top, top);
        self.rest = d;
        // At rest: the springs alone.
        Ok(self
            .params
            .primary_forces(d.as_slice(), WagonVector::zeros().as_slice()))
    }
    fn change_dt(&mut self, dt: f64) -> Result<()> {
        let p = self.params;
        self.cd.change_dt_checked(dt, |h| p.check_time_step(h))
    }
    fn state_vector(&self) -> Vec<f64> {
        self.cd.state_vector()
    }
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        let p = self.params;
        self.cd
            .restore(v, "wagon state length", |h| p.check_time_step(h))
    }
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)> {
        bodies_beyond(&self.cd, |i| WAGON_DOF_NAMES[SPRUNG[i]])
    }
    /// The half-car bogie's estimate ([`super::SprungHalfCar`]) for one of the wagon's
    /// bogies carrying half the car body, on the front bogie's wheel heights: the
    /// exchange's fastest modes are each bogie's side frames on their primary springs,
    /// which the heavy car body (its modes below 2 Hz) does not couple. The wagon's own
    /// amplification matrix (70 unknowns against the half-car's 36) took minutes.
    fn exchange_limits(&self, z: &Axles, base: f64, support: f64) -> Result<ExchangeLimits> {
        let mut bogie = self.params.bogie;
        bogie.carbody_mass = 0.5 * self.params.carbody_mass;
        let mut half = super::SprungHalfCar::new(bogie, base)?;
        SprungVehicle::set_static(&mut half, &[z[0], z[1], [0.0; 2], [0.0; 2]])?;
        SprungVehicle::exchange_limits(&half, z, base, support)
    }
    fn clone_box(&self) -> Box<dyn SprungVehicle> {
        Box::new(self.clone())
    }
}
