//! The outputs and calculated parameters of the four FMUs, by value reference.

use super::FmuModel;
use super::unit::Engine;
use crate::contact::ContactState;
use crate::fmu::vars::{QUANTITIES, Quantity};
use crate::sim::VehicleUnit;
use crate::sim::{Sample, Simulation, VehicleState};
use crate::track::RailResponse;

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
        let Some(&Some((q, side, index))) = QUANTITIES.get(r as usize) else {
            return f64::NAN;
        };
        let p = &self.published;
        if let Some(x) = site_value(&self.engine, q, side, index) {
            return x;
        }
        // Wheelset `index` (0 the leading one) of a track-carrying model; a wheelset
        // the model does not have reads 0.
        let trailing;
        let view = match (&self.engine, sample) {
            (Engine::Vehicle(u), _) => View::Vehicle(u),
            (Engine::Sim(sim), Some(s)) if index == 0 => View::Sim(sim, s),
            (Engine::Sim(sim), Some(_)) => match sim.sample_of(index) {
                Some(s) => {
                    trailing = s;
                    View::Sim(sim, &trailing)
                }
                None => return 0.0,
            },
            (Engine::Sim(_), None) => return f64::NAN,
        };
        // The contact state of a track-carrying model (the vehicle has none).
        let contact = |f: fn(&ContactState) -> f64| match view {
            View::Sim(_, s) => f(&s.contact[side]),
            View::Vehicle(_) => f64::NAN,
        };
        // Wheelset `index`'s accelerations `[now, max, min]` of `[wheel left, wheel
        // right, rail left, rail right]`.
        let accel = |which: usize, signal: usize| match view {
            View::Sim(sim, s) => sim
                .wheelsets()
                .get(index)
                .map_or(0.0, |w| w.accelerations(s)[which][signal]),
            // The vehicles carry the wheels, not the rail.
            View::Vehicle(u) if signal < 2 => u.wheel_accelerations(index)[which][signal],
            View::Vehicle(_) => f64::NAN,
        };
        // The discrete track of a track-carrying model.
        let lifted = |f: fn(&crate::track::Track) -> f64| match view {
            View::Sim(sim, _) => match sim.track() {
                crate::sim::TrackState::Discrete(t) => f(t),
                crate::sim::TrackState::Lumped(_) => 0.0,
            },
            View::Vehicle(_) => f64::NAN,
        };
        // The rail under this side's wheel of a track-carrying model.
        let rail = |f: fn(&RailResponse) -> f64| match view {
            View::Sim(sim, _) => sim
                .rail_under_wheel_of(index, side)
                .map_or(f64::NAN, |r| f(&r)),
            View::Vehicle(_) => f64::NAN,
        };
        // The vehicle that moves wheelset `index`'s wheels and the wheelset's index
        // among its own: the vehicle unit's, or the simulation's (the vehicle on several
        // wheelsets, or the wheelset's own roll-plane vehicle); `None` where nothing
        // moves them (loads, external wheels, the axle-box interface's wheelsets).
        let vehicle = match view {
            View::Vehicle(_) => None,
            View::Sim(sim, _) => sim.vehicle_of(index),
        };
        // (A vehicle unit's view has no `vehicle`: it is its own.)
        let w = vehicle.map_or(index.min(crate::vehicle::MAX_AXLES - 1), |(_, a)| a);
        // The bodies' displacements, formed only for a quantity that reads them (a
        // copy of every body: the contact forces, read at every step, do without).
        let bodies = || match (&view, vehicle) {
            (View::Vehicle(u), _) => Some(u.bodies()),
            (View::Sim(..), Some((v, _))) => Some(v.bodies()),
            (View::Sim(..), None) => None,
        };
        // The bolster's (0, 1) and the wheelset's (4, 5) bounce and roll, as the
        // roll-plane vehicle's `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}` number them.
        let body = |k: usize| match bodies() {
            Some(b) => match k {
                0 | 1 => b.bolster[w][k],
                _ => b.wheelset[w][k - 4],
            },
            None => f64::NAN,
        };
        // The side frames (the suspension's upper ends) above wheelset `index`'s axle
        // boxes: displacements and velocities.
        let frames = || match (&view, vehicle) {
            (View::Vehicle(u), _) => u.side_frames_of(index),
            (View::Sim(..), Some((v, a))) => {
                let (z, v) = v.side_frames();
                Some((z[a], v[a]))
            }
            (View::Sim(..), None) => None,
        };
        // The primary forces: the vehicle's, the axle-box interface's at the
        // communication point, or 0 where the track carries no primary suspension (TrackContact
        // with the contact interface).
        let bearing = || match (&view, vehicle) {
            (View::Vehicle(u), _) => u.bearing_forces_of(index).map_or(0.0, |f| f[side]),
            (View::Sim(..), Some((v, a))) => v.bearing_forces()[a][side],
            (View::Sim(sim, _), None) => match sim.wheelsets().get(index).map(|w| w.vehicle()) {
                Some(VehicleState::AxleBox(link)) => link.force_now()[side],
                _ => 0.0,
            },
        };
        // The axle-box interface's primary forces averaged since the last input.
        let mean_bearing = || match view {
            View::Sim(sim, _) => match sim.wheelsets().get(index).map(|w| w.vehicle()) {
                Some(VehicleState::AxleBox(link)) => link.mean_force()[side],
                _ => 0.0,
            },
            View::Vehicle(_) => 0.0,
        };
        let extremes = |sim: &Simulation| {
            sim.wheelsets()
                .get(index)
                .map_or(([0.0; 2], [0.0; 2]), |w| (w.max_force(), w.min_force()))
        };
        match q {
            Quantity::SolverStep => p.step,
            Quantity::SolverCriticalStep => p.critical_step,
            Quantity::StaticLoad => p.static_load[side],
            Quantity::StaticWheelZ if index == 0 => p.static_wheel_z[side],
            Quantity::StaticWheelZ => p.trailing_static_wheel_z[index - 1][side],
            Quantity::ContactKwUsed => p.kw_used,
            Quantity::WheelZ => match view {
                View::Vehicle(u) => u.wheel_z_of(index).map_or(0.0, |z| z[side]),
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
                View::Vehicle(u) => u.max_force_of(index)[side],
                View::Sim(sim, s) => extremes(sim).0[side].max(s.contact[side].force),
            },
            Quantity::ContactMinForce => match view {
                View::Vehicle(u) => u.min_force_of(index)[side],
                View::Sim(sim, s) => extremes(sim).1[side].min(s.contact[side].force),
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
            Quantity::CarbodyZ => bodies().map_or(0.0, |b| b.carbody[0]),
            Quantity::CarbodyPitch => bodies().map_or(0.0, |b| b.carbody[1]),
            Quantity::CarbodyRoll => bodies().map_or(0.0, |b| b.carbody[2]),
            Quantity::BolsterZ => body(0),
            Quantity::BolsterRoll => body(1),
            // Above the axle boxes of wheelset `index` (the half-car's side frames pitch).
            Quantity::SideframeZ => frames().map_or(f64::NAN, |f| f.0[side]),
            Quantity::SideframeV => frames().map_or(f64::NAN, |f| f.1[side]),
            Quantity::SideframePitch => bodies().map_or(0.0, |b| b.sideframe_pitch[w][side]),
            // `wheelset.z`, `.roll` of the leading wheelset, `wheelset[2].z`, `.roll`.
            Quantity::WheelsetZ | Quantity::Z => body(4),
            Quantity::WheelsetRoll | Quantity::Roll => body(5),
            Quantity::PrimaryForce => bearing(),
            Quantity::PrimaryMeanForce => mean_bearing(),
            // Observation points: `site_value` above.
            Quantity::SiteRailZ
            | Quantity::SiteRailZMax
            | Quantity::SiteRailZMin
            | Quantity::SiteRailBendingMoment
            | Quantity::SiteRailBendingMomentMax
            | Quantity::SiteRailBendingMomentMin
            | Quantity::SiteRailShearForce
            | Quantity::SiteRailShearForceMax
            | Quantity::SiteRailShearForceMin
            | Quantity::SiteSeatForce
            | Quantity::SiteSeatForceMax
            | Quantity::SiteSeatForceMin
            | Quantity::SiteSeatZ
            | Quantity::SiteSeatZMax
            | Quantity::SiteSeatZMin
            | Quantity::SiteBallastForce
            | Quantity::SiteBallastForceMax
            | Quantity::SiteBallastForceMin
            | Quantity::SiteSeatLifted
            | Quantity::SiteSeatLiftedMax
            | Quantity::SiteBallastLifted
            | Quantity::SiteBallastLiftedMax
            | Quantity::SiteRailAcceleration
            | Quantity::SiteRailAccelerationMax
            | Quantity::SiteRailAccelerationMin
            | Quantity::SiteSeatAcceleration
            | Quantity::SiteSeatAccelerationMax
            | Quantity::SiteSeatAccelerationMin => f64::NAN,
            Quantity::WheelAcceleration => accel(0, side),
            Quantity::WheelAccelerationMax => accel(1, side),
            Quantity::WheelAccelerationMin => accel(2, side),
            Quantity::RailAcceleration => accel(0, 2 + side),
            Quantity::RailAccelerationMax => accel(1, 2 + side),
            Quantity::RailAccelerationMin => accel(2, 2 + side),
            // Supports that lift, over the whole track.
            Quantity::TrackLiftedPads => lifted(|t| t.lifted_supports().0 as f64),
            Quantity::TrackLiftedBallast => lifted(|t| t.lifted_supports().1 as f64),
            Quantity::TrackLiftedLongest => lifted(|t| t.longest_lift().0),
            Quantity::TrackLiftedPosition => match view {
                View::Sim(sim, _) => sim.longest_lift_position(),
                View::Vehicle(_) => f64::NAN,
            },
        }
    }
}

