//! TrackContact at the axle boxes and a partner it does not know (issue 41): the
//! exchange's stable step from the side frames it carries ([`carried_limits`]), the
//! partner's side frames and the force it holds fitted from the exchange
//! ([`PartnerFit`]), and the warnings they give: an output that does not suit the
//! master, a copy of the side frames off the partner's (or, with
//! `vehicle.sideframe.source = auto`, the fitted ones taken), a step beyond the stable
//! one, and the exchange's own error, the jump of the primary forces when the
//! partner's side-frame motion comes in.

use crate::error::{Result, num};
use crate::fmu::fmi2::{StepWarning, Warned};
use crate::sim::{SideFrameSpec, Simulation, VehicleSpec};
use crate::vehicle::{
    CONTACT_STIFFNESS, ExchangeLimits, HeldForce, PartnerFit, RollPlaneParams, SideFrameInertia,
    carried_limits,
};

/// A fitted side-frame pitch inertia this far off the carried one (a share) is warned
/// of: the pitch is fitted from the primary moment alone, which nothing unseen enters
/// (within 0.1 % for every partner measured).
pub const COPY_TOLERANCE: f64 = 0.10;

/// A fitted side-frame mass this far off the carried one (a share) is warned of. The
/// bounce cannot be told apart from bodies that move fast above the side frames: the
/// exchange sees the side frame and what moves with it. Measured at 1 ms against the
/// side frames' own masses: the stand-in bogie (RK4, its bolster under the car body)
/// within 1 %; this project's half-car bogie -3.5 % (its central differences); the
/// roll-plane vehicle +15 % (+1 % at 2 ms, +12 % at 4 ms: its 232.5 kg bolster, which
/// carries the car body's weight but not its mass, bounces on the secondary springs
/// beside the side frames).
pub const MASS_TOLERANCE: f64 = 0.35;

/// The side frames are fitted (checked, or taken with `auto`) at communication steps
/// of at most this many radians of their bounce on the primary springs,
/// `h sqrt(K_1 (D + X))`: beyond, the fit's differences no longer resolve the motion
/// (the half-car's side frames, 447.5 kg, fitted 432, 428, 422, 416, 403 and 370 kg at
/// 1, 2, 4, 6, 8 and 16 ms, 0.17 to 2.7 rad).
pub const FIT_STEP_RADIANS: f64 = 1.1;

/// The primary forces' jump at a communication point, as a share of the static load,
/// above which the exchange's error is warned of. Measured with the half-car bogie on
/// the reference flat, the peaks' error was 1/15 to 1/60 of the largest jump (9 % and
/// 0.6 % under a Jacobi master at 1 ms, 23 % and 0.85 % at 2 ms, 41 % and 1.2 % at 3 ms,
/// 13.5 % and 0.9 % under a sequential one at 16 ms): only a large jump tells.
pub const JUMP_TOLERANCE: f64 = 0.60;

/// What TrackContact at the axle boxes knows of its partner; see the module.
#[derive(Debug, Clone)]
pub(super) struct PartnerWatch {
    fit: PartnerFit,
    /// The wheelset and primary suspension carried, and the static wheel loads (N).
    wheelset: RollPlaneParams,
    static_load: [f64; 2],
    /// The side frames carried: a side frame's mass (kg: the whole side frame over two
    /// wheelsets, or the one over an axle box) and pitch inertia (kg m^2, shared side
    /// frames), their wheelbase (m).
    mass: f64,
    pitch_inertia: Option<f64>,
    wheelbase: f64,
    /// The carried side frames' bounce on the primary springs (rad/s).
    omega: f64,
    /// `vehicle.sideframe.source = auto`.
    auto: bool,
    /// The fitted side frames taken (auto).
    adopted: bool,
    limits: Option<ExchangeLimits>,
    /// The point forces after the last step (N per box), for the jump.
    point: Vec<f64>,
    /// The largest jump of the primary forces when inputs came in, since the last
    /// warning's check (N), and where.
    jump: f64,
    /// The conditions warned of (each watched alike at every step, so that one that
    /// holds hides none of the others behind the layer's own record).
    warned: Warned,
    /// Communication steps taken.
    steps: u64,
    /// What it did of its own accord since last asked (the fitted side frames taken).
    events: Vec<String>,
    /// The side frames handed on at the last point (m, m/s), and the points in a row at
    /// which their displacements moved while their velocities stayed as they were.
    last_frames: Option<(Vec<f64>, Vec<f64>)>,
    still_velocities: u32,
    /// The primary forces at rest (N per box) and their largest departure from it so far,
    /// as a share of the static load: whether an impact has run before auto took the
    /// fitted side frames.
    rest: Vec<f64>,
    departure: f64,
    /// The static wheel load the partner's first step shows (N per wheel, left and
    /// right), once the first step is in.
    partner_load: Option<[f64; 2]>,
}

