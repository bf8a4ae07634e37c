//! The static start: the run begins in the static equilibrium of the whole system,
//! solved directly (the thesis starts the track at rest and waits about 0.2 s), and a
//! contact or track too soft to carry the static wheel load is refused.

use super::simulation::{Simulation, TrackState};
use super::vehicle_state::VehicleState;
use super::wheelset::wheel_loads;
use crate::contact::{ContactLaw, ContactModel, kw_from_hertz};
use crate::error::{Error, Result, non_negative, num, out_of_range};
use crate::limits::{MAX_STATIC_OVERLAP, MAX_STATIC_RAIL_DEFLECTION, within};
use crate::sim::{Scenario, TrackSpec, VehicleSpec};
use crate::wheel::WheelProfile;

/// Passes of the static start's track and vehicle on several wheelsets
/// ([`Simulation::set_static`]); each settles the loads by about the ratio of the
/// suspension's twist stiffness to the track's (a tenth with table 4.4).
pub(crate) const STATIC_ITERATIONS: usize = 50;
/// How close the loads that hold a vehicle on several wheelsets must come to those the
/// track carries, as a fraction of the static wheel load.
pub(crate) const STATIC_LOAD_TOLERANCE: f64 = 1e-10;

/// The static load on each wheel `[left, right]` (N) of the scenario's vehicle: the
/// roll-plane vehicle's weight share (table 4.4: 107.6 kN), the lumped wheel's load, the
/// constant loads or the external vehicle's static loads.
///
/// Errors: a constant or static load below 0 N.
pub(crate) fn static_loads(vehicle: &VehicleSpec) -> Result<[f64; 2]> {
    Ok(match vehicle {
        VehicleSpec::RollPlane(p) => [p.static_wheel_load(); 2],
        VehicleSpec::Carrier(c) => [c.model().static_wheel_load(); 2],
        VehicleSpec::AxleBox { static_load, .. } => {
            non_negative("static_load.left", static_load[0], "N")?;
            non_negative("static_load.right", static_load[1], "N")?;
            *static_load
        }
        VehicleSpec::LumpedWheels(p) => [p.load; 2],
        VehicleSpec::ConstantLoad(p) => {
            non_negative("load.left", p[0], "N")?;
            non_negative("load.right", p[1], "N")?;
            *p
        }
        VehicleSpec::External { static_load } => {
            non_negative("static_load.left", static_load[0], "N")?;
            non_negative("static_load.right", static_load[1], "N")?;
            *static_load
        }
    })
}

/// The scenario's contact law: adaptive with its `K_w`, or with `K_w` calibrated from
/// `C_H` and the static load `static_load[0]` (N) by (2.25, 2.26) when it is 0; or
/// Hertz (1.3).
///
/// Errors: a law its constructor refuses; a contact so soft that the larger static
/// load sinks a perfect wheel more than [`MAX_STATIC_OVERLAP`] into the rail (a wheel on
/// a rail overlaps it by about 0.1 mm), named by `contact.Kw` when given, else
/// `contact.CH`.
pub(crate) fn contact_law(s: &Scenario, static_load: [f64; 2]) -> Result<ContactLaw> {
    let law = match s.contact_model {
        ContactModel::Adaptive => {
            let kw = if s.kw > 0.0 {
                s.kw
            } else {
                kw_from_hertz(s.hertz_coefficient, static_load[0].max(1.0), s.wheel_radius)?
            };
            ContactLaw::adaptive(kw)?
        }
        ContactModel::Hertz => ContactLaw::hertz(s.hertz_coefficient)?,
    };
    let load = static_load[0].max(static_load[1]);
    let perfect = WheelProfile::perfect(s.wheel_radius)?;
    let overlap = law.overlap_for_force(&perfect, 0.0, load);
    if load > 0.0 && !within(overlap, MAX_STATIC_OVERLAP) {
        let (name, value) = match (s.contact_model, s.kw > 0.0) {
            (ContactModel::Adaptive, true) => ("contact.Kw", s.kw),
            _ => ("contact.CH", s.hertz_coefficient),
        };
        return Err(out_of_range(
            name,
            value,
            format!(
                "a contact that carries the static wheel load {} N with an overlap of at \
                 most {MAX_STATIC_OVERLAP} m (this one: {} m; wheel on rail: about 0.1 mm)",
                num(load),
                num(overlap)
            ),
        ));
    }
    Ok(law)
}