/// The value of an observation point's quantity `q` on `side` at site `index`: what
/// the track feels there now, or its extremes; 0 for a site the model does not have.
/// `None` for the other quantities.
fn site_value(engine: &Engine, q: Quantity, side: usize, index: usize) -> Option<f64> {
    use Quantity::*;
    // [`crate::sim::SITE_QUANTITIES`] order, then now (0), max (1) or min (2).
    let (k, which) = match q {
        SiteRailZ => (0, 0),
        SiteRailZMax => (0, 1),
        SiteRailZMin => (0, 2),
        SiteRailBendingMoment => (1, 0),
        SiteRailBendingMomentMax => (1, 1),
        SiteRailBendingMomentMin => (1, 2),
        SiteRailShearForce => (2, 0),
        SiteRailShearForceMax => (2, 1),
        SiteRailShearForceMin => (2, 2),
        SiteSeatForce => (3, 0),
        SiteSeatForceMax => (3, 1),
        SiteSeatForceMin => (3, 2),
        SiteSeatZ => (4, 0),
        SiteSeatZMax => (4, 1),
        SiteSeatZMin => (4, 2),
        SiteBallastForce => (5, 0),
        SiteBallastForceMax => (5, 1),
        SiteBallastForceMin => (5, 2),
        SiteSeatLifted => (6, 0),
        SiteSeatLiftedMax => (6, 1),
        SiteBallastLifted => (7, 0),
        SiteBallastLiftedMax => (7, 1),
        SiteRailAcceleration => (8, 0),
        SiteRailAccelerationMax => (8, 1),
        SiteRailAccelerationMin => (8, 2),
        SiteSeatAcceleration => (9, 0),
        SiteSeatAccelerationMax => (9, 1),
        SiteSeatAccelerationMin => (9, 2),
        _ => return None,
    };
    let Engine::Sim(sim) = engine else {
        return Some(f64::NAN);
    };
    Some(sim.sites().get(index).map_or(0.0, |site| {
        let values = match which {
            0 => site.now(),
            1 => site.max(),
            _ => site.min(),
        };
        values[side][k]
    }))
}
