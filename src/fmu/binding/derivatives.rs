//! The derivatives TrackContact and the vehicles give: TrackContact's directional
//! derivatives of its contact outputs (and, at the axle boxes, its primary forces)
//! against its inputs, and the vehicles' output derivatives (`fmi2GetRealOutputDerivatives`).

use super::inputs::FRAME_VRS;
use super::unit::{Engine, FmuModel};
use crate::error::Error;
use crate::fmu::fmi2::Model;
use crate::fmu::vars::{TRAILING_FRAME_VRS, TRAILING_INPUT_VRS, vr};
use crate::sim::VehicleState;

/// The refusal of derivatives of value reference `r`.
pub(super) fn no_derivative(r: u32) -> Error {
    Error::Unsupported(format!(
        "derivatives of `{}`: TrackContact interpolates wheel.*.z (orders 1 and 2) and \
         wheel.rotation (order 1) of each wheelset, with the contact interface; \
         RollPlaneVehicle, HalfCarBogie and Wagon give the first derivatives of wheel.*.z, \
         wheel.rotation and sideframe.*.z",
        name_of(r)
    ))
}

/// The variable name of value reference `r`.
pub(super) fn name_of(r: u32) -> String {
    crate::fmu::vars::FMUS
        .iter()
        .flat_map(|t| t.vars.iter())
        .find(|v| v.vr == r)
        .map_or_else(|| format!("value reference {r}"), |v| v.name.to_string())
}

/// The wheelset (0 the leading one) and input (0 left height, 1 right height, 2 axle
/// angle) of the wheel input (or vehicle output) `r`.
pub(super) fn wheel_input(r: u32) -> Option<(usize, usize)> {
    let lead = [vr::WHEEL_LEFT_Z, vr::WHEEL_RIGHT_Z, vr::WHEEL_ROTATION];
    std::iter::once(lead)
        .chain(TRAILING_INPUT_VRS)
        .enumerate()
        .find_map(|(k, refs)| refs.iter().position(|&x| x == r).map(|i| (k, i)))
}

/// The wheelset, side and quantity of a contact output `r` of TrackContact.
pub(super) fn contact_output(r: u32) -> Option<(usize, usize, crate::fmu::vars::Quantity)> {
    use crate::fmu::vars::Quantity;
    let &Some((q, side, k)) = crate::fmu::vars::QUANTITIES.get(r as usize)? else {
        return None;
    };
    match q {
        Quantity::ContactForce
        | Quantity::ContactOverlap
        | Quantity::ContactFrontAngle
        | Quantity::ContactRearAngle
        | Quantity::ContactLength
        | Quantity::ContactMaxForce
        | Quantity::ContactMinForce
        | Quantity::RailZ
        | Quantity::WheelAcceleration
        | Quantity::RailAcceleration => Some((k, side, q)),
        _ => None,
    }
}

/// The wheelset and side of a primary-force output `r` of TrackContact (at the point or
/// the mean, `interface = axle_box`).
pub(super) fn primary_output(r: u32) -> Option<(usize, usize)> {
    use crate::fmu::vars::Quantity;
    let &Some((q, side, k)) = crate::fmu::vars::QUANTITIES.get(r as usize)? else {
        return None;
    };
    matches!(q, Quantity::PrimaryForce | Quantity::PrimaryMeanForce).then_some((k, side))
}

/// The wheelset, side and whether it is the velocity of a side-frame input `r`.
pub(super) fn frame_input(r: u32) -> Option<(usize, usize, bool)> {
    std::iter::once(FRAME_VRS)
        .chain(TRAILING_FRAME_VRS)
        .enumerate()
        .find_map(|(k, refs)| {
            refs.iter()
                .position(|&x| x == r)
                .map(|i| (k, i % 2, i >= 2))
        })
}

