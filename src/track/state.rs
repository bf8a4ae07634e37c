//! Saving and restoring the track state.

use super::*;

impl Track {
    /// Number of values in [`Track::state_vector`].
    pub fn state_len(&self) -> usize {
        1 + 8 * self.nk
            + 6 * self.ns
            + self.unilateral.as_ref().map_or(0, |_| 4 * self.ns + 2)
            + self.exact.as_ref().map_or(0, |e| e.history_len())
    }

    /// Everything that determines the continuation: the step, rails (node order, both
    /// rails end to end) and sleepers at t_j and t_(j-1), and the last pad forces;
    /// with supports that can lift, how long each has been lifted and the longest
    /// lift with its sleeper; with exact ends ([`Track::set_exact_ends`]), their drive
    /// histories and pending response.
    /// [`Track::set_state_vector`] restores it exactly.
    pub fn state_vector(&self) -> Vec<f64> {
        let mut v = Vec::with_capacity(self.state_len());
        v.push(self.dt);
        for a in [&self.z, &self.th, &self.z_prev, &self.th_prev] {
            v.extend(self.to_nodes(a));
        }
        let (ns, sp) = (self.ns, self.sp);
        for a in [&self.zs, &self.ph, &self.zs_prev, &self.ph_prev] {
            v.extend_from_slice(&a[..ns]);
        }
        v.extend_from_slice(&self.pad[..ns]);
        v.extend_from_slice(&self.pad[sp..sp + ns]);
        if let Some(u) = &self.unilateral {
            v.extend_from_slice(&u.pad_lifted);
            v.extend_from_slice(&u.ballast_lifted);
            v.extend([u.longest, u.longest_at as f64]);
        }
        if let Some(e) = &self.exact {
            e.write_history(&mut v);
        }
        v
    }

    /// Restores a state written by [`Track::state_vector`] of a track with the same
    /// parameters.
    pub fn set_state_vector(&mut self, v: &[f64]) -> Result<()> {
        if v.len() != self.state_len() {
            return Err(out_of_range(
                "track state length",
                v.len() as f64,
                format!("{} values for this grid", self.state_len()),
            ));
        }
        if let Some(e) = &self.exact {
            e.check_history(&v[v.len() - e.history_len()..])?;
        }
        if v[0] != self.dt {
            self.change_dt(v[0])?;
        }
        let (nr, ns, sp) = (2 * self.nk, self.ns, self.sp);
        let mut rest = &v[1..];
        for a in [
            &mut self.z,
            &mut self.th,
            &mut self.z_prev,
            &mut self.th_prev,
        ] {
            let (head, tail) = rest.split_at(nr);
            Self::from_nodes(&self.slot, sp, head, a);
            rest = tail;
        }
        let (pl, pr) = self.pad.split_at_mut(sp);
        for a in [
            &mut self.zs[..ns],
            &mut self.ph[..ns],
            &mut self.zs_prev[..ns],
            &mut self.ph_prev[..ns],
            &mut pl[..ns],
            &mut pr[..ns],
        ] {
            let (head, tail) = rest.split_at(ns);
            a.copy_from_slice(head);
            rest = tail;
        }
        if let Some(e) = &mut self.exact {
            let (head, tail) = rest.split_at(rest.len() - e.history_len());
            e.read_history(tail);
            rest = head;
        }
        if let Some(u) = &mut self.unilateral {
            let (times, longest) = rest.split_at(4 * ns);
            if let Some(&x) = times
                .iter()
                .chain(longest)
                .find(|x| !(x.is_finite() && **x >= -1e15))
            {
                return Err(out_of_range("state: support lift times", x, "finite"));
            }
            u.pad_lifted.copy_from_slice(&times[..2 * ns]);
            u.ballast_lifted.copy_from_slice(&times[2 * ns..]);
            (u.longest, u.longest_at) = (longest[0], longest[1] as i64);
        }
        Ok(())
    }

    /// Sets sleeper bounce (m) and roll (rad) at t_j and t_(j-1).
    pub fn set_sleeper_state(&mut self, zs: &[f64], ph: &[f64], zs_prev: &[f64], ph_prev: &[f64]) {
        let ns = self.ns;
        self.zs[..ns].copy_from_slice(zs);
        self.ph[..ns].copy_from_slice(ph);
        self.zs_prev[..ns].copy_from_slice(zs_prev);
        self.ph_prev[..ns].copy_from_slice(ph_prev);
    }
}
