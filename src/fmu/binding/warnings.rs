//! The warnings a step returns with `fmi2Warning`: the fixed rail end's zone, a vehicle
//! at the axle-box interface stepped above its Jacobi estimate, what TrackContact's
//! contact watch sees, a vehicle's first step off its forces at rest.

use super::Kind;
use super::unit::{Engine, FmuModel};
use super::watch::{HELD_STEPS, INTERPOLATED_STEPS};
use crate::error::num;
use crate::fmu::fmi2::StepWarning;
use crate::sim::{TrackSpec, VehicleState, VehicleUnit};
use crate::wheel::WheelProfile;

/// The zone at the fixed rail end, in sleeper spans, where `fmi2DoStep` warns that the
/// end's reflections raise the forces (the default start position, 1.37 m, is two
/// spans from the other end).
pub const END_ZONE_SPANS: f64 = 2.0;

impl FmuModel {
    /// When the wheel is within [`END_ZONE_SPANS`] sleeper spans of the fixed rail end,
    /// where the end's reflections raise the impact forces (by 20 to 35 % within the
    /// last span, table 4.4); for the vehicles with the axle-box interface, a
    /// communication step above the Jacobi estimate of [`VehicleUnit::exchange_limits`]; for
    /// TrackContact at the contact interface, what its contact watch sees (`watch.rs`); for a vehicle's
    /// first step, forces off its forces at rest.
    #[inline]
    pub(super) fn warning_after_step(&mut self, time: f64, at_stop: bool) -> Option<StepWarning> {
        if let Engine::Vehicle(u) = &self.engine {
            // The forces that drove the first step against those that hold this vehicle
            // at rest: a partner that does not carry it at rest.
            if !self.started {
                self.started = true;
                if let Some(w) = off_rest(u) {
                    return Some(StepWarning::once("static load", w));
                }
            }
            let e = u.exchange_limits()?;
            let h = self.last_step;
            return (h > e.jacobi).then(|| {
                let message = if h > e.sequential {
                    format!(
                        "at t = {time} s the communication step {} s is above {} s, the \
                         largest at which the axle-box exchange stays stable under any master \
                         (estimated from the exchange's amplification matrix with the primary \
                         springs and dampers vehicle.primary.* and the side frames' inertia): \
                         expect it to diverge; use steps of at most {} s",
                        num(h),
                        num(e.sequential),
                        num(e.jacobi)
                    )
                } else {
                    format!(
                        "at t = {time} s the communication step {} s is above {} s, the \
                         largest at which the axle-box exchange stays stable under a Jacobi \
                         master (OSP libcosim, ecos: every unit steps from the same point), \
                         estimated from the exchange's amplification matrix with the primary \
                         springs and dampers vehicle.primary.* and the side frames' inertia; \
                         under such a master expect it to diverge and use steps of at most {} \
                         s. A sequential master that steps TrackContact first and hands this \
                         unit its primary.*.mean_force stays stable to {} s",
                        num(h),
                        num(e.jacobi),
                        num(e.jacobi),
                        num(e.sequential)
                    )
                };
                StepWarning {
                    kind: "axle-box step",
                    message,
                    severity: h / e.jacobi,
                }
            });
        }
        let Engine::Sim(sim) = &self.engine else {
            return None;
        };
        // The input datum taken again from the second step's inputs (`datum.rs`) comes
        // first; the contact watch below follows every step all the same.
        let axle_box = matches!(sim.vehicle(), VehicleState::AxleBox(_));
        let datum = self.datum.take_warning(axle_box, time);
        // TrackContact at the axle boxes: what it knows of its partner (at every step:
        // with vehicle.sideframe.source = auto it takes the fitted side frames here);
        // warned of only when new or worse, so it hides nothing the others hold.
        let partner = match (&mut self.partner, &mut self.engine) {
            (Some(p), Engine::Sim(sim)) => p.warning(sim, time, self.last_step),
            _ => None,
        };
        let other = self.track_warning(time, at_stop);
        datum
            .map(|w| StepWarning::once("input datum", w))
            .or(partner)
            .or(other)
    }

