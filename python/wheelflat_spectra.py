#!/usr/bin/env python3
"""The drawn rail profiles against their standard spectra (issue 44).

    python3 python/wheelflat_spectra.py [--seeds 20] [--plot docs/figures/track_spectra.png]

For each spectrum the runner knows (``wheelflat profile``: FRA classes 1 to 6, the
German low and high levels) it draws the left rail with seeds 1 to N over the FMUs'
default band (1.5 to 30 m), 2 km sampled every 0.25 m, and estimates the variance in
each third of an octave of the band from the samples alone (a Hann-windowed
periodogram, numpy's FFT), against the target the runner writes from the spectrum's
closed form (``--target``). Prints, per spectrum, the worst band's deviation of the
seeds' mean (dB) and the RMS height of the samples against the integrated spectrum;
``--plot`` draws one panel per spectrum: the target density and the estimate (the
seeds' mean) in each band. The runner's numbers are the model's; nothing here knows a
spectrum's formula.
"""

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
RUNNER = os.path.join(ROOT, "target", "release", "wheelflat")
SPECTRA = ["fra_class_1", "fra_class_2", "fra_class_3", "fra_class_4", "fra_class_5",
           "fra_class_6", "ore_low", "ore_high"]
LENGTH, DX = 2000.0, 0.25


def draw(spectrum, seed, tmp, band=(1.5, 30.0)):
    """The runner's left rail (m) every DX over LENGTH, and its target bands (rows of
    low wavenumber, high wavenumber (rad/m), variance (m^2))."""
    out, target = os.path.join(tmp, "p.csv"), os.path.join(tmp, "t.csv")
    r = subprocess.run([RUNNER, "profile", "--spectrum", spectrum, "--seed", str(seed),
                        "--band", f"{band[0]}:{band[1]}", "--length", str(LENGTH), "--dx", str(DX),
                        "--output", out, "--target", target], capture_output=True, text=True)
    if r.returncode:
        raise RuntimeError(f"wheelflat profile --spectrum {spectrum} --seed {seed}: {r.stderr.strip()}")
    x = np.loadtxt(out, delimiter=",", skiprows=1)
    return x[:, 1], np.loadtxt(target, delimiter=",", skiprows=1, ndmin=2)


def band_variances(h, dx, bands):
    """The variance of ``h`` (sampled every ``dx``) in each band ``[k0, k1)`` (rad/m):
    one-sided Hann-windowed periodogram bins summed, normalised so that all bins sum to
    the mean square (Parseval)."""
    n = len(h)
    w = np.hanning(n)
    spec = np.abs(np.fft.rfft((h - h.mean()) * w)) ** 2 * 2.0 / (n * np.sum(w * w))
    k = 2 * np.pi * np.fft.rfftfreq(n, dx)
    return np.array([spec[(k >= k0) & (k < k1)].sum() for k0, k1 in bands])


def compare(spectrum, seeds, tmp):
    """For ``spectrum`` over ``seeds``: the bands, the target variances, the seeds' mean
    estimate per band, and the samples' RMS against the integrated target (ratio,
    averaged over the seeds)."""
    est, rms = [], []
    target = None
    for seed in seeds:
        h, target = draw(spectrum, seed, tmp)
        est.append(band_variances(h, DX, target[:, :2]))
        rms.append(np.sqrt(np.mean(h ** 2)) / np.sqrt(target[:, 2].sum()))
    return target[:, :2], target[:, 2], np.mean(est, axis=0), float(np.mean(rms))


def plot(results, path, metadata=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, 4, figsize=(14, 6.5), sharex=True)
    for ax, (name, (bands, target, est, ratio)) in zip(axes.flat, results.items()):
        centre = np.sqrt(bands[:, 0] * bands[:, 1])
        width = bands[:, 1] - bands[:, 0]
        ax.loglog(centre, target / width, "k-", label="target (closed form)")
        ax.loglog(centre, est / width, "o", mfc="none", label="drawn, mean of seeds")
        ax.set_title(f"{name}: RMS {ratio:.3f} of target", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes[1]:
        ax.set_xlabel("wavenumber (rad/m)")
    for ax in axes[:, 0]:
        ax.set_ylabel("band density (m$^2$ per rad/m)")
    axes.flat[0].legend(fontsize=8)
    fig.suptitle("Drawn rail profiles against their spectra, 1.5 to 30 m, one-third octave bands")
    fig.tight_layout()
    fig.savefig(path, dpi=90, metadata={"Software": None, **(metadata or {})})
    plt.close(fig)


def digest(results):
    """A digest of the estimates and targets, to 6 digits (what the plot draws)."""
    import hashlib
    text = "\n".join(f"{name}," + ",".join(f"{x:.6g}" for x in np.concatenate([t, e, [r]]))
                     for name, (_, t, e, r) in results.items())
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seeds", type=int, default=20)
    p.add_argument("--plot")
    a = p.parse_args(argv)
    if a.seeds < 1:
        p.error(f"--seeds {a.seeds}: at least 1")
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for name in SPECTRA:
            bands, target, est, ratio = compare(name, range(1, a.seeds + 1), tmp)
            results[name] = (bands, target, est, ratio)
            db = 10 * np.log10(est / target)
            print(f"{name}: worst band {np.max(np.abs(db)):.2f} dB, RMS {ratio:.4f} of the "
                  f"integrated spectrum ({1e3 * np.sqrt(target.sum()):.2f} mm)")
    if a.plot:
        plot(results, a.plot)
        print(f"wrote {a.plot}")
    return results


if __name__ == "__main__":
    sys.exit(0 if main() else 1)
