//! What the axle-box exchange tells of a partner TrackContact does not know: the
//! inertia of its side frames and which of TrackContact's primary forces it holds over a
//! communication step (so which kind of master drives the pair, and which output it
//! reads), fitted from the side-frame motion the master hands on and the primary forces
//! TrackContact computed.
//!
//! A side frame over two wheelsets' axle boxes `a` (leading) and `b` (trailing), `l`
//! (m) from its centre, answers the primary forces `F_a`, `F_b` (N, pushing it up) it
//! holds over a step `h` (s) with the velocity changes (m/s)
//!
//! ```text
//! dv_a + dv_b = h (D + X) (F_a + F_b) + 2 h s,   D + X = 2 / m
//! dv_a - dv_b = h (D - X) (F_a - F_b),           D - X = 2 l^2 / J
//! ```
//!
//! (`m`, `J` its mass and pitch inertia, [`super::SideFrameInertia::pitching`]), `s` the
//! acceleration from everything above it (its secondary suspension at its centre and
//! gravity), which TrackContact does not see. The pitch needs nothing unseen. In bounce
//! the first differences of both sides leave gravity and the slow part of `s` out, and
//! what the secondary spring and damper add as the side frame moves (the bodies above
//! slow beside it) is fitted with it: the change of the side frame's displacement and
//! velocity over two steps are two more regressors of the first differences, whose
//! coefficients are not used. A side frame over one axle box (the roll-plane
//! vehicle's) is the bounce alone, `D = 1 / m`.
//!
//! Which force the partner held over `[t_(k-1), t_k]` is one of four that TrackContact
//! handed out: under a Jacobi master, every unit stepping from `t_(k-1)`, the force at
//! the point `t_(k-1)` (`primary.*.force`) or the mean of the step before
//! (`primary.*.mean_force`); under a sequential master that steps TrackContact first,
//! the mean of this step or the force at its end. Each is fitted; the one that explains
//! the motion (least squares, no intercept) tells the master's kind and the output it
//! reads, and its slopes give `m` and `J`. The fit decides only once the motion has
//! enough in it: at rest, or where the candidates move alike, it says nothing.

/// The force a partner holds over a communication step, one of those TrackContact
/// hands out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HeldForce {
    /// A Jacobi master with `primary.*.force`, the force at the step's start: right.
    JacobiPoint,
    /// A Jacobi master with `primary.*.mean_force`, the mean of the step before: a step
    /// late, unstable beyond a millisecond or two.
    JacobiMean,
    /// A sequential master, TrackContact first, with `primary.*.mean_force`, the mean
    /// of this step: right.
    SequentialMean,
    /// A sequential master, TrackContact first, with `primary.*.force`, the force at
    /// the step's end: a step early.
    SequentialPoint,
}

impl HeldForce {
    /// The candidates, in the order of [`PartnerFit`]'s sums.
    pub const ALL: [HeldForce; 4] = [
        HeldForce::JacobiPoint,
        HeldForce::JacobiMean,
        HeldForce::SequentialMean,
        HeldForce::SequentialPoint,
    ];

    /// Whether the master steps every unit from the same point (Jacobi).
    pub fn is_jacobi(self) -> bool {
        matches!(self, HeldForce::JacobiPoint | HeldForce::JacobiMean)
    }

    /// The output the partner reads: `force` or `mean_force` (of `primary.*.`).
    pub fn output(self) -> &'static str {
        match self {
            HeldForce::JacobiPoint | HeldForce::SequentialPoint => "force",
            HeldForce::JacobiMean | HeldForce::SequentialMean => "mean_force",
        }
    }

    /// The output this kind of master should read: `force` under Jacobi, `mean_force`
    /// under a sequential master.
    pub fn right_output(self) -> &'static str {
        if self.is_jacobi() {
            "force"
        } else {
            "mean_force"
        }
    }
}

/// Least-squares sums `[x x, x y, y y]` of one channel and candidate.
type Sums = [f64; 3];

