//! What moves the wheels of a wheelset, behind one interface: the roll-plane vehicle,
//! the lumped wheels, constant loads, the wheelset on its primary suspension under an
//! outside bogie, a wheelset of a vehicle on several wheelsets, or wheels moved from
//! outside.

use super::inputs::InputRates;
use crate::vehicle::{LumpedWheels, RollPlaneVehicle};

/// Vehicle state of a simulation.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone)]
pub enum VehicleState {
    /// Six-DOF roll-plane vehicle.
    RollPlane(RollPlaneVehicle),
    /// Chapter-2 lumped wheels.
    LumpedWheels(LumpedWheels),
    /// Constant loads (N), no contact.
    ConstantLoad([f64; 2]),
    /// The wheelset of the roll-plane vehicle with its primary suspension, the bogie
    /// above it outside ([`crate::vehicle::PrimaryLink`]): the side frames' motion is
    /// the input, the primary forces the output.
    AxleBox(crate::vehicle::PrimaryLink),
    /// Wheelset `axle` (0 the leading one) of the vehicle on several wheelsets
    /// ([`super::Simulation::carrier`]), which moves its wheels: their displacements
    /// are the vehicle's, read from it (no copy).
    OnBogie {
        /// The wheelset's index among the vehicle's.
        axle: usize,
    },
    /// Wheels moved from outside.
    External {
        /// Wheel-centre displacements `[left, right]` (m), inputs.
        wheel_z: [f64; 2],
        /// Axle rotation angle (rad) given at `since`.
        rotation: f64,
        /// Time (s) at which `rotation` was given; between inputs the axle turns at
        /// `V / R_w`.
        since: f64,
        /// The inputs' time derivatives, when the master gives them (FMI's
        /// `fmi2SetRealInputDerivatives`); zero: the inputs are held.
        rates: InputRates,
    },
}

impl VehicleState {
    /// Wheel-centre displacements `[left, right]` (m) of the wheelset's own vehicle;
    /// `None` for constant loads (the wheels then ride on the rail) and for a wheelset
    /// of a vehicle on several wheelsets, whose wheels that vehicle gives
    /// ([`super::Simulation`]'s `wheel_z_of`).
    #[inline(always)]
    pub(super) fn wheel_z(&self) -> Option<[f64; 2]> {
        match self {
            VehicleState::RollPlane(v) => Some(v.wheel_z()),
            VehicleState::LumpedWheels(v) => Some(v.wheel_z()),
            VehicleState::ConstantLoad(_) | VehicleState::OnBogie { .. } => None,
            VehicleState::External { wheel_z, .. } => Some(*wheel_z),
            VehicleState::AxleBox(link) => Some(link.body().wheel_z()),
        }
    }

    /// Advances the vehicle one step under the contact forces `p` `[left, right]` (N).
    #[inline(always)]
    pub(super) fn step(&mut self, p: [f64; 2]) {
        match self {
            VehicleState::RollPlane(v) => v.step(p),
            VehicleState::LumpedWheels(v) => v.step(p),
            VehicleState::AxleBox(link) => link.step(p),
            VehicleState::ConstantLoad(_)
            | VehicleState::External { .. }
            | VehicleState::OnBogie { .. } => {}
        }
    }
}
