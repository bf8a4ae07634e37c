//! The stability of the axle-box exchange: the bodies above the primary suspension
//! ([`SprungBogie`], a [`SprungLinearBody`] such as [`super::SprungHalfCar`]) exchange
//! with a track that carries the wheelsets and moves the side frames on under their own
//! inertia over each step ([`super::PrimaryLink`]), every communication step `h`. The
//! exchange is explicit: the bogie holds the primary forces the track computed over the
//! step (the mean of the step under a sequential master, the force at the communication
//! point under a Jacobi master, which hands it on one step later). Springs and dampers
//! both enter it.
//!
//! [`SprungVehicle::exchange_limits`] estimates the largest stable `h` of each master kind from the
//! spectral radius of the exchange's amplification matrix: the linear map of one
//! communication step, perturbations about the static state, of the bogie's state
//! (with its own substeps), the side frames the track carries, and the forces the
//! partners hold, with the axle boxes held still (the stiff contact keeps the
//! wheelset nearly still at the side frame's frequencies). The estimate covers every
//! term that crosses the cut: the primary springs (`K_1`, any value, also with `C_1 = 0`)
//! and dampers. Measured against the whole model on the track
//! (`examples/axle_box_masters.rs --limits`) it is in docs/VALIDATION.md.

use super::MAX_AXLES;
use super::linear_body::{LinearVehicle, SprungLinearBody};
use super::rail_vehicle::{Axles, SprungVehicle};
use super::{PrimaryLink, RollPlaneParams, SideFrameInertia};
use crate::error::Result;
use nalgebra::DMatrix;

/// The track's step the estimate uses (s): the default converged grid's, about 14.4 us.
const TRACK_STEP: f64 = 14.4e-6;

/// The bodies above the primary suspension, as the exchange sees them: forces in and
/// side-frame motion out at each axle box.
trait SprungBody: Clone {
    /// Axle boxes: 2 (roll-plane vehicle) or two per wheelset (a linear vehicle, such
    /// as the half-car bogie's 4, wheelset by wheelset, left then right).
    fn boxes(&self) -> usize;
    /// The side frames' displacements and velocities at the axle boxes (m, m/s).
    fn frames(&self) -> (Vec<f64>, Vec<f64>);
    /// One substep under the primary forces `f` at the axle boxes (N, pushing the side
    /// frames up).
    fn step_boxes(&mut self, f: &[f64]);
    /// The integrator's state `[dt, d, d_prev]`.
    fn state(&self) -> Vec<f64>;
    /// Sets the displacements of [`SprungBody::state`] (the step unchanged).
    fn set_state(&mut self, v: &[f64]);
    /// Changes the substep to `dt` (s), below the bogie's critical step.
    fn set_step(&mut self, dt: f64);
}

/// The largest stable communication steps (s) of the axle-box exchange, estimated as
/// the module says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExchangeLimits {
    /// Under a sequential master (track first, the bogie with the mean force of the
    /// step just taken).
    pub sequential: f64,
    /// Under a Jacobi master (every unit from the same communication point, the bogie
    /// with the force at that point): OSP libcosim's and ecos' fixed-step algorithms.
    pub jacobi: f64,
}

/// The track side of the cut: the wheelsets under the bogie, each on a contact spring
/// to a still rail, with their primary suspensions and the side frames the track moves
/// on ([`PrimaryLink`]).
#[derive(Debug, Clone)]
struct TrackSide {
    links: Vec<PrimaryLink>,
    /// Contact stiffness per wheel (N/m) and the static contact forces and wheel heights.
    support: f64,
    p0: Vec<[f64; 2]>,
    z0: Vec<[f64; 2]>,
}

/// Values of a link's state that move: the wheelset `[d, d_prev]` (4), the side frames
/// now `z`, `v` (4), the partner's and the last primary forces (4); indices into
/// [`PrimaryLink::state_vector`]. A wheelset alone under its side frames has no partner:
/// its first 8 only (the others would stay as they are, eigenvalues 1 of nothing).
const LINK_MOVING: [usize; 12] = [1, 2, 3, 4, 12, 13, 14, 15, 18, 19, 20, 21];

impl TrackSide {
    /// One track step of every link: the contact forces of the springs, then the
    /// partners' forces handed across a shared side frame.
    fn step(&mut self) {
        for (k, link) in self.links.iter_mut().enumerate() {
            let (z, v) = (link.body().wheel_z(), link.body().box_velocity());
            let p = [0, 1].map(|s| {
                self.p0[k][s] - self.support * (z[s] - self.z0[k][s]) - SUPPORT_DAMPING * v[s]
            });
            link.step(p);
        }
        if self.links.len() == 2 {
            let (a, b) = (self.links[0].last_force(), self.links[1].last_force());
            self.links[0].set_partner_force(b);
            self.links[1].set_partner_force(a);
        }
    }
}

