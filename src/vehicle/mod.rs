//! Vehicle models and the alternative loads on the track.
//!
//! * [`RollPlaneVehicle`]: the thesis' six-degree-of-freedom half-bogie roll-plane model
//!   (3.1-3.3), `d = {z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`, with gravity on every body,
//!   advanced by central differences with damping as in (3.25).
//! * [`LumpedWheels`]: the chapter-2 lumped model's wheel (2.27, first equation), one
//!   per side: half-wheelset mass on the series primary/secondary suspension, loaded by
//!   the wheel load `W`.
//! * [`LumpedTrack`]: the chapter-2 lumped track mass (2.27, second equation), one per rail.
//!
//! * [`HalfCarParams`]: the thesis' half-car bogie (figure 1.10), ten degrees of
//!   freedom, its matrices, natural frequencies and static state; [`HalfCarBogie`]
//!   and [`SprungHalfCar`] advance it in time, whole or above its primary suspension.
//! * [`WagonParams`]: a four-axle freight wagon, the car body in bounce, pitch and roll
//!   on two half-car bogies, nineteen degrees of freedom, its matrices, natural
//!   frequencies and static state; [`Wagon`] and [`SprungWagon`] advance it in time,
//!   whole or above its primary suspensions.
//! * [`RailVehicle`] and [`SprungVehicle`]: a vehicle on several wheelsets behind one
//!   interface (the half-car bogie, the wagon), whole or above its primary suspension.
//! * [`WheelsetBody`] and [`SprungBogie`]: the roll-plane vehicle cut at its axle boxes
//!   (the primary suspension), for a bogie model that couples at its own step.
//!
//! Roll angles are positive when they raise the right side (docs/MODEL.md).

mod axle_box;
mod exchange;
mod half_car;
mod half_car_bogie;
mod linear_body;
mod lumped;
mod partner_fit;
mod rail_vehicle;
mod registry;
mod roll_plane;
#[cfg(test)]
mod tests;
mod two_axle;
mod wagon;
mod wagon_motion;
#[cfg(test)]
mod wagon_tests;

pub use axle_box::{PrimaryLink, SideFrameInertia, WheelsetBody};
pub use exchange::{CONTACT_STIFFNESS, ExchangeLimits, carried_limits};
pub use half_car::{
    HALF_CAR_DOF_NAMES, HALF_CAR_DOFS, HalfCarMatrix, HalfCarParams, HalfCarVector,
};
pub use half_car_bogie::{HalfCarBogie, Quad, SprungHalfCar};
pub use linear_body::{LinearBody, LinearVehicle, SprungLinearBody};
pub use lumped::{LumpedTrack, LumpedTrackParams, LumpedWheelParams, LumpedWheels};
pub use partner_fit::{HeldForce, PartnerEstimate, PartnerFit};
pub use rail_vehicle::{Axles, Bodies, CarrierModel, MAX_AXLES, RailVehicle, SprungVehicle};
pub use registry::{
    AboveAxleBoxes, CarrierSpec, VEHICLE_KINDS, Values, VehicleKind, kind_of_fmu, kind_of_item,
    roll_plane,
};
pub use roll_plane::{BODY_DOFS, RollPlaneParams, RollPlaneVehicle, SprungBogie};
pub use two_axle::{
    SprungTwoAxleWagon, TWO_AXLE_DOFS, TwoAxleParams, TwoAxleWagon, WHEELBASE_RANGE,
};
pub use wagon::{MIN_BOGIE_GAP, WAGON_DOFS, WagonMatrix, WagonParams, WagonVector, bogie_start};
pub use wagon_motion::{Octet, SprungWagon, WAGON_DOF_NAMES, Wagon};