/// Least-squares sums of the bounce channel: `r r^T` of `r = [x, u, w, y]`: the
/// candidate's impulse (first differences, as all), the secondary suspension's two
/// regressors, and the velocity change fitted.
type BounceSums = nalgebra::Matrix4<f64>;

/// The fit of the side frames' inertia and of the held force; see the module.
#[derive(Debug, Clone)]
pub struct PartnerFit {
    /// Axle boxes, wheelset by wheelset, left then right.
    boxes: usize,
    /// Side frames span two wheelsets' boxes (wheelsets 1 and 2, 3 and 4).
    shared: bool,
    /// Half the wheelbase `l` (m) of shared side frames.
    half_wheelbase: f64,
    /// The primary forces at the last two communication points, older first: at the
    /// point `[force, mean of the step that ended there]` per box (N).
    history: Vec<[Vec<f64>; 2]>,
    /// The side-frame displacements and velocities at the last two points, older first
    /// (m, m/s).
    last: Vec<(Vec<f64>, Vec<f64>)>,
    /// The bounce channels of the last step, `(y, x per candidate)`, for the first
    /// differences.
    last_bounce: Option<Vec<(f64, [f64; 4])>>,
    /// The step of the last bounce sample (s): first differences need equal steps.
    last_h: f64,
    /// Sums of the bounce channel per candidate, over every side frame (all alike).
    bounce: [BounceSums; 4],
    /// Sums of the pitch channel per candidate.
    pitch: [Sums; 4],
    /// Steps fitted.
    steps: u64,
}

/// A candidate explains the motion when what it leaves is below this share of it.
const EXPLAINED: f64 = 0.05;
/// And the next best leaves at least this many times as much.
const APART: f64 = 4.0;
/// Steps fitted before the fit decides.
const LEAST_STEPS: u64 = 20;

/// What the fit found: the held force and the side frames' inertia.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartnerEstimate {
    /// The force the partner holds.
    pub held: HeldForce,
    /// The side frame's mass (kg): over two wheelsets, the whole side frame; over one
    /// axle box, the side frame there.
    pub mass: f64,
    /// The side frame's pitch inertia (kg m^2) over two wheelsets; `None` over one
    /// axle box, or where the pitch was not excited enough.
    pub pitch_inertia: Option<f64>,
    /// What the chosen candidate leaves unexplained, as a share of the motion.
    pub residual: f64,
}

impl PartnerFit {
    /// A fit for `wheelsets` wheelsets' axle boxes, their side frames spanning two
    /// wheelsets `wheelbase` (m) apart (`shared`; `wheelsets` even) or one axle box each.
    pub fn new(wheelsets: usize, shared: bool, wheelbase: f64) -> PartnerFit {
        PartnerFit {
            boxes: 2 * wheelsets,
            shared: shared && wheelsets.is_multiple_of(2),
            half_wheelbase: 0.5 * wheelbase,
            history: Vec::new(),
            last: Vec::new(),
            last_bounce: None,
            last_h: 0.0,
            bounce: [BounceSums::zeros(); 4],
            pitch: [[0.0; 3]; 4],
            steps: 0,
        }
    }

    /// The primary forces at a communication point (N per box): `point`, the force
    /// there; `mean`, the mean over the step that ended there.
    pub fn forces_at_point(&mut self, point: &[f64], mean: &[f64]) {
        if self.history.len() == 2 {
            self.history.remove(0);
        }
        self.history.push([point.to_vec(), mean.to_vec()]);
    }

