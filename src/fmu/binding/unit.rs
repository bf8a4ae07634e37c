//! What the model behind each FMU holds ([`FmuModel`]): its engine ([`Engine`]: the
//! coupled simulation or the vehicle unit), the values published when it is built
//! ([`Published`]), and what it keeps between steps. The FMI 2.0 layer's
//! [`crate::fmu::fmi2::Model`] is implemented on it in `model.rs`.

use super::Kind;
use super::datum::InputDatum;
use super::partner::PartnerWatch;
use super::watch::ContactWatch;
use crate::fmu::vars::TRAILING;
use crate::sim::{Simulation, VehicleUnit};

/// The engine behind an FMU.
#[derive(Debug, Clone)]
pub(super) enum Engine {
    /// Track and contact (a simulation with external wheels), or the whole system.
    Sim(Box<Simulation>),
    /// The vehicle.
    Vehicle(Box<VehicleUnit>),
}

/// The model of one of the FMUs ([`Kind`]) behind the FMI 2.0 layer.
#[derive(Debug, Clone)]
pub struct FmuModel {
    pub(super) kind: Kind,
    pub(super) engine: Engine,
    pub(super) published: Published,
    /// The largest force a physical run reaches (N),
    /// [`force_limit`](crate::limits::force_limit) of the static
    /// loads.
    pub(super) force_limit: f64,
    /// The last communication step (s), for the vehicles' warning of an axle-box
    /// exchange beyond its stable step.
    pub(super) last_step: f64,
    /// Where TrackContact's displacement inputs are measured from (`inputs.datum`).
    pub(super) datum: InputDatum,
    /// What TrackContact sees of its exchange at the contact interface.
    pub(super) watch: ContactWatch,
    /// What TrackContact at the axle boxes knows of its partner (side frames carried).
    pub(super) partner: Option<PartnerWatch>,
    /// `vehicle.sideframe.source = auto` set where TrackContact fits nothing, for the
    /// warning at the end of initialisation.
    pub(super) unused_auto: bool,
    /// The end of the master's last step, in model time (s).
    pub(super) master_end: f64,
    /// A vehicle's first step was checked against its forces at rest.
    pub(super) started: bool,
    /// TrackContact's communication steps off the track's grid (not a whole number of
    /// track steps) at the contact interface: the first is not warned of, for it may be
    /// a run's last, shorter step.
    pub(super) off_grid_steps: u32,
    /// `track.spans` set away from its default on the endless track, which sets its own
    /// length: the value, for the warning at the end of initialisation.
    pub(super) unused_spans: Option<f64>,
}

impl FmuModel {
    /// Which FMU this is.
    pub fn kind(&self) -> Kind {
        self.kind
    }

    /// The coupled simulation of the track-carrying FMUs.
    pub fn simulation(&self) -> Option<&Simulation> {
        match &self.engine {
            Engine::Sim(s) => Some(s),
            Engine::Vehicle(_) => None,
        }
    }
}

/// Values computed when the model is built, published as calculated parameters.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Published {
    /// `static_load.left`/`.right` (N).
    pub static_load: [f64; 2],
    /// `static_wheel_z.left`/`.right` (m).
    pub static_wheel_z: [f64; 2],
    /// `wheelset[k].static_wheel_z.left`/`.right` (m), k = 2, 3, .. (0 for a wheelset
    /// the model does not have).
    pub trailing_static_wheel_z: [[f64; 2]; TRAILING],
    /// `solver.step` (s).
    pub step: f64,
    /// `solver.critical_step` (s).
    pub critical_step: f64,
    /// `contact.kw_used` (N/m/rad).
    pub kw_used: f64,
}

impl Published {
    /// Number of values in [`Published::to_array`].
    pub const LEN: usize = 7 + 2 * TRAILING;

    /// The values in the order FMU states store them.
    pub fn to_array(self) -> [f64; Self::LEN] {
        let [l, r] = self.static_load;
        let [zl, zr] = self.static_wheel_z;
        let mut a = [0.0; Self::LEN];
        a[..7].copy_from_slice(&[l, r, zl, zr, self.step, self.critical_step, self.kw_used]);
        for (pair, z) in a[7..]
            .chunks_exact_mut(2)
            .zip(&self.trailing_static_wheel_z)
        {
            pair.copy_from_slice(z);
        }
        a
    }
}
