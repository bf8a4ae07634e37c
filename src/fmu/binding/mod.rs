//! This project's five FMUs over the FMI 2.0 layer: which FMU an instance is
//! ([`Kind`]), the engine's parameters from its variables, its outputs, and the
//! [`FmuModel`] that implements [`crate::fmu::fmi2::Model`].

mod datum;
mod derivatives;
mod inputs;
mod outputs;
mod parameters;
mod unit;
mod warnings;
mod watch;

pub use parameters::{scenario, track_params, vehicle_params, vehicle_unit_params};
pub use unit::{END_ZONE_SPANS, FmuModel};

use crate::fmu::vars::{self, FmuTable};

/// Which of the five FMUs an instance is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Track and contact, wheels as inputs.
    TrackContact,
    /// Roll-plane vehicle, contact forces as inputs.
    RollPlaneVehicle,
    /// The whole model.
    CoupledSystem,
    /// The half-car bogie, contact (or primary) forces of two wheelsets as inputs.
    HalfCarBogie,
    /// The four-axle wagon, contact (or primary) forces of four wheelsets as inputs.
    Wagon,
}

impl Kind {
    /// The five FMUs.
    pub const ALL: [Kind; 5] = [
        Kind::TrackContact,
        Kind::RollPlaneVehicle,
        Kind::CoupledSystem,
        Kind::HalfCarBogie,
        Kind::Wagon,
    ];

    /// The FMU with this GUID.
    pub fn from_guid(guid: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.table().guid == guid)
    }

    /// Variable table of this FMU.
    pub fn table(self) -> &'static FmuTable {
        match self {
            Kind::TrackContact => &vars::TRACK_CONTACT,
            Kind::RollPlaneVehicle => &vars::ROLL_PLANE_VEHICLE,
            Kind::CoupledSystem => &vars::COUPLED_SYSTEM,
            Kind::HalfCarBogie => &vars::HALF_CAR_BOGIE,
            Kind::Wagon => &vars::WAGON,
        }
    }
}

impl crate::fmu::Instance {
    /// Which FMU this instance is.
    pub fn kind(&self) -> Kind {
        Kind::from_guid(self.table().guid).expect("an instance of one of the five FMUs")
    }

    /// The scenario the variables of a track-carrying FMU describe.
    pub fn scenario(&self) -> crate::sim::Scenario {
        scenario(self.kind(), self.values())
    }
}
