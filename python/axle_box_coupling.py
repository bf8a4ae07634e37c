#!/usr/bin/env python3
"""A vehicle model at its own 1 ms step, coupled to the track at the axle boxes.

Couples TrackContact and RollPlaneVehicle through fmpy twice on the default scenario
(table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left wheel):

* at the axle boxes (``interface`` = axle_box) with a 1 ms communication step: the
  track carries the wheelset and its primary suspension, the vehicle the bodies above;
  per step the side frames' motion goes to the track, the track steps, its mean primary
  forces go to the vehicle, the vehicle steps;
* at the contact (the default interface) at the track's own step (14.4 us), which
  reproduces CoupledSystem exactly.

Prints both peaks and their difference, writes out/axle_box_coupling.csv (the
axle-box run's contact and primary forces at every communication point) and
out/axle_box_coupling.png.

    python3 python/axle_box_coupling.py [--stop 0.8] [--step 0.001] [--out out/]

Runs itself inside .venv (created on first use).
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402


def main():
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop", type=float, default=0.8, help="simulated time (s)")
    ap.add_argument("--step", type=float, default=1e-3, help="the axle-box coupling's communication step (s)")
    ap.add_argument("--out", default=os.path.join(wf.ROOT, "out"), help="output folder")
    args = ap.parse_args()

    import numpy as np

    paths = wf.build_fmus()
    t0 = time.perf_counter()
    record = []
    peak_box = wf.run_axle_box_pair(paths, args.stop, args.step, record=record)
    t1 = time.perf_counter()
    contact = wf.run_pair(paths, args.stop)
    t2 = time.perf_counter()
    peak_contact = [contact["contact.left.max_force"][-1], contact["contact.right.max_force"][-1]]
    print(f"axle-box interface, {args.step * 1e3:g} ms steps: peak left {peak_box[0] / 1e3:.1f} kN, "
          f"right {peak_box[1] / 1e3:.1f} kN ({len(record)} steps)")
    print(f"contact interface, the track's step: peak left {peak_contact[0] / 1e3:.1f} kN, "
          f"right {peak_contact[1] / 1e3:.1f} kN ({len(contact['time']) - 1} steps)")
    for side, a, b in (("left", peak_box[0], peak_contact[0]), ("right", peak_box[1], peak_contact[1])):
        print(f"difference, {side}: {(a - b) / 1e3:+.2f} kN ({100 * (a / b - 1):+.2f} %)")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(args.out, exist_ok=True)
    data = np.asarray(record)
    # Each column with its unit, as couple.py's.
    cols = ("time [s],contact.left.force [N],contact.right.force [N],primary.left.mean_force [N],"
            "primary.right.mean_force [N]")
    csv = os.path.join(args.out, "axle_box_coupling.csv")
    np.savetxt(csv, data, delimiter=",", header=cols, comments="", fmt="%.17g")
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.plot(contact["time"], np.asarray(contact["contact.left.force"]) / 1e3, lw=0.6,
            label="contact interface, every track step")
    ax.plot(data[:, 0], data[:, 1] / 1e3, ".", ms=2, label=f"axle-box interface, every {args.step * 1e3:g} ms")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("left contact force (kN)")
    ax.set_title("TrackContact + RollPlaneVehicle: coupled at the contact and at the axle boxes")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "axle_box_coupling.png")
    fig.savefig(png, dpi=120)
    # Relative to the working folder when inside it (as couple.py), else whole.
    shown = [f if os.path.relpath(f).startswith("..") else os.path.relpath(f) for f in (csv, png)]
    print(f"wrote {shown[0]} and {shown[1]}")
    print(f"wall time: {t2 - t0:.1f} s")


if __name__ == "__main__":
    main()
