//! Exact window ends (issue 29): the semi-infinite track beyond each end of a window as
//! a discrete convolution in time, a discrete transparent boundary condition (the idea
//! of Arnold, VLSI Design 6 (1998) 313, and Ehrhardt and Arnold, Riv. Mat. Univ. Parma
//! 6 (2001) 57, for the Schrödinger equation; Givoli, J. Comput. Phys. 94 (1991) 1, for
//! non-reflecting boundaries in general), here for the periodic discrete track.
//!
//! **The exterior.** The explicit scheme's rail stencil is three nodes wide, so the
//! window's last inner node `K - 1` feels the track beyond it only through the end node
//! `K` (above the window's last sleeper), and the track beyond `K - 1` feels the window
//! only through node `K - 1`. The track beyond is linear, periodic and unloaded, and it
//! starts in the static state (below): node `K` at `t_j` is therefore
//! `u_K(t_j) = sum_(m=1..M) h[m] u_(K-1)(t_(j-m))`, four channels (deflection and
//! rotation of both rails, coupled through the sleepers' roll), `h[m]` a 4 x 4 matrix:
//! the discrete scheme's own response, computed once on a track as long as the memory
//! (the scheme moves information by one node a step, so a track of `M / 2n + 2` spans
//! holds `M` lags free of its far end's echo). Nothing is approximated but the memory
//! `M`: with `M` as long as the run, the end's echo is gone to the rounding (the unit
//! test in `transparent_tests.rs`). The back end is the mirror image (`Z` even, `theta`
//! odd).
//!
//! **A moving window.** When the window shifts by a span:
//! - ahead, the new span enters in the state the exterior has then (each node and
//!   sleeper of the exterior's first span is its own convolution of the drive history),
//!   and the front drive history becomes that of the new inner node, again by
//!   convolution;
//! - behind, the track beyond the new end (the span leaving and the track behind it)
//!   was loaded when the wheels crossed it and may still ring, so it is not at rest:
//!   its end node's future is split into the free response from its present state (the
//!   new inner node held at zero), stepped at the shift for `M` steps on a copy of the
//!   two end spans whose own back end goes on as before, and the response to the new
//!   inner node's values from then on (the drive history starts anew at zero). Exact
//!   whatever crossed that track (breaker, issue 29: taking it as never loaded erred by
//!   up to 0.9 % of the static load at 70 m/s on a 4 m window).
//!
//! **The memory fades out.** A kernel cut off sharply at `M` lags is not the exterior's
//! and can feed energy back: the coupled scheme grew without bound at memories of 7, 8,
//! 14-18, 25, 26, 51-59, 128 and 200 steps (breaker, issue 29; a pulse, 20,000 steps).
//! The boundary's kernel therefore keeps its full weight over the memory's first half
//! and fades to zero over the second (`cos^2`); so tapered, every memory sampled from 25
//! to 3,000 steps decayed over 20,000 steps (20 to 24 did not). Longer runs found more:
//! on a 4 m window, standing and at 70 km/h, memories of 64 to 69 steps grew after 0.5
//! to 1.6 s (the third breaker, issue 29), while 70 to 1,024 steps held for 10 s and
//! 128, 150 and 200 for 60 s; memories below [`MIN_EXACT_MEMORY`] (128 steps) are
//! refused. Stability is sampled, not proven; the simulation's health check stops a run
//! that grows, and its message names the exact ends. A memory of twice the run is exact
//! over the run.
//!
//! **The static start** ([`Track::set_static`]) solves the window with 40 spans more
//! at each end and takes its middle, and every history holds that state before `t_0`.
//! The kernel's sum over `M` lags is the exterior's static stiffness only to about
//! 1e-4 of the static load, so the ends settle by that much from the first step.
//!
//! **Measured** (docs/VALIDATION.md, section 4b): the reference flat case on a 4 m a
//! side window with 0.1 s of memory is within 0.39 % of the static load of a 600-span
//! track over 1 s (fixed ends: 14.7 %; the plain converged 20 m window: 0.53 %); with
//! memory as long as the run, within 0.02 % at 4 m a side at any speed to 100 m/s.
//! What remains with a shorter memory is the kernel's tail beyond it: the error grows
//! from 0.1 s after each impact. **Not fast**: the convolutions are evaluated directly,
//! `32 M` multiply-adds a step and about `48 M^2` a shift (about 35 s of wall a
//! simulated second at `M` = 0.1 s, 70 km/h); a recursive (pole) or FFT evaluation of
//! the same kernels is what would make the short exact window cheaper than a long plain
//! one (docs/PERFORMANCE.md; issue 42 measured the recursive form and the maps its shifts
//! need, `python/recursive_ends_study.py`: about 200 states a mode, 1.6 times what the
//! fixed track's cost leaves the ends of a 4 m window). Engine only; the state vector
//! carries the histories.

