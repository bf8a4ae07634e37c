//! The inputs of a simulation whose wheels are moved from outside
//! ([`VehicleSpec::External`](super::VehicleSpec::External)): the track-carrying co-simulation unit takes the wheel
//! heights and the axle angle from the vehicle unit.

use super::simulation::{Simulation, VehicleState};
use crate::error::{Error, Result, finite, out_of_range};
use crate::limits::{DISPLACEMENT_LIMIT, within};

impl Simulation {
    /// Sets the wheel inputs of a simulation with [`VehicleSpec::External`](super::VehicleSpec::External) wheels:
    /// wheel-centre displacements `[left, right]` (m) and the axle rotation angle (rad)
    /// at the current time ([`Simulation::set_wheel_z`], [`Simulation::set_rotation`]).
    pub fn set_wheel_inputs(&mut self, z: [f64; 2], gamma: f64) -> Result<()> {
        self.set_wheel_z(z)?;
        self.set_rotation(gamma)
    }

    /// Sets the wheel-centre displacements `[left, right]` (m) of a simulation with
    /// [`VehicleSpec::External`](super::VehicleSpec::External) wheels. The axle rotation is not touched: it keeps
    /// turning at `V / R_w` from the last angle given to [`Simulation::set_rotation`].
    /// Refused for any other vehicle, and outside `|z| <=`
    /// [`crate::limits::DISPLACEMENT_LIMIT`].
    pub fn set_wheel_z(&mut self, z: [f64; 2]) -> Result<()> {
        for (name, x) in [("wheel.left.z", z[0]), ("wheel.right.z", z[1])] {
            if !within(x, DISPLACEMENT_LIMIT) {
                return Err(out_of_range(
                    name,
                    x,
                    format!(
                        "-{DISPLACEMENT_LIMIT} m <= {name} <= {DISPLACEMENT_LIMIT} m (static \
                         wheel heights are about -1.4 mm)"
                    ),
                ));
            }
        }
        match &mut self.vehicle {
            VehicleState::External { wheel_z, .. } => {
                *wheel_z = z;
                self.clear_cache();
                Ok(())
            }
            _ => Err(Self::not_external()),
        }
    }

    /// Sets the axle rotation angle `gamma` (rad) at the current time of a simulation
    /// with [`VehicleSpec::External`](super::VehicleSpec::External) wheels; from now on the axle turns at `V / R_w`
    /// from it (2.17). Refused for any other vehicle and for a non-finite angle.
    pub fn set_rotation(&mut self, gamma: f64) -> Result<()> {
        finite("wheel.rotation", gamma, "rad")?;
        let now = self.time();
        match &mut self.vehicle {
            VehicleState::External {
                rotation, since, ..
            } => {
                *rotation = gamma;
                *since = now;
                self.clear_cache();
                Ok(())
            }
            _ => Err(Self::not_external()),
        }
    }

    fn not_external() -> Error {
        Error::Unsupported("wheel inputs for a simulation that has its own vehicle".into())
    }
}
