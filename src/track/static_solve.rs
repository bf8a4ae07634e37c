//! The stiffness of the track, its direct static solve (banded, unknowns ordered along
//! the track) and the discrete energy.

use super::*;

/// The most passes of the static start's active-set iteration
/// ([`Track::set_static_unilateral`]).
const MAX_PASSES: usize = 200;

impl Track {
    /// Number of unknowns of the static problem.
    pub(super) fn static_size(&self) -> usize {
        4 * self.nk + 2 * self.ns
    }

    /// Symmetric stiffness matrix `K` of the discrete equations (rows scaled by dx so
    /// that `M = diag(m dx, m r^2 dx, m_s, J_s)`), unknowns ordered
    /// `[Z (both rails), theta (both rails), Z_s, phi_s]`. Fixed degrees of freedom have
    /// identity rows and columns. Dense: for tests and energy checks on short tracks
    /// (the static solve assembles its band directly, see [`Track::set_static`]).
    pub fn stiffness_matrix(&self) -> DMatrix<f64> {
        let n = self.static_size();
        let mut k = DMatrix::<f64>::zeros(n, n);
        self.stiffness_entries(|i, j, v| k[(i, j)] += v);
        k
    }

    /// Every contribution `v` to entry `(i, j)` of [`Track::stiffness_matrix`], in one
    /// fixed order (so any assembly sums each entry's contributions alike).
    pub(super) fn stiffness_entries(&self, add: impl FnMut(usize, usize, f64)) {
        self.stiffness_entries_with(None, add)
    }

    /// [`Track::stiffness_entries`] with only the supports that carry: `on` holds
    /// whether each pad (the left rail's seats, then the right rail's) and each
    /// ballast seat (the sleepers' left seats, then their right seats) carries; the
    /// others add no stiffness. `None`: all carry, the linear track.
    pub(super) fn stiffness_entries_with(
        &self,
        on: Option<(&[bool], &[bool])>,
        mut add: impl FnMut(usize, usize, f64),
    ) {
        let p = &self.params;
        let r = &p.rail;
        let dx = p.dx();
        let nk = self.nk;
        let ns = self.ns;
        let (iz, it, izs, iph) = (0, 2 * nk, 4 * nk, 4 * nk + ns);
        let pinned = p.ends == RailEnds::Pinned;
        for rail in 0..2 {
            for node in 0..nk {
                let g = rail * nk + node;
                let end = node == 0 || node == nk - 1;
                // Deflection row.
                if end {
                    add(iz + g, iz + g, 1.0);
                } else {
                    add(iz + g, iz + g, 2.0 * r.kag / dx);
                    for nb in [g - 1, g + 1] {
                        let nb_end = nb % nk == 0 || nb % nk == nk - 1;
                        if !nb_end {
                            add(iz + g, iz + nb, -(r.kag / dx));
                        }
                        let sgn = if nb > g { 0.5 } else { -0.5 };
                        if !nb_end || pinned {
                            add(iz + g, it + nb, sgn * r.kag);
                        }
                    }
                }
                // Rotation row.
                if end && !pinned {
                    add(it + g, it + g, 1.0);
                } else if end {
                    let inner = if node == 0 { g + 1 } else { g - 1 };
                    let sgn = if node == 0 { -0.5 } else { 0.5 };
                    add(it + g, it + g, r.ei / dx + 0.5 * r.kag * dx);
                    add(it + g, it + inner, -(r.ei / dx));
                    add(it + g, iz + inner, sgn * r.kag);
                } else {
                    add(it + g, it + g, 2.0 * r.ei / dx + r.kag * dx);
                    for nb in [g - 1, g + 1] {
                        let nb_end = nb % nk == 0 || nb % nk == nk - 1;
                        if !nb_end || pinned {
                            add(it + g, it + nb, -(r.ei / dx));
                        }
                        let sgn = if nb > g { -0.5 } else { 0.5 };
                        if !nb_end {
                            add(it + g, iz + nb, sgn * r.kag);
                        }
                    }
                }
            }
        }
        let ls = 0.5 * p.rail_seat_distance;
        for i in 0..ns {
            let node = i * p.nodes_per_span;
            for (rail, arm) in [(0usize, -ls), (1usize, ls)] {
                if on.is_some_and(|(pads, _)| !pads[rail * ns + i]) {
                    continue;
                }
                let g = rail * nk + node;
                let rail_fixed = node == 0 || node == nk - 1;
                // pad energy 1/2 K_p (Z - Z_s - arm phi)^2
                let idx = [iz + g, izs + i, iph + i];
                let v = [1.0, -1.0, -arm];
                for a in 0..3 {
                    for b in 0..3 {
                        if rail_fixed && (a == 0 || b == 0) {
                            continue;
                        }
                        add(idx[a], idx[b], p.pad_stiffness * v[a] * v[b]);
                    }
                }
            }
            match on {
                Some((_, ballast)) if !(ballast[i] && ballast[ns + i]) => {
                    for (seat, arm) in [(0usize, -ls), (1usize, ls)] {
                        if ballast[seat * ns + i] {
                            let kb = p.ballast_stiffness;
                            add(izs + i, izs + i, kb);
                            add(izs + i, iph + i, kb * arm);
                            add(iph + i, izs + i, kb * arm);
                            add(iph + i, iph + i, kb * arm * arm);
                        }
                    }
                }
                _ => {
                    add(izs + i, izs + i, 2.0 * p.ballast_stiffness);
                    add(iph + i, iph + i, 2.0 * ls * ls * p.ballast_stiffness);
                }
            }
        }
    }

