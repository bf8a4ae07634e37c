//! Measuring the stability threshold of the scheme with a contact spring.

use super::*;

/// Growth of a perturbation of the rails under a linear contact spring, for measuring
/// the stability threshold of the explicit scheme with the contact included
/// (`docs/VALIDATION.md`, section 3; `examples/stability_limit.rs`).
///
/// The track (`params`, no stability check on `dt`) starts from a pseudo-random
/// perturbation of every inner rail node (deflections of 1 um, rotations of 1 um / dx;
/// the same every call) and is stepped `steps` times at `dt` (s) with the force
/// `kc z_rail(x_w)` (N; `kc` in N/m) on the left rail under a wheel at
/// `x_w = x + v t` (m), as the coupled step applies the contact force. Returns the
/// largest `|Z|` and `|theta| dx` at the end over their largest at the start, infinite
/// once a value is not finite; it stops early, checking every 1,000 steps, once the
/// growth passes `stop`. Errors: the parameters' own ([`Track::new_without_stability_check`]).
pub fn perturbation_growth(
    params: TrackParams,
    dt: f64,
    kc: f64,
    (x, v): (f64, f64),
    steps: usize,
    stop: f64,
) -> Result<f64> {
    let mut t = Track::new_without_stability_check(params, dt)?;
    let nk = t.nodes();
    let dx = params.dx();
    // Deterministic pseudo-random start (xorshift), rail ends at zero.
    let mut s: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut rnd = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let (mut z, mut th) = (vec![0.0; 2 * nk], vec![0.0; 2 * nk]);
    for r in 0..2 {
        for k in 1..nk - 1 {
            z[r * nk + k] = 1e-6 * rnd();
            th[r * nk + k] = 1e-6 / dx * rnd();
        }
    }
    t.set_state(&z, &th, &z, &th);
    let amp = |t: &Track| {
        let mut a: f64 = 0.0;
        for r in 0..2 {
            for (z, th) in t.rail_z(r).into_iter().zip(t.rail_theta(r)) {
                if !(z.is_finite() && th.is_finite()) {
                    return f64::INFINITY;
                }
                a = a.max(z.abs()).max((th * dx).abs());
            }
        }
        a
    };
    let a0 = amp(&t);
    for j in 0..steps {
        let xw = x + v * j as f64 * dt;
        let force = kc * t.rail_z_at(0, xw);
        t.step(&[PointLoad {
            rail: 0,
            position: xw,
            force,
        }]);
        if j % 1000 == 999 && amp(&t) / a0 > stop {
            break;
        }
    }
    Ok(amp(&t) / a0)
}
