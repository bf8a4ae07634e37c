#!/usr/bin/env python3
"""Speed figures of the FMUs quoted in docs/guide/fmus.md ("Speed") and
docs/PERFORMANCE.md:
- fmpy.simulate_fmu on CoupledSystem for one simulated second with its defaults (the
  endless track, 10 m a side; output interval 1 ms, max_force keeps the peak);
- CoupledSystem through fmpy's FMU2Slave at 0.05 s communication steps, set-up not
  timed, best of three, per simulated second (issue 29's measurement): the thesis'
  fixed 30-span track (0.95 s, the wheel's whole run on it), the default window, the
  converged 20 m window, four wheelsets (roll-plane vehicles, and the wagon) and the
  half-car bogie;
- the fmpy FMU2Slave pair loop of python/couple.py, per communication step.

    python3 python/fmu_speed.py
"""
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

CONVERGED = {"track.window.ahead": 20.0, "track.window.behind": 20.0}
WAGON = {"wheelset[2].offset": 1.8, "wheelset[3].offset": 10.0, "wheelset[4].offset": 11.8}
CASES = [
    ("the thesis' fixed 30-span track", {"track.window.ahead": 0.0}, 0.95),
    ("the default endless track, 10 m a side", {}, 1.0),
    ("the converged window, 20 m a side", CONVERGED, 1.0),
    ("four roll-plane vehicles on the wagon's wheelsets, default window", {"wheelsets": 4, **WAGON}, 1.0),
    ("four roll-plane vehicles on the wagon's wheelsets, converged window",
     {"wheelsets": 4, **WAGON, **CONVERGED}, 1.0),
    ("the wagon, default window", {"wheelsets": 4, **WAGON, "vehicle.model": 3}, 1.0),
    ("the wagon, converged window", {"wheelsets": 4, **WAGON, "vehicle.model": 3, **CONVERGED}, 1.0),
    ("the half-car bogie, default window", {"wheelsets": 2, "wheelset[2].offset": 1.8,
                                            "vehicle.model": 2}, 1.0),
]


def per_simulated_second(path, params, stop_time, comm_step=0.05):
    """Wall seconds per simulated second of CoupledSystem through FMU2Slave, best of 3."""
    best = float("inf")
    for _ in range(3):
        u = wf.Unit(path, "speed")
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters(params)
        u.fmu.enterInitializationMode()
        u.fmu.exitInitializationMode()
        n = round(stop_time / comm_step)
        t0 = time.perf_counter()
        for k in range(n):
            u.fmu.doStep(k * comm_step, comm_step)
        best = min(best, (time.perf_counter() - t0) / (n * comm_step))
        u.close()
    return best


def main():
    wf.ensure_venv()
    from fmpy import simulate_fmu
    paths = wf.build_fmus()
    best = float("inf")
    for _ in range(3):
        t0 = time.perf_counter()
        r = simulate_fmu(paths["CoupledSystem"], stop_time=1.0, output_interval=1e-3,
                         output=["contact.left.max_force"])
        best = min(best, time.perf_counter() - t0)
    print(f"simulate_fmu CoupledSystem, 1 s simulated (defaults): {best:.3f} s "
          f"(best of 3), peak {r['contact.left.max_force'][-1] / 1e3:.1f} kN")
    for name, params, stop in CASES:
        w = per_simulated_second(paths["CoupledSystem"], params, stop)
        print(f"FMU2Slave, 0.05 s steps, {name}: {w * 1e3:.1f} ms a simulated second")
    t0 = time.perf_counter()
    r = wf.run_pair(paths, 0.2)
    dt = time.perf_counter() - t0
    n = len(r["time"]) - 1
    print(f"fmpy pair loop (python/couple.py), 0.2 s: {dt:.2f} s, {dt / n * 1e6:.1f} us per communication step")


if __name__ == "__main__":
    main()