impl<P, const N: usize, const S: usize> SprungBody for SprungLinearBody<P, N, S>
where
    P: LinearVehicle<N, S>,
{
    fn boxes(&self) -> usize {
        2 * P::WHEELSETS
    }
    fn frames(&self) -> (Vec<f64>, Vec<f64>) {
        let (z, v) = SprungVehicle::side_frames(self);
        let n = P::WHEELSETS;
        (z[..n].concat(), v[..n].concat())
    }
    fn step_boxes(&mut self, f: &[f64]) {
        let mut a = [[0.0; 2]; MAX_AXLES];
        for (w, aw) in a.iter_mut().enumerate().take(P::WHEELSETS) {
            *aw = [f[2 * w], f[2 * w + 1]];
        }
        SprungVehicle::step(self, &a);
    }
    fn state(&self) -> Vec<f64> {
        SprungVehicle::state_vector(self)
    }
    fn set_state(&mut self, v: &[f64]) {
        self.set_integrator_displacements(v);
    }
    fn set_step(&mut self, dt: f64) {
        self.set_substep(dt);
    }
}

/// [`ExchangeLimits`] of the linear vehicle `body` above its primary suspension, at rest
/// with its axle boxes at `z` (m), substeps of at most `base` (s), its wheelsets
/// (`wheelset`: their mass, inertia and primary suspension) on contact springs of
/// `support` (N/m per wheel), the track carrying `inertia` above each axle box.
///
/// Errors: a parameter [`PrimaryLink::new`] refuses.
pub(super) fn linear_limits<P, const N: usize, const S: usize>(
    body: &SprungLinearBody<P, N, S>,
    wheelset: &RollPlaneParams,
    inertia: SideFrameInertia,
    z: &Axles,
    base: f64,
    support: f64,
) -> Result<ExchangeLimits>
where
    P: LinearVehicle<N, S>,
{
    let z_box = z[..P::WHEELSETS].concat();
    let track = track_side(body, wheelset, inertia, &z_box, support)?;
    Ok(limits_of(body, &track, base))
}

/// The amplification matrix of one communication step `h` (s) of the exchange about the
/// state of `body` and `track`, bogie substeps of at most `base` (s); `jacobi`: the bogie
/// holds the force at the communication point, else the mean of the step.
fn amplification<B: SprungBody>(
    body: &B,
    track: &TrackSide,
    h: f64,
    base: f64,
    jacobi: bool,
) -> DMatrix<f64> {
    let sub = (h / base).ceil().max(1.0);
    let mut body = body.clone();
    body.set_step(h / sub);
    let body = &body;
    let steps = (h / TRACK_STEP).ceil().max(1.0);
    let mut track = track.clone();
    for l in &mut track.links {
        // A step no longer than the contact's and the bogie's, as the track's.
        let _ = l.change_dt(h / steps);
    }
    let track = &track;
    let s0 = body.state();
    let nv = s0.len() - 1;
    let moving = if track.links.len() == 2 {
        &LINK_MOVING[..]
    } else {
        &LINK_MOVING[..8]
    };
    let states: Vec<Vec<f64>> = track.links.iter().map(|l| l.state_vector()).collect();
    let mut reference = s0[1..].to_vec();
    for st in &states {
        reference.extend(moving.iter().map(|&i| st[i]));
    }
    let n = reference.len();
    let map = |x: &[f64]| -> Vec<f64> {
        let mut b = body.clone();
        let mut st = vec![s0[0]];
        st.extend(&x[..nv]);
        b.set_state(&st);
        let mut t = track.clone();
        for (k, l) in t.links.iter_mut().enumerate() {
            let mut v = states[k].clone();
            for (j, &i) in moving.iter().enumerate() {
                v[i] = x[nv + moving.len() * k + j];
            }
            // The same lengths and step: always accepted.
            let _ = l.set_state_vector(&v);
        }
        // The force at the communication point, then the track takes the bogie's side
        // frames and steps.
        let at_point: Vec<f64> = t.links.iter().flat_map(|l| l.force_now()).collect();
        let (fz, fv) = b.frames();
        for (k, l) in t.links.iter_mut().enumerate() {
            l.set_side_frames([fz[2 * k], fz[2 * k + 1]], [fv[2 * k], fv[2 * k + 1]]);
        }
        for _ in 0..steps as usize {
            t.step();
        }
        let held: Vec<f64> = if jacobi {
            at_point
        } else {
            t.links.iter().flat_map(|l| l.mean_force()).collect()
        };
        for _ in 0..sub as usize {
            b.step_boxes(&held);
        }
        let mut out = b.state()[1..].to_vec();
        for l in &t.links {
            let v = l.state_vector();
            out.extend(moving.iter().map(|&i| v[i]));
        }
        out
    };
    // Each value in units of a displacement (m): velocities times the step, forces
    // over the primary stiffness, so that the matrix is balanced (its eigenvalues are
    // those of the map in any units).
    let k1 = track.links[0].stiffness();
    let unit: Vec<f64> = (0..n)
        .map(|j| match j.checked_sub(nv).map(|r| r % moving.len()) {
            None | Some(0..=5) => 1.0,
            Some(6 | 7) => 1.0 / h,
            Some(_) => k1,
        })
        .collect();
    let base_out = map(&reference);
    let mut a = DMatrix::zeros(n, n);
    for j in 0..n {
        let delta = 1e-6 * unit[j];
        let mut x = reference.clone();
        x[j] += delta;
        let y = map(&x);
        for i in 0..n {
            a[(i, j)] = (y[i] - base_out[i]) / delta * unit[j] / unit[i];
        }
    }
    a
}

