//! What the track feels at a place: the rail's displacement, bending moment and shear
//! force anywhere along it, and at a sleeper the rail seat (pad) force, the seat's
//! displacement and the ballast force. The thesis names rail bending moment and shear
//! force as future work (chapter 6); they follow from the Timoshenko rail's own
//! variables.

use super::*;

/// The rail at one place on one rail at `t_j`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RailResponse {
    /// Rail deflection `Z` (m), up positive, interpolated by (3.23).
    pub displacement: f64,
    /// Bending moment `M = EI dtheta/dx` (N m), positive sagging (rail foot in tension,
    /// as under a wheel): at the nodes from the elements' moments on either side,
    /// interpolated by (3.23).
    pub bending_moment: f64,
    /// Shear force `Q = kAG (dZ/dx - theta)` (N) of the Timoshenko rail (3.4) in the
    /// element that holds the place (constant along an element; it jumps by a load
    /// acting at a node). Positive where the rail's right part pushes its left part
    /// up.
    pub shear_force: f64,
}

/// One sleeper's support of one rail at `t_j`.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SupportResponse {
    /// The sleeper's index, 0 at the track's left end.
    pub sleeper: usize,
    /// The sleeper's position along the track (m).
    pub position: f64,
    /// Rail seat force (N): the pad force (3.9), positive in compression (the pad
    /// pushing the rail up).
    pub rail_seat_force: f64,
    /// Displacement of the sleeper under the rail seat (m), up positive:
    /// `Z_s -+ L_s phi_s` (3.7, 3.8).
    pub seat_displacement: f64,
    /// Ballast force under the rail seat (N), positive in compression:
    /// `-(K_b z_seat + C_b dz_seat/dt)`, the velocity a backward difference over the
    /// last step; with supports that can lift, its limit while the seat is lifted
    /// (`-track.ballast.preload`, 0 under a hanging sleeper) and the gap counted under
    /// a hanging sleeper.
    pub ballast_force: f64,
    /// How long the rail has been lifted off this pad without a break (s); 0 while the
    /// pad carries.
    pub pad_lifted: f64,
    /// How long the seat has been lifted off the ballast without a break (s); 0 while
    /// the ballast carries.
    pub ballast_lifted: f64,
}

impl Track {
    /// The rail `rail` (0 left, 1 right) at position `x` (m), `0 <= x <= length`.
    ///
    /// # Panics
    /// When `x` lies outside the track.
    pub fn rail_response(&self, rail: usize, x: f64) -> RailResponse {
        let (k, w) = self.locate(x);
        let (z, th) = (&self.z, &self.th);
        let at = |k: usize| self.slot_of(rail, k);
        let inv_dx = self.inv_dx;
        let ei = self.params.rail.ei;
        // M of element j (nodes j, j + 1), at its midpoint.
        let element = |j: usize| {
            let j = j.min(self.nk - 2);
            ei * (th[at(j + 1)] - th[at(j)]) * inv_dx
        };
        // M at node k: the mean of the linear extrapolations of the element moments
        // from either side, second-order accurate where M is smooth, and the peak where
        // a wheel or a rail seat at the node puts a kink in it (a central difference
        // of theta would give the mean of the two elements, short of the peak by
        // about Q dx / 2).
        let moment = |k: usize| {
            let (l1, l2) = (k.saturating_sub(1), k.saturating_sub(2));
            let left = 1.5 * element(l1) - 0.5 * element(l2);
            let right = 1.5 * element(k) - 0.5 * element(k + 1);
            0.5 * (left + right)
        };
        let dz = (z[at(k + 1)] - z[at(k)]) * inv_dx;
        let theta = 0.5 * (th[at(k)] + th[at(k + 1)]);
        RailResponse {
            displacement: (1.0 - w) * z[at(k)] + w * z[at(k + 1)],
            bending_moment: (1.0 - w) * moment(k) + w * moment(k + 1),
            shear_force: self.params.rail.kag * (dz - theta),
        }
    }

