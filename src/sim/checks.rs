//! A scenario that checks itself: the parameters [`Scenario`] carries that need no
//! model built to be judged (the wheel, the speed, the start, the solver's and the
//! contact's numbers, the wheelsets' count and order, a vehicle on several wheelsets
//! against their offsets). [`super::Simulation::new`] calls it first; the models'
//! own checks follow as each is built.

use super::Scenario;
use crate::error::{Error, Result, finite, non_negative, num, out_of_range, positive};
use crate::limits::{MAX_PATCH_LENGTH, MAX_WHEELSETS};
use crate::track::{FOLLOWABLE, FOLLOWABLE_SOURCE, RailProfile};

/// Largest start position (m) by magnitude: a double resolves 1e-9 m there, well
/// below a step's travel (0.3 mm at 70 km/h), so positions integrate the speed.
pub(crate) const MAX_START_POSITION: f64 = 1e7;

impl Scenario {
    /// Checks the scenario's own parameters, naming each as the FMUs' variables do.
    ///
    /// Errors: a value outside its range ([`crate::Error::Parameter`]): a vehicle on
    /// several wheelsets whose parameters its model refuses (its wheelbase named
    /// `wheelset[2].offset`, the wagon's bogie distance `wheelset[3].offset`), the wheel
    /// radius, a negative or non-finite speed, a start beyond 1e7 m, a negative step or contact constant, more than
    /// [`MAX_WHEELSETS`] wheelsets, wheelsets out of order or closer than a wheel
    /// diameter, or a measured rail profile or out-of-roundness steeper or sharper than
    /// the contact can follow ([`crate::track::FOLLOWABLE`]).
    pub fn validate(&self) -> Result<()> {
        let s = self;
        // A bogie's wheelbase and the wagon's bogie distance are the wheelsets' offsets
        // here: a refusal names those, the variables a user of the scenario
        // (CoupledSystem) sets.
        if let Some(c) = s.vehicle.carrier() {
            // The count first: a vehicle on other wheelsets than its own is the first
            // thing to set right (its offsets are checked against them).
            if s.trailing.len() + 1 != c.wheelsets() {
                return Err(out_of_range(
                    "wheelsets",
                    (s.trailing.len() + 1) as f64,
                    format!("{} with {}", c.wheelsets(), c.name()),
                ));
            }
            c.validate().map_err(|e| {
                let e = e
                    .renamed(
                        "vehicle.wheelbase",
                        "wheelset[2].offset",
                        "(the bogies' wheelbase)",
                    )
                    .renamed(
                        "vehicle.bogie_distance",
                        "wheelset[3].offset",
                        "(the wagon's bogie centre distance)",
                    );
                // The allowed range may name the other one too.
                match e {
                    Error::Parameter {
                        name,
                        value,
                        allowed,
                    } => Error::Parameter {
                        name,
                        value,
                        allowed: allowed
                            .replace("vehicle.wheelbase", "wheelset[2].offset")
                            .replace("vehicle.bogie_distance", "wheelset[3].offset"),
                    },
                    other => other,
                }
            })?;
        }
        positive("wheel.radius", s.wheel_radius, "m")?;
        finite("speed", s.speed, "m/s")?;
        if s.speed < 0.0 {
            return Err(out_of_range("speed", s.speed, ">= 0 m/s"));
        }
        finite("start_position", s.start_position, "m")?;
        if s.start_position.abs() > MAX_START_POSITION {
            return Err(out_of_range(
                "start_position",
                s.start_position,
                format!(
                    "-{MAX_START_POSITION:e} m <= start_position <= {MAX_START_POSITION:e} m \
                 (positions along the line keep 1e-9 m of resolution there)"
                ),
            ));
        }
        non_negative("solver.dt", s.dt, "s")?;
        non_negative("contact.Kw", s.kw, "N/m/rad")?;
        non_negative("contact.CH", s.hertz_coefficient, "N/m^1.5")?;
        if s.trailing.len() + 1 > MAX_WHEELSETS {
            return Err(out_of_range(
                "wheelsets",
                (s.trailing.len() + 1) as f64,
                format!("1 to {MAX_WHEELSETS} wheelsets"),
            ));
        }
        // Measured tables the contact could not follow (the FMUs check a rail's when it
        // is set too; a wheel's needs the radius, known only here).
        for (side, rail) in ["left", "right"].iter().zip(&s.rails) {
            if let Some(t) = &rail.measured {
                RailProfile::check_measured(t, &format!("rail.{side}.profile"))?;
            }
        }
        if let Some(p) = &s.random.profile {
            p.validate()?;
        }
        if let Some(r) = &s.random.roughness {
            for (name, sp) in [("roughness.rail", &r.rail), ("roughness.wheel", &r.wheel)] {
                if let Some(sp) = sp {
                    sp.validate(name)?;
                }
            }
            if r.patch_length == 0.0 && s.hertz_coefficient <= 0.0 {
                return Err(out_of_range(
                    "contact.CH",
                    s.hertz_coefficient,
                    "contact.CH > 0 N/m^1.5 when roughness.patch_length = 0 (the roughness is \
                     averaged over the Hertz patch under the static load, which needs it): give \
                     contact.CH, or roughness.patch_length > 0 m",
                ));
            }
            if !(0.0..=MAX_PATCH_LENGTH).contains(&r.patch_length) {
                return Err(out_of_range(
                    "roughness.patch_length",
                    r.patch_length,
                    format!(
                        "0 m (the Hertz patch under the static wheel load) <= patch length \
                         <= {MAX_PATCH_LENGTH} m"
                    ),
                ));
            }
        }
        let wheels = std::iter::once(("wheel".to_string(), &s.roundness)).chain(
            (s.trailing.iter().enumerate())
                .map(|(k, w)| (format!("wheelset[{}].wheel", k + 2), &w.roundness)),
        );
        for (wheel, pair) in wheels {
            for (side, r) in ["left", "right"].iter().zip(pair) {
                if let Some(r) = r {
                    let name = format!("{wheel}.{side}.out_of_roundness");
                    r.check_followable(s.wheel_radius, FOLLOWABLE, FOLLOWABLE_SOURCE, &name)?;
                }
            }
        }
        for (k, w) in s.trailing.iter().enumerate() {
            let name = format!("wheelset[{}].offset", k + 2);
            positive(&name, w.offset, "m")?;
            let before = if k == 0 {
                0.0
            } else {
                s.trailing[k - 1].offset
            };
            // Wheels of the same rail cannot overlap: one wheel diameter apart at least.
            let least = before + 2.0 * s.wheel_radius;
            if w.offset.is_nan() || w.offset < least {
                return Err(out_of_range(
                    &name,
                    w.offset,
                    format!(
                        ">= {} m, the wheelset ahead's offset {} m plus a wheel diameter \
                     (wheelsets in order, the leading one first)",
                        num(least),
                        num(before)
                    ),
                ));
            }
        }
        Ok(())
    }
}
