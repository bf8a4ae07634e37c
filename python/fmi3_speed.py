#!/usr/bin/env python3
"""The FMI 3.0 units' cost against the FMI 2.0 units' (issue 43), CoupledSystem on its
defaults, measured in turn (machines differ: the ratios are what to quote):

- one communication step of 1 ms and a read of every Float64 (Real) output, through
  fmpy's FMU3Slave and FMU2Slave, median of five rounds of 400 steps;
- fmpy.simulate_fmu to 0.8 s at 1 ms, median of five.

    .venv/bin/python python/fmi3_speed.py
"""
import os
import statistics
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmi3 as w3  # noqa: E402
import wheelflat_fmus as wf  # noqa: E402

ROUNDS, STEPS, H = 5, 400, 1e-3


def calls(fmu2, fmu3):
    """Microseconds per step and read of all outputs: (FMI 2.0, FMI 3.0, their counts)."""
    u2, u3 = wf.Unit(fmu2, "fmi2"), w3.Unit3(fmu3, "fmi3")
    try:
        u2.fmu.setupExperiment(startTime=0.0)
        u2.fmu.enterInitializationMode()
        u2.fmu.exitInitializationMode()
        u3.initialize()
        u3.fmu.exitInitializationMode()
        o2 = [v.valueReference for v in u2.md.modelVariables if v.causality == "output" and v.type == "Real"]
        o3 = [v.valueReference for v in u3.md.modelVariables if v.causality == "output" and v.type == "Float64"]
        times = {2: [], 3: []}
        for r in range(ROUNDS):
            t0 = r * STEPS * H
            start = time.perf_counter()
            for k in range(STEPS):
                u2.fmu.doStep(t0 + k * H, H)
                u2.fmu.getReal(o2)
            times[2].append((time.perf_counter() - start) / STEPS * 1e6)
            start = time.perf_counter()
            for k in range(STEPS):
                u3.fmu.doStep(t0 + k * H, H)
                u3.fmu.getFloat64(o3, len(o3))
            times[3].append((time.perf_counter() - start) / STEPS * 1e6)
        return statistics.median(times[2]), statistics.median(times[3]), len(o2), len(o3)
    finally:
        wf.close_all(u2, u3)


def simulate(fmu2, fmu3):
    """Seconds of simulate_fmu to 0.8 s at 1 ms: (FMI 2.0, FMI 3.0)."""
    from fmpy import simulate_fmu
    times = {2: [], 3: []}
    for _ in range(ROUNDS):
        for v, path in ((2, fmu2), (3, fmu3)):
            start = time.perf_counter()
            simulate_fmu(path, stop_time=0.8, output_interval=H, step_size=H)
            times[v].append(time.perf_counter() - start)
    return statistics.median(times[2]), statistics.median(times[3])


def main():
    fmu2 = wf.build_fmus()["CoupledSystem"]
    fmu3 = w3.paths3()["CoupledSystem"]
    c2, c3, n2, n3 = calls(fmu2, fmu3)
    print(f"one 1 ms step and a read of every output: FMI 2.0 {c2:.1f} us ({n2} values), "
          f"FMI 3.0 {c3:.1f} us ({n3} values): {c3 / c2:.2f} times")
    s2, s3 = simulate(fmu2, fmu3)
    print(f"simulate_fmu to 0.8 s at 1 ms: FMI 2.0 {s2:.3f} s, FMI 3.0 {s3:.3f} s: {s3 / s2:.2f} times "
          f"(fmpy's recorder reshapes each FMI 3.0 array in Python)")


if __name__ == "__main__":
    main()