    /// The side frames' displacements `z` (m) and velocities `v` (m/s per box) the
    /// master handed on at a point, `h` (s) after the last one: fits the step between
    /// them.
    pub fn side_frames_given(&mut self, h: f64, z: &[f64], v: &[f64]) {
        let ok = v.len() == self.boxes
            && z.len() == self.boxes
            && v.iter().chain(z).all(|x| x.is_finite());
        if !ok {
            self.restart_motion();
            return;
        }
        // The points before this one: two are needed, and two points of forces.
        let before = std::mem::take(&mut self.last);
        self.last = match before.last() {
            Some(p) if h > 0.0 => vec![p.clone(), (z.to_vec(), v.to_vec())],
            _ => vec![(z.to_vec(), v.to_vec())],
        };
        let ([older, newer], [(z0, _), (z1, v1)]) = (&self.history[..], &before[..]) else {
            self.last_bounce = None;
            return;
        };
        if h.is_nan() || h <= 0.0 {
            self.last_bounce = None;
            return;
        }
        // Each box's velocity change and the impulse of each candidate over the step.
        let dv: Vec<f64> = (0..self.boxes).map(|i| v[i] - v1[i]).collect();
        let held = |i: usize| -> [f64; 4] {
            [
                h * older[0][i],
                h * older[1][i],
                h * newer[1][i],
                h * newer[0][i],
            ]
        };
        // What the secondary suspension adds to the impulse of a step, from the side
        // frame's displacements (its other end, the bolster, slow): a damper's impulse is
        // `-C_2` times the displacement over the step, exactly, so its first difference
        // is `-C_2` times the displacement's second difference; a spring's is `-K_2`
        // times the displacement's integral, `h (z_k + z_(k-1)) / 2` by the trapezoid, so
        // its first difference is `-K_2 h (z_k - z_(k-2)) / 2`.
        let moved = |i: usize| (z[i] - 2.0 * z1[i] + z0[i], 0.5 * h * (z[i] - z0[i]));
        // The bounce of both sides' side frames together: the bolster between them rolls
        // fast on its secondary springs (31 Hz with the half-car's) and carries one
        // side's secondary force to the other, but its bounce, under the car body, is
        // slow. Pitch side frame by side frame.
        let mut bounce = Vec::new();
        let mut motion = Vec::new();
        let span = if self.shared { 4 } else { 2 };
        for group in 0..self.boxes / span {
            let boxes = (span * group)..(span * (group + 1));
            let mut x = [0.0; 4];
            let (mut y, mut u, mut w) = (0.0, 0.0, 0.0);
            for i in boxes {
                let (xi, (ui, wi)) = (held(i), moved(i));
                for c in 0..4 {
                    x[c] += xi[c];
                }
                y += dv[i];
                u += ui;
                w += wi;
            }
            bounce.push((y, x));
            motion.push((u, w));
        }
        if self.shared {
            for bogie in 0..self.boxes / 4 {
                for side in 0..2 {
                    let (a, b) = (4 * bogie + side, 4 * bogie + 2 + side);
                    let (xa, xb) = (held(a), held(b));
                    let y = dv[a] - dv[b];
                    for c in 0..4 {
                        add(&mut self.pitch[c], xa[c] - xb[c], y);
                    }
                }
            }
        }
        // First differences over steps of one length only: over unequal ones the static
        // load times the change of step, unseen, would dominate them.
        let same = (h - std::mem::replace(&mut self.last_h, h)).abs() <= 1e-9 * h;
        let before = self.last_bounce.replace(bounce.clone()).filter(|_| same);
        if let Some(before) = before {
            for (((y, x), (y0, x0)), (u, w)) in bounce.iter().zip(&before).zip(&motion) {
                for c in 0..4 {
                    let r = nalgebra::Vector4::new(x[c] - x0[c], *u, *w, y - y0);
                    self.bounce[c] += r * r.transpose();
                }
            }
            self.steps += 1;
        }
    }

    /// Forgets the motion handed on so far (a step the fit cannot use).
    fn restart_motion(&mut self) {
        self.last.clear();
        self.last_bounce = None;
    }

    /// Forgets the last point (a state restored elsewhere): the sums stay.
    pub fn restart(&mut self) {
        self.history.clear();
        self.restart_motion();
    }

