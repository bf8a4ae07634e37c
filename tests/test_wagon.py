"""The Wagon FMU and CoupledSystem with vehicle.model = wagon (issue 28): the static
loads, a standstill, the Wagon with TrackContact at the track's step against
CoupledSystem (the same arithmetic), at the axle boxes at 1 ms against CoupledSystem,
and the refusals of a track that does not carry its wheelsets where the wagon has them.
The shipped system files in OSP libcosim and ecos are in tests/test_masters.py.

Run by the README's test command (after the FMUs are built)."""

import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import wheelflat_fmus as wf  # noqa: E402
from fmu_helpers import (at_the_tracks_step_against_coupled_system, axle_box_errors,  # noqa: E402
                         drift_alone_at_rest, static_loads_and_held_forces)

ENDLESS = {"track.window.ahead": 20.0, "track.window.behind": 20.0}
# CoupledSystem with the wagon of the Wagon FMU's defaults: wheelbase 1.8 m, bogie
# centres 10 m apart.
WAGON = dict(ENDLESS, **{"vehicle.model": 3, "wheelsets": 4, "wheelset[2].offset": 1.8,
                         "wheelset[3].offset": 10.0, "wheelset[4].offset": 11.8})
FORCES = wf.every_wheelset(4, ("contact.left.force", "contact.right.force"))
# Table 4.4: the wagon weighs eight times the roll-plane vehicle's wheel load.
STATIC_LOAD = 107664.75


@pytest.fixture(scope="module")
def paths():
    p = {n: os.path.join(wf.FMU_DIR, n + ".fmu") for n in wf.registry()["fmus"]}
    if not all(os.path.exists(x) for x in p.values()):
        p = wf.build_fmus()
    return p


def coupled(paths, stop, params=None, interval=None):
    """CoupledSystem with the wagon: the eight contact forces and the car body's motion
    at every output point."""
    from fmpy import simulate_fmu
    start = dict(WAGON, **(params or {}))
    out = FORCES + ["carbody.z", "carbody.pitch", "carbody.roll"]
    r = simulate_fmu(paths["CoupledSystem"], stop_time=stop, start_values=start, output=out,
                     output_interval=interval)
    return r


def test_the_wagon_publishes_an_eighth_of_its_weight_on_every_wheel(paths):
    # Table 4.4: four quarter car bodies, two bogies of twice the roll-plane vehicle's
    # bolster, side frames; 107.665 kN a wheel, as the thesis' vehicle.
    loads, held = static_loads_and_held_forces(paths["Wagon"], FORCES)
    assert loads == pytest.approx([STATIC_LOAD] * 2, rel=1e-12)
    # The inputs at rest are the forces that hold the wagon on its wheels.
    assert held == pytest.approx([STATIC_LOAD] * 8, rel=1e-9)


def test_the_wagon_alone_at_rest_stays_at_rest(paths):
    # Unset inputs take the wagon's static forces: 2 s alone at 1 ms leave the car body
    # and the wheels where they were (below 1e-8 m and rad), at both interfaces.
    names = ["carbody.z", "carbody.pitch", "carbody.roll", "wheelset[4].z", "sideframe.left.pitch"]
    for interface in (1, 2):
        drift = drift_alone_at_rest(paths["Wagon"], names, interface)
        assert drift < 1e-8, (interface, drift)


def test_coupled_system_with_the_wagon_on_a_level_track_stands_still(paths):
    # At a standstill on the endless track every wheel carries its static load to
    # 1e-8 of it after 0.2 s (the static start is the track's and the wagon's joint
    # equilibrium).
    r = coupled(paths, 0.2, {"speed": 0.0, "flat.left[1].length": 0.0, "flat.left[1].depth": 0.0}, interval=0.01)
    for name in FORCES:
        assert np.max(np.abs(r[name] / STATIC_LOAD - 1)) < 1e-8, name


def test_the_wagon_with_track_contact_at_the_tracks_step_is_coupled_system(paths):
    # The Wagon FMU and TrackContact (four wheelsets at the wagon's offsets) exchanged at
    # the track's step do CoupledSystem's arithmetic with vehicle.model = wagon: the
    # eight contact forces agree to 1e-9 through the leading wheel's first impact.
    worst, peak = at_the_tracks_step_against_coupled_system(paths, wf.run_wagon, WAGON, FORCES)
    assert worst <= 1e-9 * STATIC_LOAD
    assert peak[0][0] > 2.5 * STATIC_LOAD