    /// Puts the track in static equilibrium under `loads` (the same discrete equations
    /// with zero accelerations and velocities), solved directly.
    pub fn set_static(&mut self, loads: &[PointLoad]) -> Result<()> {
        if self.exact.is_some() {
            return self.set_static_exact(loads);
        }
        let n = self.static_size();
        let nk = self.nk;
        let mut f = DVector::<f64>::zeros(n);
        for l in loads {
            let (kk, w) = self.locate(l.position);
            let base = l.rail.min(1) * nk;
            for (node, share) in [(kk, 1.0 - w), (kk + 1, w)] {
                if node != 0 && node != nk - 1 {
                    f[base + node] -= share * l.force;
                }
            }
        }
        if self.unilateral.is_some() {
            return self.set_static_unilateral(f.as_slice());
        }
        let x = self.solve_static_banded(f.as_slice()).ok_or_else(|| {
            out_of_range(
                "track.pad.stiffness",
                self.params.pad_stiffness,
                format!(
                    "a track whose pads and ballast hold the rails (static solve singular \
                         with track.pad.stiffness = {} N/m and track.ballast.stiffness = {} \
                         N/m: give both > 0)",
                    crate::error::num(self.params.pad_stiffness),
                    crate::error::num(self.params.ballast_stiffness)
                ),
            )
        })?;
        self.set_static_state(&x);
        Ok(())
    }

    /// Sets the state at t_j and t_(j-1) to the static solution `x` (unknowns of
    /// [`Track::stiffness_matrix`]), with the linear pad forces.
    pub(super) fn set_static_state(&mut self, xs: &[f64]) {
        let (nk, ns, sp) = (self.nk, self.ns, self.sp);
        Self::from_nodes(&self.slot, sp, &xs[..2 * nk], &mut self.z);
        Self::from_nodes(&self.slot, sp, &xs[2 * nk..4 * nk], &mut self.th);
        self.zs[..ns].copy_from_slice(&xs[4 * nk..4 * nk + ns]);
        self.ph[..ns].copy_from_slice(&xs[4 * nk + ns..]);
        self.z_prev.copy_from_slice(&self.z);
        self.th_prev.copy_from_slice(&self.th);
        self.zs_prev.copy_from_slice(&self.zs);
        self.ph_prev.copy_from_slice(&self.ph);
        let ls = 0.5 * self.params.rail_seat_distance;
        for i in 0..ns {
            // Block 0 holds the rail nodes above the sleepers.
            let s = block_start(0, self.params.nodes_per_span, sp) + i;
            let (zl, zr) = (self.z[s], self.z[s + sp]);
            self.pad[i] = -self.params.pad_stiffness * (zl - self.zs[i] + ls * self.ph[i]);
            self.pad[sp + i] = -self.params.pad_stiffness * (zr - self.zs[i] - ls * self.ph[i]);
        }
    }

