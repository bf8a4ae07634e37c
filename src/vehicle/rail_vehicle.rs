//! A vehicle on several wheelsets behind one interface: [`CarrierModel`], its
//! parameters (how many wheelsets, where, its step limits and static load);
//! [`RailVehicle`], the whole vehicle in time under the contact forces of its wheels
//! (the half-car bogie, the wagon); and [`SprungVehicle`], the same vehicle above its
//! primary suspension under the primary forces at its axle boxes. The assembly
//! (`crate::sim`) builds and steps them without knowing which vehicle it is: a new kind
//! implements these traits in its own file, and is named in one match arm of the
//! scenario's vehicle (`crate::sim::VehicleSpec::carrier`) and one of the vehicle
//! unit's (`crate::sim::UnitModel::carrier`).
//!
//! Wheelsets are numbered from the leading one (0); a value of each wheelset is
//! `[left, right]`, in an [`Axles`] of which the first [`RailVehicle::wheelsets`] are
//! used.

use super::ExchangeLimits;
use crate::error::Result;

/// Most wheelsets one vehicle rests on (the wagon's four).
pub const MAX_AXLES: usize = 4;

/// A value `[left, right]` of each wheelset, the leading one first; the entries past
/// the vehicle's wheelsets are unused (zero).
pub type Axles = [[f64; 2]; MAX_AXLES];

/// The motion of a vehicle's bodies, as its outputs give it (m, rad; roll positive
/// raising the right side, pitch raising the front).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Bodies {
    /// The car body's bounce, pitch and roll at its centre (the wagon; zero for a bogie
    /// alone, whose bolster carries its share of the car body).
    pub carbody: [f64; 3],
    /// `[bounce, roll]` of the bolster of the bogie over each wheelset.
    pub bolster: Axles,
    /// `[left, right]` pitch of the side frames over each wheelset.
    pub sideframe_pitch: Axles,
    /// `[bounce, roll]` of each wheelset.
    pub wheelset: Axles,
}

/// The parameters of a vehicle on several wheelsets: what the assembly needs to place
/// its wheelsets, check its step and build it in time.
pub trait CarrierModel {
    /// Number of wheelsets.
    fn wheelsets(&self) -> usize;
    /// Where the wheelsets behind the leading one are (m behind it), each with what it
    /// is in words: the half-car's wheelbase `a`; the wagon's `a`, `d`, `d + a` (`d`
    /// its bogie distance).
    fn offsets(&self) -> Vec<(f64, &'static str)>;
    /// The vehicle in words, with the value of `vehicle.model` that selects it.
    fn name(&self) -> &'static str;
    /// Checks every parameter, naming the variables.
    ///
    /// Errors: a parameter outside its physical range.
    fn validate(&self) -> Result<()>;
    /// Critical step of central differences on the fastest mode (s).
    fn critical_time_step(&self) -> f64;
    /// Default step for the vehicle on its own (s): 50 steps per shortest period.
    fn default_dt(&self) -> f64;
    /// Static load on each wheel (N).
    fn static_wheel_load(&self) -> f64;
    /// The suspension's stiffnesses, each by its variable's name (N/m), for the
    /// refusal of a suspension too soft to carry the vehicle.
    fn stiffnesses(&self) -> Vec<(&'static str, f64)>;
    /// The whole vehicle at rest at zero, stepped with `dt` (s).
    ///
    /// Errors: a parameter refused, `dt` not positive or above the critical step.
    fn whole(&self, dt: f64) -> Result<Box<dyn RailVehicle>>;
    /// The vehicle above its primary suspension, stepped with `dt` (s).
    ///
    /// Errors: as [`CarrierModel::whole`].
    fn sprung(&self, dt: f64) -> Result<Box<dyn SprungVehicle>>;
}

/// A whole vehicle on several wheelsets, driven by the contact forces of its wheels.
pub trait RailVehicle: std::fmt::Debug + Send + Sync {
    /// Number of wheelsets (2 for the half-car bogie, 4 for the wagon).
    fn wheelsets(&self) -> usize;
    /// Step (s).
    fn dt(&self) -> f64;
    /// Critical step of central differences on the fastest mode (s).
    fn critical_time_step(&self) -> f64;
    /// Wheel-centre displacements of every wheelset (m).
    fn wheel_z(&self) -> Axles;
    /// Wheel-centre velocities of every wheelset (m/s), backward differences over the
    /// last step.
    fn wheel_velocities(&self) -> Axles;
    /// Primary suspension (bearing) forces at every axle box (N), positive pressing the
    /// wheelset down.
    fn bearing_forces(&self) -> Axles;
    /// The side frames' displacements and velocities above every wheelset's axle boxes
    /// (m, m/s; the side frames' pitch included).
    fn side_frames(&self) -> (Axles, Axles);
    /// Displacements of every degree of freedom at `t_j` (m, rad), in the model's order.
    fn displacements(&self) -> &[f64];
    /// The bodies' motion at `t_j`.
    fn bodies(&self) -> Bodies;
    /// Advances one step from `t_j` under the contact forces `p` (N, up on the wheels).
    fn step(&mut self, p: &Axles);
    /// Static equilibrium with the wheels held at `z` (m); returns the contact forces
    /// that hold it (N).
    ///
    /// Errors: a suspension that does not hold the bodies.
    fn set_static(&mut self, z: &Axles) -> Result<Axles>;
    /// Changes the step to `dt` (s), keeping the displacements and velocities.
    ///
    /// Errors: `dt` not positive or above the critical step.
    fn change_dt(&mut self, dt: f64) -> Result<()>;
    /// `[dt, d, d_prev]`.
    fn state_vector(&self) -> Vec<f64>;
    /// Restores [`RailVehicle::state_vector`].
    ///
    /// Errors: a wrong length, a step the vehicle refuses.
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()>;
    /// The first value beyond the health bounds: its name, value and limit.
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)>;
    /// A copy behind a new box.
    fn clone_box(&self) -> Box<dyn RailVehicle>;
}

impl Clone for Box<dyn RailVehicle> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}

