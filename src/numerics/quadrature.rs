//! Gauss-Legendre quadrature: the nodes and weights of the `N`-point rule on [-1, 1].

/// Nodes `x_i` (in (-1, 1), descending) and weights `w_i` of the `N`-point
/// Gauss-Legendre rule on [-1, 1]: `sum w_i p(x_i)` is the integral of `p` over [-1, 1]
/// for every polynomial `p` of degree up to `2 N - 1`. The nodes are the zeros of the
/// Legendre polynomial `P_N`, found by Newton's method from Tricomi's initial guess;
/// `w_i = 2 / ((1 - x_i^2) P_N'(x_i)^2)`.
pub(crate) fn gauss_legendre<const N: usize>() -> ([f64; N], [f64; N]) {
    let n = N;
    let mut x = [0.0; N];
    let mut w = [0.0; N];
    for i in 0..n {
        // Newton on the Legendre polynomial from Tricomi's initial guess.
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eight_points_integrate_degree_fifteen_exactly() {
        let (x, w) = gauss_legendre::<8>();
        // Symmetric nodes, descending, weights summing to 2.
        for i in 0..8 {
            assert!((x[i] + x[7 - i]).abs() < 1e-15 && (w[i] - w[7 - i]).abs() < 1e-15);
        }
        assert!(x.windows(2).all(|p| p[0] > p[1]));
        assert!((w.iter().sum::<f64>() - 2.0).abs() < 1e-14);
        // The largest node of P_8 and its weight (Abramowitz and Stegun, table 25.4).
        assert!((x[0] - 0.960_289_856_497_536).abs() < 1e-15);
        assert!((w[0] - 0.101_228_536_290_376).abs() < 1e-15);
        // x^14 + x^15 over [-1, 1] is 2/15; x^16 (degree 2N) is not integrated exactly.
        let q = |p: i32| (0..8).map(|i| w[i] * x[i].powi(p)).sum::<f64>();
        assert!((q(14) + q(15) - 2.0 / 15.0).abs() < 1e-15);
        assert!((q(16) - 2.0 / 17.0).abs() > 1e-6);
    }
}