    /// Unknowns of [`Track::stiffness_matrix`] in order along the track: at each node
    /// `Z` and `theta` of the left rail, then of the right rail, then the sleeper's
    /// bounce and roll where a sleeper sits. Couplings then stay within a few places
    /// of the diagonal.
    pub(super) fn static_order_along_track(&self) -> Vec<usize> {
        let (nk, ns, n) = (self.nk, self.ns, self.params.nodes_per_span);
        let mut order = Vec::with_capacity(self.static_size());
        for k in 0..nk {
            order.extend([k, 2 * nk + k, nk + k, 3 * nk + k]);
            if k % n == 0 {
                order.extend([4 * nk + k / n, 4 * nk + ns + k / n]);
            }
        }
        order
    }

    /// Solves `K x = f` for the symmetric positive definite stiffness matrix on its
    /// band, the unknowns taken in order along the track (half-bandwidth about 10)
    /// and the band assembled directly from [`Track::stiffness_entries`]. `None` when
    /// `K` is singular.
    pub(super) fn solve_static_banded(&self, f: &[f64]) -> Option<Vec<f64>> {
        let order = self.static_order_along_track();
        solve_banded_spd(&order, |add| self.stiffness_entries(add), f)
    }

    /// Discrete energy of the undamped scheme (J): `1/2 v^T M v + 1/2 x_(j-1)^T K x_j`
    /// with `v = (x_j - x_(j-1)) / dt`; exactly conserved by the central-difference
    /// recurrence when all damping is zero and no load acts.
    pub fn discrete_energy(&self, k: &DMatrix<f64>) -> f64 {
        let p = &self.params;
        let dx = p.dx();
        let nk = self.nk;
        let ns = self.ns;
        let n = self.static_size();
        let mut x = DVector::<f64>::zeros(n);
        let mut xp = DVector::<f64>::zeros(n);
        let mut mass = DVector::<f64>::zeros(n);
        let (z, zp) = (self.to_nodes(&self.z), self.to_nodes(&self.z_prev));
        let (th, thp) = (self.to_nodes(&self.th), self.to_nodes(&self.th_prev));
        for i in 0..2 * nk {
            let end = i % nk == 0 || i % nk == nk - 1;
            x[i] = z[i];
            xp[i] = zp[i];
            mass[i] = p.rail.mass * dx;
            x[2 * nk + i] = th[i];
            xp[2 * nk + i] = thp[i];
            mass[2 * nk + i] = p.rail.rotary_inertia * if end { 0.5 * dx } else { dx };
        }
        for i in 0..ns {
            x[4 * nk + i] = self.zs[i];
            xp[4 * nk + i] = self.zs_prev[i];
            mass[4 * nk + i] = p.sleeper_mass;
            x[4 * nk + ns + i] = self.ph[i];
            xp[4 * nk + ns + i] = self.ph_prev[i];
            mass[4 * nk + ns + i] = p.sleeper_inertia;
        }
        let v = (&x - &xp) / self.dt;
        let kin = 0.5 * v.component_mul(&v).dot(&mass);
        let pot = 0.5 * xp.dot(&(k * &x));
        kin + pot
    }

