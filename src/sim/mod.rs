//! The coupled simulation: scenarios and the thesis' parameter sets, the monolithic
//! vehicle-track-contact run with its list of wheelsets, and the two co-simulation
//! units, which share one clock, one way of counting steps and one record of force
//! extremes.

mod accelerations;
mod build;
mod checks;
mod clock;
mod external;
mod health;
mod inputs;
mod motion;
mod presets;
mod sampling;
mod scenario;
mod simulation;
mod sites;
mod state;
mod static_start;
#[cfg(test)]
mod tests;
mod travel;
mod unit_state;
mod unit_step;
mod vehicle_state;
mod vehicle_unit;
mod wheelset;

pub use accelerations::Accelerations;
pub use build::{CONTACT_STIFFNESS_MARGIN, default_dt};
pub use clock::StepPlan;
pub use inputs::InputRates;
pub use scenario::{
    DEFAULT_DT_FRACTION, DEFAULT_NODES_PER_SPAN, RandomIrregularities, Roughness, Scenario,
    SideFrameSpec, TrackSpec, TrackWindow, TrailingWheelset, VehicleSpec, VoidedSleepers, kmh,
};
pub use simulation::{Simulation, TrackState};
pub use sites::{SITE_QUANTITIES, Site, SiteValues};
pub use vehicle_state::VehicleState;
pub use vehicle_unit::{VehicleUnit, VehicleUnitParams};
pub use wheelset::{Sample, Wheelset, Wheelsets};
