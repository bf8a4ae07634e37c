//! The half-car bogie ([`HalfCarParams`]) in time, on the generic linear body
//! ([`LinearVehicle`]): [`HalfCarBogie`], the whole bogie driven by the four contact
//! forces, and [`SprungHalfCar`], the bogie above its primary suspension driven by the
//! four primary (axle-box) forces, the partner of a track that carries the wheelsets
//! ([`super::PrimaryLink`]). Both advance by the central differences of the roll-plane
//! vehicle with the damping as in (3.25).

use super::linear_body::{LinearBody, LinearVehicle, SprungLinearBody};
use super::rail_vehicle::{Axles, Bodies, CarrierModel, RailVehicle, SprungVehicle};
use super::{
    ExchangeLimits, HALF_CAR_DOF_NAMES, HALF_CAR_DOFS, HalfCarMatrix, HalfCarParams, HalfCarVector,
    RollPlaneParams, SideFrameInertia,
};
use crate::error::Result;
use nalgebra::SVector;

/// Forces or displacements of the four wheels or axle boxes: `[[left, right] of
/// wheelset 1, [left, right] of wheelset 2]`.
pub type Quad = [[f64; 2]; 2];

/// Degrees of freedom above the primary suspension: bolster bounce and roll, the side
/// frames' bounce and pitch.
const SPRUNG_DOFS: usize = 6;

/// The half-car bogie in time: ten degrees of freedom ([`HALF_CAR_DOF_NAMES`]) under
/// gravity and the four contact forces.
pub type HalfCarBogie = LinearBody<HalfCarParams, HALF_CAR_DOFS, SPRUNG_DOFS>;
/// The half-car bogie above its primary suspension: bolster bounce and roll, the side
/// frames' bounce and pitch (the first six of [`HALF_CAR_DOF_NAMES`]), under gravity
/// and the four primary forces (N, pressing the axle boxes down, so pushing the side
/// frames up at the axles), which the track side computes ([`super::PrimaryLink`], one
/// per wheelset).
pub type SprungHalfCar = SprungLinearBody<HalfCarParams, HALF_CAR_DOFS, SPRUNG_DOFS>;

/// `q` as the first two wheelsets.
fn axles(q: Quad) -> Axles {
    [q[0], q[1], [0.0; 2], [0.0; 2]]
}

impl HalfCarParams {
    /// Critical step of central differences on the fastest mode (s), `2 / omega_max`
    /// ([`LinearVehicle::critical_time_step`], here for callers without the trait).
    pub fn critical_time_step(&self) -> f64 {
        LinearVehicle::critical_time_step(self)
    }