/// A vehicle above its primary suspension, driven by the primary forces at its axle
/// boxes; its partner carries the wheelsets ([`super::PrimaryLink`]).
pub trait SprungVehicle: std::fmt::Debug + Send + Sync {
    /// Number of wheelsets under it.
    fn wheelsets(&self) -> usize;
    /// Critical step of central differences on the whole vehicle's fastest mode (s).
    fn critical_time_step(&self) -> f64;
    /// The side frames' displacements and velocities above every wheelset's axle boxes
    /// (m, m/s).
    fn side_frames(&self) -> (Axles, Axles);
    /// The bodies' motion, the wheelsets at rest where
    /// [`SprungVehicle::set_static`] put them.
    fn bodies(&self) -> Bodies;
    /// Advances one step under the primary forces `f` (N, pressing the axle boxes down)
    /// held over it.
    fn step(&mut self, f: &Axles);
    /// Static equilibrium with the axle boxes (wheels) at `z` (m); returns the static
    /// primary forces (N).
    ///
    /// Errors: a suspension that does not hold the bodies.
    fn set_static(&mut self, z: &Axles) -> Result<Axles>;
    /// As [`RailVehicle::change_dt`].
    fn change_dt(&mut self, dt: f64) -> Result<()>;
    /// `[dt, d, d_prev]`.
    fn state_vector(&self) -> Vec<f64>;
    /// Restores [`SprungVehicle::state_vector`].
    fn set_state_vector(&mut self, v: &[f64]) -> Result<()>;
    /// A body beyond the health bounds.
    fn beyond_bounds(&self) -> Option<(&'static str, f64, f64)>;
    /// The largest stable communication steps of the exchange at rest on `z` (m), with
    /// substeps of at most `base` (s) and contact springs of `support` (N/m per wheel)
    /// ([`ExchangeLimits`]).
    ///
    /// Errors: a parameter [`super::PrimaryLink::new`] refuses.
    fn exchange_limits(&self, z: &Axles, base: f64, support: f64) -> Result<ExchangeLimits>;
    /// A copy behind a new box.
    fn clone_box(&self) -> Box<dyn SprungVehicle>;
}

impl Clone for Box<dyn SprungVehicle> {
    fn clone(&self) -> Self {
        self.clone_box()
    }
}
