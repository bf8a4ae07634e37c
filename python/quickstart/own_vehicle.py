#!/usr/bin/env python3
"""Quick start: a vehicle of your own, written in Python (no FMU), on TrackContact at the
contact interface with fmpy's FMU2Slave: wheel heights and axle angle in, contact forces out.

The vehicle: under each wheel a two-mass quarter vehicle, the wheel (half a wheelset)
and the sprung mass above it on the primary spring-damper, with gravity on both.
Run from the repository root:  .venv/bin/python python/quickstart/own_vehicle.py
"""
import os
import shutil
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

# The repository's paths (fmu/ as python3 python/couple.py builds it), from wherever it runs.
os.chdir(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
if not os.path.exists("fmu/TrackContact.fmu"):
    sys.exit("no fmu/TrackContact.fmu: build the FMUs first (python3 python/couple.py)")
FMU, STOP = "fmu/TrackContact.fmu", 0.3  # s: two impacts of the default flat (at 39 and 192 ms)
SPEED, RADIUS = 70 / 3.6, 0.475          # m/s, m: the speed and the wheel radius
# Per wheel: half of table 4.4's 1,120 kg wheelset and half the 20,830 kg above it.
M_WHEEL, M_SPRUNG = 560.0, 10415.0       # kg
K1, C1, G = 6.5e6, 1.0e5, 9.81           # primary spring N/m, damper N s/m, m/s^2
W = (M_SPRUNG + M_WHEEL) * G             # static wheel load, N
WHEELS = ("wheel.left.z", "wheel.right.z", "wheel.rotation")
FORCES = ("contact.left.force", "contact.right.force")

wall = time.perf_counter()
md = read_model_description(FMU)
vr = {v.name: v.valueReference for v in md.modelVariables}
unzipped = extract(FMU)
track = FMU2Slave(guid=md.guid, unzipDirectory=unzipped,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="track")


def get(*names):
    return track.getReal([vr[n] for n in names])


def put(names, values):
    track.setReal([vr[n] for n in names], list(values))


try:
    track.instantiate()
    track.setupExperiment(startTime=0.0, stopTime=STOP)  # no step may end past STOP
    # The track's parameters from the vehicle: its static wheel load (the rails are
    # preloaded with it), its wheel radius and speed (the flats meet the rail at V / R).
    put(("static_load.left", "static_load.right", "wheel.radius", "speed"), (W, W, RADIUS, SPEED))
    # inputs.datum = absolute: wheel heights as given (0 = touching the undeformed rail), so
    # start them on static_wheel_z.*; the default, first_step, takes the first ones as static.
    track.setInteger([vr["inputs.datum"]], [2])
    track.enterInitializationMode()
    z0 = get("static_wheel_z.left", "static_wheel_z.right")  # m, the wheels at rest
    put(WHEELS, (*z0, 0.0))
    track.exitInitializationMode()
    h = get("solver.step")[0]  # s, the track's stable step: the communication step
    n = round(STOP / h)        # steps; the last ends at STOP exactly (within h / 2 of h)

    zw, vw = list(z0), [0.0, 0.0]  # wheel heights (m, up positive) and velocities
    zs, vs = list(z0), [0.0, 0.0]  # sprung masses, the same datum: springs at their static force
    t, forces = 0.0, []
    for k in range(n + 1):
        put(WHEELS, (*zw, SPEED / RADIUS * t))  # vehicle -> track, then track -> vehicle
        P = get(*FORCES)
        forces.append(P)
        if k == n:
            break
        t_next = STOP if k == n - 1 else (k + 1) * h  # never past STOP
        dt = t_next - t
        track.doStep(t, dt)
        for i in (0, 1):  # the vehicle over the same step, P held: semi-implicit Euler
            S = M_SPRUNG * G + K1 * (zw[i] - zs[i]) + C1 * (vw[i] - vs[i])  # primary force, N
            vw[i] += dt * (P[i] - M_WHEEL * G - S) / M_WHEEL
            vs[i] += dt * (S - M_SPRUNG * G) / M_SPRUNG
            zw[i] += dt * vw[i]
            zs[i] += dt * vs[i]
        t = t_next
    peak = get("contact.left.max_force", "contact.right.max_force")
    track.terminate()
except FMICallException as e:  # an fmi2Error (or fmi2Discard, fmi2Fatal): stop, non-zero
    sys.exit(f"FMI error: {e}")
finally:
    track.freeInstance()
    shutil.rmtree(unzipped, ignore_errors=True)

print(f"vehicle per wheel: wheel {M_WHEEL:.0f} kg, sprung {M_SPRUNG:.0f} kg, "
      f"primary {K1 / 1e6:g} MN/m, {C1 / 1e3:g} kN s/m")
print(f"static wheel load: {W / 1e3:.2f} kN, static wheel height {z0[0] * 1e3:.4f} mm")
print(f"communication step: {h * 1e6:.3f} us (solver.step), {n} steps, "
      f"the last {(STOP - (n - 1) * h) * 1e6:.3f} us, to t = {t:g} s")
for label, f in (("at t = 0", forces[0]), ("after the first step", forces[1])):
    print(f"forces {label}: left {f[0] / 1e3:.2f} kN, right {f[1] / 1e3:.2f} kN "
          f"({(f[0] / W - 1) * 100:+.4f} %, {(f[1] / W - 1) * 100:+.4f} % of the static load)")
for i, side in enumerate(("left", "right")):
    print(f"peak contact force, {side:5}: {peak[i] / 1e3:.2f} kN (contact.{side}.max_force), "
          f"{max(f[i] for f in forces) / 1e3:.2f} kN (recorded)")
if max(abs(f / W - 1) for f in forces[0]) > 1e-3:  # static_load.* is not the vehicle's
    sys.exit("not at rest at the start: check static_load.* and the wheel heights")
print(f"wall time: {time.perf_counter() - wall:.1f} s")