    /// What the fit found, once a candidate explains the motion and the others do not.
    pub fn estimate(&self) -> Option<PartnerEstimate> {
        if self.steps < LEAST_STEPS {
            return None;
        }
        // What each candidate leaves, over both channels, as a share of the motion, and
        // its bounce coefficients.
        // What each candidate leaves, over both channels, as a share of the motion, and
        // its bounce coefficient.
        let fits: Vec<Option<(f64, f64)>> = (0..4)
            .map(|c| {
                let m = &self.bounce[c];
                let (mut left, coef) = least_squares(m)?;
                let mut total = m[(3, 3)];
                if self.shared {
                    let [xx, xy, yy] = self.pitch[c];
                    left += if xx > 0.0 { yy - xy * xy / xx } else { yy };
                    total += yy;
                }
                (total > 0.0).then(|| (left.max(0.0) / total, coef[0]))
            })
            .collect();
        let share = |c: usize| fits[c].map_or(1.0, |f| f.0);
        let best = (0..4).min_by(|&a, &b| share(a).total_cmp(&share(b)))?;
        let next = (0..4)
            .filter(|&c| c != best)
            .map(share)
            .fold(f64::INFINITY, f64::min);
        let (residual, k) = fits[best]?;
        if !(residual < EXPLAINED && next >= APART * residual && k > 0.0) {
            return None;
        }
        let mass = if self.shared { 2.0 / k } else { 1.0 / k };
        let pitch_inertia = if self.shared {
            let [xx, xy, yy] = self.pitch[best];
            let fits = yy > 0.0 && (yy - xy * xy / xx) / yy < EXPLAINED && xy / xx > 0.0;
            let l = self.half_wheelbase;
            fits.then(|| 2.0 * l * l / (xy / xx))
        } else {
            None
        };
        Some(PartnerEstimate {
            held: HeldForce::ALL[best],
            mass,
            pitch_inertia,
            residual,
        })
    }
}

/// The least-squares fit of the last value of the sums `m` (`y`) on the others, scaled
/// to a unit diagonal first (their units differ by orders of magnitude: N s, m, m s):
/// what it leaves of `y y`, and the coefficients. `None` where the regressors are not
/// independent.
fn least_squares(m: &BounceSums) -> Option<(f64, nalgebra::Vector3<f64>)> {
    let a = m.fixed_view::<3, 3>(0, 0).into_owned();
    let b = m.fixed_view::<3, 1>(0, 3).into_owned();
    let d = a
        .diagonal()
        .map(|x| if x > 0.0 { 1.0 / x.sqrt() } else { 0.0 });
    let scale = nalgebra::Matrix3::from_diagonal(&d);
    let coef = scale * (scale * a * scale).cholesky()?.solve(&(scale * b));
    Some((m[(3, 3)] - b.dot(&coef), coef))
}

