"""Loads an FMU's shared library with ctypes (Python's standard library only, so it runs
in a bare Debian root), runs CoupledSystem from its defaults for `duration` s at its own
step and prints the left wheel's peak contact force (N) and the C library it ran on.

    python3 harness.py FMU_FOLDER [DURATION]

FMU_FOLDER is an extracted CoupledSystem.fmu (modelDescription.xml, binaries/linux64).
"""

import ctypes
import os
import platform
import sys
import xml.etree.ElementTree as ET

folder = sys.argv[1]
duration = float(sys.argv[2]) if len(sys.argv) > 2 else 0.06
md = ET.parse(os.path.join(folder, "modelDescription.xml")).getroot()
guid = md.get("guid").encode()
ident = md.find("CoSimulation").get("modelIdentifier")
vr = {v.get("name"): int(v.get("valueReference")) for v in md.iter("ScalarVariable")}
lib = ctypes.CDLL(os.path.join(folder, "binaries", "linux64", ident + ".so"))
libc = ctypes.CDLL(None)

LOGGER = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p)
ALLOC = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)
FREE = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
libc.calloc.restype = ctypes.c_void_p
libc.calloc.argtypes = [ctypes.c_size_t, ctypes.c_size_t]
libc.free.argtypes = [ctypes.c_void_p]


class Callbacks(ctypes.Structure):
    _fields_ = [("logger", LOGGER), ("allocateMemory", ALLOC), ("freeMemory", FREE),
                ("stepFinished", ctypes.c_void_p), ("componentEnvironment", ctypes.c_void_p)]


def log(env, name, status, category, message):
    if status >= 3:
        print("fmu:", message.decode(errors="replace"), file=sys.stderr)


cb = Callbacks(LOGGER(log), ALLOC(lambda n, s: libc.calloc(n, s)), FREE(lambda p: libc.free(p)), None, None)
lib.fmi2Instantiate.restype = ctypes.c_void_p
lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                ctypes.POINTER(Callbacks), ctypes.c_int, ctypes.c_int]
c = lib.fmi2Instantiate(b"harness", 1, guid, b"", ctypes.byref(cb), 0, 0)
assert c, "fmi2Instantiate failed"
C = ctypes.c_void_p(c)
lib.fmi2SetupExperiment.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_double, ctypes.c_double, ctypes.c_int,
                                    ctypes.c_double]
lib.fmi2DoStep.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
lib.fmi2GetReal.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint), ctypes.c_size_t,
                            ctypes.POINTER(ctypes.c_double)]


def get(name):
    r = (ctypes.c_uint * 1)(vr[name])
    x = (ctypes.c_double * 1)()
    assert lib.fmi2GetReal(C, r, 1, x) == 0
    return x[0]


assert lib.fmi2SetupExperiment(C, 0, 0.0, 0.0, 0, 0.0) == 0
assert lib.fmi2EnterInitializationMode(C) == 0
assert lib.fmi2ExitInitializationMode(C) == 0
h = get("solver.step")
for k in range(int(round(duration / h))):
    assert lib.fmi2DoStep(C, k * h, h, 1) == 0
print(f"peak {get('contact.left.max_force')!r} glibc {platform.libc_ver()[1]}")
lib.fmi2Terminate(C)
lib.fmi2FreeInstance(C)
