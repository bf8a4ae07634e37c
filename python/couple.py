#!/usr/bin/env python3
"""The wheelflat demo: builds the FMUs, couples TrackContact and RollPlaneVehicle with
fmpy's FMU2Slave on the default scenario (table 4.4, 70 km/h, 100 mm x 1.5 mm haversine
flat on the left wheel), prints the peak contact force per wheel, writes the time
histories as CSV and a plot of both contact forces as PNG.

    python3 python/couple.py [--stop 0.8] [--step SECONDS] [--speed KMH]
                             [--flat-length MM] [--flat-depth MM] [--out out/]

Without --step the communication step is the track's internal step (solver.step), which
gives exactly the numbers of the CoupledSystem FMU. Runs itself inside .venv (created on
first use).
"""

import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402


# couple.py keeps every communication point in memory (about 70,000 a simulated second at
# the track's step): a longer run belongs to CoupledSystem or a study.
MAX_STOP = 60.0


def main():
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--stop", type=float, default=0.8, help=f"simulated time (s), at most {MAX_STOP:g}")
    ap.add_argument("--step", type=float, default=None, help="communication step (s); default: solver.step")
    ap.add_argument("--speed", type=float, default=None, metavar="KMH",
                    help="forward speed (km/h); default: the FMUs' speed (70 km/h)")
    ap.add_argument("--flat-length", type=float, default=None, metavar="MM",
                    help="length of the left wheel's flat (mm; 0: no flat); default: the FMUs' (100 mm)")
    ap.add_argument("--flat-depth", type=float, default=None, metavar="MM",
                    help="depth of the left wheel's flat (mm; 0: from its length, (2.10)); default: the FMUs' (1.5 mm)")
    ap.add_argument("--out", default=os.path.join(wf.ROOT, "out"), help="output folder")
    args = ap.parse_args()
    # What the FMUs cannot know: the run's length and the master's step.
    import math
    if not (math.isfinite(args.stop) and 0 < args.stop <= MAX_STOP):
        ap.error(f"--stop {args.stop}: the simulated time must be finite, 0 < stop <= {MAX_STOP:g} s")
    if args.step is not None and not (math.isfinite(args.step) and 0 < args.step <= args.stop):
        ap.error(f"--step {args.step}: the communication step must be finite, 0 < step <= --stop ({args.stop:g} s)")

    t0 = time.perf_counter()
    paths = wf.build_fmus()
    t1 = time.perf_counter()
    # The case: the FMUs' defaults, with what the options change (SI units).
    track, both = {}, {}
    if args.speed is not None:
        both["speed"] = args.speed / 3.6
    if args.flat_length is not None:
        track["flat.left[1].length"] = args.flat_length / 1e3
    if args.flat_depth is not None:
        track["flat.left[1].depth"] = args.flat_depth / 1e3
    from fmpy.fmi1 import FMICallException
    try:
        r = wf.run_pair(paths, args.stop, args.step, track_params=dict(track, **both), vehicle_params=both)
    except FMICallException as e:
        # The FMU said why above ([ERROR] ...: the variable, its value and its range).
        sys.exit(f"couple.py: the FMUs refused the case ({e}); their message above names the variable")
    t2 = time.perf_counter()
    case = wf.case_of(paths["TrackContact"], dict(track, **both))

    import numpy as np
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(args.out, exist_ok=True)
    cols = ["time"] + list(wf.TRACK_RECORD) + list(wf.WHEELS)
    data = np.column_stack([np.asarray(r[c]) for c in cols])
    csv = os.path.join(args.out, "coupled_pair.csv")
    # Each column with its unit, as the model descriptions declare it ("contact.left.force [N]").
    units = wf.units_of([paths["TrackContact"], paths["RollPlaneVehicle"]])
    header = ",".join(["time [s]"] + [f"{c} [{units[c]}]" if units.get(c) else c for c in cols[1:]])
    np.savetxt(csv, data, delimiter=",", header=header, comments="", fmt="%.17g")

    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.plot(data[:, 0], data[:, 1] / 1e3, label="left wheel (flat)", lw=0.8)
    ax.plot(data[:, 0], data[:, 2] / 1e3, label="right wheel", lw=0.8)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("contact force (kN)")
    ax.set_title(f"TrackContact + RollPlaneVehicle (fmpy FMU2Slave): table 4.4, {case}")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    png = os.path.join(args.out, "coupled_pair.png")
    fig.savefig(png, dpi=120)

    print(f"case: {case}")
    steps = len(r["time"]) - 1
    print(f"communication steps: {steps} of {args.stop / steps * 1e6:.3f} us" if steps else "no steps")
    print(f"peak contact force, left wheel:  {r['contact.left.max_force'][-1] / 1e3:9.2f} kN")
    print(f"peak contact force, right wheel: {r['contact.right.max_force'][-1] / 1e3:9.2f} kN")
    # Relative to the working folder when inside it (the README's example), else whole.
    for f in (csv, png):
        rel = os.path.relpath(f)
        print(f"wrote {f if rel.startswith('..') else rel}")
    print(f"wall time: build {t1 - t0:.1f} s, co-simulation {t2 - t1:.1f} s")


if __name__ == "__main__":
    main()