use super::*;

/// Four channels: (Z, theta) of the left rail, then of the right rail.
type M4 = [[f64; 4]; 4];

/// The largest memory (steps) of [`Track::set_exact_ends`].
pub const MAX_EXACT_MEMORY: usize = 100_000;

/// The shortest memory (steps) of [`Track::set_exact_ends`]: tapered kernels of 20 to
/// 24 steps grew within 20,000 steps, and of 64 to 69 steps within 0.5 to 1.6 s of a
/// 4 m window (module docs).
pub const MIN_EXACT_MEMORY: usize = 128;

/// Largest drive value used for the kernel's impulses (m or rad): small, the track is
/// linear.
const IMPULSE: f64 = 1e-6;

/// Spans added at each end for the static start of a window with exact ends.
const STATIC_EXTRA_SPANS: usize = 40;

/// The mirror image `x -> -x`: deflections even, rotations odd.
const MIRROR: [f64; 4] = [1.0, -1.0, 1.0, -1.0];

/// The exact ends' kernels and drive histories ([`Track::set_exact_ends`]).
#[derive(Debug, Clone)]
pub(crate) struct ExactEnds {
    /// Memory `M` (steps).
    mem: usize,
    /// `g[e][m][o][c]`, exterior rail node `e = 0..=n` beyond the right end (`e = 0`
    /// the end node itself: the boundary condition): channel `o` at `t_(j+m)` per unit
    /// of drive channel `c` at `t_j`, `m = 0..=M` (`g[e][0] = 0`).
    g: Vec<Vec<M4>>,
    /// `gs[s][m][o][c]`, the exterior's sleepers `s = 0` (under the end node) and `1`
    /// (a span beyond): `o` = 0 bounce, 1 roll.
    gs: [Vec<[[f64; 4]; 2]>; 2],
    /// The right end's drive history (node `K - 1`), a ring of `2 M` by time index.
    right: Vec<[f64; 4]>,
    /// The left end's drive history (node 1), a ring of `M`: since the last shift
    /// (zero before it; before the first, the static state).
    left: Vec<[f64; 4]>,
    /// The left end node's free response, `pending[k]` at time `since + k`
    /// (`k = 1..=M`, zero after): what the track behind the window does from its
    /// state at the last shift with node 1 held at zero.
    pending: Vec<[f64; 4]>,
    /// Time index of the last shift.
    since: usize,
    /// Time index of the next record; starts at `3 M` (the rings before it hold the
    /// static state).
    t: usize,
}

impl ExactEnds {
    /// `sum_(m=1..M) k[m] d[at - m]` over ring `d` (mirrored: the left end); times
    /// before `oldest` read `d[oldest]`.
    fn conv(k: &[M4], ring: &[[f64; 4]], at: usize, oldest: usize, mirror: bool) -> [f64; 4] {
        let len = ring.len();
        let mut out = [0.0; 4];
        for (m, km) in k.iter().enumerate().skip(1) {
            let d = &ring[(at - m).max(oldest) % len];
            for o in 0..4 {
                for c in 0..4 {
                    let s = if mirror { MIRROR[o] * MIRROR[c] } else { 1.0 };
                    out[o] += s * km[o][c] * d[c];
                }
            }
        }
        out
    }

    /// Every history holds `right` and `left` at all times before now, nothing is
    /// pending.
    fn hold(&mut self, right: [f64; 4], left: [f64; 4]) {
        self.right.iter_mut().for_each(|x| *x = right);
        self.left.iter_mut().for_each(|x| *x = left);
        self.pending.iter_mut().for_each(|x| *x = [0.0; 4]);
        self.t = 3 * self.mem;
        self.since = self.t;
    }

    /// Values in [`ExactEnds::write_history`].
    pub(super) fn history_len(&self) -> usize {
        2 + 4 * (self.right.len() + self.left.len() + self.pending.len())
    }