impl FmuModel {
    /// TrackContact, every pair its model description declares. Contact interface:
    /// the contact forces and overlaps of each wheelset with respect to its wheel
    /// heights exactly (the contact stiffness `k`,
    /// [`crate::contact::ContactLaw::stiffness_at`], in series with the rail's local
    /// compliance `c` under the wheel ([`crate::track::Track::shear_compliance`]):
    /// `dP/dz = -k / (1 + c k)`; `d delta/dz = -1 / (1 + c k)`); the forces with respect to the axle angle, and the patch's front and rear
    /// angles and length with respect to either input, by central differences of the
    /// law (1e-9 m, 1e-7 rad); the extremes follow the force where it is the extreme
    /// now, else 0. Axle boxes: the primary forces with respect to their side frame's
    /// displacement and velocity exactly (`-K_1`, `-C_1`). Every pair the model
    /// description does not declare is 0; before the first step, the displacement
    /// inputs stand for the static state (`inputs.datum = first_step`): 0.
    pub(super) fn directional_derivative(&self, unknown: u32, known: u32) -> Result<f64, Error> {
        use crate::fmu::vars::Quantity;
        let Engine::Sim(sim) = &self.engine else {
            return Err(Error::Unsupported(format!(
                "the derivative of `{}` with respect to `{}`: only TrackContact gives \
                 directional derivatives",
                name_of(unknown),
                name_of(known)
            )));
        };
        if let VehicleState::AxleBox(_) = sim.vehicle() {
            let (Some((ku, su)), Some((kk, sk, velocity))) =
                (primary_output(unknown), frame_input(known))
            else {
                return Ok(0.0);
            };
            let Some(VehicleState::AxleBox(link)) = sim.wheelsets().get(ku).map(|w| w.vehicle())
            else {
                return Ok(0.0);
            };
            if ku != kk || su != sk || (!velocity && self.datum.follows(ku)) {
                return Ok(0.0);
            }
            return Ok(if velocity {
                -link.damping()
            } else {
                -link.stiffness()
            });
        }
        let (Some((ku, side, q)), Some((kk, which))) =
            (contact_output(unknown), wheel_input(known))
        else {
            return Ok(0.0);
        };
        let Some(sample) = sim.sample_of(ku) else {
            return Ok(0.0);
        };
        if ku != kk || (which != 2 && which != side) {
            return Ok(0.0);
        }
        // Before the first step the wheel heights stand for the static state
        // (`inputs.datum = first_step`): the outputs do not follow them yet.
        if which != 2 && self.datum.follows(ku) {
            return Ok(0.0);
        }
        let w = sim.wheelsets().get(ku).expect("the sample's wheelset");
        let wheel = &w.wheels()[side];
        let law = sim.contact_law();
        let overlap = sample.contact[side].overlap;
        let gamma = sample.rotation;
        // The rail's local compliance `c` under the wheel, in series with the contact
        // (the force solves `P = P_law(overlap_0 - c P)`): a change of the overlap the
        // nodes give moves the overlap by `s = 1 / (1 + c k)` of it.
        let c = sim.contact_compliance_of(ku);
        let k = law.stiffness_at(wheel, gamma, overlap);
        let s = 1.0 / (1.0 + c * k);
        // Central differences of the law's state in the overlap and the axle angle.
        let d_overlap = |pick: &dyn Fn(&crate::contact::ContactState) -> f64| -> f64 {
            let e = 1e-9;
            (pick(&law.evaluate(wheel, gamma, overlap + e))
                - pick(&law.evaluate(wheel, gamma, overlap - e)))
                / (2.0 * e)
        };
        let d_gamma = |pick: &dyn Fn(&crate::contact::ContactState) -> f64| -> f64 {
            let e = 1e-7;
            (pick(&law.evaluate(wheel, gamma + e, overlap))
                - pick(&law.evaluate(wheel, gamma - e, overlap)))
                / (2.0 * e)
        };
        // The wheel's out-of-roundness at the angle that touches the rail moves the
        // overlap with the axle angle by `dr/d gamma`.
        let rp = w.radius_deviation_slope(side, gamma);
        // dP/d gamma with the overlap following it through the compliance.
        let p_gamma = || s * (d_gamma(&|c| c.force) + k * rp);
        // A quantity of the state: a height raises the overlap by `-s` per metre, the
        // axle angle moves it by `-c dP/d gamma`.
        let difference = |pick: &dyn Fn(&crate::contact::ContactState) -> f64| -> f64 {
            if which == 2 {
                d_gamma(pick) + (rp - c * p_gamma()) * d_overlap(pick)
            } else {
                -s * d_overlap(pick)
            }
        };
        let force = || {
            if which == 2 { p_gamma() } else { -k * s }
        };
        let p = sample.contact[side].force;
        Ok(match q {
            Quantity::ContactForce => force(),
            Quantity::ContactOverlap => {
                if which == 2 {
                    rp - c * p_gamma()
                } else {
                    -s
                }
            }
            // The rail under the wheel, lowered by `c P`.
            Quantity::RailZ => {
                if which == 2 {
                    -c * p_gamma()
                } else {
                    c * k * s
                }
            }
            Quantity::ContactFrontAngle => difference(&|c| c.front_angle),
            Quantity::ContactRearAngle => difference(&|c| c.rear_angle),
            Quantity::ContactLength => difference(&|c| c.length),
            // The extreme is the force now where the force is beyond the extremes of the
            // steps taken.
            Quantity::ContactMaxForce if p >= w.max_force()[side] => force(),
            Quantity::ContactMinForce if p <= w.min_force()[side] => force(),
            // Accelerations: `1 / dt^2` of the displacement's derivative (the extremes
            // are of the steps taken: no feedthrough).
            Quantity::WheelAcceleration | Quantity::RailAcceleration => {
                let wheel = q == Quantity::WheelAcceleration;
                let signal = if wheel { side } else { 2 + side };
                // The wheel's height moves the wheel one for one, its rotation not; the
                // rail under the wheel as `rail.*.z`.
                let dz = match (wheel, which == 2) {
                    (true, true) => 0.0,
                    (true, false) => 1.0,
                    (false, true) => -c * p_gamma(),
                    (false, false) => c * k * s,
                };
                w.acceleration_record().gain(signal) * dz
            }
            _ => 0.0,
        })
    }