    /// The support of rail `rail` (0 left, 1 right) by the sleeper nearest position `x`
    /// (m).
    pub fn support_response(&self, rail: usize, x: f64) -> SupportResponse {
        let p = &self.params;
        let i = ((x / p.sleeper_spacing).round().max(0.0) as usize).min(self.ns - 1);
        let ls = 0.5 * p.rail_seat_distance;
        let side = if rail == 0 { -1.0 } else { 1.0 };
        let seat = |zs: &[f64], ph: &[f64]| zs[i] + side * ls * ph[i];
        let (now, before) = (seat(&self.zs, &self.ph), seat(&self.zs_prev, &self.ph_prev));
        let (pad_lifted, ballast_lifted) = self.lift_times(rail, i);
        let ballast_off = self.lifted(rail, i).1;
        let (gap, limit) = self
            .unilateral
            .as_ref()
            .map_or((0.0, 0.0), |u| (u.gap[i], u.ballast_limit[i]));
        SupportResponse {
            sleeper: i,
            position: i as f64 * p.sleeper_spacing,
            rail_seat_force: self.pad_forces(rail)[i],
            seat_displacement: now,
            // With supports that can lift, the force the step's update found (its
            // velocity a central difference) is at least the limit; the backward
            // difference here may stray below it by a little.
            ballast_force: if ballast_off {
                -limit
            } else {
                let f = -(p.ballast_stiffness * (now + gap)
                    + p.ballast_damping * (now - before) / self.dt);
                if self.unilateral.is_some() {
                    f.max(-limit)
                } else {
                    f
                }
            },
            pad_lifted,
            ballast_lifted,
        }
    }
}

#[cfg(test)]
mod tests_support {
    use super::*;
    use crate::sim::{Scenario, TrackSpec};

    /// The table 4.4 track at the converged grid, `spans` long.
    pub fn track(spans: usize) -> Track {
        let TrackSpec::Discrete(mut p) = Scenario::table_4_4().track else {
            unreachable!("table 4.4 has the discrete track")
        };
        p.spans = spans;
        Track::new(p, 1e-5).unwrap()
    }

    /// Static stiffness of one rail seat (N/m): pad and ballast in series (the
    /// sleeper does not roll under equal loads on both rails).
    pub fn seat_stiffness(p: &TrackParams) -> f64 {
        p.pad_stiffness * p.ballast_stiffness / (p.pad_stiffness + p.ballast_stiffness)
    }

    /// `beta = (k / (4 EI))^(1/4)` (1/m) of the Winkler foundation that spreads the
    /// seats' stiffness along the rail, `k = k_s / a`.
    pub fn winkler_beta(p: &TrackParams) -> f64 {
        (seat_stiffness(p) / p.sleeper_spacing / (4.0 * p.rail.ei)).powf(0.25)
    }
}

#[cfg(test)]
mod tests {
    use super::tests_support::*;
    use super::*;

    /// A static wheel load of 107.66 kN per rail at `x` (m).
    fn loaded(spans: usize, x: f64) -> (Track, f64) {
        let mut t = track(spans);
        let p = 107_664.75;
        let loads = [0, 1].map(|rail| PointLoad {
            rail,
            position: x,
            force: p,
        });
        t.set_static(&loads).unwrap();
        (t, p)
    }

