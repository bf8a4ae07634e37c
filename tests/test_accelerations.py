"""Accelerations through the FMUs, as a detector sees them: the wheel (axle box) and
the rail under it, the rail and the sleeper at an observation point. Each is the
central second difference of its displacement output at the track's steps, so that
sampled at every step they difference and sum back exactly (docs/MODEL.md,
"Accelerations")."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import wheelflat_fmus as wf  # noqa: E402

from fmpy import simulate_fmu  # noqa: E402


@pytest.fixture(scope="module")
def run():
    path = os.path.join(wf.FMU_DIR, "CoupledSystem.fmu")
    if not os.path.exists(path):
        path = wf.build_fmus()["CoupledSystem"]
    # The reference flat (CoupledSystem's defaults), sampled at every track step
    # through its first impact at 0.19 s; a site on the sleeper nearest it.
    step = simulate_fmu(path, stop_time=0.0, output=["solver.step"])["solver.step"][-1]
    out = [f"{q}.{side}.{what}" for q in ("wheel", "rail", "site[1].rail", "site[1].seat")
           for side in ("left", "right") for what in ("z", "acceleration", "acceleration.max",
                                                      "acceleration.min")]
    r = simulate_fmu(path, start_time=0.0, stop_time=0.22, output_interval=step,
                     start_values={"sites": 1, "site[1].position": 7 * 0.685}, output=out)
    return r, step


@pytest.mark.parametrize("q", ["wheel.left", "wheel.right", "rail.left", "rail.right",
                               "site[1].rail.left", "site[1].seat.right"])
def test_accelerations_are_the_second_difference_of_the_displacements(run, q):
    r, dt = run
    z, a = r[q + ".z"], r[q + ".acceleration"]
    # The wheels and the sites start at rest: the displacement's history holds the
    # static state. The rail under a moving wheel is no material point: its
    # acceleration starts with the third sample.
    moving = q.startswith("rail.")
    zz = np.concatenate([[z[0], z[0]], z])
    second = (zz[2:] - 2 * zz[1:-1] + zz[:-2]) / dt**2
    if moving:
        second[:2] = 0.0
    scale = np.abs(second).max()
    assert np.allclose(a, second, rtol=0, atol=1e-9 * scale), np.abs(a - second).max() / scale
    # Summed twice they give the displacements back (to the rounding of the sums),
    # from the first step's velocity for the rail under the wheel.
    j = np.arange(len(z))
    start = z[0] + (z[1] - z[0]) * j if moving else z[0]
    back = start + np.cumsum(np.cumsum(a * dt**2))
    assert np.abs(back - z).max() < 1e-9 * np.abs(z).max()
    # The extremes are the running extremes: at a site since the start, at a wheel
    # those of the steps taken (the value now is not among them: no feedthrough of a
    # master's wheel heights).
    high, low = np.maximum.accumulate(a), np.minimum.accumulate(a)
    if not q.startswith("site"):
        high, low = np.concatenate([[a[0]], high[:-1]]), np.concatenate([[a[0]], low[:-1]])
    assert np.allclose(r[q + ".acceleration.max"], high, rtol=0, atol=1e-9 * scale)
    assert np.allclose(r[q + ".acceleration.min"], low, rtol=0, atol=1e-9 * scale)


def test_the_flats_impact_shakes_the_wheel_and_the_rail(run):
    r, _ = run
    # Quiet at first (3.0 m/s^2 at most: sleeper and node passing), then the impact:
    # 516 m/s^2 (53 g) at the flat wheel's centre, 8,190 m/s^2 at the rail under it
    # (the rail's mass against the wheelset's), 168 m/s^2 at the other wheel.
    early = r["time"] < 0.01
    assert np.abs(r["wheel.left.acceleration"][early]).max() < 10.0
    wheel, rail = np.abs(r["wheel.left.acceleration"]).max(), np.abs(r["rail.left.acceleration"]).max()
    other = np.abs(r["wheel.right.acceleration"]).max()
    assert 100 < wheel < 5e3 and rail > 5 * wheel and other < 0.5 * wheel, (wheel, rail, other)


def test_the_vehicle_fmu_measures_its_wheels_as_coupled_system_does(run):
    # TrackContact + RollPlaneVehicle at the track's step reproduce CoupledSystem; the
    # vehicle's own wheel accelerations (its heights' second difference at its steps)
    # and TrackContact's (of the heights it is given) are CoupledSystem's.
    r, h = run
    paths = {n: os.path.join(wf.FMU_DIR, n + ".fmu") for n in ("TrackContact", "RollPlaneVehicle")}
    track, vehicle = wf.Unit(paths["TrackContact"], "track"), wf.Unit(paths["RollPlaneVehicle"], "vehicle")
    wheels = ["wheel.left.z", "wheel.right.z", "wheel.rotation"]
    names = ["wheel.left.acceleration", "wheel.right.acceleration", "wheel.left.acceleration.min"]
    try:
        wf.initialise_pair(track, vehicle)
        got_vehicle, got_track = [], []
        t = 0.0
        for k in range(len(r["time"])):
            track.set(wheels, vehicle.get(*wheels))
            vehicle.set(["contact.left.force", "contact.right.force"],
                        track.get("contact.left.force", "contact.right.force"))
            got_vehicle.append(vehicle.get(*names))
            got_track.append(track.get(*names))
            track.fmu.doStep(t, h)
            vehicle.fmu.doStep(t, h)
            t = (k + 1) * h
    finally:
        track.close()
        vehicle.close()
    want = np.array([r[n] for n in names]).T
    scale = np.abs(want).max()
    for got in (np.array(got_vehicle), np.array(got_track)):
        assert np.abs(got - want).max() < 1e-6 * scale, np.abs(got - want).max() / scale


def test_a_vehicle_stepped_unevenly_measures_its_wheels_over_the_steps_it_took():
    # RollPlaneVehicle under a force that swings by 30 % at 333 Hz, stepped by its
    # solver.step H and H/2 in turn (canHandleVariableCommunicationStepSize): each
    # acceleration is the second difference over the two uneven steps it spans (the
    # slopes' difference over the mean step), not a spike of the step's change (it
    # read -453 m/s^2 against a true +-76 m/s^2).
    path = os.path.join(wf.FMU_DIR, "RollPlaneVehicle.fmu")
    v = wf.Unit(path, "vehicle")
    try:
        v.fmu.setupExperiment(startTime=0.0)
        v.fmu.enterInitializationMode()
        v.fmu.exitInitializationMode()
        h = v.get("solver.step")[0]
        load = v.get("contact.left.force")[0]
        t, times, z, a = 0.0, [0.0], [v.get("wheel.left.z")[0]], [v.get("wheel.left.acceleration")[0]]
        for k in range(600):
            v.set(["contact.left.force", "contact.right.force"],
                  [load * (1 + 0.3 * np.sin(2 * np.pi * t / 0.003)), load])
            step = h if k % 2 == 0 else h / 2
            v.fmu.doStep(t, step)
            t = t + step
            times.append(t)
            z.append(v.get("wheel.left.z")[0])
            a.append(v.get("wheel.left.acceleration")[0])
    finally:
        v.close()
    t, z, a = np.array(times), np.array(z), np.array(a)
    h1, h2 = t[2:] - t[1:-1], t[1:-1] - t[:-2]
    second = 2 * ((z[2:] - z[1:-1]) / h1 - (z[1:-1] - z[:-2]) / h2) / (h1 + h2)
    scale = np.abs(second).max()
    assert np.abs(a[2:] - second).max() < 1e-6 * scale, np.abs(a[2:] - second).max() / scale
    assert 10 < scale < 200, scale