    /// Appends the time indices, the drive histories and the pending response to `v`.
    pub(super) fn write_history(&self, v: &mut Vec<f64>) {
        v.extend([self.t as f64, self.since as f64]);
        for a in [&self.right, &self.left, &self.pending] {
            v.extend(a.iter().flatten());
        }
    }

    /// Checks what [`ExactEnds::read_history`] would restore (as many values as
    /// [`ExactEnds::history_len`]).
    pub(super) fn check_history(&self, v: &[f64]) -> Result<()> {
        let (t, since) = (v[0], v[1]);
        let first = 3.0 * self.mem as f64;
        let whole = |x: f64| x.fract() == 0.0 && x >= first && x < 9e15;
        if !whole(t) {
            return Err(out_of_range(
                "state: exact ends' time index",
                t,
                format!("a whole number, {first} to 9e15"),
            ));
        }
        if !(whole(since) && since <= t) {
            return Err(out_of_range(
                "state: exact ends' last shift",
                since,
                format!("a whole number, {first} to the time index {t}"),
            ));
        }
        if let Some(&x) = v[2..].iter().find(|x| !x.is_finite()) {
            return Err(out_of_range("state: exact ends' histories", x, "finite"));
        }
        Ok(())
    }

    /// Restores what [`ExactEnds::write_history`] wrote, checked by
    /// [`ExactEnds::check_history`].
    pub(super) fn read_history(&mut self, v: &[f64]) {
        (self.t, self.since) = (v[0] as usize, v[1] as usize);
        let mut rest = &v[2..];
        for a in [&mut self.right, &mut self.left, &mut self.pending] {
            let (head, tail) = rest.split_at(4 * a.len());
            for (x, c) in a.iter_mut().zip(head.chunks(4)) {
                x.copy_from_slice(c);
            }
            rest = tail;
        }
    }

    /// The left end node at time index `at`: the drive's convolution and the free
    /// response pending.
    fn left_end(&self, at: usize) -> [f64; 4] {
        let mut u = Self::conv(&self.g[0], &self.left, at, 0, true);
        if let Some(p) = self.pending.get(at - self.since) {
            for (x, y) in u.iter_mut().zip(p) {
                *x += y;
            }
        }
        u
    }
}

impl Track {
    /// Deflection (m) and rotation (rad) of node `k` of `rail` at t_j.
    fn four(&self, k: usize) -> [f64; 4] {
        let (l, r) = (self.slot_of(0, k), self.slot_of(1, k));
        [self.z[l], self.th[l], self.z[r], self.th[r]]
    }