    /// Default step for the bogie on its own (s): 50 steps per shortest natural period
    /// ([`LinearVehicle::default_dt`]).
    pub fn default_dt(&self) -> f64 {
        LinearVehicle::default_dt(self)
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

    /// What TrackContact carries above each axle box at the axle-box interface: the
    /// pitching side frames, shared by the two wheelsets.
    pub fn above_axle_boxes(&self) -> SideFrameInertia {
        SideFrameInertia::pitching(
            self.sideframe_mass,
            self.sideframe_pitch_inertia,
            self.wheelbase,
        )
    }

    /// The wheelset and its primary suspension, in the roll-plane vehicle's parameters,
    /// as the track side carries them ([`super::PrimaryLink`] uses no more).
    pub fn wheelset(&self) -> RollPlaneParams {
        RollPlaneParams::wheelset_on_primary(
            self.wheelset_mass,
            self.wheelset_inertia,
            (
                self.primary_stiffness,
                self.primary_damping,
                self.primary_spacing,
            ),
            self.gravity,
        )
    }
}

impl LinearVehicle<HALF_CAR_DOFS, SPRUNG_DOFS> for HalfCarParams {
    const WHAT: &'static str = "half-car bogie";
    const DOF_NAMES: [&'static str; HALF_CAR_DOFS] = HALF_CAR_DOF_NAMES;
    const WHEELSETS: usize = 2;
    const SPRUNG: [usize; SPRUNG_DOFS] = [0, 1, 2, 3, 4, 5];

    fn validate(&self) -> Result<()> {
        HalfCarParams::validate(self)
    }
    fn mass_diagonal(&self) -> HalfCarVector {
        HalfCarParams::mass_diagonal(self)
    }
    fn stiffness_matrix(&self) -> HalfCarMatrix {
        HalfCarParams::stiffness_matrix(self)
    }
    fn damping_matrix(&self) -> HalfCarMatrix {
        HalfCarParams::damping_matrix(self)
    }
    /// The secondary suspension only: the primary is the other side's.
    fn above_primary(&self) -> (HalfCarMatrix, HalfCarMatrix) {
        let mut above = *self;
        above.primary_stiffness = 0.0;
        above.primary_damping = 0.0;
        (
            HalfCarParams::stiffness_matrix(&above),
            HalfCarParams::damping_matrix(&above),
        )
    }
    fn gravity_force(&self) -> HalfCarVector {
        HalfCarParams::gravity_force(self)
    }
    fn contact_force(&self, p: &Axles) -> HalfCarVector {
        HalfCarParams::contact_force(self, [p[0], p[1]])
    }
    /// `z_w -+ L_w/2 phi_w`.
    fn wheels_of(&self, d: &[f64]) -> Axles {
        let h = 0.5 * self.primary_spacing;
        axles([0, 1].map(|i| {
            let (z, phi) = (d[6 + 2 * i], d[7 + 2 * i]);
            [z - h * phi, z + h * phi]
        }))
    }
    /// The side frames at the axles: `z_sf + x_i theta_sf`.
    fn frames_at_boxes(&self, d: &[f64]) -> Axles {
        axles([0, 1].map(|i| [0, 1].map(|s| d[2 + 2 * s] + self.axle_x(i) * d[3 + 2 * s])))
    }
    fn add_primary_forces(&self, f: &Axles, g: &mut SVector<f64, SPRUNG_DOFS>) {
        for (i, fi) in f.iter().take(2).enumerate() {
            let x = self.axle_x(i);
            for (s, &fs) in fi.iter().enumerate() {
                g[2 + 2 * s] += fs;
                g[3 + 2 * s] += x * fs;
            }
        }
    }
    fn primary(&self) -> (f64, f64) {
        (self.primary_stiffness, self.primary_damping)
    }
    fn static_state(&self, z: &Axles) -> Option<HalfCarVector> {
        HalfCarParams::static_state(self, [z[0], z[1]])
    }
    fn static_contact_forces(&self, d: &HalfCarVector) -> Axles {
        axles(HalfCarParams::static_contact_forces(self, d))
    }
    /// The bolster over both wheelsets; no car body (the bolster carries its share).
    fn bodies(&self, d: &[f64]) -> Bodies {
        let bolster = [d[0], d[1]];
        let pitch = [d[3], d[5]];
        Bodies {
            carbody: [0.0; 3],
            bolster: axles([bolster, bolster]),
            sideframe_pitch: axles([pitch, pitch]),
            wheelset: axles([[d[6], d[7]], [d[8], d[9]]]),
        }
    }
    /// As the roll-plane vehicle's ([`super::SprungBogie::exchange_limits`]), its
    /// pitching side frames shared by the two wheelsets.
    fn exchange_limits(
        &self,
        body: &SprungHalfCar,
        z: &Axles,
        base: f64,
        support: f64,
    ) -> Result<ExchangeLimits> {
        super::exchange::linear_limits(
            body,
            &self.wheelset(),
            self.above_axle_boxes(),
            z,
            base,
            support,
        )
    }
}

impl CarrierModel for HalfCarParams {
    fn wheelsets(&self) -> usize {
        2
    }
    fn offsets(&self) -> Vec<(f64, &'static str)> {
        vec![(self.wheelbase, "the wheelbase")]
    }
    fn name(&self) -> &'static str {
        "the half-car bogie (vehicle.model = half_car)"
    }
    fn validate(&self) -> Result<()> {
        HalfCarParams::validate(self)
    }
    fn critical_time_step(&self) -> f64 {
        LinearVehicle::critical_time_step(self)
    }
    fn default_dt(&self) -> f64 {
        LinearVehicle::default_dt(self)
    }
    fn static_wheel_load(&self) -> f64 {
        HalfCarParams::static_wheel_load(self)
    }
    fn stiffnesses(&self) -> Vec<(&'static str, f64)> {
        vec![
            ("vehicle.primary.stiffness", self.primary_stiffness),
            ("vehicle.secondary.stiffness", self.secondary_stiffness),
        ]
    }
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>> {
        Ok(Box::new(HalfCarBogie::new(*self, dt)?))
    }
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>> {
        Ok(Box::new(SprungHalfCar::new(*self, dt)?))
    }
}
