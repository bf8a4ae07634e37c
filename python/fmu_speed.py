#!/usr/bin/env python3
"""Speed figures of the FMUs quoted in docs/guide/fmus.md ("Speed"):
- fmpy.simulate_fmu on CoupledSystem for one simulated second (40 spans so that the
  wheel stays on the track; output interval 1 ms, max_force keeps the peak);
- the fmpy FMU2Slave pair loop of python/couple.py, per communication step.

    python3 python/fmu_speed.py
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402


def main():
    wf.ensure_venv()
    from fmpy import simulate_fmu
    paths = wf.build_fmus()
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        r = simulate_fmu(paths["CoupledSystem"], stop_time=1.0, output_interval=1e-3,
                         start_values={"track.spans": 40}, output=["contact.left.max_force"])
        best = min(best, time.perf_counter() - t0)
    print(f"simulate_fmu CoupledSystem, 1 s simulated (40 spans, defaults): {best:.3f} s "
          f"(best of 3), peak {r['contact.left.max_force'][-1] / 1e3:.1f} kN")
    t0 = time.perf_counter()
    r = wf.run_pair(paths, 0.2)
    dt = time.perf_counter() - t0
    n = len(r["time"]) - 1
    print(f"fmpy pair loop (python/couple.py), 0.2 s: {dt:.2f} s, {dt / n * 1e6:.1f} us per communication step")


if __name__ == "__main__":
    main()