    /// Makes both rail ends exact boundaries with a memory of `memory` steps (0 removes
    /// them and the ends are fixed again): the track beyond each end is the
    /// semi-infinite periodic track, at rest in the static state at the start (module
    /// docs). Computing the kernels steps a track of `memory / 2n + 2` spans `4 memory`
    /// times; each step then costs `32 memory` multiply-adds more, each window shift
    /// `32 memory^2`.
    ///
    /// Errors: `memory` above [`MAX_EXACT_MEMORY`]; a track with pinned ends, with
    /// supports that can lift (the exterior must be linear), or of fewer than two
    /// spans.
    pub fn set_exact_ends(&mut self, memory: usize) -> Result<()> {
        if memory == 0 {
            self.exact = None;
            return Ok(());
        }
        if !(MIN_EXACT_MEMORY..=MAX_EXACT_MEMORY).contains(&memory) {
            return Err(out_of_range(
                "exact end memory",
                memory as f64,
                format!("0 (fixed ends), or {MIN_EXACT_MEMORY} to {MAX_EXACT_MEMORY} steps"),
            ));
        }
        if self.params.ends != RailEnds::Fixed {
            return Err(Error::Unsupported(
                "exact ends with pinned rail ends (TrackParams::ends = RailEnds::Pinned): \
                 the window's ends are the fixed ones"
                    .into(),
            ));
        }
        if self.absorbing.is_some() {
            return Err(Error::Unsupported(
                "exact ends with an absorbing layer (track.window.layer > 0)".into(),
            ));
        }
        if self.unilateral.is_some() {
            return Err(Error::Unsupported(
                "exact ends with supports that can lift (track.supports = tensionless): the \
                 track beyond the ends must be linear"
                    .into(),
            ));
        }
        if self.params.spans < 2 {
            return Err(out_of_range(
                "track.spans",
                self.params.spans as f64,
                "at least 2 spans with exact ends".to_string(),
            ));
        }
        let mut p = self.params;
        let n = p.nodes_per_span;
        p.spans = memory.div_ceil(2 * n) + 2;
        let len = memory + 1;
        let mut g = vec![vec![[[0.0; 4]; 4]; len]; n + 1];
        let mut gs = [vec![[[0.0; 4]; 2]; len], vec![[[0.0; 4]; 2]; len]];
        for c in 0..4 {
            let mut t = Track::new_unchecked(p, self.dt);
            t.simd = self.simd;
            // Node n - 1 is the drive (an impulse in channel c at t_0), node n the end.
            for m in 0..memory {
                let mut v = [0.0; 4];
                if m == 0 {
                    v[c] = IMPULSE;
                }
                for rail in 0..2 {
                    let s = t.slot_of(rail, n - 1);
                    (t.z[s], t.th[s]) = (v[2 * rail], v[2 * rail + 1]);
                }
                t.step(&[]);
                for (e, ge) in g.iter_mut().enumerate() {
                    let u = t.four(n + e);
                    for o in 0..4 {
                        ge[m + 1][o][c] = u[o] / IMPULSE;
                    }
                }
                for (s, gss) in gs.iter_mut().enumerate() {
                    gss[m + 1][0][c] = t.zs[1 + s] / IMPULSE;
                    gss[m + 1][1][c] = t.ph[1 + s] / IMPULSE;
                }
            }
        }
        // The boundary's kernel fades out over the memory's second half (module docs).
        let half = memory / 2;
        for (m, hm) in g[0].iter_mut().enumerate().skip(half + 1) {
            let x = (m - half) as f64 / (memory - half + 1) as f64;
            let w = (0.5 * std::f64::consts::PI * x).cos().powi(2);
            hm.iter_mut().flatten().for_each(|v| *v *= w);
        }
        let mut e = ExactEnds {
            mem: memory,
            g,
            gs,
            right: vec![[0.0; 4]; 2 * memory],
            left: vec![[0.0; 4]; memory],
            pending: vec![[0.0; 4]; memory + 1],
            since: 0,
            t: 0,
        };
        e.hold(self.four(self.nk - 2), self.four(1));
        self.exact = Some(Box::new(e));
        Ok(())
    }

    /// The exact ends' kernel `h[m]` (m = 0..=M, `h[0] = 0`; `h[m][o][c]`: channel `o`
    /// of the end node, `(Z, theta)` of the left rail then the right, per unit of the
    /// last inner node's channel `c` `m` steps before; the right end's, the left end's
    /// being its mirror image); `None` without exact ends.
    pub fn exact_end_kernel(&self) -> Option<&[[[f64; 4]; 4]]> {
        self.exact.as_ref().map(|e| &e.g[0][..])
    }

    /// The kernel of the exterior's rail node `e` beyond the right end (`e = 0` the end
    /// node itself, untapered: [`Track::exact_end_kernel`] is its tapered form; `e = n`
    /// the node above the exterior's first sleeper, the end after a shift by a span),
    /// as [`Track::exact_end_kernel`] lays it out: for studies of a recursive form of
    /// the exact ends and of the maps a shift needs (issue 42). `None` without exact
    /// ends or for `e` beyond `n`.
    pub fn exact_exterior_kernel(&self, e: usize) -> Option<&[[[f64; 4]; 4]]> {
        self.exact.as_ref()?.g.get(e).map(|g| &g[..])
    }

    /// Replaces the kernel of [`Track::exact_end_kernel`] by `h` (as many lags): for
    /// studies of approximations of it. The span entering ahead keeps the exact
    /// kernels.
    ///
    /// Errors: no exact ends, or `h` of another length or with a value not finite.
    pub fn set_exact_end_kernel(&mut self, h: &[[[f64; 4]; 4]]) -> Result<()> {
        let Some(e) = &mut self.exact else {
            return Err(Error::Unsupported("a kernel without exact ends".into()));
        };
        if h.len() != e.g[0].len() {
            return Err(out_of_range(
                "exact end kernel length",
                h.len() as f64,
                format!("{} lags (the memory + 1)", e.g[0].len()),
            ));
        }
        if let Some(&x) = h.iter().flatten().flatten().find(|x| !x.is_finite()) {
            return Err(out_of_range("exact end kernel value", x, "finite"));
        }
        e.g[0] = h.to_vec();
        Ok(())
    }

