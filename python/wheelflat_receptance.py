#!/usr/bin/env python3
"""The track's receptance (issue 44): run `wheelflat receptance` (or read its CSV), mark
the resonances, and plot it, optionally against the independent reference
(python/receptance_reference.py) or, for a fit, the measured against the fitted
receptance (`wheelflat receptance-fit`).

    python3 python/wheelflat_receptance.py --at midspan --reference --png out/receptance.png
    python3 python/wheelflat_receptance.py --read out/receptance.csv --png out/receptance.png
    python3 python/wheelflat_receptance.py --measured m.csv --fitted f.csv --png out/fit.png
    python3 python/wheelflat_receptance.py --fit-demo --png out/receptance_fit.png

``--fit-demo`` makes a measurement of its own (the runner's receptance of a track whose
pads and ballast differ from the default by 30 to 50 %, with 1 % multiplicative complex
noise, seeded: FIT_DEMO_TRUTH), fits it with ``wheelflat receptance-fit`` from the
default track, prints the fit and its error against the truth, and plots both.

The resonances are the prominent local maxima of the magnitude: the largest value
within +-8 % in frequency (the finite record's ripple beside the pinned-pinned peak is
not one), refined by a parabola through the three samples around it in log magnitude
against log frequency. Each is named by where it lies: the full-track resonance (rail
and sleepers bouncing on the ballast, below 150 Hz), the rail's resonance on its pads
(150 to 600 Hz), the pinned-pinned resonance (within 6 % of the Timoshenko rail's first
mode on rigid supports a span apart, ``pinned_pinned``); at a sleeper that frequency is
an antiresonance instead (the mode has a node there).

numpy and matplotlib only; the runner is target/release/wheelflat (built when missing).
"""

import argparse
import os
import subprocess
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# Within this ratio of frequency, a local maximum must be the largest to count.
PROMINENCE_WINDOW = 1.08


def runner():
    """The command-line runner, built when missing."""
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target"), "release", "wheelflat")
    if not os.path.exists(exe):
        subprocess.run(["cargo", "build", "--release", "--bin", "wheelflat"], cwd=ROOT, check=True)
    return exe


def run(output, *args):
    """Runs `wheelflat receptance ARGS --output OUTPUT`; returns what it printed."""
    p = subprocess.run([runner(), "receptance", *map(str, args), "--output", output],
                       check=True, capture_output=True, text=True)
    return p.stdout


# The fit demo's "measured" track (the default's pads and ballast times 1.4, 0.65, 0.7, 1.5).
FIT_DEMO_TRUTH = {"kp": 196e6, "cp": 29.25e3, "kb": 28e6, "cb": 75e3}


def write_csv(path, freqs, alpha):
    """A receptance CSV with the runner's columns."""
    with open(path, "w") as fh:
        fh.write("frequency_Hz,magnitude_m_per_N,phase_deg,real,imag\n")
        for f, a in zip(freqs, alpha):
            fh.write(f"{f:.6f},{abs(a):.9e},{np.degrees(np.angle(a)):.6f},{a.real:.9e},{a.imag:.9e}\n")


def fit_demo(png):
    """The fit of a made measurement (module docs); returns the runner's fit output."""
    folder = os.path.dirname(os.path.abspath(png))
    os.makedirs(folder, exist_ok=True)
    measured = os.path.join(folder, "receptance_measured.csv")
    fitted = os.path.join(folder, "receptance_fitted.csv")
    run(measured, "--points", 40, *[x for k, v in FIT_DEMO_TRUTH.items() for x in (f"--{k}", v)])
    f, a = read_csv(measured)
    rng = np.random.default_rng(44)
    write_csv(measured, f, a * (1 + 0.01 * rng.standard_normal(len(a)) + 0.01j * rng.standard_normal(len(a))))
    rel = lambda x: os.path.relpath(x)  # noqa: E731
    cmd = ["receptance-fit", rel(measured), "--band", "20:3000", "--fit", "kp,cp,kb,cb", "--output", rel(fitted)]
    p = subprocess.run([runner(), *cmd], check=True, capture_output=True, text=True)
    print(f"made {rel(measured)}: the runner's receptance with "
          + ", ".join(f"--{k} {v:g}" for k, v in FIT_DEMO_TRUTH.items()) + ", 1 % noise")
    print("running: wheelflat " + " ".join(cmd))
    print(p.stdout.rstrip())
    for line in p.stdout.split("\n"):
        parts = line.split()
        if parts and parts[0] in FIT_DEMO_TRUTH:
            value = float(line.split(": ")[1].split()[0])
            print(f"{parts[0]}: {100 * (value / FIT_DEMO_TRUTH[parts[0]] - 1):+.2f} % from the truth")
    ff, af = read_csv(fitted)
    plot(png, [("measured (made: the model, 1 % noise)", f, read_csv(measured)[1], "k."), ("fitted", ff, af, "C1-")],
         "measured and fitted receptance (point, one rail, at a sleeper)")
    return p.stdout


