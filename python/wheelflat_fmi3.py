"""The wheelflat FMUs as FMI 3.0 co-simulation units (``fmu/fmi3/<name>.fmu``) through
fmpy's FMU3Slave, and their coupling as :mod:`wheelflat_fmus` couples the FMI 2.0 ones.

In FMI 3.0 every per-wheelset variable is one array, the leading wheelset first, sized
by ``wheelsets``: TrackContact's and CoupledSystem's is a structural parameter, set in
Configuration Mode (:meth:`Unit3.configure`); a vehicle's is a constant. ``wheel.left.z``
of a track on two wheelsets is ``[leading, second]``, which FMI 2.0 names
``wheel.left.z`` and ``wheelset[2].wheel.left.z``. Enumerations are set as Int64.
"""

import os
import shutil

import wheelflat_fmus as wf

FMU3_DIR = os.path.join(wf.FMU_DIR, "fmi3")


def paths3(fmu_dir=FMU3_DIR):
    """The FMI 3.0 FMUs by name (built with the FMI 2.0 ones by
    :func:`wheelflat_fmus.build_fmus`)."""
    names = wf.registry()["fmus"]
    p = {n: os.path.join(fmu_dir, n + ".fmu") for n in names}
    if not all(os.path.exists(x) for x in p.values()):
        wf.build_fmus()
    return p


class Unit3:
    """One FMI 3.0 instance through fmpy's FMU3Slave. Values are read and written by
    name, flat: an array gives (and takes) one value per wheelset in use."""

    def __init__(self, path, instance_name, log_message=None, logging_on=False, early_return=False):
        """`early_return`: instantiated with earlyReturnAllowed, so that a track-carrying
        unit's step ends where a wheel loses contact or hits the rail (:meth:`do_step`
        says where)."""
        from fmpy import extract, read_model_description
        from fmpy.fmi3 import FMU3Slave

        self.path = path
        self.md = read_model_description(path)
        self.dir = extract(path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.vr = {n: v.valueReference for n, v in self.vars.items()}
        self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.fmu.instantiate(loggingOn=logging_on, logMessage=log_message, earlyReturnAllowed=early_return)
        self.wheelsets = int(self.vars["wheelsets"].start)

    def size(self, name):
        """How many values the variable `name` has now."""
        return self.wheelsets if self.vars[name].dimensions else 1

    def configure(self, wheelsets):
        """Sets the structural parameter ``wheelsets`` in Configuration Mode (after
        instantiation or reset): every array then has that many elements."""
        self.fmu.enterConfigurationMode()
        self.fmu.setUInt64([self.vr["wheelsets"]], [int(wheelsets)])
        self.fmu.exitConfigurationMode()
        self.wheelsets = int(wheelsets)

    def get(self, *names):
        """The Float64 values of `names`, flat."""
        n = sum(self.size(x) for x in names)
        return list(self.fmu.getFloat64([self.vr[x] for x in names], n))

    def set(self, names, values):
        """Sets the Float64 variables `names` to `values`, flat."""
        self.fmu.setFloat64([self.vr[x] for x in names], [float(x) for x in values])

    def set_parameters(self, params):
        """Sets parameters by name, by their type (an array's value a list, or one value
        for every element); ``wheelsets`` in Configuration Mode (before the others)."""
        params = dict(params or {})
        if "wheelsets" in params:
            self.configure(params.pop("wheelsets"))
        for name, value in params.items():
            vr, ty = [self.vr[name]], self.vars[name].type
            values = list(value) if isinstance(value, (list, tuple)) else [value] * self.size(name)
            if ty == "String":
                self.fmu.setString(vr, [str(x) for x in values])
            elif ty == "Enumeration":
                self.fmu.setInt64(vr, [int(x) for x in values])
            elif ty == "Int32":
                self.fmu.setInt32(vr, [int(x) for x in values])
            else:
                self.fmu.setFloat64(vr, [float(x) for x in values])

    def initialize(self, start_time=0.0, stop_time=None):
        """Initialization Mode (at `start_time`, with `stop_time` if given); the caller
        exchanges what it needs there (the static loads and wheel heights, as
        :func:`run_carrier` does), then calls ``self.fmu.exitInitializationMode()``."""
        self.fmu.enterInitializationMode(startTime=start_time, stopTime=stop_time)

    def do_step(self, t, h):
        """One ``fmi3DoStep`` from `t` by `h`: ``(terminate, early_return,
        last_successful_time)``; the next step starts at `last_successful_time` (t + h
        unless the step returned early). A master's clock that steps on the grid
        (``t = k * h``, not summed) keeps a coupling bit for bit with CoupledSystem."""
        _, terminate, early, last = self.fmu.doStep(t, h)
        return terminate, early, last

    def close(self, terminate=True):
        """Terminates (after stepping) and frees the instance, removing its folder."""
        from fmpy.fmi1 import FMICallException
        try:
            if terminate:
                self.fmu.terminate()
        except FMICallException:
            pass
        finally:
            self.fmu.freeInstance()
            shutil.rmtree(self.dir, ignore_errors=True)


def close_all(*units):
    """Closes every unit (see :func:`wheelflat_fmus.close_all`)."""
    wf.close_all(*units)


def run_carrier(paths, model, n, stop_time, track_params=None, vehicle_params=None, record=None):
    """:func:`wheelflat_fmus.run_carrier` through the FMI 3.0 units: TrackContact on `n`
    wheelsets (configured) and the vehicle FMU `model` exchange the arrays
    ``wheel.*.z``, ``wheel.rotation`` and ``contact.*.force`` at the track's internal
    step. Returns the largest contact forces ``[[left, right] of each wheelset]`` (N);
    ``record``, a list, receives ``[time, the contact forces (left of every wheelset,
    then right)]`` at every point."""
    track = Unit3(paths["TrackContact"], "track")
    vehicle = Unit3(paths[model], "vehicle")
    try:
        vp = dict(vehicle_params or {})
        tp = dict(track_params or {})
        if n > 1:
            start = {v.name: v.start for v in vehicle.md.modelVariables}
            kind = wf.vehicle_kind(model, os.path.dirname(os.path.dirname(paths[model])))
            tp["wheelsets"] = n
            for k, names in enumerate(kind["offsets"], start=2):
                tp[f"wheelset[{k}].offset"] = sum(float(vp.get(x, start[x])) for x in names)
        track.set_parameters(tp)
        vehicle.set_parameters(vp)
        for u in (vehicle, track):
            u.initialize()
        loads = ("static_load.left", "static_load.right")
        track.set(loads, vehicle.get(*loads))
        vehicle.set(wf.HEIGHTS, track.get(*wf.HEIGHTS))
        track.set(wf.WHEELS, vehicle.get(*wf.WHEELS))
        vehicle.set(wf.FORCES, track.get(*wf.FORCES))
        vehicle.fmu.exitInitializationMode()
        track.fmu.exitInitializationMode()
        h = track.get("solver.step")[0]
        steps = int(round(stop_time / h))
        peak = [[-1e300] * 2 for _ in range(n)]
        t = 0.0
        for k in range(steps + 1):
            track.set(wf.WHEELS, vehicle.get(*wf.WHEELS))
            p = track.get(*wf.FORCES)
            vehicle.set(wf.FORCES, p)
            for i in range(n):
                peak[i] = [max(peak[i][0], p[i]), max(peak[i][1], p[n + i])]
            if record is not None:
                record.append([t] + p)
            if k == steps:
                break
            track.do_step(t, h)
            vehicle.do_step(t, h)
            t = (k + 1) * h
        return peak
    finally:
        close_all(track, vehicle)
