//! What the wheels and the rail under them are at the current time: the samples of
//! every wheelset (wheel and rail displacements, the contact states), computed once per
//! instant and cached, with the rail's local compliance and the irregularities there.

use super::simulation::{Simulation, TrackState, at_level};
use super::vehicle_state::VehicleState;
use super::wheelset::{Sample, Wheelset, contact_states};
use crate::vehicle::RailVehicle;

impl Simulation {
    /// Forgets the cached samples: the time or the inputs changed.
    #[inline]
    pub(super) fn clear_cache(&self) {
        self.wheelsets.clear_cache();
    }

    /// Wheel-centre displacements `[left, right]` (m) of the leading wheelset.
    pub fn wheel_z(&self) -> [f64; 2] {
        self.wheel_z_of(self.lead())
    }

    /// Wheel-centre displacements `[left, right]` (m) of wheelset `w` (on the rails
    /// under constant loads).
    #[inline(always)]
    pub(super) fn wheel_z_of(&self, w: &Wheelset) -> [f64; 2] {
        if let VehicleState::External { wheel_z, rates, .. } = &w.vehicle
            && rates.moves()
        {
            return rates.wheel_z_at(*wheel_z, self.time());
        }
        if let (VehicleState::OnBogie { axle }, Some(b)) = (&w.vehicle, &self.carrier) {
            return b.wheel_z()[*axle];
        }
        match w.vehicle.wheel_z() {
            Some(z) => z,
            None => self.rail_z_under(w.position(self.position()) - self.origin),
        }
    }

    /// The vehicle that moves wheelset `k`'s wheels, with the wheelset's index among
    /// its own: the vehicle on several wheelsets ([`Simulation::carrier`]), or the
    /// wheelset's own roll-plane vehicle; `None` for loads, lumped or external wheels,
    /// the wheelsets the axle-box interface carries and a wheelset the simulation does
    /// not have.
    pub fn vehicle_of(&self, k: usize) -> Option<(&dyn RailVehicle, usize)> {
        match &self.wheelsets.get(k)?.vehicle {
            VehicleState::RollPlane(v) => Some((v, 0)),
            VehicleState::OnBogie { axle } => self.carrier.as_deref().map(|b| (b, *axle)),
            _ => None,
        }
    }

    /// Rail displacements under the wheels of the leading wheelset (m) (3.23).
    pub fn rail_z(&self) -> [f64; 2] {
        self.rail_z_under(self.lead().position(self.position()) - self.origin)
    }

    /// Rail displacements (m) under wheels at track position `x` (m).
    #[inline(always)]
    pub(super) fn rail_z_under(&self, x: f64) -> [f64; 2] {
        match &self.track {
            TrackState::Discrete(t) => t.rail_z_pair(x),
            TrackState::Lumped(t) => t.rail_z(),
        }
    }

    /// Everything at the current time for the leading wheelset, contact forces
    /// included.
    pub fn sample(&self) -> Sample {
        self.sample_of_wheelset(self.lead())
    }

    /// Everything at the current time for wheelset `k` (0 the leading one), contact
    /// forces included; `None` for a wheelset the simulation does not have.
    pub fn sample_of(&self, k: usize) -> Option<Sample> {
        Some(self.sample_of_wheelset(self.wheelsets.get(k)?))
    }

    /// Wheelset `k`'s sample at the current time if it was already computed (a master
    /// read the outputs since the state last changed), without computing it.
    pub fn computed_sample_of(&self, k: usize) -> Option<Sample> {
        self.wheelsets.get(k)?.cached.get()
    }

    pub(super) fn sample_of_wheelset(&self, w: &Wheelset) -> Sample {
        if let Some(s) = w.cached.get() {
            return s;
        }
        // `compute_sample` compiled for the SIMD level, as in `step` (a co-simulation
        // master reads the outputs before it steps, so this is where its contact
        // forces are computed).
        let s = at_level(
            self.simd,
            #[inline(always)]
            || self.compute_sample(w),
        );
        w.cached.set(Some(s));
        s
    }

