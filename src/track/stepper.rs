//! The track state and its stepper: construction, accessors, the step, step changes.

use super::*;

/// A vertical point force on a rail.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointLoad {
    /// Rail index: 0 left, 1 right.
    pub rail: usize,
    /// Position along the track (m), in (0, length).
    pub position: f64,
    /// Force pushing the rail down (N) (the contact force `P`).
    pub force: f64,
}

/// The discrete track and its explicit time stepper: two Timoshenko rails (deflection
/// and rotation at every node, 3.4, 3.5) on rail pads (3.9), sleepers with bounce and
/// roll on ballast (3.6-3.8), advanced by central differences (3.10-3.20) at a fixed
/// step `dt` (s) no larger than the stability limit
/// [`TrackParams::critical_time_step`]. Rail ends as [`TrackParams::ends`] says; a
/// wheel acts as a [`PointLoad`] shared between the two nodes around it (3.21-3.23).
///
/// Displacements are in m and rad, positive up (`docs/MODEL.md`); the accessors return
/// node order, the left rail first. Errors of [`Track::new`]: any parameter out of its
/// physical range, or `dt` above the stability limit.
//
// Storage (an implementation detail of the stepper's speed): rail nodes are kept by *phase* within a span so that every loop runs over
// contiguous memory, in whole vectors. With `N_s = N + 1` sleepers padded to `S`, a
// multiple of `LANES` (8), phase block `p = k % n` holds node `k` of rail `r` at
// `r S + k / n`, and the blocks are stored `1, 2, .., n - 1, 0` after `G = LANES`
// unused values (as many behind; arrays start on a cache line, so every block does
// too). Block 0 therefore holds the rail nodes above the sleepers, left rail then
// right rail, in sleeper order, and the sleeper loop reads it directly. Every block
// is stepped whole.
//
// Slots past a rail's last node (one per rail in block 0 when `N_s < S`, more in
// blocks `1..n`, which have `N` nodes) are padding. No real node reads a padding
// slot, and padding slots read only padding, the rail ends and the guards (this is
// why block 0 comes last: the slot one past it, which the last slot of block `n - 1`
// reads, is the trailing guard and not node 1 of the left rail). Block 0's stencil
// masks its padding and the rail ends to zero, so with fixed ends the padding, the
// padded sleepers and their pads start at zero and stay there without a store after
// the loops; pinned ends, whose end rotations move, clear the padding after every
// step. Accessors return node order.
#[derive(Debug, Clone)]
pub struct Track {
    pub(super) params: TrackParams,
    pub(super) dt: f64,
    pub(super) dt_critical: f64,
    /// `1 / dx` (1/m), for locating loads.
    pub(super) inv_dx: f64,
    /// `dx / kAG` (m/N), for [`Track::shear_compliance`]; 0 with
    /// [`RailBetweenNodes::Linear`].
    pub(super) shear_dx_per_kag: f64,
    /// `dx / 2` (m), the bending sag's factor in [`Track::rail_z_at`]; 0 with
    /// [`RailBetweenNodes::Linear`].
    pub(super) sag_dx: f64,
    /// Nodes per rail `K + 1`.
    pub(super) nk: usize,
    /// Sleepers `N_s = N + 1`.
    pub(super) ns: usize,
    /// Sleepers padded to a multiple of [`LANES`], `S`: the length of the sleeper arrays and
    /// of each rail's part of a block.
    pub(super) sp: usize,
    pub(super) c: Coeffs,
    /// Storage slot of node `k` of the left rail (add `S` for the right rail).
    pub(super) slot: Vec<usize>,
    /// Padding slots of the rail arrays (kept at zero).
    pub(super) padding: Vec<usize>,
    /// Slots of the rail ends (first and last node of the left rail, then of the
    /// right rail), each with the slot of its inner neighbour node.
    pub(super) ends_inner: [(usize, usize); 4],
    /// Rail deflection at t_j (m), phase-blocked.
    pub(super) z: Aligned,
    /// Rail rotation at t_j (rad), phase-blocked.
    pub(super) th: Aligned,
    pub(super) z_prev: Aligned,
    pub(super) th_prev: Aligned,
    pub(super) zs: Aligned,
    pub(super) ph: Aligned,
    pub(super) zs_prev: Aligned,
    pub(super) ph_prev: Aligned,
    /// Pad forces on the rails (N): left rail sleepers at `0..N_s`, right rail
    /// sleepers at `S..S + N_s`.
    pub(super) pad: Aligned,
    /// Mask of block 0's new values (bit patterns, laid out as the block): all bits
    /// set over the interior nodes, none over the rail ends and the padding.
    pub(super) keep: Aligned,
    pub(super) simd: SimdLevel,
    /// Supports that can lift ([`SupportLaw::Tensionless`] or a gap under a sleeper);
    /// `None`: the thesis' linear supports.
    pub(super) unilateral: Option<Box<Unilateral>>,
    /// A graded damping layer at the rail ends ([`Track::set_absorbing_ends`]).
    pub(super) absorbing: Option<Box<absorbing::AbsorbingEnds>>,
    /// Exact ends ([`Track::set_exact_ends`]).
    pub(super) exact: Option<Box<transparent::ExactEnds>>,
}

