//! The coupled simulation: scenarios and the thesis' parameter sets, the monolithic
//! vehicle-track-contact run, and the two co-simulation units.

mod scenario;
mod simulation;
mod vehicle_unit;

pub use scenario::{
    DEFAULT_DT_FRACTION, DEFAULT_NODES_PER_SPAN, Scenario, TrackSpec, VehicleSpec, kmh,
};
pub use simulation::{
    CONTACT_STIFFNESS_MARGIN, Sample, Simulation, TrackState, VehicleState, default_dt,
};
pub use vehicle_unit::{VehicleUnit, VehicleUnitParams};