    /// Builds wheelset `k`'s (0 the leading one) sample at the current time in place in
    /// its `latest`, whose contact states (the step before's) start the contact's
    /// solve: the same bits as [`Simulation::compute_sample`], without a sample built in
    /// a temporary and copied at once (the copy's wide loads waited on the narrow stores
    /// that had just built it). `k` is one the simulation has.
    #[inline(always)]
    pub(super) fn sample_in_place(&mut self, k: usize) {
        let w = &self.wheelsets.get(k).expect("a wheelset of the simulation");
        let head = self.sample_head(w);
        let compliance = self.compliance_under(head.1 - self.origin);
        let shift = self.irregularity_of(w, head.1, head.2);
        let w = self
            .wheelsets
            .get_mut(k)
            .expect("a wheelset of the simulation");
        let (wheels, vehicle, s) = w.parts_mut();
        (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = head;
        contact_states(vehicle, &self.law, wheels, compliance, shift, s);
    }

    #[inline(always)]
    pub(super) fn compute_sample(&self, w: &Wheelset) -> Sample {
        // The step before's contact forces start the contact's solve, as in `step`
        // (the same bits whether a master reads the outputs before stepping or not).
        let mut s = Sample {
            contact: w.latest().contact,
            ..Sample::default()
        };
        (s.time, s.position, s.rotation, s.wheel_z, s.rail_z) = self.sample_head(w);
        let compliance = self.compliance_under(s.position - self.origin);
        let shift = self.irregularity_of(w, s.position, s.rotation);
        contact_states(&w.vehicle, &self.law, w.wheels(), compliance, shift, &mut s);
        s
    }

    /// What the rails' profiles and the wheels' out-of-roundness add to the overlaps
    /// `[left, right]` (m) of wheelset `w` at line position `x` (m) and axle rotation
    /// `gamma` (rad): the rail's height there plus the wheel's radius deviation at the
    /// angle that touches the rail (`docs/MODEL.md`, "Measured irregularities");
    /// `None` when there are none.
    #[inline(always)]
    pub(super) fn irregularity_of(&self, w: &Wheelset, x: f64, gamma: f64) -> Option<[f64; 2]> {
        if !self.irregular {
            return None;
        }
        Some([0, 1].map(|i| self.rails[i].at(x).0 + w.radius_deviation(i, gamma)))
    }

    /// The overlap's change `[left, right]` (m) of wheelset `k` (0 the leading one)
    /// from the rails' profiles and its wheels' out-of-roundness now; zeros when there
    /// are none.
    pub fn irregularity(&self, k: usize) -> [f64; 2] {
        self.wheelsets.get(k).map_or([0.0; 2], |w| {
            self.irregularity_of(w, w.position(self.position()), self.rotation_of(w))
                .unwrap_or([0.0; 2])
        })
    }

    /// The rail's local compliance (m/N) under wheels at track position `x` (m):
    /// [`crate::track::Track::shear_compliance`]; 0 on the lumped track.
    #[inline(always)]
    pub(super) fn compliance_under(&self, x: f64) -> f64 {
        match &self.track {
            TrackState::Discrete(t) => t.shear_compliance(x),
            TrackState::Lumped(_) => 0.0,
        }
    }

    /// The rail's local compliance (m/N) under wheelset `k` (0 the leading one) now, in
    /// series with its contacts ([`crate::track::Track::shear_compliance`]); 0 on the
    /// lumped track and for a wheelset the simulation does not have.
    pub fn contact_compliance_of(&self, k: usize) -> f64 {
        match self.wheelsets.get(k) {
            Some(w) => self.compliance_under(w.position(self.position()) - self.origin),
            None => 0.0,
        }
    }

    /// Everything of wheelset `w`'s sample at the current time but the contact states:
    /// time (s), position (m, line coordinates), axle rotation (rad), wheel and rail
    /// displacements (m).
    #[inline(always)]
    pub(super) fn sample_head(&self, w: &Wheelset) -> (f64, f64, f64, [f64; 2], [f64; 2]) {
        let time = self.time();
        let m = &self.motion;
        let x = m.x_ref + m.speed * (time - m.t_ref);
        let position = w.position(x);
        let (rotation, wheel_z) = (self.rotation_of(w), self.wheel_z_of(w));
        (
            time,
            position,
            rotation,
            wheel_z,
            self.rail_z_under(position - self.origin),
        )
    }
}