impl Simulation {
    /// Static equilibrium of the whole system at the start position: static wheel
    /// loads from the vehicle, track deflection under the loads of every wheelset
    /// (direct solve), overlaps from the inverse contact law, then the vehicle resting
    /// on those wheel heights. A vehicle on several wheelsets is not determinate in
    /// twist (the wagon, the half-car bogie): the loads that hold it on uneven wheel
    /// heights (a flat or a rail defect under a wheel) differ from the equal static
    /// loads, so the track and the vehicle are solved again with the vehicle's loads
    /// until they agree to [`STATIC_LOAD_TOLERANCE`] of the static load.
    ///
    /// Errors: the track's static solve; a suspension that does not hold the bodies;
    /// no agreement within [`STATIC_ITERATIONS`] passes.
    pub(crate) fn set_static(&mut self) -> Result<()> {
        let n = self.wheelsets.len();
        let mut loads = vec![self.static_load; n];
        for _ in 0..STATIC_ITERATIONS {
            let heights = self.rest_on(&loads)?;
            let Some(b) = &mut self.carrier else {
                return Ok(());
            };
            let z: crate::vehicle::Axles =
                std::array::from_fn(|k| heights.get(k).copied().unwrap_or([0.0; 2]));
            let held = b.set_static(&z)?;
            let scale = self.static_load[0].max(self.static_load[1]).max(1.0);
            let change = (0..n)
                .flat_map(|k| (0..2).map(move |i| (k, i)))
                .map(|(k, i)| (held[k][i] - loads[k][i]).abs())
                .fold(0.0, f64::max);
            if change <= STATIC_LOAD_TOLERANCE * scale {
                return Ok(());
            }
            for (l, h) in loads.iter_mut().zip(held) {
                *l = h;
            }
        }
        Err(Error::Unsupported(format!(
            "static equilibrium of the vehicle on the track: the wheel loads did not settle \
             within {STATIC_ITERATIONS} passes (a suspension too stiff in twist for the \
             track under it)"
        )))
    }

    /// The track under the wheel loads `loads[k]` `[left, right]` (N) of every wheelset
    /// at rest, and each wheelset's wheels (its vehicle) at rest on it; returns every
    /// wheelset's wheel heights there (m), for the vehicle on several wheelsets.
    fn rest_on(&mut self, loads: &[[f64; 2]]) -> Result<Vec<[f64; 2]>> {
        let mut heights = Vec::with_capacity(loads.len());
        self.clear_cache();
        let x = self.position() - self.origin;
        let p = self.static_load;
        match &mut self.track {
            TrackState::Discrete(t) => {
                wheel_loads(x, &self.wheelsets, |_| p, &mut self.loads);
                for (pair, l) in self.loads.chunks_exact_mut(2).zip(loads) {
                    pair[0].force = l[0];
                    pair[1].force = l[1];
                }
                t.set_static(&self.loads)?;
            }
            TrackState::Lumped(t) => t.set_static(p),
        }
        for (k, &p) in loads.iter().enumerate() {
            let w = self.wheelsets.get(k).expect("k < len");
            let xw = w.position(x);
            // The rail under each wheel: the nodes' deflection there, lowered by the
            // wheel's load through the rail's local compliance between nodes.
            let zr = match &self.track {
                TrackState::Discrete(t) => {
                    let c = t.shear_compliance(xw);
                    [t.rail_z_at(0, xw) - c * p[0], t.rail_z_at(1, xw) - c * p[1]]
                }
                TrackState::Lumped(t) => t.rail_z(),
            };
            let delta = [0, 1].map(|i| self.law.overlap_for_force(&w.wheels()[i], 0.0, p[i]));
            // The rails' profiles and the wheels' out-of-roundness where they touch.
            let h = self.irregularity(k);
            let zw = [zr[0] - delta[0] + h[0], zr[1] - delta[1] + h[1]];
            // The loads start the first step's contact solve (the force of "the step
            // before"), so a wheelset at rest stays there to rounding.
            let latest = &mut self.wheelsets.get_mut(k).expect("k < len").latest;
            for (c, &f) in latest.contact.iter_mut().zip(&p) {
                c.force = f;
            }
            match &mut self.wheelsets.get_mut(k).expect("k < len").vehicle {
                VehicleState::RollPlane(v) => v.set_static(zw)?,
                VehicleState::AxleBox(link) => link.set_static(zw, p),
                VehicleState::LumpedWheels(v) => v.set_static(zw),
                // The vehicle on several wheelsets rests on `heights` after this.
                VehicleState::ConstantLoad(_) | VehicleState::OnBogie { .. } => {}
                VehicleState::External { wheel_z, .. } => *wheel_z = zw,
            }
            heights.push(zw);
        }
        Ok(heights)
    }

