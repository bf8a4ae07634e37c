#!/usr/bin/env python3
"""The thesis' half-car bogie (HalfCarBogie) coupled with the track, two ways.

Couples TrackContact (two wheelsets, the second at the bogie's wheelbase, on an endless
track) and HalfCarBogie through fmpy on the default scenario (table 4.4, 70 km/h,
100 mm x 1.5 mm flat on the leading wheelset's left wheel):

* at the axle boxes (``interface`` = axle_box) with a 1 ms communication step, as a
  multibody bogie model would: the track carries both wheelsets and their primary
  suspensions, the bogie the bolster and side frames; per step the side frames' motion
  above each axle box goes to the track, the track steps, its mean primary forces go to
  the bogie, the bogie steps;
* at the contact (the default interface) at the track's own step (14.4 us), which
  reproduces CoupledSystem with ``vehicle.model`` = half_car bit for bit.

Prints the four wheels' peaks of both runs and their differences, writes
out/half_car_coupling.csv (the axle-box run's four contact forces at every
communication point) and out/half_car_coupling.png.

    python3 python/half_car_coupling.py [--stop 0.6] [--step 0.001] [--out out/]

Runs itself inside .venv (created on first use).
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

ENDLESS = {"track.window.ahead": 20.0, "track.window.behind": 20.0}


def main():
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop", type=float, default=0.6, help="simulated time (s): four impacts")
    ap.add_argument("--step", type=float, default=1e-3, help="the axle-box coupling's communication step (s)")
    ap.add_argument("--out", default=os.path.join(wf.ROOT, "out"), help="output folder")
    args = ap.parse_args()

    import numpy as np

    paths = wf.build_fmus()
    t0 = time.perf_counter()
    box_record = []
    peak_box = wf.run_half_car_axle_box(paths, args.stop, args.step, track_params=ENDLESS, record=box_record)
    t1 = time.perf_counter()
    contact_record = []
    peak_contact = wf.run_half_car(paths, args.stop, track_params=ENDLESS, record=contact_record)
    t2 = time.perf_counter()
    print(f"axle-box interface, {args.step * 1e3:g} ms steps: {len(box_record)} steps")
    print(f"contact interface, the track's step: {len(contact_record) - 1} steps")
    print("peak contact force (kN)   axle boxes   contact   difference")
    for k in range(2):
        for s, side in enumerate(("left", "right")):
            a, b = peak_box[k][s], peak_contact[k][s]
            print(f"  wheelset {k + 1}, {side:5s}      {a / 1e3:8.1f}  {b / 1e3:8.1f}   "
                  f"{(a - b) / 1e3:+6.2f} kN ({100 * (a / b - 1):+.2f} %)")

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    os.makedirs(args.out, exist_ok=True)
    data = np.asarray(box_record)
    ref = np.asarray(contact_record)
    names = ["contact.left.force", "contact.right.force",
             "wheelset[2].contact.left.force", "wheelset[2].contact.right.force"]
    csv = os.path.join(args.out, "half_car_coupling.csv")
    np.savetxt(csv, data, delimiter=",", header=",".join(["time [s]"] + [f"{n} [N]" for n in names]), comments="", fmt="%.17g")
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    for ax, col, title in ((axes[0], 1, "leading wheelset, left wheel (the flat)"),
                           (axes[1], 3, "trailing wheelset, left wheel")):
        ax.plot(ref[:, 0], ref[:, col] / 1e3, lw=0.6, label="contact interface, every track step")
        ax.plot(data[:, 0], data[:, col] / 1e3, ".", ms=2, label=f"axle-box interface, every {args.step * 1e3:g} ms")
        ax.set_ylabel("contact force (kN)")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
    axes[0].legend()
    axes[1].set_xlabel("time (s)")
    fig.suptitle("TrackContact + HalfCarBogie: coupled at the contact and at the axle boxes")
    fig.tight_layout()
    png = os.path.join(args.out, "half_car_coupling.png")
    fig.savefig(png, dpi=120)
    # Relative to the working folder when inside it (as couple.py), else whole.
    shown = [f if os.path.relpath(f).startswith("..") else os.path.relpath(f) for f in (csv, png)]
    print(f"wrote {shown[0]} and {shown[1]}")
    print(f"wall time: {t2 - t0:.1f} s")


if __name__ == "__main__":
    main()