def read_csv(path):
    """(frequencies (Hz), complex receptance (m/N)) of a receptance CSV: real,imag or
    magnitude_m_per_N,phase_deg columns."""
    d = np.genfromtxt(path, delimiter=",", names=True, comments="#")
    names = d.dtype.names
    if "real" in names and "imag" in names:
        a = d["real"] + 1j * d["imag"]
    else:
        a = d["magnitude_m_per_N"] * np.exp(1j * np.radians(d["phase_deg"]))
    return np.atleast_1d(d["frequency_Hz"]), np.atleast_1d(a)


def pinned_pinned(ei=2.07e11 * 2.94e-5, kag=0.34 * 7.77e-3 * 81e9, m=60.0, mr2=60.0 * 2.94e-5 / 7.77e-3, a=0.685):
    """The first mode (Hz) of a Timoshenko rail simply supported a span `a` apart
    (wavenumber pi / a): the lower root of
    ``m mr2 / kAG w^4 - (m + k^2 (mr2 + m EI / kAG)) w^2 + EI k^4 = 0``; table 4.4's
    rail by default (830 Hz)."""
    k2 = (np.pi / a) ** 2
    a4 = m * mr2 / kag
    b = m + k2 * (mr2 + m * ei / kag)
    c = ei * k2 * k2
    w2 = (b - np.sqrt(b * b - 4 * a4 * c)) / (2 * a4)
    return np.sqrt(w2) / (2 * np.pi)


def extrema(f, a, kind="max"):
    """The prominent local maxima (or minima) of |a| at frequencies f: [(frequency
    (Hz), |a| (m/N))], each the extreme within PROMINENCE_WINDOW of its frequency,
    refined by a parabola in log |a| against log f."""
    f = np.asarray(f, float)
    m = np.log(abs(np.asarray(a)))
    if kind == "min":
        m = -m
    out = []
    for i in range(1, len(f) - 1):
        near = (f >= f[i] / PROMINENCE_WINDOW) & (f <= f[i] * PROMINENCE_WINDOW)
        if m[i] < m[near].max() or not (m[i] > m[i - 1] and m[i] >= m[i + 1]):
            continue
        x = np.log(f[i - 1:i + 2])
        c = np.polyfit(x - x[1], m[i - 1:i + 2], 2)
        dx = -c[1] / (2 * c[0]) if c[0] < 0 else 0.0
        dx = float(np.clip(dx, x[0] - x[1], x[2] - x[1]))
        peak = np.polyval(c, dx)
        out.append((float(np.exp(x[1] + dx)), float(np.exp(peak if kind == "max" else -peak))))
    return out


def name(freq, pp=None):
    """What a resonance at `freq` (Hz) is, by where it lies."""
    pp = pp or pinned_pinned()
    if abs(freq / pp - 1) < 0.06:
        return "pinned-pinned"
    if freq < 150:
        return "full track"
    if freq < 600:
        return "rail on pads"
    return "local maximum"


