//! What a physical run can reach, and what one call may cost.
//!
//! * [`PARAMETER_RANGES`]: the physical range of every named parameter. The engine's
//!   `validate` functions check against it, and the FMUs' variable table
//!   (`modelDescription/variables.xml`) declares the same `min`/`max` (a unit test in
//!   `fmu` keeps the two equal), so an FMU refuses a value at `fmi2SetReal` already.
//!   The ranges bracket every parameter set of the thesis (chapter 2, tables 4.1, 4.4,
//!   5.1, 5.2) and standard-gauge freight and passenger vehicles and track with wide
//!   margins; they exist so that no value inside them overflows the arithmetic
//!   (a mass of 1e-300 kg or a stiffness of 1e308 N/m is not a railway).
//! * The health bounds: a displacement of a decimetre at a rail or a wheel, or a
//!   contact force of [`FORCE_LIMIT_FACTOR`] times the static wheel load, is reached by
//!   no physical run (impact forces of wheel flats stay below about six times the
//!   static load: thesis chapter 1; this model gives 2.85 times for the reference flat).
//!   Reaching one means the scheme diverged or the inputs are not a running wheel, and
//!   the run stops with an error naming the quantity, the time and the likely cause.
//! * The work bounds of one FMI call (see [`MAX_NODE_STEPS_PER_CALL`]).

use crate::error::{Error, Result, num};

/// The physical range of one parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Parameter name, as in the FMUs' variable table.
    pub name: &'static str,
    /// Least value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
    /// SI unit, for messages.
    pub unit: &'static str,
}

const fn r(name: &'static str, min: f64, max: f64, unit: &'static str) -> Range {
    Range {
        name,
        min,
        max,
        unit,
    }
}

/// The endless track's window behind the last wheelset (m); `track.window.ahead` is 0
/// (the fixed track) or in the same range (`crate::sim` checks both against
/// `MIN_WINDOW_SIDE` and the sleeper spacing when the simulation is built).
const WINDOW_BEHIND: Range = r("track.window.behind", 4.0, 1000.0, "m");

/// The longest contact patch the roughness may be averaged over (m): a wheel-rail
/// patch is some 10 to 20 mm long.
pub const MAX_PATCH_LENGTH: f64 = 0.05;

/// Physical ranges of the parameters, by name (the FMUs' variable names).
pub const PARAMETER_RANGES: &[Range] = &[
    r("speed", 0.0, 200.0, "m/s"),
    r("wheel.radius", 0.05, 2.0, "m"),
    r("contact.Kw", 0.0, 1e13, "N/m/rad"),
    r("contact.CH", 0.0, 1e13, "N/m^1.5"),
    r("track.sleeper_spacing", 0.1, 3.0, "m"),
    r("track.window.ahead", 0.0, 1000.0, "m"),
    WINDOW_BEHIND,
    r("track.rail_seat_distance", 0.3, 3.0, "m"),
    r("track.rail.EI", 3e5, 1e9, "N m^2"),
    r("track.rail.kAG", 1e7, 1e11, "N"),
    r("track.rail.mass", 5.0, 500.0, "kg/m"),
    r("track.rail.rotary_inertia", 1e-4, 100.0, "kg m"),
    r("track.pad.stiffness", 0.0, 1e11, "N/m"),
    r("track.pad.damping", 0.0, 1e8, "N s/m"),
    r("track.ballast.stiffness", 0.0, 1e11, "N/m"),
    r("track.ballast.damping", 0.0, 1e8, "N s/m"),
    r("track.sleeper.mass", 10.0, 1e4, "kg"),
    r("track.sleeper.inertia", 0.1, 1e4, "kg m^2"),
    r("vehicle.carbody_mass", 0.0, 2e5, "kg"),
    r("vehicle.bolster.mass", 1.0, 1e5, "kg"),
    r("vehicle.bolster.inertia", 0.1, 1e5, "kg m^2"),
    r("vehicle.sideframe.mass", 1.0, 1e5, "kg"),
    r("vehicle.wheelset.mass", 50.0, 1e5, "kg"),
    r("vehicle.wheelset.inertia", 1.0, 1e5, "kg m^2"),
    r("vehicle.primary.stiffness", 1e4, 1e10, "N/m"),
    r("vehicle.primary.damping", 0.0, 1e7, "N s/m"),
    r("vehicle.primary.spacing", 0.5, 3.0, "m"),
    r("vehicle.secondary.stiffness", 1e4, 1e10, "N/m"),
    r("vehicle.secondary.damping", 0.0, 1e7, "N s/m"),
    r("vehicle.secondary.spacing", 0.1, 3.0, "m"),
    r("vehicle.wheelbase", 1.0, 5.0, "m"),
    r("vehicle.sideframe.pitch_inertia", 1.0, 1e5, "kg m^2"),
    r("vehicle.bogie_distance", 2.0, 30.0, "m"),
    r("vehicle.carbody.pitch_inertia", 1e3, 1e8, "kg m^2"),
    r("vehicle.carbody.roll_inertia", 1e2, 1e7, "kg m^2"),
    r("rail.spectrum.shortest_wavelength", 0.1, 500.0, "m"),
    r("rail.spectrum.longest_wavelength", 0.2, 1000.0, "m"),
    r("rail.spectrum.ramp", 1.0, 1000.0, "m"),
    r("roughness.patch_length", 0.0, MAX_PATCH_LENGTH, "m"),
    r("gravity", 0.0, 100.0, "m/s^2"),
    r("static_load.left", 0.0, 2e6, "N"),
    r("static_load.right", 0.0, 2e6, "N"),
    // Half the wheels' health bound (DISPLACEMENT_LIMIT): a vehicle at rest there
    // stays inside it after the rounding of its first steps.
    r("static_wheel_z.left", -0.05, 0.05, "m"),
    r("static_wheel_z.right", -0.05, 0.05, "m"),
];