    /// The exact static solution of an Euler-Bernoulli rail on discrete elastic rail
    /// seats (pad and ballast in series, `k_s` per seat every `a`), fixed at both ends,
    /// under a point load `p` (N, down) at `x` (m), a node of the half-span grid:
    /// cubic (Hermite) beam elements between the nodes are exact for point loads and
    /// supports at the nodes. Returns the deflection (m) and the sagging bending moment
    /// (N m) at `x`, and the rail seat force (N, compression) at the sleeper nearest.
    fn discrete_support_exact(t: &Track, p: f64, x: f64) -> (f64, f64, f64) {
        use nalgebra::{DMatrix, DVector};
        let pr = t.params();
        let (ei, a) = (pr.rail.ei, pr.sleeper_spacing);
        let ks = seat_stiffness(pr);
        let n = 2 * pr.spans + 1;
        let l = a / 2.0;
        let mut k = DMatrix::<f64>::zeros(2 * n, 2 * n);
        let ke = [
            [12.0, 6.0 * l, -12.0, 6.0 * l],
            [6.0 * l, 4.0 * l * l, -6.0 * l, 2.0 * l * l],
            [-12.0, -6.0 * l, 12.0, -6.0 * l],
            [6.0 * l, 2.0 * l * l, -6.0 * l, 4.0 * l * l],
        ];
        for e in 0..n - 1 {
            for r in 0..4 {
                for c in 0..4 {
                    k[(2 * e + r, 2 * e + c)] += ei / (l * l * l) * ke[r][c];
                }
            }
        }
        for j in (0..n).step_by(2) {
            k[(2 * j, 2 * j)] += ks;
        }
        let mut f = DVector::<f64>::zeros(2 * n);
        let jl = (x / l).round() as usize;
        f[2 * jl] = -p;
        // Fixed ends: deflection and rotation 0.
        for d in [0, 1, 2 * n - 2, 2 * n - 1] {
            k.row_mut(d).fill(0.0);
            k.column_mut(d).fill(0.0);
            k[(d, d)] = 1.0;
            f[d] = 0.0;
        }
        let u = k.lu().solve(&f).unwrap();
        let (w, th, w2, th2) = (u[2 * jl], u[2 * jl + 1], u[2 * jl + 2], u[2 * jl + 3]);
        let moment = ei * (-6.0 * w - 4.0 * l * th + 6.0 * w2 - 2.0 * l * th2) / (l * l);
        let js = 2 * ((x / a).round() as usize);
        (w, moment, -ks * u[2 * js])
    }

    #[test]
    fn static_wheel_load_against_winkler_and_the_exact_discrete_support_solution() {
        let a = 0.685;
        // Over a sleeper (the 30th of 60 spans) and at mid-span.
        let mut moments = Vec::new();
        for (x, over_sleeper) in [(30.0 * a, true), (30.5 * a, false)] {
            let (t, p) = loaded(60, x);
            let r = t.rail_response(0, x);
            let s = t.support_response(0, x);
            // Statics: the rail seats carry the whole load, and the shear force jumps by
            // the load where it acts (less the seat force there).
            let seats: f64 = (0..=60)
                .map(|i| t.support_response(0, i as f64 * a).rail_seat_force)
                .sum();
            assert!((seats - p).abs() < 1e-9 * p, "{seats}");
            let dx = a / 8.0;
            let jump = t.rail_response(0, x + 0.5 * dx).shear_force
                - t.rail_response(0, x - 0.5 * dx).shear_force;
            let seat_here = if over_sleeper { s.rail_seat_force } else { 0.0 };
            assert!((jump - (p - seat_here)).abs() < 1e-6 * p, "{jump}");
            // The exact Euler-Bernoulli solution on the same discrete seats: at the
            // default grid the model is 3 to 6 % softer, its moment's peak 6 to 7 %
            // lower, and the seat forces agree to 3 %.
            let (w, m, seat) = discrete_support_exact(&t, p, x);
            let (dw, dm, ds) = (
                r.displacement / w - 1.0,
                r.bending_moment / m - 1.0,
                s.rail_seat_force / seat - 1.0,
            );
            assert!((0.02..0.07).contains(&dw), "deflection {dw}");
            assert!((-0.08..-0.04).contains(&dm), "moment {dm}");
            assert!(ds.abs() < 0.035, "seat force {ds}");
            // On a refined grid (n = 64) the model tends to the continuous Timoshenko
            // rail on the same seats: 4.5 to 7.3 % softer than Euler-Bernoulli and a
            // moment 1 to 3 % lower, its shear flexibility; the default grid (n = 8)
            // is within 1.7 % of it in deflection and 5 % in moment.
            let mut q = *t.params();
            q.nodes_per_span = 64;
            let mut fine = Track::new_without_stability_check(q, 1e-5).unwrap();
            let loads = [0, 1].map(|rail| PointLoad {
                rail,
                position: x,
                force: p,
            });
            fine.set_static(&loads).unwrap();
            let (rf, sf) = (fine.rail_response(0, x), fine.support_response(0, x));
            let shear_w = rf.displacement / w - 1.0;
            let shear_m = rf.bending_moment / m - 1.0;
            assert!((0.04..0.08).contains(&shear_w), "{shear_w}");
            assert!((-0.04..0.0).contains(&shear_m), "{shear_m}");
            assert!((sf.rail_seat_force / seat - 1.0).abs() < 0.05);
            assert!((r.displacement / rf.displacement - 1.0).abs() < 0.02);
            assert!((r.bending_moment / rf.bending_moment - 1.0).abs() < 0.05);
            assert!((s.rail_seat_force / sf.rail_seat_force - 1.0).abs() < 0.015);
            moments.push((r.bending_moment, m));
        }
        // A load over a sleeper bends the rail less than one between two (Zimmermann);
        // the continuous (Winkler) foundation's moment P / (4 beta) lies between.
        let winkler = 107_664.75 / (4.0 * winkler_beta(track(60).params()));
        assert!(moments[0].0 < moments[1].0 && moments[0].1 < moments[1].1);
        assert!(
            moments[0].1 < winkler && winkler < moments[1].1,
            "{winkler}"
        );
    }
}