impl Track {
    /// A track at rest and undeformed, stepped with `dt` (s). Refuses a step above
    /// the critical step with a message naming the limit.
    pub fn new(params: TrackParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        let (dtc, limit) = params.critical_time_step();
        if dt > dtc {
            return Err(Error::UnstableTimeStep {
                dt,
                critical: dtc,
                limit,
            });
        }
        let mut t = Self::new_unchecked(params, dt);
        t.dt_critical = dtc;
        Ok(t)
    }

    /// [`Track::new`] without the stability check: for measuring where the scheme
    /// becomes unstable (`examples/stability_limit.rs`). Above the stability limit
    /// the results grow without bound; use [`Track::new`] for everything else.
    pub fn new_without_stability_check(params: TrackParams, dt: f64) -> Result<Self> {
        params.validate()?;
        positive("solver.dt", dt, "s")?;
        let mut t = Self::new_unchecked(params, dt);
        t.dt_critical = params.critical_time_step().0;
        Ok(t)
    }

    /// Builds the stepper without the stability check (validated parameters only).
    pub(crate) fn new_unchecked(params: TrackParams, dt: f64) -> Self {
        let n = params.nodes_per_span;
        let nk = params.spans * n + 1;
        let ns = params.spans + 1;
        let sp = ns.next_multiple_of(LANES);
        let c = Coeffs::new(&params, dt);
        let b = 2 * sp;
        let len = GUARD + n * b + GUARD;
        let slot: Vec<usize> = (0..nk).map(|k| block_start(k % n, n, sp) + k / n).collect();
        let mut used = vec![false; len];
        for &s in &slot {
            used[s] = true;
            used[s + sp] = true;
        }
        let padding = (GUARD..GUARD + n * b).filter(|&s| !used[s]).collect();
        let ends_inner = [
            (slot[0], slot[1]),
            (slot[nk - 1], slot[nk - 2]),
            (slot[0] + sp, slot[1] + sp),
            (slot[nk - 1] + sp, slot[nk - 2] + sp),
        ];
        // Block 0's mask: every bit set over its interior nodes, none over the rail
        // ends and the padding.
        let mut keep = Aligned::zeros(b);
        let start = block_start(0, n, sp);
        for k in (n..nk - 1).step_by(n) {
            keep[slot[k] - start] = f64::from_bits(u64::MAX);
            keep[slot[k] + sp - start] = f64::from_bits(u64::MAX);
        }
        Track {
            params,
            dt,
            dt_critical: f64::NAN,
            inv_dx: 1.0 / params.dx(),
            shear_dx_per_kag: match params.between_nodes {
                RailBetweenNodes::Beam => params.dx() / params.rail.kag,
                RailBetweenNodes::Linear => 0.0,
            },
            sag_dx: match params.between_nodes {
                RailBetweenNodes::Beam => 0.5 * params.dx(),
                RailBetweenNodes::Linear => 0.0,
            },
            nk,
            ns,
            sp,
            c,
            slot,
            padding,
            ends_inner,
            z: Aligned::zeros(len),
            th: Aligned::zeros(len),
            z_prev: Aligned::zeros(len),
            th_prev: Aligned::zeros(len),
            zs: Aligned::zeros(sp),
            ph: Aligned::zeros(sp),
            zs_prev: Aligned::zeros(sp),
            ph_prev: Aligned::zeros(sp),
            pad: Aligned::zeros(2 * sp),
            keep,
            simd: SimdLevel::detect(),
            unilateral: (params.supports.law == SupportLaw::Tensionless)
                .then(|| Box::new(Unilateral::new(&params, ns, dt))),
            absorbing: None,
            exact: None,
        }
    }