    /// The memory (steps) of the exact ends; `None` without them.
    pub fn exact_ends(&self) -> Option<usize> {
        self.exact.as_ref().map(|e| e.mem)
    }

    /// Records the drives at t_j (before a step).
    #[cold]
    #[inline(never)]
    pub(super) fn exact_save(&mut self) {
        let (r, l) = (self.four(self.nk - 2), self.four(1));
        let e = self.exact.as_mut().unwrap();
        let (t, mem) = (e.t, e.mem);
        e.right[t % (2 * mem)] = r;
        e.left[t % mem] = l;
        e.t += 1;
    }

    /// Sets the end nodes at t_(j+1) (after a step) and clears the padding, which
    /// reads the ends.
    #[cold]
    #[inline(never)]
    pub(super) fn exact_apply(&mut self) {
        let kk = self.nk - 1;
        let e = self.exact.as_ref().unwrap();
        let r = ExactEnds::conv(&e.g[0], &e.right, e.t, 0, false);
        let l = e.left_end(e.t);
        for rail in 0..2 {
            let (s0, s1) = (self.slot_of(rail, 0), self.slot_of(rail, kk));
            (self.z[s0], self.th[s0]) = (l[2 * rail], l[2 * rail + 1]);
            (self.z[s1], self.th[s1]) = (r[2 * rail], r[2 * rail + 1]);
        }
        for &s in &self.padding {
            self.z[s] = 0.0;
            self.th[s] = 0.0;
        }
    }

    /// Before the state moves one span towards the left end ([`Track::shift_spans`]):
    /// the track behind the new left end (the span leaving and the track behind it)
    /// is a linear system in a known state, so its end node's future is its free
    /// response from that state (node `n + 1`, the new inner node, held at zero),
    /// stepped here for `M` steps on a copy of the two end spans, plus its response to
    /// node `n + 1`'s values from now on (the drive history starts anew at zero). Exact
    /// whatever loads crossed that track before.
    pub(super) fn exact_shift_back(&mut self) {
        let n = self.params.nodes_per_span;
        let Some(e) = self.exact.as_ref() else {
            return;
        };
        let (t0, mem) = (e.t, e.mem);
        let mut p = self.params;
        p.spans = 2;
        let mut two = Track::new_unchecked(p, self.dt);
        two.simd = self.simd;
        for k in 0..=2 * n {
            for rail in 0..2 {
                let (a, b) = (two.slot_of(rail, k), self.slot_of(rail, k));
                (two.z[a], two.th[a]) = (self.z[b], self.th[b]);
                (two.z_prev[a], two.th_prev[a]) = (self.z_prev[b], self.th_prev[b]);
            }
        }
        for i in 0..3 {
            (two.zs[i], two.ph[i]) = (self.zs[i], self.ph[i]);
            (two.zs_prev[i], two.ph_prev[i]) = (self.zs_prev[i], self.ph_prev[i]);
        }
        // The old left end goes on as before, driven by the copy's node 1.
        let mut old = e.clone();
        let mut pending = vec![[0.0; 4]; mem + 1];
        for (k, p) in pending.iter_mut().enumerate().skip(1) {
            let t = t0 + k - 1;
            old.left[t % mem] = two.four(1);
            for rail in 0..2 {
                let s = two.slot_of(rail, n + 1);
                (two.z[s], two.th[s]) = (0.0, 0.0);
            }
            two.step(&[]);
            let u = old.left_end(t + 1);
            for rail in 0..2 {
                let s = two.slot_of(rail, 0);
                (two.z[s], two.th[s]) = (u[2 * rail], u[2 * rail + 1]);
            }
            for &s in &two.padding {
                two.z[s] = 0.0;
                two.th[s] = 0.0;
            }
            *p = two.four(n);
        }
        let e = self.exact.as_mut().unwrap();
        e.pending = pending;
        e.since = t0;
        e.left.iter_mut().for_each(|x| *x = [0.0; 4]);
    }

