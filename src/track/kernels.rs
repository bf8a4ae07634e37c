//! The explicit step: update coefficients and the rail and sleeper loops, compiled per
//! SIMD level.

use super::*;

/// Precomputed update coefficients.
#[derive(Debug, Clone, Copy)]
pub(super) struct Coeffs {
    pub(super) zz: f64,
    /// `2 - 2 zz`: centre weight of the deflection update.
    pub(super) zc: f64,
    pub(super) zt: f64,
    pub(super) tt: f64,
    /// `2 - 2 tt - t0`: centre weight of the rotation update.
    pub(super) tc: f64,
    pub(super) tz: f64,
    pub(super) t0: f64,
    pub(super) force: f64,
    pub(super) s: SleeperCoeffs,
}

/// Pad forces and sleeper update (3.9, 3.18) written with the fewest constants (so
/// that the vectorised loop keeps them all in registers):
/// `F = c_p u_(j-1) - k_pc u_j` per rail seat, with `u` the rail deflection over the
/// seat minus the seat's displacement, and the implicit damping denominators of (3.18)
/// folded into the update weights.
#[derive(Debug, Clone, Copy)]
pub(super) struct SleeperCoeffs {
    /// Half the rail seat distance `l_s / 2` (m).
    pub(super) ls: f64,
    /// `k_p + c_p / dt` (N/m).
    pub(super) kpc: f64,
    /// `c_p / dt` (N/m).
    pub(super) cp: f64,
    /// Bounce weights of `Z_s(t_j)`, `Z_s(t_(j-1))` and of the pad forces.
    pub(super) zz: f64,
    pub(super) zzp: f64,
    pub(super) zf: f64,
    /// Roll weights of `phi(t_j)`, `phi(t_(j-1))` and of the pad-force difference.
    pub(super) pp: f64,
    pub(super) ppp: f64,
    pub(super) pf: f64,
}

impl Coeffs {
    /// Update coefficients of the explicit scheme for step `dt` (s).
    pub(super) fn new(params: &TrackParams, dt: f64) -> Self {
        let p = params;
        let r = &p.rail;
        let dx = p.dx();
        let dt2 = dt * dt;
        let ls = 0.5 * p.rail_seat_distance;
        let kphi = 2.0 * ls * ls * p.ballast_stiffness;
        let cphi = 2.0 * ls * ls * p.ballast_damping;
        let zz = r.kag * dt2 / (r.mass * dx * dx);
        let tt = r.ei * dt2 / (r.rotary_inertia * dx * dx);
        let t0 = r.kag * dt2 / r.rotary_inertia;
        Coeffs {
            zz,
            zc: 2.0 - 2.0 * zz,
            zt: r.kag * dt2 / (2.0 * r.mass * dx),
            tt,
            tc: 2.0 - 2.0 * tt - t0,
            tz: r.kag * dt2 / (2.0 * r.rotary_inertia * dx),
            t0,
            force: dt2 / (r.mass * dx),
            s: {
                let zden = 1.0 / (1.0 + p.ballast_damping * dt / p.sleeper_mass);
                let pden = 1.0 / (1.0 + 0.5 * cphi * dt / p.sleeper_inertia);
                SleeperCoeffs {
                    ls,
                    kpc: p.pad_stiffness + p.pad_damping / dt,
                    cp: p.pad_damping / dt,
                    zz: (2.0 - 2.0 * p.ballast_stiffness * dt2 / p.sleeper_mass) * zden,
                    zzp: (p.ballast_damping * dt / p.sleeper_mass - 1.0) * zden,
                    zf: dt2 / p.sleeper_mass * zden,
                    pp: (2.0 - kphi * dt2 / p.sleeper_inertia) * pden,
                    ppp: (0.5 * cphi * dt / p.sleeper_inertia - 1.0) * pden,
                    pf: ls * dt2 / p.sleeper_inertia * pden,
                }
            },
        }
    }
}