    /// [`FmuModel::warning_after_step`] for the units that carry the track: the contact
    /// watch, the fixed rail end's zone.
    fn track_warning(&mut self, time: f64, at_stop: bool) -> Option<StepWarning> {
        let Engine::Sim(sim) = &self.engine else {
            return None;
        };
        // TrackContact at the contact interface: what it sees of the exchange (the
        // watch follows every step, whichever warning is returned).
        let mut contact = None;
        if self.kind == Kind::TrackContact && matches!(sim.vehicle(), VehicleState::External { .. })
        {
            let load = sim.static_load()[0].max(sim.static_load()[1]);
            // No list built at every step: the wheelsets' forces as they come.
            let forces = sim.wheelsets().iter().map(|w| w.forces());
            let chatter = self.watch.forces_at_point(forces, load);
            let jump = self.watch.take_jump(load);
            let held = !sim.wheelsets().iter().any(|w| match w.vehicle() {
                VehicleState::External { rates, .. } => rates.moves(),
                _ => false,
            });
            let ratio = self.last_step / sim.dt();
            let most = if held { HELD_STEPS } else { INTERPOLATED_STEPS };
            contact = if let Some(name) = chatter {
                Some(StepWarning::once(
                    "contact chatter",
                    format!(
                        "at t = {time} s {name} has jumped up and down at each of the last \
                     communication points: the contact exchange chatters, its forces are \
                     numerical; the communication step {} s ({ratio:.1} track steps) is beyond \
                     what an explicit exchange of the stiff contact tolerates; use the \
                     track's step solver.step = {} s, or the axle-box interface (interface = \
                     axle_box) for a vehicle model that steps at a millisecond",
                        num(self.last_step),
                        num(sim.dt())
                    ),
                ))
            } else if let Some((j, name)) = jump {
                Some(StepWarning::worse(
                    "contact exchange",
                    j / load,
                    format!(
                        "at t = {time} s {name} jumped by {} N ({:.0} % of the static load) when \
                     the wheel heights of this communication point came in: the heights the \
                     vehicle returns are far from those the track held over the step, so the \
                     contact exchange chatters and its forces are numerical; the \
                     communication step {} s ({ratio:.1} track steps) is beyond what an \
                     explicit exchange of the stiff contact tolerates; use the track's step \
                     solver.step = {} s, or the axle-box interface (interface = axle_box) for \
                     a vehicle model that steps at a millisecond",
                        num(j),
                        100.0 * j / load,
                        num(self.last_step),
                        num(sim.dt())
                    ),
                ))
            } else if self.watch.is_coupled()
                && (ratio - ratio.round()).abs() > 1e-3
                && !at_stop
                && {
                    self.off_grid_steps += 1;
                    self.off_grid_steps > 1
                }
            {
                // A run's last step, shorter than the others when the stop time is not a
                // whole number of them, is no reason to warn; masters such as OMSimulator
                // and PyFMI's Master do not give the stop time (stopTimeDefined false), so
                // the first step off the grid is not warned of, the second is.
                Some(StepWarning::once(
                    "contact step grid",
                    format!(
                        "at t = {time} s the communication step {} s is {ratio:.3} track steps \
                     (solver.step = {} s), the second step of this run off the track's grid \
                     (the first is not warned of: it may be a run's last, shorter step): \
                     the track steps on its own grid, so the wheel \
                     heights and contact forces meet at other times than the master's (the \
                     peak of the reference flat +4.7 % at half a track step); use a whole \
                     number of solver.step",
                        num(self.last_step),
                        num(sim.dt())
                    ),
                ))
            } else if ratio > most && self.watch.is_coupled() {
                Some(StepWarning::worse(
                    "contact step",
                    ratio / most,
                    format!(
                        "at t = {time} s the communication step {} s is {ratio:.1} track steps \
                     (solver.step = {} s) with {}: the contact exchange's error grows with \
                     the step (peak of the reference flat: held heights +1.1 %, +4.2 %, +12 % \
                     at 2, 5, 10 track steps under a sequential master, +2.2 %, +7.0 %, +19 % \
                     under a Jacobi one; with the wheel velocities +0.7 % at 5, +3.3 % at 10); \
                     use at most {} s, give the wheel velocities (fmi2SetRealInputDerivatives), \
                     or couple at the axle boxes (interface = axle_box)",
                        num(self.last_step),
                        num(sim.dt()),
                        if held {
                            "the wheel heights held over it"
                        } else {
                            "the wheel heights extrapolated with their derivatives"
                        },
                        num(most.floor() * sim.dt())
                    ),
                ))
            } else {
                self.watch
                    .rate_warning()
                    .map(|m| StepWarning::once("axle rate", format!("at t = {time} s {m}")))
            };
        }
        // TrackContact at the axle boxes: any partner's exchange, unstable or fed the
        // wrong output, shows as wheels that bounce more often than their flats strike.
        if self.kind == Kind::TrackContact && matches!(sim.vehicle(), VehicleState::AxleBox(_)) {
            let load = sim.static_load()[0].max(sim.static_load()[1]);
            let lead = sim.wheelsets().iter().next().map(|w| &w.wheels()[0]);
            let turn = lead.map_or(f64::INFINITY, |w| std::f64::consts::TAU * w.radius())
                / sim.speed().abs().max(1e-3);
            let wheels = sim.wheelsets().iter().map(|w| {
                let WheelProfile::Flatted(l) = &w.wheels()[0];
                let WheelProfile::Flatted(r) = &w.wheels()[1];
                (w.forces(), [l.flats().len(), r.flats().len()])
            });
            if let Some((name, n, turn)) = self.watch.strikes_at_point(time, wheels, load, turn) {
                contact = Some(StepWarning::once(
                    "axle-box exchange bounces",
                    format!(
                        "at t = {time} s {name} has struck the rail {n} times in the last {} s \
                     (nine tenths of a turn of the wheel), each at more than twice the static \
                     load after lifting off, more than its flats explain: the axle-box exchange is unstable and \
                     its forces are numerical. Likely causes: the communication step {} s is \
                     beyond the stable step of your bogie's exchange (try half of it), or a \
                     Jacobi master (every unit from the same point: OSP libcosim, ecos) hands \
                     your bogie primary.*.mean_force, meant for a master that steps the track \
                     first: under a Jacobi master read primary.*.force",
                        num(turn),
                        num(self.last_step)
                    ),
                ));
            }
        }
        let TrackSpec::Discrete(p) = &sim.scenario().track else {
            return contact;
        };
        if sim.window().is_some() {
            return contact;
        }
        let zone = p.length() - END_ZONE_SPANS * p.sleeper_spacing;
        let x = sim.position();
        if x <= zone {
            return contact;
        }
        Some(StepWarning::once(
            "rail end",
            format!(
                "at t = {time} s the wheel is at {x:.3} m, within {END_ZONE_SPANS} sleeper spans \
                 of the fixed rail end at {:.3} m: the end's reflections raise impact forces \
                 here (by 20 to 35 % near the last sleeper but one); the run ends with \
                 fmi2Discard at that sleeper, {:.3} m (the last span carries no wheel); keep \
                 the impacts of interest at least {END_ZONE_SPANS} spans from the ends \
                 (track.spans)",
                p.length(),
                p.running_length()
            ),
        ))
    }
}