/// The partner's static wheel loads, as its first step shows them, this far off
/// `static_load.*` (a share of the static load) are warned of: 1 % moved the half-car's
/// peaks by 2.6 % under a Jacobi master at 1 ms (the trial).
const STATIC_TOLERANCE: f64 = 0.005;

/// Points in a row at which the side frames' displacements move and their velocities do
/// not, before TrackContact warns that the velocities are not handed on.
const STILL_VELOCITY_POINTS: u32 = 10;

/// The departure of the primary forces from rest (a share of the static load) past which
/// an impact has run: auto's fitted side frames taken after it come too late for it.
const IMPACT_DEPARTURE: f64 = 0.05;

/// Communication steps the step's warning waits for the fit to tell the master's kind
/// (it decides after 20 to 25 with the reference flat); then, still unknown, the Jacobi
/// limit holds.
const KIND_WAIT_STEPS: u64 = 40;

/// Under a Jacobi master the step is warned of above this share of the stable one: the
/// peaks' error passes 1 % there (the stand-in half-car bogie, `primary.*.force`, the
/// reference flat: 0.86 % at 0.73 of the estimate, 1.15 % at 1.10 with its side frames
/// as TrackContact's; 0.43 % at 0.55 and 1.13 % at 0.82 with them twice as heavy; 1.43 %
/// at about 1.0 with them half as heavy).
pub const JACOBI_ACCURATE: f64 = 0.75;

impl PartnerWatch {
    /// The watch of `sim` (TrackContact with side frames above its axle boxes), its
    /// side frames from `vehicle.sideframe.source`: `auto` or as configured; `None`
    /// without the axle-box interface or with nothing carried (the two-axle wagon).
    ///
    /// Errors: the carried parameters [`carried_limits`] refuses.
    pub fn new(sim: &Simulation, auto: bool) -> Result<Option<PartnerWatch>> {
        let s = sim.scenario();
        let VehicleSpec::AxleBox {
            vehicle,
            side_frames,
            ..
        } = &s.vehicle
        else {
            return Ok(None);
        };
        let (mass, pitch_inertia, shared) = match *side_frames {
            SideFrameSpec::PerWheelset { mass } => (mass, None, false),
            SideFrameSpec::HalfCar {
                mass,
                pitch_inertia,
                ..
            } => (mass, Some(pitch_inertia), true),
            SideFrameSpec::Nothing { .. } => return Ok(None),
        };
        let wheelbase = s.trailing.first().map_or(0.0, |w| w.offset);
        let static_load = sim.static_load();
        let (inertia, _) = side_frames.inertia(s)?;
        let (omega, limits) = carried(vehicle, inertia, shared, static_load)?;
        let n = sim.wheelsets().len();
        let mut w = PartnerWatch {
            fit: PartnerFit::new(n, shared, wheelbase),
            wheelset: *vehicle,
            static_load,
            mass,
            pitch_inertia,
            wheelbase,
            omega,
            auto,
            adopted: false,
            limits,
            point: Vec::new(),
            jump: 0.0,
            warned: Warned::default(),
            steps: 0,
            events: Vec::new(),
            last_frames: None,
            still_velocities: 0,
            rest: Vec::new(),
            departure: 0.0,
            partner_load: None,
        };
        w.after_step(sim);
        w.rest = w.point.clone();
        Ok(Some(w))
    }