    /// RollPlaneVehicle, HalfCarBogie and Wagon, first order: the wheel-centre and
    /// side-frame velocities (backward differences over the last step) and the axle's
    /// rate `speed / wheel.radius`.
    pub(super) fn vehicle_output_derivative(&self, r: u32, order: i32) -> Result<f64, Error> {
        let Engine::Vehicle(u) = &self.engine else {
            return Err(no_derivative(r));
        };
        if order != 1 {
            return Err(no_derivative(r));
        }
        if let Some((k, which)) = wheel_input(r) {
            return match which {
                2 => Ok(u.params().speed / u.params().wheel_radius),
                side => u
                    .wheel_velocity_of(k)
                    .map(|v| v[side])
                    .ok_or_else(|| no_derivative(r)),
            };
        }
        let frames = std::iter::once(FRAME_VRS).chain(TRAILING_FRAME_VRS);
        for (k, [zl, zr, _, _]) in frames.enumerate() {
            if r == zl || r == zr {
                let side = usize::from(r == zr);
                return u
                    .side_frames_of(k)
                    .map(|(_, v)| v[side])
                    .ok_or_else(|| no_derivative(r));
            }
        }
        // The extremes are piecewise constant: 0 between their jumps.
        use crate::fmu::vars::Quantity;
        if let Some(Some((Quantity::ContactMaxForce | Quantity::ContactMinForce, _, _))) =
            crate::fmu::vars::QUANTITIES.get(r as usize)
        {
            return Ok(0.0);
        }
        // Every other output: its rate over one more substep under the held inputs, a
        // forward difference (first order in the substep; the held forces' is 0).
        let dt = u.dt();
        let mut ahead = self.clone();
        if let Engine::Vehicle(t) = &mut ahead.engine {
            t.advance(dt, 0.0)?;
        }
        let (now, next) = (
            self.output(&self.outputs(), r),
            ahead.output(&ahead.outputs(), r),
        );
        Ok((next - now) / dt)
    }
}