def test_the_wagon_at_1_ms_couples_at_the_axle_boxes_within_one_percent(paths):
    # fmpy's sequential loop (track first, the mean primary forces of the step to the
    # wagon) every 1 ms: every wheel's largest force over 0.3 s (the leading wheel's
    # flat hits at 34, 184 and 334 ms... within it: two impacts) within 1 % of
    # CoupledSystem's. Measured: 0.15 % on the second wheelset, 0.06 % on the flat.
    errors, ref = axle_box_errors(paths, wf.run_wagon_axle_box, WAGON)
    assert max(abs(e) for e in errors) < 0.01, [f"{100 * e:+.3f} %" for e in errors]
    # The impact is the flat's: 2.8 times the static load on the flat wheel, and the
    # trailing wheelset of the same bogie feels it (through the rails and the side
    # frames' pitch) more than the rear bogie's.
    assert ref[0] > 2.5 * STATIC_LOAD
    assert max(ref[2:4]) > max(ref[4:8]) > STATIC_LOAD


@pytest.mark.parametrize("offsets, message", [
    ({"wheelsets": 2}, "`wheelsets` = 2 is out of range: allowed 4 with the wagon"),
    ({"wheelset[4].offset": 12.0}, "`wheelset[4].offset` = 12 is out of range: allowed 11.8 m, wheelset[3].offset + "
                                   "wheelset[2].offset"),
    ({"wheelset[3].offset": 40.0, "wheelset[4].offset": 41.8}, "`wheelset[3].offset` = 40"),
])
def test_coupled_system_refuses_a_wagon_on_other_wheelsets(paths, offsets, message, capfd):
    # The wagon carries four wheelsets at its wheelbase (wheelset[2].offset) and bogie
    # distance (wheelset[3].offset, at most 30 m): another count, a fourth wheelset
    # elsewhere than their sum or a bogie distance out of range is refused at the end
    # of initialization, naming the variable, its value and what is allowed.
    from fmpy import simulate_fmu
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["CoupledSystem"], stop_time=0.01, start_values=dict(WAGON, **offsets))
    out = capfd.readouterr().out
    assert message in out, out


@pytest.mark.parametrize("params, message", [
    ({"vehicle.model": 3, "wheelsets": 2}, "`wheelsets` = 2 is out of range: allowed 4 with vehicle.model = wagon"),
    ({"vehicle.model": 2, "wheelsets": 4, "wheelset[2].offset": 1.8, "wheelset[3].offset": 10.0,
      "wheelset[4].offset": 11.8}, "`wheelsets` = 4 is out of range: allowed 2 with vehicle.model = half_car"),
])
def test_track_contact_at_the_axle_boxes_carries_the_side_frames_of_the_vehicle_it_names(paths, params, message, capfd):
    # vehicle.model names the bogies whose side frames TrackContact carries: the wagon's
    # two over four wheelsets, the half-car's one over two; another count is refused.
    from fmpy import simulate_fmu
    start = dict(ENDLESS, interface=2, **params)
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["TrackContact"], stop_time=0.01, start_values=start)
    out = capfd.readouterr().out
    assert message in out, out


def test_a_refused_wagon_geometry_names_the_offsets_coupled_system_has(paths, capfd):
    # CoupledSystem has no vehicle.wheelbase or vehicle.bogie_distance: the wagon's
    # refusal of a bogie distance below the wheelbase names the offsets that carry them.
    from fmpy import simulate_fmu
    start = dict(WAGON, **{"wheelset[2].offset": 5.0, "wheelset[3].offset": 4.5, "wheelset[4].offset": 9.5})
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["CoupledSystem"], stop_time=0.01, start_values=start)
    out = capfd.readouterr().out
    assert "`wheelset[3].offset` = 4.5 is out of range: allowed wheelset[2].offset + 1 m = 6 m <=" in out, out
    assert "vehicle." not in out.split("out of range")[1].split("\n")[0], out


def test_the_wagon_at_rest_at_the_end_of_its_static_heights_range_steps(paths):
    # The static wheel heights' range (0.05 m) is half the wheels' health bound: a wagon
    # at rest at its end steps without tripping the bound; beyond it fmi2SetReal refuses.
    u = wf.Unit(paths["Wagon"], "w")
    u.fmu.setupExperiment(startTime=0.0)
    u.set_parameters({"static_wheel_z.left": 0.05, "wheelset[4].static_wheel_z.right": -0.05})
    u.fmu.enterInitializationMode()
    u.fmu.exitInitializationMode()
    for k in range(10):
        u.fmu.doStep(k * 1e-3, 1e-3)
    assert abs(u.get("wheel.left.z")[0] - 0.05) < 1e-6
    u.close()
    v = wf.Unit(paths["Wagon"], "v")
    v.fmu.setupExperiment(startTime=0.0)
    with pytest.raises(Exception, match="fmi2SetReal"):
        v.set(["static_wheel_z.left"], [0.06])
    v.close(terminate=False)
