//! The wheelsets of a simulation: each with its two wheels, its place behind the
//! leading wheelset and its contact states, and the loads they put on the rails.

use super::accelerations::Accelerations;
use super::clock::ForceExtremes;
use super::vehicle_state::VehicleState;
use crate::contact::{ContactLaw, ContactState};
use crate::error::{Result, non_negative};
use crate::numerics::CosineSeries;
use crate::track::PointLoad;
use crate::wheel::OutOfRoundness;
use crate::wheel::{FlatSpec, WheelProfile};
use std::cell::Cell;
use std::sync::Arc;

/// Everything reported at one instant for one wheelset.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Time `t_j` (s).
    pub time: f64,
    /// Wheelset position along the track (m).
    pub position: f64,
    /// Axle rotation angle `gamma` (rad) (2.17).
    pub rotation: f64,
    /// Wheel-centre displacements `[left, right]` (m), up positive.
    pub wheel_z: [f64; 2],
    /// Rail displacements under the wheels `[left, right]` (m) (3.23).
    pub rail_z: [f64; 2],
    /// Contact states `[left, right]`: force, overlap (2.7), patch angles (2.22), length.
    pub contact: [ContactState; 2],
}

/// One wheelset on the track: its left and right wheel (nominal radius `R_w` and
/// flats, 2.9-2.21), its distance `d_k >= 0` (m) behind the leading wheelset (it runs at
/// `x_k = x_1 - d_k`), what moves its wheels (its vehicle: a roll-plane vehicle, lumped
/// wheels, constant loads or external inputs), its contact states and the extremes of
/// its contact forces.
#[derive(Debug, Clone)]
pub struct Wheelset {
    wheels: [WheelProfile; 2],
    /// The wheels' measured out-of-roundness (none: round but for the flats).
    roundness: [Option<Arc<OutOfRoundness>>; 2],
    /// The wheels' drawn roughness, radius deviation (m) against wheel angle (rad),
    /// through the contact filter (none: smooth).
    roughness: [Option<Arc<CosineSeries>>; 2],
    offset: f64,
    pub(crate) vehicle: VehicleState,
    pub(crate) extremes: ForceExtremes,
    /// The wheels' and the rail's accelerations under them.
    pub(crate) accelerations: Accelerations,
    // The sample of the latest step, contact states included, built here in place by
    // `Simulation::step` (a sample built in a temporary and copied at once stalled the
    // copy's wide loads on the narrow stores that had just built it).
    pub(crate) latest: Sample,
    // The sample at the current time and inputs, once computed (a co-simulation master
    // reads the outputs and then steps: the contact is evaluated once).
    pub(crate) cached: Cell<Option<Sample>>,
}

impl Wheelset {
    /// A wheelset `offset` (m) behind the leading one whose wheels have the nominal
    /// radius `radius` (m) and the flats `flats` `[left, right]`, moved by `vehicle`.
    ///
    /// Errors: `offset` negative or not finite; a radius or flat that
    /// [`WheelProfile::new`] refuses (named `{name}flat.left` or `{name}flat.right`:
    /// `name` is `""` for the leading wheelset, `"wheelset[k]."` for wheelset k).
    pub fn new(
        radius: f64,
        flats: &[Vec<FlatSpec>; 2],
        offset: f64,
        vehicle: VehicleState,
        name: &str,
    ) -> Result<Wheelset> {
        non_negative(&format!("{name}offset"), offset, "m")?;
        Ok(Wheelset {
            wheels: [
                WheelProfile::new(radius, &flats[0], &format!("{name}flat.left"))?,
                WheelProfile::new(radius, &flats[1], &format!("{name}flat.right"))?,
            ],
            roundness: [None, None],
            roughness: [None, None],
            offset,
            vehicle,
            extremes: ForceExtremes::NONE,
            accelerations: Accelerations::NONE,
            latest: Sample::default(),
            cached: Cell::new(None),
        })
    }

    /// The wheelset with the wheels' measured out-of-roundness `[left, right]`.
    pub fn with_roundness(mut self, roundness: [Option<Arc<OutOfRoundness>>; 2]) -> Self {
        self.roundness = roundness;
        self
    }

    /// The wheelset with the wheels' drawn roughness `[left, right]` (radius deviation
    /// (m) against wheel angle (rad), `crate::contact::RoughnessSpectrum::wheel`).
    pub fn with_roughness(mut self, roughness: [Option<Arc<CosineSeries>>; 2]) -> Self {
        self.roughness = roughness;
        self
    }

    /// Whether a wheel has an out-of-roundness or a roughness.
    pub fn is_out_of_round(&self) -> bool {
        self.roundness.iter().any(Option::is_some) || self.roughness.iter().any(Option::is_some)
    }