/// Spectral radius of `a`, through its real Schur form with a bounded number of QR
/// iterations: nalgebra's `complex_eigenvalues` iterates without bound and spun forever
/// on some of these matrices (dimforge/nalgebra#1291). A form that does not converge
/// counts as unstable (infinite), so the scan stops below it: the estimate errs low.
fn spectral_radius(a: &DMatrix<f64>) -> f64 {
    match nalgebra::linalg::Schur::try_new(a.clone(), f64::EPSILON, SCHUR_ITERATIONS) {
        Some(schur) => schur
            .complex_eigenvalues()
            .iter()
            .map(|z| z.norm())
            .fold(0.0, f64::max),
        None => f64::INFINITY,
    }
}

/// The most QR iterations of one Schur decomposition in [`spectral_radius`]: a few per
/// eigenvalue converge (the matrices here are about 30 by 30).
const SCHUR_ITERATIONS: usize = 5_000;

/// The largest `h` of a geometric scan from 0.05 ms (ratio 1.1, up to 20 ms) below
/// which every step keeps the spectral radius at most 1 (to 1e-9).
fn largest_stable<B: SprungBody>(body: &B, track: &TrackSide, base: f64, jacobi: bool) -> f64 {
    let mut h = 5e-5;
    while h < 20e-3 {
        let next = h * 1.1;
        if spectral_radius(&amplification(body, track, next, base, jacobi)) > 1.0 + 1e-9 {
            return h;
        }
        h = next;
    }
    h
}

/// The track side under `body` at rest with its axle boxes at `z_box` (m), one link per
/// wheelset of `wheelset` (its mass, inertia, primary suspension, gravity) with side
/// frames of `inertia`, on contact springs of `support` (N/m per wheel).
fn track_side<B: SprungBody>(
    body: &B,
    wheelset: &RollPlaneParams,
    inertia: SideFrameInertia,
    z_box: &[f64],
    support: f64,
) -> Result<TrackSide> {
    let (zf, _) = body.frames();
    let k1 = wheelset.primary_stiffness;
    let w = 0.5 * wheelset.wheelset_mass * wheelset.gravity;
    let mut links = Vec::new();
    let (mut p0, mut z0) = (Vec::new(), Vec::new());
    for k in 0..body.boxes() / 2 {
        let zb = [z_box[2 * k], z_box[2 * k + 1]];
        // The contact forces that carry the bogie's static primary forces and the
        // wheelset's weight.
        let p = [0, 1].map(|s| k1 * (zb[s] - zf[2 * k + s]) + w);
        let mut link = PrimaryLink::new(wheelset, TRACK_STEP, inertia)?;
        link.set_static(zb, p);
        links.push(link);
        p0.push(p);
        z0.push(zb);
    }
    Ok(TrackSide {
        links,
        support,
        p0,
        z0,
    })
}

