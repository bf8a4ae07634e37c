//! The moving window of an endless track: the rails and sleepers shift back by whole
//! sleeper spans, and new track enters ahead at rest (its unloaded equilibrium, zero
//! displacement: the track's own weight is not modelled, `docs/MODEL.md`).

use super::*;

impl Track {
    /// Shifts the track's state `m` sleeper spans towards its left end: node `k` takes
    /// the state (displacements at `t_j` and `t_(j-1)`, pad forces) of node `k + m n`,
    /// sleeper `i` that of sleeper `i + m`; the last `m` spans enter at rest, and the
    /// rail ends are held at rest (`Z = theta = 0`, the fixed ends of the window). The
    /// left `m` spans' state leaves the window. Each phase block moves as one
    /// `copy_within`, so a shift costs about one step.
    ///
    /// Errors: `m` not below [`TrackParams::spans`] (nothing of the window would
    /// remain), or a track with pinned ends (the window's ends are fixed).
    pub fn shift_spans(&mut self, m: usize) -> Result<()> {
        if m == 0 {
            return Ok(());
        }
        let spans = self.params.spans;
        if m >= spans {
            return Err(out_of_range(
                "window shift",
                m as f64,
                format!("fewer than track.spans = {spans} spans"),
            ));
        }
        if self.params.ends != RailEnds::Fixed {
            return Err(Error::Unsupported(
                "a moving window on a track with pinned ends".into(),
            ));
        }
        if self.exact.is_some() && m > 1 {
            // Exact ends take the exterior's state one span at a time.
            for _ in 0..m {
                self.shift_spans(1)?;
            }
            return Ok(());
        }
        if self.exact.is_some() {
            self.exact_shift_back();
        }
        let n = self.params.nodes_per_span;
        let sp = self.sp;
        // Phase block p holds nodes k = i n + p, i = 0..count(p), of each rail at
        // indices i of its rail part: a shift by m spans moves every part by m.
        let count = |p: usize| if p == 0 { spans + 1 } else { spans };
        for a in [
            &mut self.z,
            &mut self.th,
            &mut self.z_prev,
            &mut self.th_prev,
        ] {
            for p in 0..n {
                let start = block_start(p, n, sp);
                for rail in 0..2 {
                    let part = &mut a[start + rail * sp..start + rail * sp + count(p)];
                    shift_left(part, m);
                }
            }
        }
        let ns = self.ns;
        for a in [
            &mut self.zs,
            &mut self.ph,
            &mut self.zs_prev,
            &mut self.ph_prev,
        ] {
            shift_left(&mut a[..ns], m);
        }
        for rail in 0..2 {
            shift_left(&mut self.pad[rail * sp..rail * sp + ns], m);
        }
        // Supports that can lift: their lift times move with them (the gaps are the
        // caller's to place anew, `Track::set_sleeper_gaps`).
        if let Some(u) = &mut self.unilateral {
            for a in [&mut u.pad_lifted, &mut u.ballast_lifted] {
                for side in 0..2 {
                    let part = &mut a[side * ns..(side + 1) * ns];
                    shift_left(part, m);
                    let len = part.len();
                    part[len - m.min(len)..].fill(CARRIES);
                }
            }
            shift_left(&mut u.gap, m);
            let ns = u.hanging.len();
            u.hanging.copy_within(m.min(ns).., 0);
            u.hanging[ns - m.min(ns)..].fill(false);
            let p = self.params;
            u.set_limits(&p);
            u.longest_at -= m as i64;
        }
        if self.exact.is_some() {
            self.exact_shift_one();
            return Ok(());
        }
        // The window's ends are fixed.
        for (end, _) in self.ends_inner {
            for a in [
                &mut self.z,
                &mut self.th,
                &mut self.z_prev,
                &mut self.th_prev,
            ] {
                a[end] = 0.0;
            }
        }
        Ok(())
    }
}

/// Moves `a[m..]` to the front of `a` and sets the last `m` values to zero.
fn shift_left(a: &mut [f64], m: usize) {
    let len = a.len();
    let m = m.min(len);
    a.copy_within(m.., 0);
    a[len - m..].iter_mut().for_each(|x| *x = 0.0);
}