    /// The radius deviation (m) of wheel `i` (0 left, 1 right) where it touches the
    /// rail at axle rotation `gamma` (rad): its out-of-roundness and its roughness at
    /// wheel angle `gamma`; 0 for a wheel without either.
    #[inline(always)]
    pub fn radius_deviation(&self, i: usize, gamma: f64) -> f64 {
        self.roundness[i].as_ref().map_or(0.0, |r| r.at(gamma))
            + self.roughness[i].as_ref().map_or(0.0, |r| r.eval(gamma).0)
    }

    /// `d/d gamma` of [`Wheelset::radius_deviation`] (m/rad).
    pub fn radius_deviation_slope(&self, i: usize, gamma: f64) -> f64 {
        self.roundness[i]
            .as_ref()
            .map_or(0.0, |r| r.slope_at(gamma))
            + self.roughness[i].as_ref().map_or(0.0, |r| r.eval(gamma).1)
    }

    /// The wheels `[left, right]`.
    pub fn wheels(&self) -> &[WheelProfile; 2] {
        &self.wheels
    }
    /// What moves the wheels.
    pub fn vehicle(&self) -> &VehicleState {
        &self.vehicle
    }
    /// The latest sample, of the step last taken.
    pub fn latest(&self) -> &Sample {
        &self.latest
    }
    /// Distance `d_k` behind the leading wheelset (m).
    pub fn offset(&self) -> f64 {
        self.offset
    }
    /// Position `x_1 - d_k` (m) when the leading wheelset is at `x` (m).
    #[inline(always)]
    pub fn position(&self, x: f64) -> f64 {
        x - self.offset
    }
    /// Largest contact force per wheel `[left, right]` that has driven a step (N);
    /// `f64::MIN` before the first step.
    pub fn max_force(&self) -> [f64; 2] {
        self.extremes.max
    }
    /// Smallest contact force per wheel `[left, right]` that has driven a step (N);
    /// `f64::MAX` before the first step.
    pub fn min_force(&self) -> [f64; 2] {
        self.extremes.min
    }
    /// The vertical accelerations `[wheel left, wheel right, rail left, rail right]`
    /// (m/s^2, up) when the sample now is `now`, with their
    /// largest and smallest of the steps taken: the second differences of
    /// [`Sample::wheel_z`] and [`Sample::rail_z`] at the engine's steps
    /// ([`Accelerations`]).
    pub fn accelerations(&self, now: &Sample) -> [[f64; 4]; 3] {
        let z = [now.wheel_z[0], now.wheel_z[1], now.rail_z[0], now.rail_z[1]];
        let a = self.accelerations.now(z);
        [a, self.accelerations.max(a), self.accelerations.min(a)]
    }

    /// The accelerations' record, for their derivatives.
    pub fn acceleration_record(&self) -> &Accelerations {
        &self.accelerations
    }

    /// Takes the latest sample's displacements into the accelerations, step `dt` (s).
    #[inline(always)]
    pub(crate) fn record_accelerations(&mut self, dt: f64) {
        let s = &self.latest;
        let z = [s.wheel_z[0], s.wheel_z[1], s.rail_z[0], s.rail_z[1]];
        self.accelerations.record(z, dt);
    }

    /// The wheels, the vehicle and the latest sample, to build the sample in place.
    #[inline(always)]
    pub(crate) fn parts_mut(&mut self) -> (&[WheelProfile; 2], &VehicleState, &mut Sample) {
        (&self.wheels, &self.vehicle, &mut self.latest)
    }
    /// The contact forces `[left, right]` (N) of the latest step.
    #[inline(always)]
    pub(crate) fn forces(&self) -> [f64; 2] {
        let c = &self.latest.contact;
        [c[0].force, c[1].force]
    }
}

/// The wheelsets on the track, the leading one first (`d_1 = 0`): a list that is never
/// empty, and the one place the wheels of a simulation live.
#[derive(Debug, Clone)]
pub struct Wheelsets {
    // The leading wheelset is kept apart from the vector of the others: the step reaches
    // it without a bounds check or a pointer chase (a plain `Vec` cost 2 % of the step).
    lead: Wheelset,
    trailing: Vec<Wheelset>,
}

