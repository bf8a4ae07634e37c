//! The wagon ([`WagonParams`]) in time, on the generic linear body ([`LinearVehicle`]):
//! [`Wagon`], the whole wagon driven by the eight contact forces, and [`SprungWagon`],
//! the wagon above its primary suspensions driven by the eight primary (axle-box)
//! forces, the partner of a track that carries the four wheelsets
//! ([`super::PrimaryLink`]). Both advance by the central differences of the roll-plane
//! vehicle with the damping as in (3.25), as the half-car bogie does, and both stand
//! behind [`RailVehicle`] and [`SprungVehicle`].

use super::linear_body::{LinearBody, LinearVehicle, SprungLinearBody};
use super::rail_vehicle::{Axles, Bodies, CarrierModel, RailVehicle, SprungVehicle};
use super::{
    ExchangeLimits, SprungHalfCar, WAGON_DOFS, WagonMatrix, WagonParams, WagonVector, bogie_start,
};
use crate::error::Result;
use nalgebra::SVector;

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

/// The wagon in time: nineteen degrees of freedom ([`WAGON_DOF_NAMES`]) under gravity
/// and the eight contact forces.
pub type Wagon = LinearBody<WagonParams, WAGON_DOFS, SPRUNG_DOFS>;
/// The wagon above its primary suspensions: the car body (bounce, pitch, roll) with
/// the bolsters, and each bogie's side frames (bounce, pitch), under gravity and the
/// eight primary forces (N, positive pressing the axle boxes down, so pushing the side
/// frames up at the axles), which the track side computes ([`super::PrimaryLink`], one
/// per wheelset, the side frames shared by each bogie's two wheelsets).
pub type SprungWagon = SprungLinearBody<WagonParams, WAGON_DOFS, SPRUNG_DOFS>;

impl WagonParams {
    /// Where wheelset `i` of a bogie (0 leading) lies from the bogie's centre (m).
    fn axle_x(&self, i: usize) -> f64 {
        if i == 0 {
            0.5 * self.bogie.wheelbase
        } else {
            -0.5 * self.bogie.wheelbase
        }
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

impl LinearVehicle<WAGON_DOFS, SPRUNG_DOFS> for WagonParams {
    const WHAT: &'static str = "wagon";
    const DOF_NAMES: [&'static str; WAGON_DOFS] = WAGON_DOF_NAMES;
    const WHEELSETS: usize = 4;
    const SPRUNG: [usize; SPRUNG_DOFS] = SPRUNG;

    fn validate(&self) -> Result<()> {
        WagonParams::validate(self)
    }
    fn mass_diagonal(&self) -> WagonVector {
        WagonParams::mass_diagonal(self)
    }
    fn stiffness_matrix(&self) -> WagonMatrix {
        WagonParams::stiffness_matrix(self)
    }
    fn damping_matrix(&self) -> WagonMatrix {
        WagonParams::damping_matrix(self)
    }
    /// The secondary suspensions only: the primary is the other side's.
    fn above_primary(&self) -> (WagonMatrix, WagonMatrix) {
        let mut above = *self;
        above.bogie.primary_stiffness = 0.0;
        above.bogie.primary_damping = 0.0;
        (
            WagonParams::stiffness_matrix(&above),
            WagonParams::damping_matrix(&above),
        )
    }
    fn gravity_force(&self) -> WagonVector {
        WagonParams::gravity_force(self)
    }
    fn contact_force(&self, p: &Axles) -> WagonVector {
        WagonParams::contact_force(self, octet(p))
    }
    /// Wheelset by wheelset: `z_w -+ L_w/2 phi_w`.
    fn wheels_of(&self, d: &[f64]) -> Axles {
        let h = 0.5 * self.bogie.primary_spacing;
        let mut a = [[0.0; 2]; 4];
        for (w, aw) in a.iter_mut().enumerate() {
            let j = bogie_start(w / 2) + 4 + 2 * (w % 2);
            *aw = [d[j] - h * d[j + 1], d[j] + h * d[j + 1]];
        }
        a
    }
    /// The side frames at the eight axle boxes, wheelset by wheelset from the leading
    /// one: `z_sf + x_i theta_sf`.
    fn frames_at_boxes(&self, d: &[f64]) -> Axles {
        let mut a = [[0.0; 2]; 4];
        for (w, aw) in a.iter_mut().enumerate() {
            let (s0, x) = (bogie_start(w / 2), self.axle_x(w % 2));
            *aw = [0, 1].map(|s| d[s0 + 2 * s] + x * d[s0 + 2 * s + 1]);
        }
        a
    }
    fn add_primary_forces(&self, f: &Axles, g: &mut SVector<f64, SPRUNG_DOFS>) {
        for (w, fw) in f.iter().enumerate() {
            // Bogie w / 2's side frames start at 3 + 4 (w / 2) here.
            let (s0, x) = (3 + 4 * (w / 2), self.axle_x(w % 2));
            for (s, &fs) in fw.iter().enumerate() {
                g[s0 + 2 * s] += fs;
                g[s0 + 2 * s + 1] += x * fs;
            }
        }
    }
    fn primary(&self) -> (f64, f64) {
        (self.bogie.primary_stiffness, self.bogie.primary_damping)
    }
    fn static_state(&self, z: &Axles) -> Option<WagonVector> {
        WagonParams::static_state(self, octet(z))
    }
    fn static_contact_forces(&self, d: &WagonVector) -> Axles {
        flat(WagonParams::static_contact_forces(self, d))
    }
    /// Each bolster moves with the car body at its centre plate, `x = +- d / 2`.
    fn bodies(&self, d: &[f64]) -> Bodies {
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
    /// The half-car bogie's estimate ([`SprungHalfCar`]) for one of the wagon's
    /// bogies carrying half the car body, on the front bogie's wheel heights: the
    /// exchange's fastest modes are each bogie's side frames on their primary springs,
    /// which the heavy car body (its modes below 2 Hz) does not couple. The wagon's own
    /// amplification matrix (70 unknowns against the half-car's 36) took minutes.
    fn exchange_limits(
        &self,
        _body: &SprungWagon,
        z: &Axles,
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits> {
        let mut bogie = self.bogie;
        bogie.carbody_mass = 0.5 * self.carbody_mass;
        let mut half = SprungHalfCar::new(bogie, base)?;
        SprungVehicle::set_static(&mut half, &[z[0], z[1], [0.0; 2], [0.0; 2]])?;
        SprungVehicle::exchange_limits(&half, z, base, support)
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
        LinearVehicle::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        LinearVehicle::default_dt(self)
    }
    fn static_wheel_load(&self) -> f64 {
        WagonParams::static_wheel_load(self)
    }
    fn stiffnesses(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("vehicle.primary.stiffness", self.bogie.primary_stiffness),
            (
                "vehicle.secondary.stiffness",
                self.bogie.secondary_stiffness,
            ),
        ]
    }
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>> {
        Ok(Box::new(Wagon::new(*self, dt)?))
    }
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>> {
        Ok(Box::new(SprungWagon::new(*self, dt)?))
    }
}
