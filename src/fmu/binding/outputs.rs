//! The outputs and calculated parameters of the three FMUs, by value reference.

use super::FmuModel;
use super::unit::Engine;
use crate::contact::ContactState;
use crate::fmu::vars::{QUANTITIES, Quantity};
use crate::sim::VehicleUnit;
use crate::sim::{Sample, Simulation, VehicleState};
use crate::track::RailResponse;

/// Values computed when the model is built, published as calculated parameters.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Published {
    /// `static_load.left`/`.right` (N).
    pub static_load: [f64; 2],
    /// `static_wheel_z.left`/`.right` (m).
    pub static_wheel_z: [f64; 2],
    /// `solver.step` (s).
    pub step: f64,
    /// `solver.critical_step` (s).
    pub critical_step: f64,
    /// `contact.kw_used` (N/m/rad).
    pub kw_used: f64,
}

impl Published {
    /// The values in the order FMU states store them.
    pub fn to_array(self) -> [f64; 7] {
        let [l, r] = self.static_load;
        let [zl, zr] = self.static_wheel_z;
        [l, r, zl, zr, self.step, self.critical_step, self.kw_used]
    }
}

/// What the outputs are read from.
enum View<'a> {
    /// RollPlaneVehicle.
    Vehicle(&'a VehicleUnit),
    /// TrackContact and CoupledSystem, with the sample at the current time.
    Sim(&'a Simulation, &'a Sample),
}

impl FmuModel {
    /// Value of an output or calculated parameter; `sample` is the track-carrying
    /// models' sample at the current time. NaN for a reference the FMU does not have.
    ///
    /// The table names each computed variable's quantity and side
    /// ([`QUANTITIES`]); this is the one place a quantity meets the engine.
    pub(super) fn output_value(&self, r: u32, sample: Option<&Sample>) -> f64 {
        let Some(&Some((q, side))) = QUANTITIES.get(r as usize) else {
            return f64::NAN;
        };
        let p = &self.published;
        let view = match (&self.engine, sample) {
            (Engine::Vehicle(u), _) => View::Vehicle(u),
            (Engine::Sim(sim), Some(s)) => View::Sim(sim, s),
            (Engine::Sim(_), None) => return f64::NAN,
        };
        // The contact state of a track-carrying model (the vehicle has none).
        let contact = |f: fn(&ContactState) -> f64| match view {
            View::Sim(_, s) => f(&s.contact[side]),
            View::Vehicle(_) => f64::NAN,
        };
        // The rail under this side's wheel of a track-carrying model.
        let rail = |f: fn(&RailResponse) -> f64| match view {
            View::Sim(sim, _) => sim.rail_under_wheel(side).map_or(f64::NAN, |r| f(&r)),
            View::Vehicle(_) => f64::NAN,
        };
        // The roll-plane vehicle's displacements and bearing forces, where there is one.
        let body = |k: usize| match view {
            View::Vehicle(u) => u.displacements()[k],
            View::Sim(sim, _) => match sim.vehicle() {
                VehicleState::RollPlane(v) => v.displacements()[k],
                _ => f64::NAN,
            },
        };
        let bearing = || match view {
            View::Vehicle(u) => u.bearing_forces()[side],
            View::Sim(sim, _) => match sim.vehicle() {
                VehicleState::RollPlane(v) => v.bearing_forces()[side],
                _ => f64::NAN,
            },
        };
        match q {
            Quantity::SolverStep => p.step,
            Quantity::SolverCriticalStep => p.critical_step,
            Quantity::StaticLoad => p.static_load[side],
            Quantity::StaticWheelZ => p.static_wheel_z[side],
            Quantity::ContactKwUsed => p.kw_used,
            Quantity::WheelZ => match view {
                View::Vehicle(u) => u.wheel_z()[side],
                View::Sim(_, s) => s.wheel_z[side],
            },
            Quantity::WheelRotation => match view {
                View::Vehicle(u) => u.rotation(),
                View::Sim(_, s) => s.rotation,
            },
            Quantity::ContactForce => contact(|c| c.force),
            Quantity::ContactOverlap => contact(|c| c.overlap),
            Quantity::ContactFrontAngle => contact(|c| c.front_angle),
            Quantity::ContactRearAngle => contact(|c| c.rear_angle),
            Quantity::ContactLength => contact(|c| c.length),
            Quantity::ContactIntervals => contact(|c| c.intervals as f64),
            // The extremes up to the last step, with the force at the current time.
            Quantity::ContactMaxForce => match view {
                View::Vehicle(u) => u.max_force()[side],
                View::Sim(sim, s) => sim.max_force()[side].max(s.contact[side].force),
            },
            Quantity::ContactMinForce => match view {
                View::Vehicle(u) => u.min_force()[side],
                View::Sim(sim, s) => sim.min_force()[side].min(s.contact[side].force),
            },
            Quantity::RailZ => match view {
                View::Sim(_, s) => s.rail_z[side],
                View::Vehicle(_) => f64::NAN,
            },
            Quantity::RailBendingMoment => rail(|r| r.bending_moment),
            Quantity::RailShearForce => rail(|r| r.shear_force),
            Quantity::Position => match view {
                View::Sim(_, s) => s.position,
                View::Vehicle(_) => f64::NAN,
            },
            // `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`
            Quantity::BolsterZ => body(0),
            Quantity::BolsterRoll => body(1),
            Quantity::SideframeZ => body(2 + side),
            Quantity::WheelsetZ => body(4),
            Quantity::WheelsetRoll => body(5),
            Quantity::PrimaryForce => bearing(),
        }
    }
}