impl Wheelsets {
    /// The list of `lead` followed by `trailing`.
    pub(crate) fn new(lead: Wheelset, trailing: Vec<Wheelset>) -> Wheelsets {
        Wheelsets { lead, trailing }
    }
    /// Wheelset `k`, the leading one 0.
    pub fn get(&self, k: usize) -> Option<&Wheelset> {
        match k {
            0 => Some(&self.lead),
            _ => self.trailing.get(k - 1),
        }
    }
    pub(crate) fn get_mut(&mut self, k: usize) -> Option<&mut Wheelset> {
        match k {
            0 => Some(&mut self.lead),
            _ => self.trailing.get_mut(k - 1),
        }
    }
    /// The wheelsets behind the leading one.
    #[inline(always)]
    pub fn trailing(&self) -> &[Wheelset] {
        &self.trailing
    }
    #[inline(always)]
    pub(crate) fn trailing_mut(&mut self) -> &mut [Wheelset] {
        &mut self.trailing
    }
    /// Number of wheelsets (at least 1).
    pub fn len(&self) -> usize {
        1 + self.trailing.len()
    }
    /// Never: there is at least the leading wheelset.
    pub fn is_empty(&self) -> bool {
        false
    }
    /// The leading wheelset, `d_1 = 0`.
    #[inline(always)]
    pub fn lead(&self) -> &Wheelset {
        &self.lead
    }
    #[inline(always)]
    pub(crate) fn lead_mut(&mut self) -> &mut Wheelset {
        &mut self.lead
    }
    /// The wheelsets, the leading one first.
    pub fn iter(&self) -> impl Iterator<Item = &Wheelset> {
        std::iter::once(&self.lead).chain(&self.trailing)
    }
    /// Forgets every cached sample.
    #[inline(always)]
    pub(crate) fn clear_cache(&self) {
        self.lead.cached.set(None);
        for w in &self.trailing {
            w.cached.set(None);
        }
    }
    /// The wheelsets, the leading one first.
    pub(crate) fn iter_mut(&mut self) -> impl Iterator<Item = &mut Wheelset> {
        std::iter::once(&mut self.lead).chain(&mut self.trailing)
    }
}

/// The loads of every wheelset on the rails, written into `loads`, two per wheelset
/// (left rail, then right) in the order of the list: wheelset k, at `x - d_k` (m, in
/// the track's coordinates) when the leading one is at `x`, pushes each rail down with its wheel's force of
/// `p(wheelset)` `[left, right]` (N): the contact forces `P` (3.22 shares each between
/// the two nodes around it), or the static loads. `loads` holds two per wheelset.
#[inline(always)]
pub(crate) fn wheel_loads(
    x: f64,
    wheelsets: &Wheelsets,
    p: impl Fn(&Wheelset) -> [f64; 2],
    loads: &mut [PointLoad],
) {
    let place = |w: &Wheelset, pair: &mut [PointLoad]| {
        let (position, force) = (w.position(x), p(w));
        for (rail, load) in pair.iter_mut().enumerate() {
            *load = PointLoad {
                rail,
                position,
                force: force[rail],
            };
        }
    };
    let (lead, rest) = loads.split_at_mut(2);
    place(&wheelsets.lead, lead);
    if !wheelsets.trailing.is_empty() {
        for (w, pair) in wheelsets.trailing.iter().zip(rest.chunks_exact_mut(2)) {
            place(w, pair);
        }
    }
}

/// The contact states of sample `s` of a wheelset with wheels `wheels` moved by
/// `vehicle`, whose head
/// (time, rotation, wheel and rail displacements) is set, written in place: the
/// contact law at the overlaps `z_rail - z_wheel` (2.7) with the axle at the sample's
/// rotation, or the constant loads. `compliance` (m/N): the rail's local compliance
/// under the wheels ([`crate::track::Track::shear_compliance`]; 0 on a node and on the
/// lumped track), in series with the contact; the sample's rail displacements end as
/// those under the loads (lowered by `compliance` times the force). The contact
/// forces `s` holds on entry (the step before's) start the solve.
#[inline(always)]
pub(crate) fn contact_states(
    vehicle: &VehicleState,
    law: &ContactLaw,
    wheels: &[WheelProfile; 2],
    compliance: f64,
    irregularity: Option<[f64; 2]>,
    s: &mut Sample,
) {
    match vehicle {
        VehicleState::ConstantLoad(p) => {
            for (i, (c, &force)) in s.contact.iter_mut().zip(p).enumerate() {
                *c = ContactState {
                    force,
                    intervals: 1,
                    ..Default::default()
                };
                s.rail_z[i] -= compliance * force;
            }
        }
        _ => {
            let gamma = wrap_turns(s.rotation);
            for i in 0..2 {
                let mut overlap = s.rail_z[i] - s.wheel_z[i];
                if let Some(h) = irregularity {
                    overlap += h[i];
                }
                // The force of the step before (what `s` holds) starts the solve.
                let guess = s.contact[i].force;
                let p = law.evaluate_in_series_into(
                    &wheels[i],
                    gamma,
                    overlap,
                    compliance,
                    guess,
                    &mut s.contact[i],
                );
                s.rail_z[i] -= compliance * p;
            }
        }
    }
}

/// Angle `a` (rad) wrapped into [0, 2 pi).
#[inline]
fn wrap_turns(a: f64) -> f64 {
    use std::f64::consts::TAU;
    if !a.is_finite() || a.abs() > 1e15 {
        return a.rem_euclid(TAU);
    }
    // The whole number of turns is taken off by truncation rather than `rem_euclid`
    // (a libm `fmod` call): the result differs by a rounding of the turns removed,
    // which is below the rounding already in the unwrapped angle.
    let r = a - (a * (1.0 / TAU)) as i64 as f64 * TAU;
    if r < 0.0 { r + TAU } else { r }
}
