"""Quick start (a): TrackContact and RollPlaneVehicle coupled in fmpy, step by step.

    .venv/bin/python python/quickstart/pair_in_fmpy.py

The FMUs' defaults: table 4.4's track and vehicle, 70 km/h, a 100 mm x 1.5 mm flat on
the left wheel. Build the FMUs first (`python3 python/couple.py` does). Prints the
track's step, the static wheel load and the peak contact force of each wheel.
"""
import os
import shutil
import sys
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

# The repository's paths (fmu/ as python3 python/couple.py builds it), from wherever it runs.
os.chdir(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
if not os.path.exists("fmu/TrackContact.fmu"):
    sys.exit("no fmu/TrackContact.fmu: build the FMUs first (python3 python/couple.py)")
STOP = 0.3  # s: two impacts of the flat (at 39 and 192 ms)
LOADS = ["static_load.left", "static_load.right"]
HEIGHTS = ["static_wheel_z.left", "static_wheel_z.right"]
WHEELS = ["wheel.left.z", "wheel.right.z", "wheel.rotation"]
FORCES = ["contact.left.force", "contact.right.force"]


def exchange(src, svr, dst, dvr, names):
    dst.setReal([dvr[n] for n in names], src.getReal([svr[n] for n in names]))


units = {}  # name -> (FMU2Slave, value references, its unpacked folder)
try:
    for name in ("TrackContact", "RollPlaneVehicle"):
        md = read_model_description(f"fmu/{name}.fmu")
        units[name] = (None, {v.name: v.valueReference for v in md.modelVariables}, extract(f"fmu/{name}.fmu"))
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=units[name][2], modelIdentifier=name, instanceName=name)
        fmu.instantiate()
        units[name] = (fmu,) + units[name][1:]
        fmu.setupExperiment(startTime=0.0, stopTime=STOP)
        fmu.enterInitializationMode()
    (track, tvr, _), (vehicle, vvr, _) = units["TrackContact"], units["RollPlaneVehicle"]
    # The static handshake (in initialization mode): the vehicle's loads to the track, the
    # track's static wheel heights back; then the first exchange.
    exchange(vehicle, vvr, track, tvr, LOADS)
    exchange(track, tvr, vehicle, vvr, HEIGHTS)
    exchange(vehicle, vvr, track, tvr, WHEELS)
    exchange(track, tvr, vehicle, vvr, FORCES)
    for fmu in (vehicle, track):
        fmu.exitInitializationMode()

    h = track.getReal([tvr["solver.step"]])[0]  # the track's step: CoupledSystem's arithmetic
    n = round(STOP / h)
    print(f"track step {h * 1e6:.3f} us, {n} steps to {STOP} s")
    print(f"static wheel load {track.getReal([tvr['contact.left.force']])[0] / 1e3:.2f} kN")
    for k in range(n):
        t = k * h
        step = STOP - t if k == n - 1 else h  # the last step ends exactly at STOP
        track.doStep(t, step)
        vehicle.doStep(t, step)
        exchange(vehicle, vvr, track, tvr, WHEELS)
        exchange(track, tvr, vehicle, vvr, FORCES)

    left, right = track.getReal([tvr["contact.left.max_force"], tvr["contact.right.max_force"]])
    print(f"peak contact force: left {left / 1e3:.2f} kN, right {right / 1e3:.2f} kN")
    for fmu in (track, vehicle):
        fmu.terminate()
finally:
    for fmu, _, folder in units.values():
        if fmu is not None:
            fmu.freeInstance()
        shutil.rmtree(folder, ignore_errors=True)