    /// Before a step: the side-frame motion the master handed on, `h` (s) after the
    /// last point (0 at the first step).
    pub fn before_step(&mut self, sim: &Simulation, h: f64) {
        let n = sim.wheelsets().len();
        let (mut z, mut v) = (Vec::with_capacity(2 * n), Vec::with_capacity(2 * n));
        let mut now = Vec::with_capacity(2 * n);
        for k in 0..n {
            if let (Some((zk, vk)), Some(f)) = (sim.side_frames_of(k), sim.primary_force_of(k)) {
                z.extend(zk);
                v.extend(vk);
                now.extend(f);
            }
        }
        if h > 0.0 && now.len() == self.point.len() {
            for (a, b) in now.iter().zip(&self.point) {
                self.jump = self.jump.max((a - b).abs());
            }
        }
        if let Some((_, v0)) = &self.last_frames
            && h > 0.0
            && self.steps == 1
        {
            self.partner_load = Some(self.first_step_load(h, v0, &v));
        }
        if let Some((z0, v0)) = self.last_frames.replace((z.clone(), v.clone()))
            && h > 0.0
        {
            let moved = z.iter().zip(&z0).any(|(a, b)| (a - b).abs() > 1e-9);
            let still = v == v0;
            self.still_velocities = if moved && still {
                self.still_velocities + 1
            } else {
                0
            };
        }
        self.fit.side_frames_given(h, &z, &v);
    }

    /// After a step: the forces at the point and their means over the step.
    pub fn after_step(&mut self, sim: &Simulation) {
        let n = sim.wheelsets().len();
        let (mut point, mut mean) = (Vec::with_capacity(2 * n), Vec::with_capacity(2 * n));
        for k in 0..n {
            if let (Some(f), Some((m, _, _))) = (sim.primary_force_of(k), sim.primary_of(k)) {
                point.extend(f);
                mean.extend(m);
            }
        }
        self.fit.forces_at_point(&point, &mean);
        let load = self.static_load[0].max(self.static_load[1]);
        for (p, r) in point.iter().zip(&self.rest) {
            self.departure = self.departure.max((p - r).abs() / load);
        }
        self.point = point;
    }

    /// The static wheel loads `[left, right]` (N) under which the partner's side frames
    /// stay at rest, from their velocity change `v0` to `v` (m/s per box) over the first
    /// step `h` (s): the primary forces handed over it were the static ones of
    /// `static_load.*`, so a partner whose own differ moves off at `(F - F_own) / m`, the
    /// carried side frames' mass `m`.
    fn first_step_load(&self, h: f64, v0: &[f64], v: &[f64]) -> [f64; 2] {
        let m = self.per_axle_box(self.mass);
        let mut off = [0.0; 2];
        let boxes = v.len().min(v0.len());
        for i in 0..boxes {
            off[i % 2] += m * (v[i] - v0[i]) / h / (boxes / 2) as f64;
        }
        // The partner's static primary force is TrackContact's minus what moved it.
        let ours = self.static_load;
        [ours[0] - off[0], ours[1] - off[1]]
    }

    /// A side frame's mass `mass` (kg) as `vehicle.sideframe.mass` gives it, per axle
    /// box: half of it where a side frame spans two wheelsets (pitching, shared).
    fn per_axle_box(&self, mass: f64) -> f64 {
        if self.pitch_inertia.is_some() {
            0.5 * mass
        } else {
            mass
        }
    }

    /// What it did of its own accord since last asked.
    pub fn take_events(&mut self) -> Vec<String> {
        std::mem::take(&mut self.events)
    }

    /// A state restored: the fit forgets the last point, its sums stay.
    pub fn restart(&mut self) {
        self.fit.restart();
        self.point.clear();
    }