    /// Parameters.
    pub fn params(&self) -> &TrackParams {
        &self.params
    }
    /// Time step (s).
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Critical time step (s).
    pub fn dt_critical(&self) -> f64 {
        self.dt_critical
    }
    /// Nodes per rail, `K + 1`.
    pub fn nodes(&self) -> usize {
        self.nk
    }
    /// Vector instructions the stepper uses.
    pub fn simd(&self) -> SimdLevel {
        self.simd
    }
    /// Makes the stepper use `level`; refused when this CPU lacks it.
    pub fn set_simd(&mut self, level: SimdLevel) -> Result<()> {
        if level > SimdLevel::detect() {
            return Err(Error::Unsupported(format!(
                "track.simd = {level:?}: this CPU supports up to {:?}",
                SimdLevel::detect()
            )));
        }
        self.simd = level;
        Ok(())
    }

    /// Storage slot of node `k` (0..=K) of `rail` (0 left, 1 right).
    #[inline]
    pub(super) fn slot_of(&self, rail: usize, k: usize) -> usize {
        self.slot[k] + rail.min(1) * self.sp
    }

    /// Values of phase-blocked array `a` on `rail`, nodes 0..=K.
    pub(super) fn rail_nodes<'a>(
        &'a self,
        a: &'a [f64],
        rail: usize,
    ) -> impl Iterator<Item = f64> + 'a {
        (0..self.nk).map(move |k| a[self.slot_of(rail, k)])
    }

    /// Phase-blocked array `a` in node order, both rails end to end.
    pub(super) fn to_nodes(&self, a: &[f64]) -> Vec<f64> {
        self.rail_nodes(a, 0).chain(self.rail_nodes(a, 1)).collect()
    }

    /// Writes node-order values `v` (both rails end to end) into phase-blocked `a`
    /// (`sp`: the right rail's offset in a block).
    pub(super) fn from_nodes(slot: &[usize], sp: usize, v: &[f64], a: &mut [f64]) {
        let nk = slot.len();
        for r in 0..2 {
            for (k, &s) in slot.iter().enumerate() {
                a[s + r * sp] = v[r * nk + k];
            }
        }
    }

    /// Rail deflections (m) of rail 0 (left) or 1 (right), nodes 0..=K.
    pub fn rail_z(&self, rail: usize) -> Vec<f64> {
        self.rail_nodes(&self.z, rail).collect()
    }
    /// Rail rotations (rad) of one rail, nodes 0..=K.
    pub fn rail_theta(&self, rail: usize) -> Vec<f64> {
        self.rail_nodes(&self.th, rail).collect()
    }
    /// Sleeper bounce displacements (m).
    pub fn sleeper_z(&self) -> &[f64] {
        &self.zs[..self.ns]
    }
    /// Sleeper roll angles (rad), positive raising the right seat.
    pub fn sleeper_roll(&self) -> &[f64] {
        &self.ph[..self.ns]
    }
    /// Pad forces on the rails (N, up on the rail) at the last step, per sleeper.
    pub fn pad_forces(&self, rail: usize) -> &[f64] {
        let at = rail.min(1) * self.sp;
        &self.pad[at..at + self.ns]
    }

    /// Largest absolute rail deflection or sleeper bounce displacement at t_j (m); NaN
    /// if any is NaN. For the health check of the solver (padding slots hold zeros).
    pub fn max_abs_displacement(&self) -> f64 {
        let mut m: f64 = 0.0;
        for &x in self.z.iter().chain(self.zs.iter()) {
            if x.is_nan() {
                return f64::NAN;
            }
            m = m.max(x.abs());
        }
        m
    }

    /// Sets every displacement (at t_j and t_(j-1)) and pad force to zero.
    pub fn reset(&mut self) {
        for v in [
            &mut self.z,
            &mut self.th,
            &mut self.z_prev,
            &mut self.th_prev,
            &mut self.zs,
            &mut self.ph,
            &mut self.zs_prev,
            &mut self.ph_prev,
            &mut self.pad,
        ] {
            v.iter_mut().for_each(|x| *x = 0.0);
        }
        if let Some(u) = &mut self.unilateral {
            u.pad_lifted.iter_mut().for_each(|t| *t = CARRIES);
            u.ballast_lifted.iter_mut().for_each(|t| *t = CARRIES);
            (u.longest, u.longest_at) = (0.0, 0);
        }
        self.exact_reset();
    }

    /// Node index and shape-function weight for a position: the load at `x` goes
    /// `(1 - w)` to node `k` and `w` to node `k + 1` (3.22).
    #[inline]
    pub fn locate(&self, x: f64) -> (usize, f64) {
        locate(x, self.inv_dx, self.nk)
    }

    /// Rail deflection (m) under position `x` on `rail`: (3.23)'s interpolation of the
    /// two nodes around `x` with the bending sag between them,
    /// `(1 - w) Z_k + w Z_(k+1) - (theta_(k+1) - theta_k) dx w (1 - w) / 2` (the
    /// element's curvature `(theta_(k+1) - theta_k) / dx` over its chord; 0 on a node);
    /// (3.23) alone with [`RailBetweenNodes::Linear`].
    /// A load at `x` deflects the rail there further by [`Track::shear_compliance`]
    /// times the load (`docs/MODEL.md`, "The rail between nodes").
    #[inline]
    pub fn rail_z_at(&self, rail: usize, x: f64) -> f64 {
        let (k, w) = self.locate(x);
        let (a, b) = (self.slot_of(rail, k), self.slot_of(rail, k + 1));
        let sag = self.sag_dx * w * (1.0 - w);
        (1.0 - w) * self.z[a] + w * self.z[b] - (self.th[b] - self.th[a]) * sag
    }

    /// [`Track::rail_z_at`] of the left and right rail at `x`, located once.
    #[inline(always)]
    pub fn rail_z_pair(&self, x: f64) -> [f64; 2] {
        let (k, w) = self.locate(x);
        let (s0, s1) = (self.slot[k], self.slot[k + 1]);
        let sp = self.sp;
        let sag = self.sag_dx * w * (1.0 - w);
        [
            (1.0 - w) * self.z[s0] + w * self.z[s1] - (self.th[s1] - self.th[s0]) * sag,
            (1.0 - w) * self.z[s0 + sp] + w * self.z[s1 + sp]
                - (self.th[s1 + sp] - self.th[s0 + sp]) * sag,
        ]
    }

    /// The rail's local compliance under a point load at `x` (m/N): a Timoshenko
    /// rail's slope jumps by `F / kAG` under a point load `F`, a kink that nodal values
    /// represent only when the load sits on a node; between nodes, at `w` of the way
    /// from node `k`, the rail under the load lies `F dx w (1 - w) / kAG` below what the
    /// nodes give (the kink's tent over the element, split `(1 - w, w)` as the load is
    /// by (3.22)). 0 on a node; at most `dx / (4 kAG)` mid-element (8.9e-11 m/N at
    /// n = 8 on table 4.4's rail, against 6.9e-10 m/N for the contact at the static
    /// load). The contact solves its force with it in series (`docs/MODEL.md`).
    #[inline(always)]
    pub fn shear_compliance(&self, x: f64) -> f64 {
        let (_, w) = self.locate(x);
        self.shear_dx_per_kag * w * (1.0 - w)
    }

    /// Advances the track from t_j to t_(j+1) under point loads applied at t_j.
    #[inline(always)]
    pub fn step(&mut self, loads: &[PointLoad]) {
        if self.absorbing.is_some() {
            self.absorbing_save();
        }
        if self.exact.is_some() {
            self.exact_save();
        }
        match self.simd {
            // No hardware FMA assumed at the baseline (the library `fma` is slow).
            SimdLevel::Baseline => step_body::<false>(self, loads),
            level => level.run(
                #[inline(always)]
                || step_body::<true>(self, loads),
            ),
        }
        if self.absorbing.is_some() {
            self.absorbing_apply();
        }
        if self.exact.is_some() {
            self.exact_apply();
        }
    }
}