    /// The static state of a track whose supports can lift: the active-set iteration
    /// over the direct solve (each pass solves with the supports that carried in the
    /// last, the others at their limit; the pads are settled before the ballast; a
    /// pass that changes none ends it). At most [`MAX_PASSES`] passes.
    pub(super) fn set_static_unilateral(&mut self, f: &[f64]) -> Result<()> {
        let (nk, ns) = (self.nk, self.ns);
        let u = self.unilateral.as_ref().expect("supports that can lift");
        let (pad_lim, kp, kb) = (
            u.pad_limit,
            self.params.pad_stiffness,
            self.params.ballast_stiffness,
        );
        let ls = 0.5 * self.params.rail_seat_distance;
        let (izs, iph) = (4 * nk, 4 * nk + ns);
        let n = self.params.nodes_per_span;
        let mut pad_on = vec![true; 2 * ns];
        // A hanging sleeper starts hanging (its ballast, pulled down to it by the gap,
        // would pull the sleeper and its pads with it).
        let mut ballast_on: Vec<bool> = (0..2 * ns).map(|k| !u.hanging[k % ns]).collect();
        // A support lets go beyond its limit by more than this (N): one that sits at
        // it (a hanging sleeper's pads with no preload) keeps carrying.
        let tol = 1e-6;
        let order = self.static_order_along_track();
        for _ in 0..MAX_PASSES {
            let mut rhs = f.to_vec();
            for i in 0..ns {
                let node = i * n;
                let fixed = node == 0 || node == nk - 1;
                let (g, lim) = (u.gap[i], u.ballast_limit[i]);
                for (s, arm) in [(0usize, -ls), (1usize, ls)] {
                    if !pad_on[s * ns + i] {
                        if !fixed {
                            rhs[s * nk + node] -= pad_lim;
                        }
                        rhs[izs + i] += pad_lim;
                        rhs[iph + i] += arm * pad_lim;
                    }
                    let load = if ballast_on[s * ns + i] {
                        -kb * g
                    } else {
                        -lim
                    };
                    rhs[izs + i] += load;
                    rhs[iph + i] += arm * load;
                }
            }
            let on = (pad_on.as_slice(), ballast_on.as_slice());
            let x = solve_banded_spd(
                &order,
                |add| self.stiffness_entries_with(Some(on), add),
                &rhs,
            )
            .ok_or_else(|| {
                Error::Unsupported(
                    "the static state of a track whose lifted supports leave a sleeper \
                         free (no pad or ballast holds it): give the pads a preload \
                         (track.pad.preload) or the hanging sleepers a smaller gap"
                        .into(),
                )
            })?;
            // The pads first: a pass that releases or takes back a pad leaves the
            // ballast as it was (released together, a sleeper's pads and ballast
            // would leave it free, where its ballast carries nothing once the pads
            // have let go).
            let mut pads = pad_on.clone();
            let mut seats = ballast_on.clone();
            for i in 0..ns {
                let node = i * n;
                let (g, lim) = (u.gap[i], u.ballast_limit[i]);
                for (s, arm) in [(0usize, -ls), (1usize, ls)] {
                    let seat = x[izs + i] + arm * x[iph + i];
                    let pad = -kp * (x[s * nk + node] - seat);
                    let slack = if pad_on[s * ns + i] { tol } else { 0.0 };
                    pads[s * ns + i] = pad >= -pad_lim - slack;
                    let ballast = -kb * (seat + g);
                    let slack = if ballast_on[s * ns + i] { tol } else { 0.0 };
                    seats[s * ns + i] = ballast >= -lim - slack;
                }
            }
            let changed = if pads != pad_on {
                pad_on = pads;
                true
            } else if seats != ballast_on {
                ballast_on = seats;
                true
            } else {
                false
            };
            if !changed {
                self.set_static_state(&x);
                for i in 0..2 * ns {
                    if !pad_on[i] {
                        let at = (i / ns) * self.sp + i % ns;
                        self.pad[at] = -pad_lim;
                    }
                }
                // The supports lifted at the start, for no time yet.
                let u = self.unilateral.as_mut().expect("supports that can lift");
                let at_start = |on: &[bool], t: &mut [f64]| {
                    for (t, &on) in t.iter_mut().zip(on) {
                        *t = if on { CARRIES } else { 0.0 };
                    }
                };
                at_start(&pad_on, &mut u.pad_lifted);
                at_start(&ballast_on, &mut u.ballast_lifted);
                (u.longest, u.longest_at) = (0.0, 0);
                return Ok(());
            }
        }
        Err(Error::Unsupported(format!(
            "the static state of the track's lifting supports: the active-set \
                 iteration did not settle in {MAX_PASSES} passes (give the pads and the \
                 ballast their physical preloads, track.pad.preload and \
                 track.ballast.preload)"
        )))
    }
}