    /// The warning after a step of `h` (s) ending at `time` (s), if any: the output
    /// choice, the copy of the side frames (or, auto, the fitted ones taken), the step
    /// beyond the stable one, the exchange's jump.
    pub fn warning(&mut self, sim: &mut Simulation, time: f64, h: f64) -> Option<StepWarning> {
        self.steps += 1;
        if self.still_velocities >= STILL_VELOCITY_POINTS
            && self.warned.fresh("side-frame velocities", 1.0)
        {
            return Some(StepWarning::once(
                "side-frame velocities",
                format!(
                    "at t = {time} s the side frames' velocities sideframe.*.v have stayed as \
                     they were for {STILL_VELOCITY_POINTS} communication points while their \
                     displacements sideframe.*.z moved: TrackContact moves the side frames on \
                     over each step from the velocities handed on and computes the primary \
                     dampers' forces from them, so velocities left unset (or held) give wrong \
                     forces; connect the bogie's side-frame velocities (m/s, up) to \
                     sideframe.*.v"
                ),
            ));
        }
        if let Some(own) = self.partner_load {
            let load = self.static_load[0].max(self.static_load[1]);
            let off = (0..2)
                .map(|s| (own[s] - self.static_load[s]).abs() / load)
                .fold(0.0, f64::max);
            if off > STATIC_TOLERANCE && self.warned.fresh("static load", 1.0) {
                return Some(StepWarning::once(
                    "static load",
                    format!(
                        "at t = {time} s the partner's side frames moved off at the first \
                         step as under primary forces {:.1} % off those that hold it at rest: \
                         its static wheel loads are about {} N left and {} N right (from the \
                         side frames' velocities over that step and the carried side frames' \
                         mass), TrackContact's static_load.* {} N and {} N; set static_load.* \
                         to your bogie's wheel loads, or the bogie starts with a bounce that \
                         moves the peaks",
                        100.0 * off,
                        sig(own[0]),
                        sig(own[1]),
                        num(self.static_load[0]),
                        num(self.static_load[1])
                    ),
                ));
            }
        }
        let estimate = self.fit.estimate();
        let held = estimate.map(|e| e.held);
        if let Some(e) = estimate
            && e.held.output() != e.held.right_output()
            && self.warned.fresh("axle-box output", 1.0)
        {
            return Some(StepWarning::once(
                "axle-box output",
                output_message(time, e.held, e.residual),
            ));
        }
        if let Some(e) = estimate.filter(|_| h * self.omega <= FIT_STEP_RADIANS) {
            // Side frames outside every physical range: not the partner's, the inputs.
            let physical =
                crate::limits::check("vehicle.sideframe.mass", self.per_axle_box(e.mass)).is_ok()
                    && e.pitch_inertia.is_none_or(|j| {
                        crate::limits::check("vehicle.sideframe.pitch_inertia", j).is_ok()
                    });
            if !physical {
                return self.warned.fresh("side-frame units", 1.0).then(|| {
                    StepWarning::once(
                        "side-frame units",
                        format!(
                            "at t = {time} s the side-frame motion handed on, fitted against the \
                             primary forces the bogie held, gives side frames of {} kg{}: \
                             outside the range of vehicle.sideframe.*, so not a bogie's; check \
                             that sideframe.*.z are the side frames' displacements in m and \
                             sideframe.*.v their velocities in m/s, both up",
                            sig(e.mass),
                            e.pitch_inertia
                                .map_or(String::new(), |j| format!(" and {} kg m^2", sig(j)))
                        ),
                    )
                });
            }
            let pitch = e.pitch_inertia.zip(self.pitch_inertia);
            let off_mass = (e.mass / self.mass - 1.0).abs();
            let off_pitch = pitch.map_or(0.0, |(f, c)| (f / c - 1.0).abs());
            // Each against its own tolerance: the pitch is told exactly, the bounce
            // with whatever moves fast above the side frames.
            let severity = (off_mass / MASS_TOLERANCE).max(off_pitch / COPY_TOLERANCE);
            if self.auto {
                // What the fit tells beyond its tolerance is taken when first decided,
                // and again when it moves by more than 2 %.
                let mass = if off_mass > MASS_TOLERANCE {
                    e.mass
                } else {
                    self.mass
                };
                let moved = (mass / self.mass - 1.0).abs() > 0.02 || off_pitch > 0.02;
                if !self.adopted || moved {
                    // Side frames beyond the tolerances taken after an impact: it ran with
                    // the configured ones.
                    let late = severity > 1.0 && self.departure > IMPACT_DEPARTURE;
                    let before = self.copy_message(time, e.mass, e.pitch_inertia);
                    self.adopt(sim, mass, e.pitch_inertia);
                    if late && self.warned.fresh("side frames taken late", 1.0) {
                        return Some(StepWarning::once(
                            "side frames taken late",
                            format!(
                                "vehicle.sideframe.source = auto took the partner's side frames \
                                 only after an impact had run with the configured ones (the fit \
                                 decides about 25 communication steps after the motion starts), \
                                 so that impact's forces are off: {before}"
                            ),
                        ));
                    }
                }
            } else if severity > 1.0 && self.warned.fresh("side-frame copy", severity) {
                return Some(StepWarning::worse(
                    "side-frame copy",
                    severity,
                    format!(
                        "{}, or vehicle.sideframe.source = auto to take the fitted ones",
                        self.copy_message(time, e.mass, e.pitch_inertia)
                    ),
                ));
            }
        }
        if let Some(l) = self.limits {
            // The master's kind once the fit knows it; still unknown after
            // KIND_WAIT_STEPS, the Jacobi limit, the lower.
            let jacobi = held.is_none_or(HeldForce::is_jacobi);
            let limit = if jacobi { l.jacobi } else { l.sequential };
            // Under a Jacobi master the error grows as the step nears the stable one.
            let most = if jacobi {
                JACOBI_ACCURATE * limit
            } else {
                limit
            };
            let known = held.is_some() || self.steps > KIND_WAIT_STEPS;
            if known && h > most * (1.0 + 1e-9) && self.warned.fresh("axle-box step", h / most) {
                return Some(StepWarning::worse(
                    "axle-box step",
                    h / most,
                    self.step_message(time, h, (limit, most, l.sequential), held),
                ));
            }
        }
        let load = self.static_load[0].max(self.static_load[1]);
        let jump = std::mem::take(&mut self.jump);
        if jump > JUMP_TOLERANCE * load
            && self
                .warned
                .fresh("axle-box jump", jump / load / JUMP_TOLERANCE)
        {
            return Some(StepWarning::worse(
                "axle-box jump",
                jump / load / JUMP_TOLERANCE,
                format!(
                    "at t = {time} s the primary forces jumped by {} N ({:.1} % of the static \
                     load) when the side frames' motion came in: the bogie's side frames \
                     moved over the communication step {} s otherwise than those TrackContact \
                     carries, so the exchange's forces are off by as much (more than {:.0} % \
                     of the static load). Likely causes: the step (try half of it), side \
                     frames carried that are not the partner's (vehicle.sideframe.*), or a \
                     Jacobi master handing on primary.*.mean_force (read primary.*.force); \
                     TrackContact names the one it finds once the exchange shows it",
                    sig(jump),
                    100.0 * jump / load,
                    sig(h),
                    100.0 * JUMP_TOLERANCE
                ),
            ));
        }
        None
    }