/// The range of parameter `name`, if it has one.
pub fn range(name: &str) -> Option<&'static Range> {
    PARAMETER_RANGES.iter().find(|r| r.name == name)
}

/// Checks `value` against the physical range of parameter `name` (and that it is
/// finite). A name without a range only has to be finite.
pub fn check(name: &str, value: f64) -> Result<f64> {
    match range(name) {
        // 0 is the thesis' fixed track; a window side is at least the behind side's least.
        Some(r) if r.name == "track.window.ahead" && value > 0.0 && value < WINDOW_BEHIND.min => {
            Err(Error::Parameter {
                name: name.into(),
                value,
                allowed: format!(
                    "track.window.ahead = 0 m (the thesis' fixed track) or {} m <= \
                     track.window.ahead <= {} m (the endless track)",
                    num(WINDOW_BEHIND.min),
                    num(r.max)
                ),
            })
        }
        Some(r) if !(value >= r.min && value <= r.max) => Err(Error::Parameter {
            name: name.into(),
            value,
            allowed: format!("{} <= {name} <= {} {}", num(r.min), num(r.max), r.unit),
        }),
        None if !value.is_finite() => Err(Error::Parameter {
            name: name.into(),
            value,
            allowed: "a finite number".into(),
        }),
        _ => Ok(value),
    }
}

/// `|x| <= limit`, false for NaN: the health bounds' test.
#[inline(always)]
pub fn within(x: f64, limit: f64) -> bool {
    x.abs() <= limit
}

/// Deepest wheel flat (m), given or derived from its length (2.13, 2.15): flats worn in
/// service are a few millimetres deep; at 20 mm the wheel would drop a fifth of the way
/// to the displacement bound.
pub const MAX_FLAT_DEPTH: f64 = 0.02;
/// Largest static overlap of wheel and rail (m) under the static wheel load: a wheel on a
/// rail overlaps about 0.1 mm (table 4.4: 0.11 mm); 5 mm is a contact too soft to be
/// one.
pub const MAX_STATIC_OVERLAP: f64 = 5e-3;
/// Largest static deflection of the rail under the wheel (m) under the static wheel
/// load: table 4.4's track deflects 1.3 mm; 10 mm is a track too soft to carry a
/// train.
pub const MAX_STATIC_RAIL_DEFLECTION: f64 = 0.01;
/// Largest static deflection of a suspension stage (m) under its share of the weight:
/// freight suspensions deflect some centimetres.
pub const MAX_STATIC_DEFLECTION: f64 = 0.3;
/// Most grid nodes per sleeper span: the grid study converges at 8 (docs/VALIDATION.md);
/// 64 puts a node every 11 mm, finer than any contact patch.
pub const MAX_NODES_PER_SPAN: usize = 64;

/// `x` is a whole number in `[0, 2^53)`: a step count that an FMU state (stored as
/// `f64`) may hold.
pub fn is_count(x: f64) -> bool {
    (0.0..9.007_199_254_740_992e15).contains(&x) && x.fract() == 0.0
}