/// Why the forces that drove a vehicle's first step do not hold it at rest (more than
/// 1 % off, wheel by wheel), in words; `None` when they do.
fn off_rest(u: &VehicleUnit) -> Option<String> {
    let (names, partner) = if u.is_axle_box() {
        (
            "axle_box.*.force",
            "TrackContact's static_load.* (and its vehicle.wheelset.*, vehicle.primary.*, gravity) \
             to this vehicle's",
        )
    } else {
        (
            "contact.*.force",
            "TrackContact's static_load.* to this vehicle's",
        )
    };
    let mut worst: Option<(f64, f64, f64)> = None;
    for k in 0..u.wheelsets() {
        let (Some(held), Some(rest)) = (u.held_forces_of(k), u.rest_forces_of(k)) else {
            continue;
        };
        for s in 0..2 {
            let off = (held[s] - rest[s]).abs() / rest[s].abs().max(1.0);
            if off > 0.01 && worst.is_none_or(|(o, _, _)| off > o) {
                worst = Some((off, held[s], rest[s]));
            }
        }
    }
    let (off, held, rest) = worst?;
    // Every force exactly 0: connectors at their initial value, as fmpy's simulate_ssp
    // starts them, before the partner's forces come in (issue 38).
    let all_zero = (0..u.wheelsets())
        .filter_map(|k| u.held_forces_of(k))
        .all(|f| f == [0.0; 2]);
    if all_zero {
        return Some(format!(
            "the {names} that drove the first step are all 0 N, not the {} N that hold this \
             vehicle at rest: connectors that start at 0 (fmpy's simulate_ssp starts them \
             so) before the partner's forces come in; the vehicle fell freely for that step. \
             Start the connectors at the partner's initial outputs where the master allows",
            num(rest)
        ));
    }
    let load = u.static_load();
    Some(format!(
        "the {names} that drove the first step ({} N) are {:.1} % off the {} N that hold this \
         vehicle at rest: its partner does not carry it at rest and it will start moving; \
         set {partner} (static_load.left = {} N, static_load.right = {} N)",
        num(held),
        100.0 * off,
        num(rest),
        num(load[0]),
        num(load[1])
    ))
}
