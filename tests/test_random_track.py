"""Random rail profiles and roughness through the FMUs (issue 44): the parameters set by
fmpy, the same seed the same run and another seed another, an FMU state restored in a
fresh instance that continues bit for bit (it carries the seeds, the band and the
spectra), and refusals that name the parameter (docs/MODEL.md, "Random rail profiles
and roughness")."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import wheelflat_fmus as wf  # noqa: E402

from fmpy import simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402

# FRA class 4 (item 5), ISO 3095 roughness on the rails and the wheels.
RANDOM = {"rail.spectrum": 5, "rail.spectrum.seed": 17, "roughness.rail": "iso3095",
          "roughness.wheel": "iso3095", "roughness.seed": 4}


@pytest.fixture(scope="module")
def coupled():
    path = os.path.join(wf.FMU_DIR, "CoupledSystem.fmu")
    return path if os.path.exists(path) else wf.build_fmus()["CoupledSystem"]


def forces(path, **start):
    r = simulate_fmu(path, stop_time=0.4, output_interval=1e-3, start_values=start,
                     output=["contact.left.force", "contact.right.force"])
    return np.column_stack([r["contact.left.force"], r["contact.right.force"]])


def test_the_same_seed_draws_the_same_run_and_another_seed_another(coupled):
    ideal = forces(coupled)
    a = forces(coupled, **RANDOM)
    b = forces(coupled, **RANDOM)
    c = forces(coupled, **{**RANDOM, "rail.spectrum.seed": 18})
    assert np.array_equal(a, b)
    # The first 2 m (0.1 s at 70 km/h) are the profile's ramp: without the wheels'
    # roughness, which is there from the start, the run starts as on ideal rails.
    rails = forces(coupled, **{"rail.spectrum": 5, "rail.spectrum.seed": 17})
    assert np.array_equal(rails[0], ideal[0])
    # 1 ms on, 2 cm into the ramp, the profile is a fraction of a micrometre: tens of N.
    assert np.max(np.abs(rails[:2] - ideal[:2])) < 1e-3 * ideal[0, 0]
    assert np.max(np.abs(rails - ideal)) > 0.01 * ideal[0, 0]
    assert np.max(np.abs(a - c)) > 0.01 * ideal[0, 0]
    assert np.max(np.abs(a - ideal)) > 0.01 * ideal[0, 0]


def test_an_fmu_state_carries_the_seeds_into_a_fresh_instance(coupled):
    a, b = wf.Unit(coupled, "random"), wf.Unit(coupled, "restored")
    a.fmu.setupExperiment(startTime=0.0)
    a.set_parameters({**RANDOM, "rail.spectrum.shortest_wavelength": 1.0,
                      "rail.spectrum.longest_wavelength": 20.0})
    a.fmu.enterInitializationMode()
    a.fmu.exitInitializationMode()
    h, t = 1e-3, 0.0
    for _ in range(200):
        a.fmu.doStep(t, h)
        t += h
    b.fmu.setFMUstate(b.fmu.deSerializeFMUstate(a.fmu.serializeFMUstate(a.fmu.getFMUstate())))
    vr = a.vr
    assert b.fmu.getInteger([vr["rail.spectrum.seed"], vr["roughness.seed"]]) == [17, 4]
    assert b.get("rail.spectrum.longest_wavelength") == [20.0]
    for _ in range(200):
        a.fmu.doStep(t, h)
        b.fmu.doStep(t, h)
        t += h
        assert a.get(*wf.FORCES) == b.get(*wf.FORCES)
    wf.close_all(a, b)


@pytest.mark.parametrize("start, message", [
    ({"roughness.rail": "0.025 -5; 0.04 -3"}, "roughness.rail: the bands at 0.025 m and 0.04 m"),
    ({"roughness.wheel": "0.025 -5; 0.0315 95"}, "roughness.wheel (level at 0.0315 m)"),
    ({"rail.spectrum": 5, "rail.spectrum.rails": 2}, "rail.spectrum.rails"),
    ({"rail.spectrum": 8, "rail.spectrum.shortest_wavelength": 10.0,
      "rail.spectrum.longest_wavelength": 11.0}, "rail.spectrum.longest_wavelength"),
    ({"roughness.patch_length": 0.2}, "roughness.patch_length"),
    # A name that is not the ISO limit's is a path; the refusal names the keyword.
    ({"roughness.rail": "ISO3095"}, "or iso3095 (the ISO 3095 limit)"),
    # A profile at full height at the start would jump under the wheels at the first step.
    ({"rail.spectrum": 2, "rail.spectrum.ramp": 0.0}, "rail.spectrum.ramp"),
    # The Hertz patch the roughness is averaged over needs the Hertz coefficient.
    ({"contact.CH": 0.0, "roughness.rail": "iso3095"}, "contact.CH"),
])
def test_bad_spectra_are_refused_with_the_parameter(coupled, capfd, start, message):
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values=start)
    out = capfd.readouterr().out
    assert message in out, out


def test_the_cross_level_spectrum_runs_on_the_german_levels(coupled):
    a = forces(coupled, **{"rail.spectrum": 9, "rail.spectrum.rails": 2})
    assert np.all(np.isfinite(a)) and np.max(np.abs(a[:, 0] - a[:, 1])) > 100.0
