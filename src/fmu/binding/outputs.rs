//! The outputs and calculated parameters of the three FMUs, by value reference.

use super::FmuModel;
use super::unit::Engine;
use crate::fmu::vars::vr;
use crate::solver::{Sample, VehicleState};

/// Values computed when the model is built, published as calculated parameters.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Published {
    /// `static_load.left`/`.right` (N).
    pub static_load: [f64; 2],
    /// `static_wheel_z.left`/`.right` (m).
    pub static_wheel_z: [f64; 2],
    /// `solver.step` (s).
    pub step: f64,
    /// `solver.critical_step` (s).
    pub critical_step: f64,
    /// `contact.kw_used` (N/m/rad).
    pub kw_used: f64,
}

impl Published {
    /// The values in the order FMU states store them.
    pub fn to_array(self) -> [f64; 7] {
        let [l, r] = self.static_load;
        let [zl, zr] = self.static_wheel_z;
        [l, r, zl, zr, self.step, self.critical_step, self.kw_used]
    }

    /// The calculated parameter `r`, if it is one.
    fn get(&self, r: u32) -> Option<f64> {
        Some(match r {
            vr::STATIC_LOAD_LEFT => self.static_load[0],
            vr::STATIC_LOAD_RIGHT => self.static_load[1],
            vr::STATIC_WHEEL_Z_LEFT => self.static_wheel_z[0],
            vr::STATIC_WHEEL_Z_RIGHT => self.static_wheel_z[1],
            vr::SOLVER_STEP => self.step,
            vr::SOLVER_CRITICAL_STEP => self.critical_step,
            vr::CONTACT_KW_USED => self.kw_used,
            _ => return None,
        })
    }
}

impl FmuModel {
    /// Value of an output or calculated parameter; `sample` is the track-carrying
    /// models' sample at the current time. NaN for a reference the FMU does not have.
    pub(super) fn output_value(&self, r: u32, sample: Option<&Sample>) -> f64 {
        if let Some(x) = self.published.get(r) {
            return x;
        }
        match &self.engine {
            Engine::Vehicle(u) => match r {
                vr::WHEEL_LEFT_Z => u.wheel_z()[0],
                vr::WHEEL_RIGHT_Z => u.wheel_z()[1],
                vr::WHEEL_ROTATION => u.rotation(),
                vr::CONTACT_LEFT_MAX_FORCE => u.max_force()[0],
                vr::CONTACT_RIGHT_MAX_FORCE => u.max_force()[1],
                vr::CONTACT_LEFT_MIN_FORCE => u.min_force()[0],
                vr::CONTACT_RIGHT_MIN_FORCE => u.min_force()[1],
                _ => body_output(r, u.displacements(), || u.bearing_forces()),
            },
            Engine::Sim(sim) => {
                let Some(s) = sample else { return f64::NAN };
                let c = &s.contact;
                match r {
                    vr::CONTACT_LEFT_FORCE => c[0].force,
                    vr::CONTACT_RIGHT_FORCE => c[1].force,
                    vr::CONTACT_LEFT_OVERLAP => c[0].overlap,
                    vr::CONTACT_RIGHT_OVERLAP => c[1].overlap,
                    vr::CONTACT_LEFT_FRONT_ANGLE => c[0].front_angle,
                    vr::CONTACT_RIGHT_FRONT_ANGLE => c[1].front_angle,
                    vr::CONTACT_LEFT_REAR_ANGLE => c[0].rear_angle,
                    vr::CONTACT_RIGHT_REAR_ANGLE => c[1].rear_angle,
                    vr::CONTACT_LEFT_LENGTH => c[0].length,
                    vr::CONTACT_RIGHT_LENGTH => c[1].length,
                    vr::CONTACT_LEFT_INTERVALS => c[0].intervals as f64,
                    vr::CONTACT_RIGHT_INTERVALS => c[1].intervals as f64,
                    vr::CONTACT_LEFT_MAX_FORCE => sim.max_force()[0].max(c[0].force),
                    vr::CONTACT_RIGHT_MAX_FORCE => sim.max_force()[1].max(c[1].force),
                    vr::CONTACT_LEFT_MIN_FORCE => sim.min_force()[0].min(c[0].force),
                    vr::CONTACT_RIGHT_MIN_FORCE => sim.min_force()[1].min(c[1].force),
                    vr::RAIL_LEFT_Z => s.rail_z[0],
                    vr::RAIL_RIGHT_Z => s.rail_z[1],
                    vr::POSITION => s.position,
                    vr::WHEEL_LEFT_Z => s.wheel_z[0],
                    vr::WHEEL_RIGHT_Z => s.wheel_z[1],
                    vr::WHEEL_ROTATION => s.rotation,
                    _ => match sim.vehicle() {
                        VehicleState::RollPlane(v) => {
                            body_output(r, v.displacements(), || v.bearing_forces())
                        }
                        _ => f64::NAN,
                    },
                }
            }
        }
    }
}

/// Vehicle body outputs from the displacements `{z_b, phi_b, z_sfl, z_sfr, z_w, phi_w}`
/// and the bearing forces; NaN for any other reference.
fn body_output(r: u32, d: &nalgebra::Vector6<f64>, bearing: impl Fn() -> [f64; 2]) -> f64 {
    match r {
        vr::BOLSTER_Z => d[0],
        vr::BOLSTER_ROLL => d[1],
        vr::SIDEFRAME_LEFT_Z => d[2],
        vr::SIDEFRAME_RIGHT_Z => d[3],
        vr::WHEELSET_Z => d[4],
        vr::WHEELSET_ROLL => d[5],
        vr::PRIMARY_LEFT_FORCE => bearing()[0],
        vr::PRIMARY_RIGHT_FORCE => bearing()[1],
        _ => f64::NAN,
    }
}