/// Pad forces (3.9) and sleeper update (3.18) for every sleeper: rail deflections
/// above the sleepers at t_j (`rl`, `rr`) and t_(j-1) (`rlp`, `rrp`), sleeper bounce
/// and roll at t_j (`zs`, `ph`) and t_(j-1) (`zsp`, `php`, overwritten with t_(j+1)),
/// pad forces out (`pl`, `pr`). Separate slice arguments (not a struct of slices) so
/// that the compiler knows they do not alias and vectorises without runtime checks.
/// Slices are as long as `zs`, a multiple of [`LANES`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn sleepers_body<const FMA: bool>(
    rl: &[f64],
    rr: &[f64],
    rlp: &[f64],
    rrp: &[f64],
    zs: &[f64],
    ph: &[f64],
    zsp: &mut [f64],
    php: &mut [f64],
    pl: &mut [f64],
    pr: &mut [f64],
    c: &SleeperCoeffs,
) {
    let m = zs.len();
    let (rl, rr, rlp, rrp) = (&rl[..m], &rr[..m], &rlp[..m], &rrp[..m]);
    let (ph, zsp, php) = (&ph[..m], &mut zsp[..m], &mut php[..m]);
    let (pl, pr) = (&mut pl[..m], &mut pr[..m]);
    for i in 0..m {
        let (z, f, zp, fp) = (zs[i], ph[i], zsp[i], php[i]);
        let (fl, fr) = c.pad_forces::<FMA>([rl[i], rr[i], rlp[i], rrp[i]], [z, f], [zp, fp]);
        pl[i] = fl;
        pr[i] = fr;
        (zsp[i], php[i]) = c.sleeper_update::<FMA>([z, f], [zp, fp], fl, fr);
    }
}

impl SleeperCoeffs {
    /// The pad forces (3.9) `(left, right)` (N, up on the rails) of one sleeper: the rail
    /// over its seats now and a step back `[left, right, left back, right back]` (m),
    /// its bounce and roll now and a step back (m, rad).
    #[inline(always)]
    pub(super) fn pad_forces<const FMA: bool>(
        &self,
        rail: [f64; 4],
        now: [f64; 2],
        back: [f64; 2],
    ) -> (f64, f64) {
        let ([rl, rr, rlp, rrp], [z, f], [zp, fp]) = (rail, now, back);
        // Rail over seat, now and one step back: u = Z_rail - (Z_s -/+ l_s/2 phi).
        let (ul, ur) = (
            rl - madd::<FMA>(-self.ls, f, z),
            rr - madd::<FMA>(self.ls, f, z),
        );
        let (upl, upr) = (
            rlp - madd::<FMA>(-self.ls, fp, zp),
            rrp - madd::<FMA>(self.ls, fp, zp),
        );
        (
            madd::<FMA>(-self.kpc, ul, self.cp * upl),
            madd::<FMA>(-self.kpc, ur, self.cp * upr),
        )
    }

    /// The sleeper's bounce and roll a step on (3.18) from now and a step back (m,
    /// rad) under the pad forces `fl`, `fr` (N, up on the rails), both ballast seats
    /// carrying.
    #[inline(always)]
    pub(super) fn sleeper_update<const FMA: bool>(
        &self,
        now: [f64; 2],
        back: [f64; 2],
        fl: f64,
        fr: f64,
    ) -> (f64, f64) {
        let ([z, f], [zp, fp]) = (now, back);
        (
            madd::<FMA>(-self.zf, fl + fr, madd::<FMA>(self.zzp, zp, self.zz * z)),
            madd::<FMA>(self.pf, fl - fr, madd::<FMA>(self.ppp, fp, self.pp * f)),
        )
    }
}

/// `a b + c`: fused (one rounding) with `FMA`, else a product and a sum.
#[inline(always)]
pub(super) fn madd<const FMA: bool>(a: f64, b: f64, c: f64) -> f64 {
    if FMA { a.mul_add(b, c) } else { a * b + c }
}

/// One phase block of the rail stencil (3.12): centre nodes `zc`, `tc` with their
/// left (`zl`, `tl`) and right (`zr`, `tr`) neighbours, new values written over the
/// t_(j-1) values `zn`, `tn`. With `PAD` the block is block 0: it holds the sleeper
/// nodes, the pad forces `pad` enter, and the new values are masked by `keep` (bit
/// patterns: all ones keep a value, zero clears it), which holds the rail ends and
/// block 0's padding at exactly `+0.0` without a scalar store after the loop (a vector
/// load of the next step over a slot just written by a scalar store cannot take its
/// value from the store buffer and waits for the store to reach the cache).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn stencil_body<const PAD: bool, const FMA: bool>(
    zl: &[f64],
    zc: &[f64],
    zr: &[f64],
    tl: &[f64],
    tc: &[f64],
    tr: &[f64],
    zn: &mut [f64],
    tn: &mut [f64],
    pad: &[f64],
    keep: &[f64],
    c: &Coeffs,
) {
    let m = zc.len();
    let (zl, zr) = (&zl[..m], &zr[..m]);
    let (tl, tc, tr) = (&tl[..m], &tc[..m], &tr[..m]);
    let (zn, tn) = (&mut zn[..m], &mut tn[..m]);
    let (pad, keep) = if PAD {
        (&pad[..m], &keep[..m])
    } else {
        (&pad[..0], &keep[..0])
    };
    // `v` with its bits and-ed with `mask`'s.
    let masked = |v: f64, mask: f64| f64::from_bits(v.to_bits() & mask.to_bits());
    for i in 0..m {
        // (3.12) with the centre terms gathered: 5 multiply-adds per value.
        let znew = madd::<FMA>(
            -c.zt,
            tr[i] - tl[i],
            madd::<FMA>(c.zz, zr[i] + zl[i], madd::<FMA>(c.zc, zc[i], -zn[i])),
        );
        let tnew = madd::<FMA>(
            c.tz,
            zr[i] - zl[i],
            madd::<FMA>(c.tt, tr[i] + tl[i], madd::<FMA>(c.tc, tc[i], -tn[i])),
        );
        if PAD {
            zn[i] = masked(madd::<FMA>(c.force, pad[i], znew), keep[i]);
            tn[i] = masked(tnew, keep[i]);
        } else {
            zn[i] = znew;
            tn[i] = tnew;
        }
    }
}

