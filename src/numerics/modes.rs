//! Undamped natural frequencies of a system of lumped masses and springs.

use nalgebra::{SMatrix, SVector};

/// The undamped natural frequencies (rad/s), ascending, of the system with the masses
/// `mass` (the diagonal of `M`, kg or kg m^2) and the stiffness `k`: the square roots of
/// the eigenvalues of `M^-1 K`, through the symmetric `M^-1/2 K M^-1/2` (rigid modes
/// and rounding below zero give 0).
pub fn natural_frequencies<const N: usize>(
    mass: &SVector<f64, N>,
    k: &SMatrix<f64, N, N>,
) -> [f64; N] {
    let d = SMatrix::<f64, N, N>::from_diagonal(&mass.map(|m| 1.0 / m.sqrt()));
    let a = d * k * d;
    // Dynamic storage: the symmetric eigensolver of a fixed size needs bounds a const
    // generic size cannot state; the algorithm is the same.
    let a = nalgebra::DMatrix::from_fn(N, N, |i, j| a[(i, j)]);
    let mut w: Vec<f64> = a
        .symmetric_eigenvalues()
        .iter()
        .map(|l| l.max(0.0).sqrt())
        .collect();
    w.sort_by(f64::total_cmp);
    std::array::from_fn(|i| w[i])
}
