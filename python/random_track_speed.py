#!/usr/bin/env python3
"""What a drawn rail profile and roughness cost (issue 44): CoupledSystem over 0.5 s at
70 km/h (fmpy's simulate_fmu, outputs every 10 ms) on ideal rails, on FRA class 4, with
the ISO 3095 roughness on the rails or the wheels, and with all three; the cases in
turn, REPEATS times, the median of each and its ratio to the ideal rails' (this
machine's speed swings: only ratios measured side by side mean anything).

    .venv/bin/python python/random_track_speed.py [REPEATS]
"""

import os
import statistics
import sys
import time

from fmpy import simulate_fmu

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASES = {"ideal rails": {},
         "FRA class 4 (1.5 to 30 m)": {"rail.spectrum": 5},
         "ISO 3095 on the rails": {"roughness.rail": "iso3095"},
         "ISO 3095 on the wheels": {"roughness.wheel": "iso3095"},
         "all three": {"rail.spectrum": 5, "roughness.rail": "iso3095", "roughness.wheel": "iso3095"}}


def main(repeats=5):
    path = os.path.join(ROOT, "fmu", "CoupledSystem.fmu")
    times = {k: [] for k in CASES}
    for _ in range(repeats):
        for name, start in CASES.items():
            t = time.perf_counter()
            simulate_fmu(path, stop_time=0.5, output_interval=1e-2, start_values=start,
                         output=["contact.left.force"])
            times[name].append(time.perf_counter() - t)
    base = statistics.median(times["ideal rails"])
    for name, ts in times.items():
        m = statistics.median(ts)
        print(f"{name}: {1e3 * m:.0f} ms, {m / base:.2f} x ideal rails")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)