/// One track step's loops over phase-blocked arrays of `n` blocks (see [`Track`]):
/// 1. pad forces at t_j (backward-difference damper velocities) and the sleeper
///    update (3.18), in place over the t_(j-1) sleeper arrays; block 0 holds the rail
///    nodes above the sleepers; with supports that can lift, `unilateral`'s loop
///    ([`sleepers_unilateral`]) in place of the vectorised one;
/// 2. the rail stencil block by block, each whole, written in place over the t_(j-1)
///    rail arrays, the pad forces entering block 0 and its mask `keep` clearing the
///    rail ends and its padding. Block p's left neighbours are block p - 1 (block
///    n - 1 one slot back for p = 0), its right neighbours block p + 1 (block 0 one
///    slot on for p = n - 1).
///
/// Inlined into [`step_body`], which is compiled once per SIMD level.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn kernels_body<const FMA: bool>(
    z: &[f64],
    th: &[f64],
    z_prev: &mut [f64],
    th_prev: &mut [f64],
    zs: &[f64],
    ph: &[f64],
    zs_prev: &mut [f64],
    ph_prev: &mut [f64],
    pad: &mut [f64],
    keep: &[f64],
    c: &Coeffs,
    n: usize,
    unilateral: Option<&mut Unilateral>,
) {
    let sp = zs.len();
    {
        let b0 = block_start(0, n, sp)..block_start(0, n, sp) + 2 * sp;
        let (rl, rr) = z[b0.clone()].split_at(sp);
        let (rlp, rrp) = z_prev[b0].split_at(sp);
        let (pl, pr) = pad.split_at_mut(sp);
        match unilateral {
            None => sleepers_body::<FMA>(rl, rr, rlp, rrp, zs, ph, zs_prev, ph_prev, pl, pr, &c.s),
            Some(u) => sleepers_unilateral::<FMA>(
                rl, rr, rlp, rrp, zs, ph, zs_prev, ph_prev, pl, pr, &c.s, u,
            ),
        }
    }
    rail_body::<FMA>(z, th, z_prev, th_prev, pad, keep, c, n);
}

/// The rail stencil (3.12) over every phase block (see [`kernels_body`]). Blocks
/// `2..=n - 2`, stored one after another with their neighbours a block away on either
/// side, run as one loop (each loop's set-up costs about 120 instructions, as much as
/// five of its vector iterations at the default window); blocks 0, 1 and `n - 1`,
/// whose neighbours lie elsewhere, run alone.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn rail_body<const FMA: bool>(
    z: &[f64],
    th: &[f64],
    z_prev: &mut [f64],
    th_prev: &mut [f64],
    pad: &[f64],
    keep: &[f64],
    c: &Coeffs,
    n: usize,
) {
    let sp = keep.len() / 2;
    let b = 2 * sp;
    let block = |p: usize| block_start(p, n, sp)..block_start(p, n, sp) + b;
    // One stencil loop over the centre slots `centre`, its left and right neighbours
    // `left` and `right` slots away (wrapping: a neighbour before the centre).
    let mut run = inlined(
        #[inline(always)]
        |centre: std::ops::Range<usize>, left: usize, right: usize| {
            let (zl, zc, zr) = (
                &z[centre.start.wrapping_sub(left)..centre.end.wrapping_sub(left)],
                &z[centre.clone()],
                &z[centre.start + right..centre.end + right],
            );
            let (tl, tc, tr) = (
                &th[centre.start.wrapping_sub(left)..centre.end.wrapping_sub(left)],
                &th[centre.clone()],
                &th[centre.start + right..centre.end + right],
            );
            let (zn, tn) = (&mut z_prev[centre.clone()], &mut th_prev[centre]);
            stencil_body::<false, FMA>(zl, zc, zr, tl, tc, tr, zn, tn, &[], &[], c);
        },
    );
    // Offset of block q from block p (as a left neighbour: p's start minus q's).
    let gap = |p: usize, q: usize| block(p).start.wrapping_sub(block(q).start);
    // Block 1: block 0 on its left, block 2 (block 0 one slot on, for n = 2) on its right.
    if n >= 2 {
        let right = if n == 2 {
            block(0).start + 1
        } else {
            block(2).start
        };
        run(block(1), gap(1, 0), right - block(1).start);
    }
    // Blocks 2..=n - 2 as one loop, their neighbours a block away.
    if n >= 4 {
        run(block(2).start..block(n - 2).end, b, b);
    }
    // Block n - 1: block n - 2 on its left, block 0 one slot on on its right.
    if n >= 3 {
        let centre = block(n - 1);
        run(centre.clone(), b, block(0).start + 1 - centre.start);
    }
    // Block 0 last, with the pad forces and the mask: block n - 1 one slot back on its
    // left, block 1 on its right.
    let centre = block(0);
    let left = block(n - 1).start - 1..block(n - 1).end - 1;
    let right = block(1.min(n - 1)).start + usize::from(n == 1)..;
    let right = right.start..right.start + b;
    let (zl, zc, zr) = (&z[left.clone()], &z[centre.clone()], &z[right.clone()]);
    let (tl, tc, tr) = (&th[left], &th[centre.clone()], &th[right]);
    let (zn, tn) = (&mut z_prev[centre.clone()], &mut th_prev[centre]);
    stencil_body::<true, FMA>(zl, zc, zr, tl, tc, tr, zn, tn, pad, keep, c);
}