    /// Carries the fitted side frames: `mass` (kg) and `pitch_inertia` (kg m^2, the
    /// carried one kept where the fit has none).
    fn adopt(&mut self, sim: &mut Simulation, mass: f64, pitch_inertia: Option<f64>) {
        let j = pitch_inertia.or(self.pitch_inertia);
        let inertia = match j {
            Some(j) => SideFrameInertia::pitching(mass, j, self.wheelbase),
            None => SideFrameInertia::single(mass),
        };
        // Fitted values outside what the links take are not taken (the warning of the
        // copy stays as it was).
        if sim.set_side_frame_inertia(inertia).is_ok() {
            let per_box = self.per_axle_box(mass);
            self.events.push(format!(
                "vehicle.sideframe.source = auto: at t = {} s took the partner's side frames as \
                 fitted from the exchange: vehicle.sideframe.mass = {} kg per axle box{}",
                sim.time(),
                sig(per_box),
                j.map_or(String::new(), |j| format!(
                    ", vehicle.sideframe.pitch_inertia = {} kg m^2",
                    sig(j)
                ))
            ));
            self.mass = mass;
            self.pitch_inertia = j;
            self.adopted = true;
            if let Ok((omega, limits)) =
                carried(&self.wheelset, inertia, j.is_some(), self.static_load)
            {
                (self.omega, self.limits) = (omega, limits);
            }
        }
    }

    /// The copy of the side frames against the fitted `mass` (kg) and `pitch` (kg m^2):
    /// what is carried, how far off, and the values beyond their tolerances to set.
    fn copy_message(&self, time: f64, mass: f64, pitch: Option<f64>) -> String {
        let (per_box, set_mass) = (self.per_axle_box(self.mass), self.per_axle_box(mass));
        // How far each carried value is from the partner's, as a share of the partner's.
        let off = |carried: f64, fitted: f64| format!("{:+.0} %", 100.0 * (carried / fitted - 1.0));
        let mut carried = format!(
            "vehicle.sideframe.mass = {} kg per axle box ({} against the partner's)",
            num(per_box),
            off(self.mass, mass)
        );
        let mut fitted = format!("{} kg", sig(mass));
        let mut set = Vec::new();
        if (mass / self.mass - 1.0).abs() > MASS_TOLERANCE {
            set.push(format!(
                "vehicle.sideframe.mass = {} kg (per axle box)",
                sig(set_mass)
            ));
        }
        if let (Some(c), Some(f)) = (self.pitch_inertia, pitch) {
            carried = format!(
                "vehicle.sideframe.mass = {} kg per axle box (a side frame of {} kg, {}) and \
                 vehicle.sideframe.pitch_inertia = {} kg m^2 ({})",
                num(per_box),
                num(self.mass),
                off(self.mass, mass),
                num(c),
                off(c, f)
            );
            fitted = format!("{} kg and {} kg m^2 per side frame", sig(mass), sig(f));
            if (f / c - 1.0).abs() > COPY_TOLERANCE {
                set.push(format!(
                    "vehicle.sideframe.pitch_inertia = {} kg m^2 (unless your bogie's wheelbase \
                     is not wheelset[2].offset = {} m: the pitch inertia fitted scales with \
                     its square, so set that instead)",
                    sig(f),
                    num(self.wheelbase)
                ));
            }
        }
        format!(
            "at t = {time} s the partner's side frames, fitted from the exchange (their \
             velocities against the primary forces they held), are {fitted}; TrackContact \
             carries {carried}: over each communication step it moves side frames that are \
             not the partner's, which moves the peaks and the stable step (lighter side \
             frames lower it: mind the step warning that follows); set {}",
            set.join(" and ")
        )
    }

