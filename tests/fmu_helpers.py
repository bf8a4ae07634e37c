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