/// [`Track::step`]: the loops of [`kernels_body`], then the wheel forces, end
/// conditions and padding; products and sums fused with `FMA`. The whole step is
/// compiled once per [`SimdLevel`], the glue with the loops.
#[inline(always)]
pub(super) fn step_body<const FMA: bool>(t: &mut Track, loads: &[PointLoad]) {
    let (inv_dx, nk) = (t.inv_dx, t.nk);
    let Track {
        params,
        c,
        sp,
        z,
        th,
        z_prev,
        th_prev,
        zs,
        ph,
        zs_prev,
        ph_prev,
        pad,
        keep,
        padding,
        ends_inner,
        slot,
        unilateral,
        ..
    } = t;
    let sp = *sp;
    let n = params.nodes_per_span;
    // The stencil overwrites every slot; pinned ends need their t_(j-1) rotation.
    let th_prev_ends = match params.ends {
        RailEnds::Pinned => ends_inner.map(|(e, _)| th_prev[e]),
        RailEnds::Fixed => [0.0; 4],
    };
    // 1-2. Sleepers and pads, then the rail stencil (see `kernels_body`).
    kernels_body::<FMA>(
        z,
        th,
        z_prev,
        th_prev,
        zs,
        ph,
        zs_prev,
        ph_prev,
        pad,
        keep,
        c,
        n,
        unilateral.as_deref_mut(),
    );
    // 3. Wheel forces on the new rail state, the rail ends (which the loops left at
    // zero) excepted.
    let mut apply = inlined(
        #[inline(always)]
        |k: usize, w: f64, rail: usize, force: f64| {
            let r = rail.min(1) * sp;
            if k > 0 {
                z_prev[slot[k] + r] -= c.force * (1.0 - w) * force;
            }
            if k + 2 < nk {
                z_prev[slot[k + 1] + r] -= c.force * w * force;
            }
        },
    );
    match loads {
        // A wheelset: both wheels at one position, located once.
        [a, b] if a.position == b.position => {
            let (k, w) = locate(a.position, inv_dx, nk);
            apply(k, w, a.rail, a.force);
            apply(k, w, b.rail, b.force);
        }
        _ => {
            for l in loads {
                let (k, w) = locate(l.position, inv_dx, nk);
                apply(k, w, l.rail, l.force);
            }
        }
    }
    match params.ends {
        // The padding stays at zero by itself (see `Track`).
        RailEnds::Fixed => {}
        RailEnds::Pinned => {
            // The end rotations are not zero, and padding next to an end reads them.
            for &s in padding.iter() {
                z_prev[s] = 0.0;
                th_prev[s] = 0.0;
            }
            // Ghost nodes: Z odd, theta even about the support.
            for (e, &(end, inner)) in ends_inner.iter().enumerate() {
                let sgn = if e % 2 == 0 { 1.0 } else { -1.0 };
                let (t0, ti, zi) = (th[end], th[inner], z[inner]);
                th_prev[end] = 2.0 * t0 - th_prev_ends[e]
                    + c.tt * (2.0 * ti - 2.0 * t0)
                    + sgn * c.tz * 2.0 * zi
                    - c.t0 * t0;
            }
        }
    }
    std::mem::swap(z, z_prev);
    std::mem::swap(th, th_prev);
    std::mem::swap(zs, zs_prev);
    std::mem::swap(ph, ph_prev);
}
