#!/usr/bin/env python3
"""How the communication step of the TrackContact + RollPlaneVehicle pair changes the
peak impact force (default scenario). Inputs are held over a step (zero-order hold),
so the wheel does not feel the contact force change inside a step.

    python3 python/comm_step_study.py [--stop 0.06]
"""
import argparse
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402


def main():
    wf.ensure_venv()
    ap = argparse.ArgumentParser()
    ap.add_argument("--stop", type=float, default=0.06)
    ap.add_argument("--multiples", default="1,2,3,5,7,14,28")
    args = ap.parse_args()
    paths = wf.build_fmus()
    ref = None
    dt = wf.track_step(paths)
    print("comm step (us)  multiple of dt  peak left (kN)  error vs h = dt  wall (s)")
    for m in [int(x) for x in args.multiples.split(",")]:
        t0 = time.perf_counter()
        r = wf.run_pair(paths, args.stop, comm_step=m * dt)
        peak = r["contact.left.max_force"][-1]
        if ref is None:
            ref = peak
        print(f"{m * dt * 1e6:14.2f}  {m:14d}  {peak / 1e3:14.2f}  {100 * (peak - ref) / ref:+14.2f}%  {time.perf_counter() - t0:8.2f}")


if __name__ == "__main__":
    main()
