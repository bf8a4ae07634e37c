//! This project's FMUs over the FMI 2.0 layer: which FMU an instance is
//! ([`Kind`]), the engine's parameters from its variables, its outputs, and the
//! [`FmuModel`] that implements [`crate::fmu::fmi2::Model`].

mod datum;
mod derivatives;
mod inputs;
mod model;
mod outputs;
mod parameters;
mod partner;
mod unit;
mod warnings;
mod watch;

pub use parameters::{scenario, track_params, vehicle_params, vehicle_unit_params};
pub use partner::{
    COPY_TOLERANCE, FIT_STEP_RADIANS, JACOBI_ACCURATE, JUMP_TOLERANCE, MASS_TOLERANCE,
};
pub use unit::FmuModel;
pub use warnings::END_ZONE_SPANS;

use crate::fmu::vars::{self, FmuTable};
use crate::vehicle::{VEHICLE_KINDS, VehicleKind};

/// Which FMU an instance is: TrackContact, CoupledSystem, or the own FMU of a kind of
/// vehicle in the registry ([`crate::vehicle::VEHICLE_KINDS`], by its index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Track and contact, wheels (or side frames) as inputs.
    TrackContact,
    /// The whole model.
    CoupledSystem,
    /// A vehicle, contact (or primary) forces of its wheelsets as inputs:
    /// `VEHICLE_KINDS[i]`.
    Vehicle(usize),
}

impl Kind {
    /// The roll-plane vehicle's FMU, RollPlaneVehicle (the registry's first kind).
    pub const ROLL_PLANE_VEHICLE: Kind = Kind::Vehicle(0);

    /// Every FMU: TrackContact, CoupledSystem, then each kind of vehicle's.
    pub const ALL: [Kind; 2 + VEHICLE_KINDS.len()] = {
        let mut all = [Kind::TrackContact; 2 + VEHICLE_KINDS.len()];
        all[1] = Kind::CoupledSystem;
        let mut i = 0;
        while i < VEHICLE_KINDS.len() {
            all[2 + i] = Kind::Vehicle(i);
            i += 1;
        }
        all
    };

    /// The FMU with this GUID.
    pub fn from_guid(guid: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.table().guid == guid)
    }

    /// The FMU with this model identifier.
    pub fn from_model_identifier(id: &str) -> Option<Kind> {
        Kind::ALL
            .into_iter()
            .find(|k| k.table().model_identifier == id)
    }

    /// The kind of vehicle whose own FMU this is.
    pub fn vehicle(self) -> Option<&'static VehicleKind> {
        match self {
            Kind::Vehicle(i) => Some(&VEHICLE_KINDS[i]),
            _ => None,
        }
    }

    /// Variable table of this FMU.
    pub fn table(self) -> &'static FmuTable {
        match self {
            Kind::TrackContact => &vars::TRACK_CONTACT,
            Kind::CoupledSystem => &vars::COUPLED_SYSTEM,
            // A test checks every kind's FMU is in the table.
            Kind::Vehicle(i) => vars::fmu_table(VEHICLE_KINDS[i].fmu)
                .expect("every kind of vehicle has its FMU in the table"),
        }
    }
}

impl Kind {
    /// The FMI 3.0 table of this FMU.
    pub fn table3(self) -> &'static vars::Fmu3Table {
        let t = self.table();
        vars::FMI3_FMUS
            .into_iter()
            .find(|x| std::ptr::eq(x.fmi2, t))
            .expect("every FMU has its FMI 3.0 table")
    }
}

impl crate::fmu::Instance {
    /// Which FMU this instance is.
    pub fn kind(&self) -> Kind {
        Kind::from_guid(self.table().guid).expect("an instance of one of the FMUs")
    }

    /// The scenario the variables of a track-carrying FMU describe.
    pub fn scenario(&self) -> crate::sim::Scenario {
        scenario(self.kind(), self.values())
    }
}