    /// Refuses a discrete track that sinks more than [`MAX_STATIC_RAIL_DEFLECTION`]
    /// under the static wheel loads (table 4.4: 1.3 mm), named by the support softest
    /// against table 4.4's (pads 140 MN/m, ballast 40 MN/m); the message gives all that
    /// carry the load.
    pub(crate) fn check_static_sag(&self) -> Result<()> {
        let (TrackSpec::Discrete(p), TrackState::Discrete(_)) = (&self.scenario.track, &self.track)
        else {
            return Ok(());
        };
        let z = self.rail_z();
        let sag = z[0].abs().max(z[1].abs());
        if within(sag, MAX_STATIC_RAIL_DEFLECTION) {
            return Ok(());
        }
        let load = self.static_load[0].max(self.static_load[1]);
        // Hanging sleepers under a wheel (breaker, issue 29: their gap was blamed on the
        // pads): named by their gap.
        let x = self.scenario.start_position;
        let behind = (self.scenario.trailing.iter()).fold(0.0_f64, |d, t| d.max(t.offset));
        if let Some(v) = self.scenario.voids.filter(|v| v.gap > 0.0) {
            let a = p.sleeper_spacing;
            let (from, to) = (v.position - a, v.position + v.sleepers as f64 * a);
            if x >= from && x - behind <= to {
                return Err(out_of_range(
                    "track.void.gap",
                    v.gap,
                    format!(
                        "a gap under the hanging sleepers (track.void.sleepers = {} from \
                         track.void.position = {} m, under the wheels at the start) that \
                         leaves the rail's static deflection under the wheel load {} N \
                         within {MAX_STATIC_RAIL_DEFLECTION} m (this one: {} m); or the \
                         wheels started off the voided sleepers",
                        v.sleepers,
                        num(v.position),
                        num(load),
                        num(sag)
                    ),
                ));
            }
        }
        let (name, value) = if p.ballast_stiffness / 40e6 < p.pad_stiffness / 140e6 {
            ("track.ballast.stiffness", p.ballast_stiffness)
        } else {
            ("track.pad.stiffness", p.pad_stiffness)
        };
        Err(out_of_range(
            name,
            value,
            format!(
                "a track that carries the static wheel load {} N with a rail deflection \
                 of at most {MAX_STATIC_RAIL_DEFLECTION} m (this one: {} m with \
                 track.pad.stiffness = {} N/m, track.ballast.stiffness = {} N/m, \
                 track.rail.EI = {} N m^2, track.rail.kAG = {} N, track.sleeper_spacing \
                 = {} m; table 4.4: 1.3 mm)",
                num(load),
                num(sag),
                num(p.pad_stiffness),
                num(p.ballast_stiffness),
                num(p.rail.ei),
                num(p.rail.kag),
                num(p.sleeper_spacing)
            ),
        ))
    }
}