#[cfg(test)]
mod superposition {
    use super::tests_support::*;
    use super::*;

    /// The track is linear: the static state under the wheel loads of several
    /// wheelsets (a four-axle wagon: bogie wheelbase 1.8 m, bogie centres 10 m apart,
    /// unequal loads) is the sum of the states under each wheelset alone.
    #[test]
    fn static_states_of_several_wheelsets_superpose() {
        let positions = [25.0, 23.2, 15.0, 13.2];
        let forces = [107e3, 98e3, 112e3, 90e3];
        let loads_of = |w: usize| {
            [0, 1].map(|rail| PointLoad {
                rail,
                position: positions[w],
                force: forces[w] * if rail == 0 { 1.0 } else { 0.9 },
            })
        };
        let mut all = track(60);
        let every: Vec<PointLoad> = (0..4).flat_map(loads_of).collect();
        all.set_static(&every).unwrap();
        let mut sum = vec![0.0; 2 * all.nodes()];
        let mut seats = [0.0; 2];
        for w in 0..4 {
            let mut one = track(60);
            one.set_static(&loads_of(w)).unwrap();
            for (s, z) in sum
                .iter_mut()
                .zip(one.rail_z(0).into_iter().chain(one.rail_z(1)))
            {
                *s += z;
            }
            for (rail, seat) in seats.iter_mut().enumerate() {
                *seat += one.support_response(rail, 24.66).rail_seat_force;
            }
        }
        let scale = sum.iter().fold(0.0f64, |m, z| m.max(z.abs()));
        let together: Vec<f64> = all.rail_z(0).into_iter().chain(all.rail_z(1)).collect();
        for (k, (a, b)) in together.iter().zip(&sum).enumerate() {
            assert!((a - b).abs() <= 1e-9 * scale, "node {k}: {a} against {b}");
        }
        for (rail, seat) in seats.iter().enumerate() {
            let a = all.support_response(rail, 24.66).rail_seat_force;
            assert!((a - seat).abs() <= 1e-9 * 107e3, "{a} against {seat}");
        }
        // The trailing wheelset of a bogie deflects the rail under the leading one.
        let mut lead = track(60);
        lead.set_static(&loads_of(0)).unwrap();
        let mut bogie = track(60);
        bogie
            .set_static(&[loads_of(0), loads_of(1)].concat())
            .unwrap();
        let (alone, both) = (
            lead.rail_response(0, 25.0).displacement,
            bogie.rail_response(0, 25.0).displacement,
        );
        // It adds 3.9 % to the leading wheel's deflection; the Winkler foundation's
        // influence line `exp(-beta x) (cos beta x + sin beta x)` at 1.8 m gives 4.0 %.
        let bx = winkler_beta(track(60).params()) * 1.8;
        let winkler = (-bx).exp() * (bx.cos() + bx.sin()) * forces[1] / forces[0];
        let added = both / alone - 1.0;
        assert!((added - winkler).abs() < 0.005, "{added} against {winkler}");
    }
}
