//! A direct solver for symmetric positive definite systems whose couplings stay near
//! the diagonal once the unknowns are put in a suitable order.

/// Solves `K x = f` (`f` and the result: one value per unknown) for a symmetric positive
/// definite `K` by Gaussian elimination on its band, the unknowns taken in `order`
/// (`order[i]` is the unknown at place `i`). `entries(add)` calls `add(i, j, v)` for the
/// entries of `K` (row, column, value; repeated entries add up). `O(N b)` memory and
/// `O(N b^2)` time with half-bandwidth `b` in that order, where the dense matrix would
/// take `O(N^2)` and `O(N^3)`.
///
/// `None` when a pivot is not positive (`K` is singular or not positive definite) or
/// the solution is not finite.
pub(crate) fn solve_banded_spd(
    order: &[usize],
    entries: impl Fn(&mut dyn FnMut(usize, usize, f64)),
    f: &[f64],
) -> Option<Vec<f64>> {
    let n = order.len();
    // Place of each unknown in the order.
    let mut pos = vec![0; n];
    for (i, &g) in order.iter().enumerate() {
        pos[g] = i;
    }
    let mut bw = 0;
    entries(&mut |i, j, v| {
        if v != 0.0 {
            bw = bw.max(pos[i].abs_diff(pos[j]));
        }
    });
    let w = 2 * bw + 1;
    let mut a = vec![0.0; n * w];
    let at = |i: usize, j: usize| i * w + j + bw - i;
    entries(&mut |i, j, v| {
        if v != 0.0 {
            a[at(pos[i], pos[j])] += v;
        }
    });
    let mut b: Vec<f64> = order.iter().map(|&g| f[g]).collect();
    let scale = (0..n).map(|i| a[at(i, i)].abs()).fold(0.0, f64::max);
    for c in 0..n {
        let pivot = a[at(c, c)];
        if pivot.is_nan() || pivot <= 1e-14 * scale {
            return None;
        }
        let end = (c + bw + 1).min(n);
        for i in c + 1..end {
            let l = a[at(i, c)] / pivot;
            if l == 0.0 {
                continue;
            }
            for j in c + 1..end {
                a[at(i, j)] -= l * a[at(c, j)];
            }
            b[i] -= l * b[c];
        }
    }
    let mut y = vec![0.0; n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for j in i + 1..(i + bw + 1).min(n) {
            s -= a[at(i, j)] * y[j];
        }
        y[i] = s / a[at(i, i)];
    }
    let mut x = vec![0.0; n];
    for (i, &g) in order.iter().enumerate() {
        x[g] = y[i];
    }
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tridiagonal system in a shuffled order against its exact solution, and a
    /// singular one refused.
    #[test]
    fn solves_a_shuffled_tridiagonal_system_and_refuses_a_singular_one() {
        // K = tridiag(-1, 2, -1) of size 5 with x = (1, 2, 3, 4, 5): f = K x.
        let n = 5;
        let x: Vec<f64> = (1..=n).map(|k| k as f64).collect();
        let entries = |add: &mut dyn FnMut(usize, usize, f64)| {
            for i in 0..n {
                add(i, i, 2.0);
                if i + 1 < n {
                    add(i, i + 1, -1.0);
                    add(i + 1, i, -1.0);
                }
            }
        };
        let mut f = vec![0.0; n];
        entries(&mut |i, j, v| f[i] += v * x[j]);
        for order in [
            vec![0, 1, 2, 3, 4],
            vec![4, 3, 2, 1, 0],
            vec![2, 0, 4, 1, 3],
        ] {
            let got = solve_banded_spd(&order, entries, &f).unwrap();
            for k in 0..n {
                assert!((got[k] - x[k]).abs() < 1e-12, "{order:?}: {got:?}");
            }
        }
        // The Laplacian with free ends is singular.
        let free = |add: &mut dyn FnMut(usize, usize, f64)| {
            for i in 0..n - 1 {
                add(i, i, 1.0);
                add(i + 1, i + 1, 1.0);
                add(i, i + 1, -1.0);
                add(i + 1, i, -1.0);
            }
        };
        assert!(solve_banded_spd(&[0, 1, 2, 3, 4], free, &f).is_none());
    }
}