/// Adds a sample `(x, y)` to the sums.
fn add(s: &mut Sums, x: f64, y: f64) {
    s[0] += x * x;
    s[1] += x * y;
    s[2] += y * y;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A side frame over two boxes `l` = 0.9 m from its centre (mass `m`, pitch
    /// inertia `j`) on the half-car's secondary spring and damper (to a still bolster),
    /// its boxes driven by primary springs to moving axle boxes, exchanged every `h`
    /// with `held`; the fit's estimate after 0.3 s.
    fn exchange(m: f64, j: f64, held: HeldForce, h: f64) -> Option<PartnerEstimate> {
        let (k1, c1, l, k2, c2) = (6.5e6, 1e5, 0.9, 2.55e6, 4.4e4);
        let mut fit = PartnerFit::new(2, true, 2.0 * l);
        // Side frame [z, theta] and rates; axle boxes' motion prescribed: an impact's
        // ringing under the leading box, a slower one under the trailing.
        let (mut z, mut th, mut vz, mut vth) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let sub = 200;
        let dt = h / sub as f64;
        let boxes = |t: f64| -> ([f64; 2], [f64; 2]) {
            let a = 1e-3 * (-30.0 * t).exp() * (400.0 * t).sin();
            let va =
                1e-3 * (-30.0 * t).exp() * (400.0 * (400.0 * t).cos() - 30.0 * (400.0 * t).sin());
            let b = 4e-4 * (90.0 * t).sin();
            let vb = 4e-4 * 90.0 * (90.0 * t).cos();
            ([a, b], [va, vb])
        };
        let frames = |z: f64, th: f64, vz: f64, vth: f64| {
            ([z + l * th, z - l * th], [vz + l * vth, vz - l * vth])
        };
        let force = |t: f64, z: f64, th: f64, vz: f64, vth: f64| -> [f64; 2] {
            let (zb, vb) = boxes(t);
            let (zf, vf) = frames(z, th, vz, vth);
            [0, 1].map(|i| k1 * (zb[i] - zf[i]) + c1 * (vb[i] - vf[i]))
        };
        // The track's side: the forces at each point and their means over each step,
        // with the side frames moving as the partner's (for the test, exactly).
        let mut t = 0.0;
        let mut points = vec![force(0.0, 0.0, 0.0, 0.0, 0.0)];
        let mut means = vec![points[0]];
        let four = |f: [f64; 2]| vec![f[0], 0.0, f[1], 0.0];
        fit.forces_at_point(&four(points[0]), &four(means[0]));
        for k in 0..(0.3 / h) as usize {
            let (zf, vf) = frames(z, th, vz, vth);
            fit.side_frames_given(h, &[zf[0], 0.0, zf[1], 0.0], &[vf[0], 0.0, vf[1], 0.0]);
            // The track's step: the forces along the exact motion of the step (the
            // side frames moved as monolithic here, a stand-in for the track's copy).
            let (mut s, mut sum) = ((z, th, vz, vth), [0.0; 2]);
            for i in 0..sub {
                let f = force(t + i as f64 * dt, s.0, s.1, s.2, s.3);
                sum = [sum[0] + f[0] / sub as f64, sum[1] + f[1] / sub as f64];
                let az = (f[0] + f[1] - k2 * s.0 - c2 * s.2) / m;
                let ath = l * (f[0] - f[1]) / j;
                s = (
                    s.0 + dt * (s.2 + dt * az),
                    s.1 + dt * (s.3 + dt * ath),
                    s.2 + dt * az,
                    s.3 + dt * ath,
                );
            }
            let point_now = force(t + h, s.0, s.1, s.2, s.3);
            // The partner's held force over [t_k, t_k+1].
            let fh = match held {
                HeldForce::JacobiPoint => points[k],
                HeldForce::JacobiMean => means[k],
                HeldForce::SequentialMean => sum,
                HeldForce::SequentialPoint => point_now,
            };
            // The partner: the side frame under the held forces and its own secondary
            // spring, in fine substeps.
            for _ in 0..sub {
                let az = (fh[0] + fh[1] - k2 * z - c2 * vz) / m;
                let ath = l * (fh[0] - fh[1]) / j;
                vz += dt * az;
                vth += dt * ath;
                z += dt * vz;
                th += dt * vth;
            }
            t += h;
            points.push(point_now);
            means.push(sum);
            fit.forces_at_point(&four(point_now), &four(sum));
        }
        fit.estimate()
    }

    #[test]
    fn the_fit_finds_the_held_force_and_the_side_frames_inertia() {
        let (m, j) = (900.0, 180.0);
        for held in HeldForce::ALL {
            let e = exchange(m, j, held, 1e-3).expect("a decision");
            assert_eq!(e.held, held, "{e:?}");
            assert!((e.mass / m - 1.0).abs() < 0.03, "{held:?} {e:?}");
            let jj = e.pitch_inertia.unwrap();
            assert!((jj / j - 1.0).abs() < 0.01, "{held:?} {e:?}");
        }
    }
}