/// The side frames TrackContact carries above the axle boxes, standing in for a partner's
/// bogie that TrackContact does not know: free bodies of the carried inertia
/// ([`SideFrameInertia`]) at the axle boxes, held at rest by the static load from above
/// (the secondary suspension, far softer than the primary, is left out), moved exactly
/// under the forces held over each communication step, as any integrator that resolves
/// the step does.
#[derive(Debug, Clone)]
struct CarriedFrames {
    inertia: SideFrameInertia,
    /// Each side frame spans the axle boxes of two wheelsets (the half-car bogie's and
    /// the wagon's); else one side frame per axle box.
    shared: bool,
    /// Acceleration from above at each axle box (m/s^2), wheelset by wheelset, left
    /// then right.
    free: Vec<f64>,
    z: Vec<f64>,
    v: Vec<f64>,
    dt: f64,
}

impl SprungBody for CarriedFrames {
    fn boxes(&self) -> usize {
        self.z.len()
    }
    fn frames(&self) -> (Vec<f64>, Vec<f64>) {
        (self.z.clone(), self.v.clone())
    }
    fn step_boxes(&mut self, f: &[f64]) {
        let n = self.z.len();
        for i in 0..n {
            // The other wheelset's axle box on the same side frame.
            let other = if self.shared { f[(i + 2) % n] } else { 0.0 };
            let a = self.free[i] + self.inertia.direct * f[i] + self.inertia.cross * other;
            self.z[i] += self.dt * (self.v[i] + 0.5 * self.dt * a);
            self.v[i] += self.dt * a;
        }
    }
    fn state(&self) -> Vec<f64> {
        let mut s = vec![self.dt];
        s.extend(&self.z);
        s.extend(&self.v);
        s
    }
    fn set_state(&mut self, s: &[f64]) {
        let n = self.z.len();
        self.z.copy_from_slice(&s[1..=n]);
        self.v.copy_from_slice(&s[n + 1..=2 * n]);
    }
    fn set_step(&mut self, dt: f64) {
        self.dt = dt;
    }
}

/// [`ExchangeLimits`] of the axle-box exchange as TrackContact can estimate it for any
/// partner, from what it carries: the wheelsets of `wheelset` (mass, roll inertia,
/// primary stiffness, damping and spacing, gravity) on contact springs of `support` (N/m
/// per wheel) under the static wheel loads `static_load` `[left, right]` (N), and above
/// them the side frames of `inertia`, spanning two wheelsets' axle boxes when `shared`.
/// The partner is taken as those side frames alone, moved exactly under the forces it
/// holds over a step (`CarriedFrames`): its secondary suspension and the bodies above
/// are slow beside the exchange's fast modes, and its integrator is its own. `None` with
/// nothing carried ([`SideFrameInertia::NONE`]: the partner's bodies there are unknown).
///
/// Errors: a parameter [`PrimaryLink::new`] refuses.
pub fn carried_limits(
    wheelset: &RollPlaneParams,
    inertia: SideFrameInertia,
    shared: bool,
    static_load: [f64; 2],
    support: f64,
) -> Result<Option<ExchangeLimits>> {
    if inertia == SideFrameInertia::NONE {
        return Ok(None);
    }
    let wheelsets = if shared { 2 } else { 1 };
    let k1 = wheelset.primary_stiffness;
    let w = 0.5 * wheelset.wheelset_mass * wheelset.gravity;
    // The static primary forces at the boxes (N), wheelset by wheelset, left then right.
    let f: Vec<f64> = (0..2 * wheelsets).map(|i| static_load[i % 2] - w).collect();
    let body = CarriedFrames {
        inertia,
        shared,
        free: f
            .iter()
            .map(|fi| -(inertia.direct + inertia.cross) * fi)
            .collect(),
        z: f.iter().map(|fi| -fi / k1).collect(),
        v: vec![0.0; 2 * wheelsets],
        dt: TRACK_STEP,
    };
    let track = track_side(&body, wheelset, inertia, &vec![0.0; 2 * wheelsets], support)?;
    // One step of the partner per communication step: it moves exactly.
    Ok(Some(limits_of(&body, &track, f64::INFINITY)))
}

fn limits_of<B: SprungBody>(body: &B, track: &TrackSide, base: f64) -> ExchangeLimits {
    ExchangeLimits {
        sequential: largest_stable(body, track, base, false),
        jacobi: largest_stable(body, track, base, true),
    }
}

/// Damping of the support under each wheel (N s/m): the rail pads' and ballast's that the
/// wheel feels through the rail, of the order of table 4.4's pad damping; without it the
/// wheelset on its contact spring is an undamped oscillator, which any explicit
/// exchange nudges past a spectral radius of 1.
const SUPPORT_DAMPING: f64 = 1e5;

/// Contact stiffness per wheel (N/m) the estimates take by default: the adaptive
/// contact's at the static load of table 4.4, about 1.45e9 N/m.
pub const CONTACT_STIFFNESS: f64 = 1.45e9;
