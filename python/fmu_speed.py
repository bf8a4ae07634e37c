#!/usr/bin/env python3
"""Speed figures of the FMUs quoted in docs/guide/fmus.md ("Speed") and
docs/PERFORMANCE.md:
- fmpy.simulate_fmu on CoupledSystem for one simulated second with its defaults (the
  endless track, 10 m a side; output interval 1 ms, max_force keeps the peak);
- CoupledSystem through fmpy's FMU2Slave at 0.05 s communication steps, set-up not
  timed, best of three measured in turn, per simulated second and as ratios to the
  fixed track (issue 42: machines differ, the ratios are what to quote): the thesis'
  fixed 30-span track (0.95 s, the wheel's whole run on it), the default window, the
  converged 20 m window, four wheelsets (roll-plane vehicles, and the wagon) and the
  half-car bogie, and the wagon against one wheelset; the default window over 60 s
  against over 1 s;
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


def one_run(path, params, stop_time, comm_step=0.05):
    """Wall seconds per simulated second of one run of CoupledSystem through FMU2Slave
    (set-up not timed)."""
    u = wf.Unit(path, "speed")
    try:
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters(params)
        u.fmu.enterInitializationMode()
        u.fmu.exitInitializationMode()
        n = round(stop_time / comm_step)
        t0 = time.perf_counter()
        for k in range(n):
            u.fmu.doStep(k * comm_step, comm_step)
        return (time.perf_counter() - t0) / (n * comm_step)
    finally:
        u.close()


def side_by_side(path, cases, rounds=3):
    """Each case's best of `rounds` runs (s per simulated second), the cases measured in
    turn within each round, so that a machine whose speed drifts (this project's VMs
    swing by up to 1.7 times) drifts for all of them alike: the ratios between them are
    the figures to quote, not the times."""
    best = [float("inf")] * len(cases)
    for _ in range(rounds):
        for i, (_, params, stop) in enumerate(cases):
            best[i] = min(best[i], one_run(path, params, stop))
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
    times = side_by_side(paths["CoupledSystem"], CASES)
    fixed = times[0]
    print("FMU2Slave, 0.05 s steps, best of 3 measured in turn; the ratio to the fixed track is the figure")
    for (name, _, _), w in zip(CASES, times):
        print(f"  {name}: {w * 1e3:.1f} ms a simulated second, {w / fixed:.2f} x the fixed track")
    # The endless track's cost in run length: the default window over 1 s and over 60 s,
    # in turn (issue 42: constant in run length).
    short, long_ = side_by_side(paths["CoupledSystem"], [("1 s", {}, 1.0), ("60 s", {}, 60.0)])
    print(f"  the default window over 60 s against over 1 s: {long_ / short:.2f} x a simulated second")
    one = dict(zip((c[0] for c in CASES), times))
    for window in ("default window", "converged window"):
        single = one["the default endless track, 10 m a side" if window == "default window"
                     else "the converged window, 20 m a side"]
        print(f"  the wagon against one wheelset, {window}: {one[f'the wagon, {window}'] / single:.2f} x")
    t0 = time.perf_counter()
    r = wf.run_pair(paths, 0.2)
    dt = time.perf_counter() - t0
    n = len(r["time"]) - 1
    print(f"fmpy pair loop (python/couple.py), 0.2 s: {dt:.2f} s, {dt / n * 1e6:.1f} us per communication step")


if __name__ == "__main__":
    main()
