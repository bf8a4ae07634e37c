"""What the FMU tests (tests/test_fmu_*.py) share: wheelflat_fmus as ``wf``, the
exported FMI 2.0 co-simulation functions, a recording logger, an instance made or
initialised, a run of a few steps. The ``paths`` fixture (the packed FMUs) is in
conftest.py."""

import ctypes
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import wheelflat_fmus as wf  # noqa: E402

from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE  # noqa: E402

FMI2_CS_FUNCTIONS = """fmi2GetTypesPlatform fmi2GetVersion fmi2SetDebugLogging fmi2Instantiate fmi2FreeInstance
fmi2SetupExperiment fmi2EnterInitializationMode fmi2ExitInitializationMode fmi2Terminate fmi2Reset
fmi2GetReal fmi2GetInteger fmi2GetBoolean fmi2GetString fmi2SetReal fmi2SetInteger fmi2SetBoolean fmi2SetString
fmi2GetFMUstate fmi2SetFMUstate fmi2FreeFMUstate fmi2SerializedFMUstateSize fmi2SerializeFMUstate
fmi2DeSerializeFMUstate fmi2GetDirectionalDerivative fmi2SetRealInputDerivatives fmi2GetRealOutputDerivatives
fmi2DoStep fmi2CancelStep fmi2GetStatus fmi2GetRealStatus fmi2GetIntegerStatus fmi2GetBooleanStatus
fmi2GetStringStatus""".split()


class Log:
    """A logger for FMU2Slave that records (status, category, message)."""

    def __init__(self):
        self.records = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)(
            lambda n, s: None)
        self.callbacks.freeMemory = ctypes.CFUNCTYPE(None, ctypes.c_void_p)(lambda p: None)

    def _log(self, env, name, status, category, message):
        self.records.append((status, category.decode(), message.decode()))

    def last(self):
        return self.records[-1] if self.records else (None, "", "")

    def text(self):
        return "\n".join(m for _, _, m in self.records)


def unit(paths, name, log=None, instance="inst"):
    return wf.Unit(paths[name], instance, callbacks=log.callbacks if log else None)


def initialised(paths, name, log=None, params=None):
    u = unit(paths, name, log)
    u.fmu.setupExperiment(startTime=0.0)
    u.set_parameters(params)
    u.fmu.enterInitializationMode()
    u.fmu.exitInitializationMode()
    return u


def run_for(u, t0, n, h=2e-5, names=("contact.left.force", "contact.right.force")):
    out = []
    for k in range(n):
        u.fmu.doStep(t0 + k * h, h)
        out.append(u.get(*names))
    return out


def static_loads_and_held_forces(path, forces):
    """A vehicle FMU alone: the static wheel loads it publishes in initialization mode
    (``static_load.left``, ``.right``, N) and the contact forces `forces` its unset inputs
    hold after it (N)."""
    u = wf.Unit(path, "w")
    try:
        u.fmu.setupExperiment(startTime=0.0)
        u.fmu.enterInitializationMode()
        loads = u.get("static_load.left", "static_load.right")
        u.fmu.exitInitializationMode()
        return loads, u.get(*forces)
    finally:
        u.close()


def drift_alone_at_rest(path, names, interface, steps=2000, h=1e-3):
    """The largest change of the outputs `names` of a vehicle FMU left alone at rest (its
    inputs unset) over `steps` steps of `h` s at `interface` (1 contact, 2 axle boxes)."""
    import numpy as np
    u = wf.Unit(path, "w")
    try:
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters({"interface": interface})
        u.fmu.enterInitializationMode()
        u.fmu.exitInitializationMode()
        before = np.array(u.get(*names))
        for k in range(steps):
            u.fmu.doStep(k * h, h)
        return float(np.max(np.abs(np.array(u.get(*names)) - before)))
    finally:
        u.close()


def at_the_tracks_step_against_coupled_system(paths, run, start, forces, stop=0.06):
    """A vehicle FMU and TrackContact coupled at the track's step by `run`
    (``wf.run_wagon``, ``wf.run_two_axle``: the endless track of `start`), against
    CoupledSystem with `start` sampled at the same points: (the largest difference of
    the contact forces `forces` (N), the run's peaks ``[[left, right] per wheelset]``)."""
    import numpy as np
    from fmpy import simulate_fmu
    window = {k: v for k, v in start.items() if k.startswith("track.window.")}
    rec = []
    peak = run(paths, stop, track_params=window, record=rec)
    got = np.array([x[1:] for x in rec])
    h = rec[1][0] - rec[0][0]
    r = simulate_fmu(paths["CoupledSystem"], stop_time=stop, start_values=start, output=forces, output_interval=h)
    ref = np.column_stack([r[n] for n in forces])[:len(got)]
    assert got.shape == ref.shape
    return float(np.max(np.abs(got - ref))), peak


def axle_box_errors(paths, run_axle_box, start):
    """:func:`wf.axle_box_against_coupled_system` as relative errors: (each wheel's
    largest contact force's error against CoupledSystem's, CoupledSystem's forces (N))."""
    got, ref = wf.axle_box_against_coupled_system(paths, run_axle_box, start)
    return [g / m - 1 for g, m in zip(got, ref)], ref