impl Track {
    /// Sets the rail state at t_j and t_(j-1) directly (for tests and restarts): rail
    /// deflections `z`, `z_prev` (m) and rotations `th`, `th_prev` (rad), each of the
    /// left rail's nodes `0..=K` followed by the right rail's, `2 (K + 1)` values
    /// ([`Track::nodes`] is `K + 1`). The sleepers keep their state.
    ///
    /// # Panics
    /// When a slice is shorter than `2 (K + 1)`.
    pub fn set_state(&mut self, z: &[f64], th: &[f64], z_prev: &[f64], th_prev: &[f64]) {
        let (slot, sp) = (&self.slot, self.sp);
        Self::from_nodes(slot, sp, z, &mut self.z);
        Self::from_nodes(slot, sp, th, &mut self.th);
        Self::from_nodes(slot, sp, z_prev, &mut self.z_prev);
        Self::from_nodes(slot, sp, th_prev, &mut self.th_prev);
    }

    /// Changes the time step to `dt` (s), keeping the displacements at t_j and the
    /// backward-difference velocities `(x_j - x_(j-1)) / dt`: the t_(j-1) values are
    /// moved to `x_j - (x_j - x_(j-1)) dt_new / dt_old`. First-order accurate at the
    /// switch; used when a communication step is not a multiple of the step.
    pub fn change_dt(&mut self, dt: f64) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        if self.exact.is_some() {
            return Err(Error::Unsupported(
                "a change of step with exact ends (their kernels are the step's)".into(),
            ));
        }
        if dt > self.dt_critical {
            return Err(Error::UnstableTimeStep {
                dt,
                critical: self.dt_critical,
                limit: self.params.critical_time_step().1,
            });
        }
        let ratio = dt / self.dt;
        for (cur, prev) in [
            (&self.z, &mut self.z_prev),
            (&self.th, &mut self.th_prev),
            (&self.zs, &mut self.zs_prev),
            (&self.ph, &mut self.ph_prev),
        ] {
            for (p, c) in prev.iter_mut().zip(cur.iter()) {
                *p = c - (c - *p) * ratio;
            }
        }
        self.c = Coeffs::new(&self.params, dt);
        let dt_old = self.dt;
        self.dt = dt;
        self.absorbing_rescale(dt_old, dt);
        if let Some(u) = &mut self.unilateral {
            u.set_dt(&self.params, dt);
        }
        Ok(())
    }
}