/// A contact force above this many static wheel loads is reached by no physical run.
pub const FORCE_LIMIT_FACTOR: f64 = 20.0;
/// The static load the force limit is taken from is at least this (N), so an unloaded
/// wheel pressed onto the rail from outside keeps a physical margin.
pub const FORCE_LIMIT_MIN_STATIC_LOAD: f64 = 100e3;

/// The largest contact force (N) a physical run reaches with static wheel loads
/// `static_load` (N).
pub fn force_limit(static_load: [f64; 2]) -> f64 {
    FORCE_LIMIT_FACTOR
        * static_load[0]
            .max(static_load[1])
            .max(FORCE_LIMIT_MIN_STATIC_LOAD)
}

/// Largest displacement of a rail node, sleeper seat or wheel centre (m) a physical run
/// reaches (static deflections are about 1.5 mm).
pub const DISPLACEMENT_LIMIT: f64 = 0.1;
/// Largest displacement of a vehicle body (m) or roll angle (rad) a physical run
/// reaches (static suspension deflections are some centimetres).
pub const BODY_DISPLACEMENT_LIMIT: f64 = 1.0;

/// The most track work one FMI call may do: internal steps times rail nodes. About a
/// second on this project's machine on the default track (1 to 1.5 ns per rail node and
/// step), up to about three on the longest (cache misses); 5e8 node steps are 1.0e6
/// steps (15 s of simulated time) on the default 30-span, n = 8 track.
pub const MAX_NODE_STEPS_PER_CALL: f64 = 5e8;
/// Most observation points of a simulation ([`crate::sim::Site`]).
pub const MAX_SITES: usize = 8;
/// Most wheelsets on one track (a four-axle wagon, or two two-axle bogies).
pub const MAX_WHEELSETS: usize = 4;
/// The most rail segments (`track.spans * track.nodes_per_span`) a track may have: the
/// banded static solve of 1e5 segments takes about 75 MB at its peak (740 MB at 1e6,
/// which aborts a host short of memory), and 1e5 is 12,500 spans at the default n = 8
/// (8.6 km).
pub const MAX_RAIL_SEGMENTS: usize = 100_000;
/// The most vehicle steps one FMI call may do (RollPlaneVehicle; about 2 s).
pub const MAX_VEHICLE_STEPS_PER_CALL: f64 = 2e7;
/// The engine checks every state of the track and vehicle for the health bounds every
/// this many steps (the contact forces, wheel and rail under the wheel every step).
pub const HEALTH_CHECK_INTERVAL: u64 = 256;
/// RollPlaneVehicle carries a communication step shorter than this fraction of its
/// step over to the next call rather than stepping it (see
/// [`crate::sim::VehicleUnit::advance`]).
pub const MIN_STEP_FRACTION: f64 = 1e-3;
/// `solver.dt`, when given, must be at least this fraction of the critical step: a
/// smaller step resolves nothing more and only multiplies the work.
pub const MIN_DT_FRACTION: f64 = 1e-3;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{Scenario, TrackSpec, VehicleSpec};

    #[test]
    fn every_seed_parameter_set_is_inside_the_ranges() {
        for s in [
            Scenario::table_4_1(),
            Scenario::table_4_4(),
            Scenario::table_5_1(),
            Scenario::table_5_2(),
        ] {
            check("speed", s.speed).unwrap();
            check("wheel.radius", s.wheel_radius).unwrap();
            check("contact.CH", s.hertz_coefficient).unwrap();
            check("contact.Kw", s.kw).unwrap();
            if let TrackSpec::Discrete(t) = s.track {
                t.validate().unwrap();
            }
            if let VehicleSpec::RollPlane(v) = s.vehicle {
                v.validate().unwrap();
            }
        }
    }

    #[test]
    fn out_of_range_names_the_parameter_value_and_range() {
        let e = check("vehicle.primary.stiffness", 1e308).unwrap_err();
        assert_eq!(
            e.to_string(),
            "parameter `vehicle.primary.stiffness` = 1e308 is out of range: allowed \
             10000 <= vehicle.primary.stiffness <= 1e10 N/m"
        );
        assert!(check("track.rail.mass", 1e-300).is_err());
        assert!(check("track.rail.mass", f64::NAN).is_err());
        assert_eq!(check("track.rail.mass", 60.0).unwrap(), 60.0);
        assert!(check("no.such.name", f64::INFINITY).is_err());
    }
}