def draw(ax, bx, curves, title, marks=True):
    """Magnitude (on `ax`) and phase (on `bx`) of each (label, f, a, style) against
    frequency, the first curve's resonances marked."""
    for label, f, a, style in curves:
        ax.loglog(f, abs(a), style, label=label, lw=1.2, ms=3)
        bx.semilogx(f, np.degrees(np.angle(a)), style, lw=1.2, ms=3)
    if marks:
        label, f, a, _ = curves[0]
        for fr, mag in extrema(f, a):
            ax.plot(fr, mag, "rv", ms=7)
            ax.annotate(f"{name(fr)}\n{fr:.0f} Hz", (fr, mag), textcoords="offset points", xytext=(0, 9),
                        ha="center", fontsize=8)
    ax.set_ylabel("receptance magnitude (m/N)")
    ax.set_title(title.replace("; ", "\n", 1), fontsize=9)
    lo, hi = ax.get_ylim()
    ax.set_ylim(lo, hi * 3)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8, loc="lower left")
    bx.set_ylabel("phase (deg)")
    bx.set_xlabel("frequency (Hz)")
    bx.set_ylim(-180, 180)
    bx.set_yticks([-180, -90, 0, 90, 180])
    bx.grid(True, which="both", alpha=0.3)


def plot_panels(png, panels, metadata=None):
    """One column (magnitude over phase) per (title, curves) of `panels`; writes `png`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(2, len(panels), figsize=(8 * len(panels), 6.5), sharex="col", squeeze=False,
                             gridspec_kw={"height_ratios": [2, 1]})
    for k, (title, curves) in enumerate(panels):
        draw(axes[0, k], axes[1, k], curves, title)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=110, metadata=dict({"Software": None}, **(metadata or {})))
    plt.close(fig)


def plot(png, curves, title):
    """Magnitude and phase of each (label, f, a, style), the first's resonances marked."""
    plot_panels(png, [(title, curves)])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--read", help="a receptance CSV to plot instead of running the runner")
    ap.add_argument("--at", choices=["sleeper", "midspan"], default=None, help="sleeper (default) or midspan")
    ap.add_argument("--rails", choices=["one", "both"], default=None, help="one (default) or both")
    ap.add_argument("--response", default="point", help="point, other-rail or a distance (m)")
    ap.add_argument("--points", type=int, default=400)
    ap.add_argument("--csv", default=None, help="where the runner's CSV goes (default: beside the PNG)")
    ap.add_argument("--reference", action="store_true", help="plot python/receptance_reference.py's too")
    ap.add_argument("--measured", help="a measured receptance CSV (with --fitted)")
    ap.add_argument("--fitted", help="the CSV of `wheelflat receptance-fit` (with --measured)")
    ap.add_argument("--fit-demo", action="store_true", help="fit a made measurement (module docs)")
    ap.add_argument("--png", required=True)
    args = ap.parse_args(argv)
    if args.fit_demo:
        fit_demo(args.png)
        print(f"wrote {os.path.relpath(args.png)}")
        return 0
    if bool(args.measured) != bool(args.fitted):
        ap.error("--measured and --fitted go together")
    if args.measured:
        fm, am = read_csv(args.measured)
        ff, af = read_csv(args.fitted)
        plot(args.png, [("measured", fm, am, "k."), ("fitted", ff, af, "C1-")], "measured and fitted receptance")
        for fr, mag in extrema(ff, af):
            print(f"fitted {name(fr)}: {fr:.1f} Hz, {mag:.3e} m/N")
        print(f"wrote {os.path.relpath(args.png)}")
        return 0
    if args.read and args.reference and (args.at is None or args.rails is None):
        # A CSV does not say where the load was: a reference for another place differs
        # by up to 20 times.
        ap.error("--read with --reference needs --at and --rails, those the CSV was made with")
    args.at, args.rails = args.at or "sleeper", args.rails or "one"
    if args.read:
        f, a = read_csv(args.read)
        title = os.path.basename(args.read)
    else:
        csv = args.csv or os.path.splitext(args.png)[0] + ".csv"
        out = run(csv, "--at", args.at, "--rails", args.rails, "--response", args.response, "--points", args.points)
        f, a = read_csv(csv)
        title = out.split("\n")[0]
        print(f"wrote {os.path.relpath(csv)}")
    curves = [("model (wheelflat receptance)", f, a, "C0-")]
    if args.reference:
        sys.path.insert(0, os.path.join(ROOT, "python"))
        import receptance_reference
        ref = receptance_reference.receptance(f, args.at, args.rails, args.response)
        curves.append(("reference (exact Timoshenko, frequency domain)", f, ref, "k--"))
    plot(args.png, curves, title)
    for fr, mag in extrema(f, a):
        print(f"{name(fr)}: {fr:.1f} Hz, {mag:.3e} m/N")
    print(f"wrote {os.path.relpath(args.png)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
