//! How the FMUs take their inputs: TrackContact's wheel heights and axle rotations
//! (contact interface) or side frames (axle-box interface), the vehicles' contact or
//! primary forces, the speed; and the value an input never set stands for (at rest).

use super::Kind;
use super::unit::{Engine, FmuModel};
use crate::error::Error;
use crate::fmu::vars::{
    AXLE_BOX_FORCE_VRS, CONTACT_FORCE_VRS, TRAILING_FRAME_VRS, TRAILING_INPUT_VRS, vr,
};
use crate::sim::{Sample, Simulation, VehicleState};

/// TrackContact's side-frame inputs of the leading wheelset (`interface = axle_box`):
/// left and right displacement, left and right velocity.
pub(super) const FRAME_VRS: [u32; 4] = [
    vr::SIDEFRAME_LEFT_Z,
    vr::SIDEFRAME_RIGHT_Z,
    vr::SIDEFRAME_LEFT_V,
    vr::SIDEFRAME_RIGHT_V,
];

/// Hands wheelset `k` of `sim` its wheel inputs `[left z, right z, rotation]` (value
/// references) among `changed`: the heights `z` (m, measured from the datum), the
/// rotation from `values`.
#[inline(always)]
fn wheel_inputs(
    sim: &mut Simulation,
    k: usize,
    [left, right, rotation]: [u32; 3],
    z: [f64; 2],
    values: &[f64],
    changed: &[u32],
) -> Result<(), Error> {
    match (changed.contains(&left), changed.contains(&right)) {
        (true, true) => sim.set_wheel_z_of(k, z)?,
        (true, false) => sim.set_wheel_side_z_of(k, 0, z[0])?,
        (false, true) => sim.set_wheel_side_z_of(k, 1, z[1])?,
        (false, false) => {}
    }
    if changed.contains(&rotation) {
        sim.set_rotation_of(k, values[rotation as usize])?;
    }
    Ok(())
}

impl FmuModel {
    /// TrackContact: the wheel heights when one of them changed, the axle rotation
    /// when it changed (not at every step: the track turns the axle on at `V / R_w`
    /// from the last rotation it was given, so setting a wheel height alone leaves it
    /// turning). RollPlaneVehicle: the contact forces.
    pub(super) fn take_inputs(&mut self, values: &[f64], changed: &[u32]) -> Result<(), Error> {
        let v = |r: u32| values[r as usize];
        match (&mut self.engine, self.kind) {
            (Engine::Sim(sim), kind) => {
                if changed.contains(&vr::SPEED) {
                    sim.set_speed(v(vr::SPEED))?;
                }
                if kind != Kind::TrackContact {
                    return Ok(());
                }
                let changed_any = |a: u32, b: u32| changed.iter().any(|&r| r == a || r == b);
                let n = sim.wheelsets().len();
                if matches!(sim.vehicle(), VehicleState::AxleBox(_)) {
                    // The axle-box interface: the side frames of each wheelset.
                    let frames = std::iter::once(FRAME_VRS).chain(TRAILING_FRAME_VRS);
                    for (k, [zl, zr, vl, vr_]) in frames.take(n).enumerate() {
                        if changed_any(zl, zr) || changed_any(vl, vr_) {
                            let set = [changed.contains(&zl), changed.contains(&zr)];
                            let z = self.datum.apply(k, [v(zl), v(zr)], set, sim.steps() == 0);
                            sim.set_side_frames_of(k, z, [v(vl), v(vr_)])?;
                        }
                    }
                    return Ok(());
                }
                // The leading wheelset, then those behind it; the inputs of a wheelset
                // the model does not have are kept and unused. A wheel whose height was
                // not set keeps moving as it was.
                let lead = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z, vr::WHEEL_ROTATION];
                let refs = std::iter::once(lead).chain(TRAILING_INPUT_VRS);
                for (k, r) in refs.take(n).enumerate() {
                    let set = [changed.contains(&r[0]), changed.contains(&r[1])];
                    let z = self
                        .datum
                        .apply(k, [v(r[0]), v(r[1])], set, sim.steps() == 0);
                    // The forces the master read at this point before the new heights (a
                    // Jacobi master reads the outputs first), and those it reads after.
                    // A master that sets the heights first (a sequential loop) has read
                    // nothing yet: no jump to measure, and no contact computed for it.
                    let forces = |s: Sample| [s.contact[0].force, s.contact[1].force];
                    let before = sim.computed_sample_of(k).map(forces);
                    wheel_inputs(sim, k, r, z, values, changed)?;
                    if changed.contains(&r[0]) || changed.contains(&r[1]) {
                        self.watch.coupled();
                        if let Some(b) = before
                            && let Some(a) = sim.sample_of(k).map(forces)
                        {
                            self.watch.heights_given(k, b, a);
                        }
                    }
                    if changed.contains(&r[2]) {
                        let radius = sim.scenario().wheel_radius;
                        let track = (sim.time(), sim.position(), sim.dt());
                        self.watch.rotation_given(k, track, v(r[2]), radius);
                    }
                }
                Ok(())
            }
            (Engine::Vehicle(u), _) => {
                if changed.contains(&vr::SPEED) {
                    u.set_speed(v(vr::SPEED))?;
                }
                let refs = if u.is_axle_box() {
                    AXLE_BOX_FORCE_VRS
                } else {
                    CONTACT_FORCE_VRS
                };
                for (k, [l, r]) in refs.into_iter().take(u.wheelsets()).enumerate() {
                    u.set_forces_of(k, [v(l), v(r)])?;
                }
                Ok(())
            }
        }
    }

    /// TrackContact's wheel heights not set by the master: the static heights of the
    /// wheelset's wheels, so that an unconnected wheel starts at rest.
    pub(super) fn rest_input(&self, r: u32) -> Option<f64> {
        if let Engine::Vehicle(u) = &self.engine {
            // The held forces at rest: the axle-box interface's primary forces, the
            // contact forces of a vehicle on several wheelsets (which share its weight by
            // its static state).
            let refs = match (u.is_axle_box(), u.wheelsets()) {
                (true, _) => AXLE_BOX_FORCE_VRS,
                (false, 1) => return None,
                (false, _) => CONTACT_FORCE_VRS,
            };
            for (k, [l, rr]) in refs.into_iter().take(u.wheelsets()).enumerate() {
                let f = u.held_forces_of(k)?;
                if r == l {
                    return Some(f[0]);
                }
                if r == rr {
                    return Some(f[1]);
                }
            }
            return None;
        }
        let sim = self.simulation()?;
        // With inputs.datum = first_step an input never set keeps its start value,
        // which stands for the static state like any first input; with absolute the
        // input reports where the track rests.
        if self.kind != Kind::TrackContact || self.datum.is_relative() {
            return None;
        }
        // The axle-box interface's side frames at rest.
        let frames = std::iter::once(FRAME_VRS).chain(TRAILING_FRAME_VRS);
        for (k, [zl, zr, _, _]) in frames.enumerate() {
            if r == zl || r == zr {
                let (z, _) = sim.side_frames_of(k)?;
                return Some(if r == zl { z[0] } else { z[1] });
            }
        }
        let lead = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z, vr::WHEEL_ROTATION];
        let inputs = std::iter::once(lead).chain(TRAILING_INPUT_VRS);
        for (k, [left, right, _]) in inputs.enumerate() {
            let side = if r == left {
                0
            } else if r == right {
                1
            } else {
                continue;
            };
            return sim.sample_of(k).map(|s| s.wheel_z[side]);
        }
        None
    }
}