    /// After the state moved one span towards the left end ([`Track::shift_spans`]):
    /// the new span ahead takes the exterior's state at t_j and t_(j-1), and the front
    /// drive history becomes the new inner node's.
    pub(super) fn exact_shift_one(&mut self) {
        let kk = self.nk - 1;
        let n = self.params.nodes_per_span;
        let ns = self.ns;
        let Some(mut e) = self.exact.take() else {
            return;
        };
        let (t, mem) = (e.t, e.mem);
        for (ei, ge) in e.g.iter().enumerate().skip(1) {
            let now = ExactEnds::conv(ge, &e.right, t, 0, false);
            let before = ExactEnds::conv(ge, &e.right, t - 1, 0, false);
            let k = kk - n + ei;
            for rail in 0..2 {
                let s = self.slot_of(rail, k);
                (self.z[s], self.th[s]) = (now[2 * rail], now[2 * rail + 1]);
                (self.z_prev[s], self.th_prev[s]) = (before[2 * rail], before[2 * rail + 1]);
            }
        }
        for (si, gss) in e.gs.iter().enumerate() {
            let g4: Vec<M4> = gss
                .iter()
                .map(|x| [x[0], x[1], [0.0; 4], [0.0; 4]])
                .collect();
            let now = ExactEnds::conv(&g4, &e.right, t, 0, false);
            let before = ExactEnds::conv(&g4, &e.right, t - 1, 0, false);
            let i = ns - 2 + si;
            (self.zs[i], self.ph[i]) = (now[0], now[1]);
            (self.zs_prev[i], self.ph_prev[i]) = (before[0], before[1]);
        }
        let ls = 0.5 * self.params.rail_seat_distance;
        for i in [ns - 2, ns - 1] {
            let k = i * n;
            let (zl, zr) = (self.four(k)[0], self.four(k)[2]);
            self.pad[i] = -self.params.pad_stiffness * (zl - self.zs[i] + ls * self.ph[i]);
            self.pad[self.sp + i] =
                -self.params.pad_stiffness * (zr - self.zs[i] - ls * self.ph[i]);
        }
        // The front drive history: exterior node n - 1's, the ring's 2 M values (the
        // older half from drives older than the ring holds: its oldest value stands
        // for them, an error in lags beyond M, where the memory ends anyway).
        let oldest = t - 2 * mem;
        let hist: Vec<[f64; 4]> = (oldest..t)
            .map(|j| ExactEnds::conv(&e.g[n - 1], &e.right, j, oldest, false))
            .collect();
        for (j, h) in (oldest..t).zip(hist) {
            e.right[j % (2 * mem)] = h;
        }
        self.exact = Some(e);
    }

    /// The static state of a window with exact ends (module docs).
    pub(super) fn set_static_exact(&mut self, loads: &[PointLoad]) -> Result<()> {
        let len = self.params.length();
        if let Some(l) = loads
            .iter()
            .find(|l| !(l.position > 0.0 && l.position < len))
        {
            return Err(out_of_range(
                "static load position",
                l.position,
                format!("inside the track, 0 < x < {} m", crate::error::num(len)),
            ));
        }
        let extra = STATIC_EXTRA_SPANS;
        let mut p = self.params;
        p.spans += 2 * extra;
        let n = p.nodes_per_span;
        let mut big = Track::new_unchecked(p, self.dt);
        let shift = extra as f64 * p.sleeper_spacing;
        let moved: Vec<PointLoad> = loads
            .iter()
            .map(|l| PointLoad {
                position: l.position + shift,
                ..*l
            })
            .collect();
        big.set_static(&moved)?;
        for k in 0..self.nk {
            for rail in 0..2 {
                let (s, b) = (self.slot_of(rail, k), big.slot_of(rail, k + extra * n));
                (self.z[s], self.th[s]) = (big.z[b], big.th[b]);
                (self.z_prev[s], self.th_prev[s]) = (big.z[b], big.th[b]);
            }
        }
        for i in 0..self.ns {
            let j = i + extra;
            (self.zs[i], self.ph[i]) = (big.zs[j], big.ph[j]);
            (self.zs_prev[i], self.ph_prev[i]) = (big.zs[j], big.ph[j]);
            self.pad[i] = big.pad[j];
            self.pad[self.sp + i] = big.pad[big.sp + j];
        }
        let (r, l) = (self.four(self.nk - 2), self.four(1));
        self.exact.as_mut().unwrap().hold(r, l);
        Ok(())
    }

    /// After [`Track::reset`]: the histories hold the state at rest.
    pub(super) fn exact_reset(&mut self) {
        let (r, l) = (self.four(self.nk - 2), self.four(1));
        if let Some(e) = &mut self.exact {
            e.hold(r, l);
        }
    }
}

#[cfg(test)]
#[path = "transparent_tests.rs"]
pub(super) mod tests;
