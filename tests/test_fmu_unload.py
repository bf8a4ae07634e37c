"""Every FMU unloads (issue 38, N4): a thread-local with a destructor, registered during
initialisation, pinned TrackContact's and CoupledSystem's libraries after dlclose, and
1,500 ``fmpy.simulate_fmu`` calls in one process grew from 59 MB to 2.9 GB. Here each
FMU is loaded, instantiated, initialised, freed and unloaded (fmpy's ``freeLibrary``,
dlclose) 1,000 times in this process: its library is no longer mapped after each cycle,
and the resident memory stays flat."""

import os

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

# WHEELFLAT_UNLOAD_CYCLES=10000 for the figure in issue 38's note (pytest -s prints it).
CYCLES = int(os.environ.get("WHEELFLAT_UNLOAD_CYCLES", "1000"))
# Resident growth allowed over the cycles after the first ten (MB): the bound.
GROWTH_MB = 20.0


def resident_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS in /proc/self/status")


def mapped(path):
    with open("/proc/self/maps") as f:
        return any(line.rstrip().endswith(path) for line in f)


def cycle(md, folder):
    s = FMU2Slave(guid=md.guid, unzipDirectory=folder,
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName="unload")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.doStep(0.0, 1e-3)
    s.terminate()
    s.freeInstance()
    s.freeLibrary()


@pytest.mark.parametrize("name", ["TrackContact", "CoupledSystem", "RollPlaneVehicle",
                                  "HalfCarBogie", "Wagon"])
def test_every_fmu_unloads_at_dlclose_and_a_thousand_cycles_keep_memory_flat(paths, tmp_path, name):
    md = read_model_description(paths[name])
    folder = extract(paths[name], unzipdir=str(tmp_path))
    library = os.path.realpath(os.path.join(folder, "binaries", "linux64",
                                            md.coSimulation.modelIdentifier + ".so"))
    cycle(md, folder)
    assert not mapped(library), f"{name}: the library stays mapped after dlclose"
    for _ in range(9):
        cycle(md, folder)
    before = resident_mb()
    for _ in range(CYCLES - 10):
        cycle(md, folder)
    grown = resident_mb() - before
    print(f"{name}: {CYCLES} cycles, resident memory {grown:+.2f} MB after the first ten")
    assert not mapped(library)
    assert grown < GROWTH_MB, f"{name}: {grown:.1f} MB more after {CYCLES} cycles"
