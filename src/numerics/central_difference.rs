//! Central differences for a linear system `M x'' + C x' + K x = f` with a diagonal
//! mass matrix, the damping taken implicitly as in the thesis' (3.25):
//! `[I + dt/2 M^-1 C] x_(j+1) = dt^2 M^-1 f + [2 I - dt^2 M^-1 K] x_j + [dt/2 M^-1 C - I] x_(j-1)`.
//! The vehicles' bodies use it (`crate::vehicle`).

use super::SimdLevel;
use crate::error::{Result, out_of_range, positive};
use nalgebra::{SMatrix, SVector};

/// Bodies of up to this many degrees of freedom (the roll-plane vehicle's 6) keep
/// nalgebra's product, which its compiler unrolls whole; larger ones (the wagon's 19)
/// go through [`mat_vec`].
const SMALL_BODY: usize = 8;

/// `m x` for a small dense matrix `m` (`N x N`), with nalgebra's rounding: the sum runs
/// over the columns in order, each product rounded (`y = m_0 x_0`, then
/// `y = m_j x_j + y`), so that the result has the same bits as `m * x`, while the rows
/// are left to the vector units of the caller's [`SimdLevel`] (the wagon's 19 degrees
/// of freedom: 1,865 instructions a step through nalgebra's generic product, issue 42).
#[inline(always)]
pub(crate) fn mat_vec<const N: usize>(m: &SMatrix<f64, N, N>, x: &SVector<f64, N>) -> [f64; N] {
    // The columns as arrays (nalgebra stores a matrix column by column), so that the
    // row loops have their length at compile time and are vectorised whole.
    let a: &[[f64; N]; N] = &m.data.0;
    let mut y = [0.0; N];
    if N == 0 {
        return y;
    }
    for i in 0..N {
        y[i] = a[0][i] * x[0];
    }
    for j in 1..N {
        let xj = x[j];
        for i in 0..N {
            y[i] += a[j][i] * xj;
        }
    }
    y
}

/// [`mat_vec`] compiled for the widest vectors the CPU has (AVX2 at most, as the
/// coupled step's other work), as an `SVector`.
#[inline(always)]
pub(crate) fn mat_vec_dispatched<const N: usize>(
    m: &SMatrix<f64, N, N>,
    x: &SVector<f64, N>,
) -> SVector<f64, N> {
    if N <= SMALL_BODY {
        return m * x;
    }
    let y = SimdLevel::detect().min(SimdLevel::Avx2).run(
        #[inline(always)]
        || mat_vec(m, x),
    );
    SVector::from(y)
}

/// Refuses a step `dt` (s) above the `critical` step (s) of central differences on a
/// system's fastest mode (`2 / omega_max`), `what` naming the system.
pub(crate) fn check_critical_step(dt: f64, critical: f64, what: &str) -> Result<()> {
    if dt > critical {
        return Err(crate::error::Error::UnstableTimeStep {
            dt,
            critical,
            limit: format!(
                "{what}: central differences on the fastest suspension mode (2 / omega_max)"
            ),
        });
    }
    Ok(())
}

/// The state `x_j`, `x_(j-1)` of an `N`-degree-of-freedom system and the update
/// matrices of its step `dt` (s).
#[derive(Debug, Clone)]
pub(crate) struct CentralDifference<const N: usize> {
    mass_inv: SMatrix<f64, N, N>,
    stiffness: SMatrix<f64, N, N>,
    damping: SMatrix<f64, N, N>,
    dt: f64,
    d: SVector<f64, N>,
    d_prev: SVector<f64, N>,
    p_cur: SMatrix<f64, N, N>,
    p_prev: SMatrix<f64, N, N>,
    p_force: SMatrix<f64, N, N>,
}

impl<const N: usize> CentralDifference<N> {
    /// Values of [`CentralDifference::state_vector`].
    pub(crate) const STATE_LEN: usize = 1 + 2 * N;

    /// The system of masses `mass` (the diagonal of `M`), stiffness `k` and damping `c`
    /// at rest at zero, stepped with `dt` (s). The caller checks `dt` against the
    /// system's stability limit.
    pub(crate) fn new(
        mass: &SVector<f64, N>,
        k: SMatrix<f64, N, N>,
        c: SMatrix<f64, N, N>,
        dt: f64,
    ) -> Self {
        let mut s = CentralDifference {
            mass_inv: SMatrix::from_diagonal(&mass.map(|m| 1.0 / m)),
            stiffness: k,
            damping: c,
            dt,
            d: SVector::zeros(),
            d_prev: SVector::zeros(),
            p_cur: SMatrix::zeros(),
            p_prev: SMatrix::zeros(),
            p_force: SMatrix::zeros(),
        };
        s.set_coefficients(dt);
        s
    }

    fn set_coefficients(&mut self, dt: f64) {
        let mc = self.mass_inv * self.damping;
        let mk = self.mass_inv * self.stiffness;
        let id = SMatrix::<f64, N, N>::identity();
        // I + dt/2 M^-1 C is M^-1 (M + dt/2 C) with M + dt/2 C symmetric positive
        // definite, hence regular; the identity fallback is never taken.
        let inv = (id + mc * (0.5 * dt)).try_inverse().unwrap_or(id);
        self.p_cur = inv * (id * 2.0 - mk * (dt * dt));
        self.p_prev = inv * (mc * (0.5 * dt) - id);
        self.p_force = inv * self.mass_inv * (dt * dt);
        self.dt = dt;
    }

