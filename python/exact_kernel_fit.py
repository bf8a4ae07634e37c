"""How many poles the exact window ends' kernel needs (issue 29): a sum of damped
oscillations fitted to the kernel `h[m]` of `Track::set_exact_ends`, the recursive form
that would make exact ends cheap, and the echo it leaves.

The kernel (4 x 4 a lag: deflection and rotation of both rails) splits into the rails'
symmetric and antisymmetric motion, `H_ll + H_lr` and `H_ll - H_lr` (2 x 2 each). Its
first `--head` lags stay as they are (a short direct convolution); from there each
mode's four entries are fitted with `--poles` common poles by the matrix pencil method
(Hua and Sarkar, IEEE Trans. Acoust. Speech Signal Process. 38 (1990) 814) on every
`--decimate`-th lag of the first `--fit` lags, the residues by least squares on every
lag. The fitted kernel, `--out` lags long, is written for `exact_kernel echo`:

    cargo run --release --example exact_kernel dump 34700 /tmp/h.bin
    .venv/bin/python python/exact_kernel_fit.py /tmp/h.bin --poles 80 --out-lags 13880 /tmp/f.bin
    cargo run --release --example exact_kernel echo /tmp/f.bin 0.2
"""

import argparse
import time

import numpy as np


def fit_mode(y, head, fit, poles, decimate):
    """Poles and residues of a mode's four entries `y` (lags x 4) from lag `head`."""
    tail = y[head : fit + 1].T
    yd = tail[:, ::decimate]
    n = yd.shape[1]
    span = n // 3
    hankel = np.vstack(
        [np.lib.stride_tricks.sliding_window_view(yd[c], span + 1) for c in range(4)]
    )
    _, s, vt = np.linalg.svd(hankel, full_matrices=False)
    v = vt[:poles].conj().T
    z = np.linalg.eigvals(np.linalg.pinv(v[:-1]) @ v[1:])
    lam = z ** (1.0 / decimate)
    lags = np.arange(tail.shape[1])
    basis = lam[None, :] ** lags[:, None]
    res, *_ = np.linalg.lstsq(basis, tail.T.astype(complex), rcond=None)
    err = np.abs((basis @ res).real - tail.T).max() / np.abs(tail).max()
    return lam, res, err, s[poles] / s[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("kernel")
    ap.add_argument("out")
    ap.add_argument("--poles", type=int, default=80, help="poles a mode")
    ap.add_argument("--head", type=int, default=64, help="lags kept as they are")
    ap.add_argument("--fit", type=int, default=6940, help="lags fitted (0.1 s)")
    ap.add_argument("--decimate", type=int, default=2)
    ap.add_argument("--out-lags", type=int, default=13880)
    a = ap.parse_args()
    h = np.fromfile(a.kernel, "<f8").reshape(-1, 4, 4)
    ll, lr = h[:, 0:2, 0:2], h[:, 0:2, 2:4]
    assert np.array_equal(h[:, 2:4, 2:4], ll) and np.array_equal(h[:, 2:4, 0:2], lr)
    out = np.zeros((a.out_lags + 1, 4, 4))
    out[: a.head] = h[: a.head]
    modes = []
    for name, k in [("symmetric", ll + lr), ("antisymmetric", ll - lr)]:
        t0 = time.time()
        lam, res, err, sv = fit_mode(k.reshape(-1, 4), a.head, a.fit, a.poles, a.decimate)
        print(
            f"{name}: {a.poles} poles, largest |lambda| {np.abs(lam).max():.7f}, fit's "
            f"largest error {err:.3f} of the fitted lags' largest, singular value "
            f"{sv:.1e} of the first ({time.time() - t0:.1f} s)"
        )
        lags = np.arange(a.out_lags + 1 - a.head)
        modes.append(((lam[None, :] ** lags[:, None]) @ res).real.reshape(-1, 2, 2))
    sym, anti = modes
    out[a.head :, 0:2, 0:2] = out[a.head :, 2:4, 2:4] = (sym + anti) / 2
    out[a.head :, 0:2, 2:4] = out[a.head :, 2:4, 0:2] = (sym - anti) / 2
    n = min(len(h), len(out))
    print(f"largest kernel error over {n - 1} lags: {np.abs(out[:n] - h[:n]).max():.2e}")
    out.astype("<f8").tofile(a.out)


if __name__ == "__main__":
    main()
