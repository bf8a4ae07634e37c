#!/usr/bin/env python3
"""A bogie's two wheelsets on one TrackContact: the recipe for coupling a third-party
bogie or wagon model. One TrackContact carries both wheelsets on shared rails (the
rear wheelset feels the front one's impact through them); a vehicle model per
wheelset (here two RollPlaneVehicle instances stand in for the bogie model) gives each
wheelset's wheel heights and axle rotation and takes its contact forces, every
communication step, at the track's internal step. The same system in one unit,
CoupledSystem with wheelsets = 2, gives the same numbers, which the script checks.

Scenario: table 4.4 at 70 km/h, the reference 100 mm x 1.5 mm flat on the leading
wheelset's left wheel, the second wheelset 1.8 m behind, an endless track (20 m ahead
and behind).

    python3 python/bogie_coupling.py [--stop 0.5] [--out out/]

Writes out/bogie_coupling.csv (time and the four contact forces) and
out/bogie_coupling.png. Runs itself inside .venv (created on first use).
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

TRACK = {"track.window.ahead": 20.0, "track.window.behind": 20.0, "wheelset[2].offset": 1.8}


def main():
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop", type=float, default=0.5, help="simulated time (s)")
    ap.add_argument("--out", default=os.path.join(wf.ROOT, "out"), help="output folder")
    args = ap.parse_args()

    import numpy as np
    from fmpy import simulate_fmu

    paths = wf.build_fmus()
    t0 = time.perf_counter()
    r = wf.run_bogie(paths, args.stop, wheelsets=2, track_params=TRACK)
    t1 = time.perf_counter()
    names = ["force[1].left", "force[1].right", "force[2].left", "force[2].right"]
    outputs = ["contact.left.force", "contact.right.force", "wheelset[2].contact.left.force",
               "wheelset[2].contact.right.force"]
    dt = wf.track_step(paths, TRACK)
    c = simulate_fmu(paths["CoupledSystem"], stop_time=args.stop, step_size=dt, output_interval=dt,
                     start_values=dict(TRACK, wheelsets=2), output=outputs)
    n = min(len(r["time"]), len(c["time"]))
    print(f"two wheelsets 1.8 m apart on one TrackContact, coupled with two vehicle units through fmpy: "
          f"{len(r['time']) - 1} steps")
    worst = 0.0
    for name, out in zip(names, outputs):
        a, b = np.asarray(r[name][:n]), np.asarray(c[out][:n])
        worst = max(worst, float(np.max(np.abs(a - b))))
        print(f"  {name:16s} peak {a.max() / 1e3:7.1f} kN (CoupledSystem {b.max() / 1e3:7.1f} kN), "
              f"smallest {a.min() / 1e3:6.1f} kN")
    print(f"largest difference from CoupledSystem over the whole run: {worst:.3g} N")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(args.out, exist_ok=True)
    data = np.column_stack([np.asarray(r["time"])] + [np.asarray(r[k]) for k in names])
    csv = os.path.join(args.out, "bogie_coupling.csv")
    np.savetxt(csv, data, delimiter=",", header="time [s]," + ",".join(f"{n} [N]" for n in names), comments="", fmt="%.17g")
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for k, label in zip(range(1, 5), ["front, left (flat)", "front, right", "rear, left", "rear, right"]):
        ax.plot(data[:, 0], data[:, k] / 1e3, lw=0.8, label=label)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("contact force (kN)")
    ax.set_title("A bogie's two wheelsets on one TrackContact (fmpy): flat on the front wheelset")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "bogie_coupling.png")
    fig.savefig(png, dpi=120)
    # Relative to the working folder when inside it (as couple.py), else whole.
    shown = [f if os.path.relpath(f).startswith("..") else os.path.relpath(f) for f in (csv, png)]
    print(f"wrote {shown[0]} and {shown[1]}")
    print(f"wall time: {t1 - t0:.1f} s")
    return 0 if worst < 1e-6 else 1


if __name__ == "__main__":
    sys.exit(main())