    /// Step (s).
    pub(crate) fn dt(&self) -> f64 {
        self.dt
    }
    /// `x_j`.
    pub(crate) fn d(&self) -> &SVector<f64, N> {
        &self.d
    }
    /// `x_(j-1)`.
    pub(crate) fn d_prev(&self) -> &SVector<f64, N> {
        &self.d_prev
    }
    /// `dt^2 [I + dt/2 M^-1 C]^-1 M^-1`, the force's share of the update.
    #[inline(always)]
    pub(crate) fn p_force(&self) -> &SMatrix<f64, N, N> {
        &self.p_force
    }
    /// Backward-difference velocities `(x_j - x_(j-1)) / dt`.
    pub(crate) fn velocities(&self) -> SVector<f64, N> {
        (self.d - self.d_prev) / self.dt
    }
    /// Sets `x_j` and `x_(j-1)`.
    pub(crate) fn set_state(&mut self, d: SVector<f64, N>, d_prev: SVector<f64, N>) {
        self.d = d;
        self.d_prev = d_prev;
    }

    /// Advances one step with the force's share `pf` (`p_force f`, formed by the
    /// caller).
    #[inline(always)]
    pub(crate) fn advance_premultiplied(&mut self, pf: SVector<f64, N>) {
        let next = mat_vec_dispatched(&self.p_cur, &self.d)
            + mat_vec_dispatched(&self.p_prev, &self.d_prev)
            + pf;
        self.d_prev = self.d;
        self.d = next;
    }

    /// Advances one step under the force `f` held over it.
    #[inline(always)]
    pub(crate) fn advance(&mut self, f: SVector<f64, N>) {
        self.advance_premultiplied(mat_vec_dispatched(&self.p_force, &f));
    }

    /// Changes the step to `dt` (s), keeping `x_j` and the backward-difference
    /// velocities: `x_(j-1)` moves to `x_j - (x_j - x_(j-1)) dt / dt_old` (first-order
    /// accurate at the switch). The caller checks `dt`.
    pub(crate) fn change_dt(&mut self, dt: f64) {
        let ratio = dt / self.dt;
        self.d_prev = self.d - (self.d - self.d_prev) * ratio;
        self.set_coefficients(dt);
    }

    /// [`CentralDifference::change_dt`] to `dt` (s) once it is positive and `limit`
    /// (the caller's stability check) accepts it.
    ///
    /// Errors: `dt` not positive (named `solver.dt`), `limit`'s.
    pub(crate) fn change_dt_checked(
        &mut self,
        dt: f64,
        limit: impl Fn(f64) -> Result<()>,
    ) -> Result<()> {
        positive("solver.dt", dt, "s")?;
        limit(dt)?;
        self.change_dt(dt);
        Ok(())
    }

    /// Restores [`CentralDifference::state_vector`] `v`, changing the step through
    /// [`CentralDifference::change_dt_checked`] when it differs.
    ///
    /// Errors: a length other than [`CentralDifference::STATE_LEN`] (named `what`), the
    /// step's refusals.
    pub(crate) fn restore(
        &mut self,
        v: &[f64],
        what: &str,
        limit: impl Fn(f64) -> Result<()>,
    ) -> Result<()> {
        if v.len() != Self::STATE_LEN {
            return Err(out_of_range(
                what,
                v.len() as f64,
                format!("{} values", Self::STATE_LEN),
            ));
        }
        if v[0] != self.dt {
            self.change_dt_checked(v[0], limit)?;
        }
        self.set_displacements_from(v);
        Ok(())
    }

    /// `[dt, x_j (N), x_(j-1) (N)]`.
    pub(crate) fn state_vector(&self) -> Vec<f64> {
        let mut v = vec![self.dt];
        v.extend(self.d.iter());
        v.extend(self.d_prev.iter());
        v
    }

    /// Sets `x_j`, `x_(j-1)` from the tail of [`CentralDifference::state_vector`]
    /// (`v` of [`CentralDifference::STATE_LEN`] values whose step the caller has
    /// already taken over).
    pub(crate) fn set_displacements_from(&mut self, v: &[f64]) {
        self.d = SVector::from_column_slice(&v[1..1 + N]);
        self.d_prev = SVector::from_column_slice(&v[1 + N..1 + 2 * N]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The wagon's body size: the product through the vector units has nalgebra's bits
    /// (the same order of sums, no fused products), at every level this CPU has.
    #[test]
    fn the_vectorised_product_has_nalgebras_bits() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        for _ in 0..20 {
            let m = SMatrix::<f64, 19, 19>::from_fn(|_, _| next() * 1e3);
            let x = SVector::<f64, 19>::from_fn(|_, _| next() * 1e-3);
            let want = m * x;
            for level in SimdLevel::available() {
                let got = level.run(
                    #[inline(always)]
                    || mat_vec(&m, &x),
                );
                for i in 0..19 {
                    assert_eq!(got[i].to_bits(), want[i].to_bits(), "row {i}, {level:?}");
                }
            }
            assert_eq!(mat_vec_dispatched(&m, &x), want);
        }
    }
}
