"""Can the exact window ends be made recursive and still follow the window's moves?
(issue 42): a state-space realization of the exterior's kernels and the map a shift
by one span needs, measured.

The exterior beyond the window's right end (`Track::set_exact_ends`) answers the drive
(the last inner node, four channels) at its end node with the kernel `h[m]`, and at
every node of its first span with a kernel of its own. Split into the rails'
symmetric and antisymmetric motion (2 x 2 each), each mode's `h` and the kernel `g_v`
of the node that becomes the last inner node when the window moves a span ahead are
realized together, `x_(j+1) = A x_j + B u_j`, `[h; g_v][m] = C A^(m-1) B`, by the
eigensystem realization algorithm (Ho-Kalman: the SVD of the block Hankel matrix of
the first `2 P` lags, truncated to order `r`). A recursive end keeps `x`; a shift must
replace it by the state of the exterior one span on, driven by the new inner node's
history: `x' = sum_k W_k u_(j-k)` with `W_k = sum_(s<k) A^(k-s-1) B g_v[s]`, which a map
`x' = M x` gives only if the realized states span it. `M` is fitted by least squares
over the first 3,000 lags, and its error is measured where it matters, at the new end
node over the next 2,000 steps, against that node's response.

Prints, per mode and order: the spectral radius of `A` (above 1 the end grows), the
largest error of the realized `h` (over all lags, and beyond lag 2,000 against the
tail's own largest value) and `g_v`, and the shift map's error.

    cargo run --release --example exact_kernel dump 8000 /tmp/g0.bin 0
    cargo run --release --example exact_kernel dump 8000 /tmp/g7.bin 7
    .venv/bin/python python/recursive_ends_study.py /tmp/g0.bin /tmp/g7.bin --hankel 1500 --orders 40,80,120,200
"""
import argparse

import numpy as np


def load(path):
    return np.fromfile(path, "<f8").reshape(-1, 4, 4)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("end", help="kernel of the end node (exact_kernel dump M FILE 0)")
    ap.add_argument(
        "next_inner",
        help="kernel of the exterior's node n - 1, the last inner node after a shift "
        "(exact_kernel dump M FILE 7 at the default n = 8)",
    )
    ap.add_argument("--hankel", type=int, default=1500, help="block rows and columns P")
    ap.add_argument("--orders", default="40,80,120,200")
    a = ap.parse_args()
    h, gv = load(a.end), load(a.next_inner)
    p = a.hankel
    need = max(3001, 2 * p + 2)
    if min(len(h), len(gv)) < need:
        ap.error(f"the kernels have {min(len(h), len(gv))} lags; --hankel {p} needs {need} "
                 f"(exact_kernel dump {need - 1} ...)")
    # The rails' symmetry: the right rail answers as the left.
    assert np.allclose(h[:, 2:4, 2:4], h[:, 0:2, 0:2])
    orders = [int(x) for x in a.orders.split(",")]
    for name, sign in [("symmetric", 1.0), ("antisymmetric", -1.0)]:
        hm = h[:, 0:2, 0:2] + sign * h[:, 0:2, 2:4]
        gm = gv[:, 0:2, 0:2] + sign * gv[:, 0:2, 2:4]
        y = np.concatenate([hm, gm], axis=1)
        lags = y.shape[0]
        h0 = np.zeros((4 * p, 2 * p))
        h1 = np.zeros((4 * p, 2 * p))
        for i in range(p):
            h0[4 * i : 4 * i + 4] = y[1 + i : 1 + i + p].transpose(1, 0, 2).reshape(4, -1)
            h1[4 * i : 4 * i + 4] = y[2 + i : 2 + i + p].transpose(1, 0, 2).reshape(4, -1)
        u, s, vt = np.linalg.svd(h0, full_matrices=False)
        for r in orders:
            si = np.diag(s[:r] ** -0.5)
            a_ = si @ u[:, :r].T @ h1 @ vt[:r].T @ si
            b = (np.diag(s[:r] ** 0.5) @ vt[:r])[:, :2]
            c = (u[:, :r] @ np.diag(s[:r] ** 0.5))[:4]
            rho = np.abs(np.linalg.eigvals(a_)).max()
            x = b.copy()
            fit = np.zeros_like(y)
            states = np.zeros((lags - 1, r, 2))
            for m in range(1, lags):
                fit[m] = c @ x
                states[m - 1] = x
                x = a_ @ x
            err_h = np.abs(fit[:, :2] - hm).max() / np.abs(hm).max()
            err_tail = np.abs(fit[2000:, :2] - hm[2000:]).max() / np.abs(hm[2000:]).max()
            err_g = np.abs(fit[:, 2:] - gm).max() / np.abs(gm).max()
            k_fit = 3000
            w = np.zeros((k_fit, r, 2))
            for k in range(2, k_fit + 1):
                w[k - 1] = a_ @ w[k - 2] + b @ (c[2:] @ states[k - 2])
            rm = states[:k_fit].transpose(1, 0, 2).reshape(r, -1)
            wm = w.transpose(1, 0, 2).reshape(r, -1)
            shift = np.linalg.lstsq(rm.T, wm.T, rcond=None)[0].T
            d, ref = shift @ rm - wm, wm.copy()
            a10 = np.linalg.matrix_power(a_, 10)
            err, top = 0.0, 0.0
            for _ in range(200):
                err = max(err, np.abs(c[:2] @ d).max())
                top = max(top, np.abs(c[:2] @ ref).max())
                d, ref = a10 @ d, a10 @ ref
            print(
                f"{name}, order {r}: spectral radius {rho:.6f}; h within {err_h:.1e} "
                f"(beyond lag 2,000: {err_tail:.1e} of the tail), g_v within {err_g:.1e}; "
                f"the shift's map errs by {err / top:.1e} of the new end's response"
            )


if __name__ == "__main__":
    main()