    /// The step `h` (s) against `limit`, the stable step of the master seen (s), `most`,
    /// the step warned above (s), and `sequential`, a sequential master's stable step.
    fn step_message(
        &self,
        time: f64,
        h: f64,
        (limit, most, sequential): (f64, f64, f64),
        held: Option<HeldForce>,
    ) -> String {
        let master = match held {
            Some(f) if f.is_jacobi() => {
                "a Jacobi master (every unit from the same point), as the exchange shows"
            }
            Some(_) => "a sequential master (TrackContact first), as the exchange shows",
            None => {
                "a Jacobi master (every unit from the same point: OSP libcosim, ecos), if it \
                 is one: the exchange has not shown the master's kind in 40 steps"
            }
        };
        let what = if h > limit {
            "expect the forces to grow and diverge"
        } else {
            "below it, but above three quarters of it, where a Jacobi exchange's error on the \
             peaks passes 1 % (the stand-in bogie of tests/test_partner_bogie.py: 1.15 % at \
             1.1 times three quarters)"
        };
        let other = if held.is_none() {
            format!(
                " (under a sequential master that steps TrackContact first and hands the bogie \
                 primary.*.mean_force the stable step is {} s)",
                sig(sequential)
            )
        } else {
            String::new()
        };
        format!(
            "at t = {time} s the communication step {} s is {} the largest at which \
             the axle-box exchange stays stable under {master}, {} s, estimated from what \
             TrackContact carries (the wheelsets on the contact, the primary suspension \
             vehicle.primary.*, the side frames vehicle.sideframe.*): {what}; use steps of at \
             most {} s{other}",
            sig(h),
            if h > limit { "above" } else { "near" },
            sig(limit),
            sig(most)
        )
    }
}

/// What TrackContact's copy of the side frames `inertia` (over two wheelsets' boxes when
/// `shared`) on the primary suspension of `wheelset`, under the static wheel loads
/// `static_load` (N), sets: their bounce on the primary springs (rad/s) and the
/// exchange's stable steps ([`carried_limits`]).
fn carried(
    wheelset: &RollPlaneParams,
    inertia: SideFrameInertia,
    shared: bool,
    static_load: [f64; 2],
) -> Result<(f64, Option<ExchangeLimits>)> {
    let omega = (wheelset.primary_stiffness * (inertia.direct + inertia.cross)).sqrt();
    let limits = carried_limits(wheelset, inertia, shared, static_load, CONTACT_STIFFNESS)?;
    Ok((omega, limits))
}

fn output_message(time: f64, held: HeldForce, residual: f64) -> String {
    let fit = format!(
        "(fitted from the exchange: the side frames' velocities follow it, {:.1} % of their \
         motion left unexplained)",
        100.0 * residual
    );
    match held {
        HeldForce::JacobiMean => format!(
            "at t = {time} s the bogie holds primary.*.mean_force of the step before {fit}: a \
             Jacobi master (every unit from the same point: OSP libcosim, ecos) hands it the \
             mean force meant for a master that steps TrackContact first, a step late, which \
             bounces beyond a millisecond or two; connect primary.*.force to the bogie's \
             axle-box inputs instead"
        ),
        _ => format!(
            "at t = {time} s the bogie holds primary.*.force at the end of the step TrackContact \
             just took {fit}: a sequential master that steps TrackContact first hands it the \
             force at the point, meant for a Jacobi master, a step early (+0.8 % on the peaks \
             at 1 ms, unstable from 5 ms); connect primary.*.mean_force to the bogie's axle-box \
             inputs instead"
        ),
    }
}

/// `x` to four significant digits, as a person reads a fitted value.
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (3 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}
