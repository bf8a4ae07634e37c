"""The TwoAxleWagon FMU and CoupledSystem with vehicle.model = two_axle (issue 39): the
static loads, a standstill, the pair at the track's step against CoupledSystem (the same
arithmetic), at the axle boxes at 1 ms against CoupledSystem, and the reference flat on
its leading wheel at 70 km/h on the endless track. The shipped system files in OSP
libcosim and ecos are in tests/test_masters.py (every kind of the registry).

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
FORCES = wf.every_wheelset(2, ("contact.left.force", "contact.right.force"))
# Table 4.4: the car body twice the car-body share per wheelset (2 x 20,150 kg) and two
# wheelsets of 1,120 kg, a quarter of the weight on each wheel (g = 9.81).
STATIC_LOAD = 0.25 * 9.81 * (2 * 20150.0 + 2 * 1120.0)


@pytest.fixture(scope="module")
def paths():
    p = {n: os.path.join(wf.FMU_DIR, n + ".fmu") for n in wf.registry()["fmus"]}
    if not all(os.path.exists(x) for x in p.values()):
        p = wf.build_fmus()
    return p


@pytest.fixture(scope="module")
def two_axle(paths):
    """CoupledSystem's parameters for the TwoAxleWagon's defaults: vehicle.model and the
    wheelbase from the registry and the FMU."""
    kind = wf.vehicle_kind("TwoAxleWagon")
    from fmpy import read_model_description
    md = read_model_description(paths["TwoAxleWagon"])
    a = float(next(v.start for v in md.modelVariables if v.name == "wheelset[2].offset"))
    assert a == 9.0
    return dict(ENDLESS, **{"vehicle.model": kind["value"], "wheelsets": 2, "wheelset[2].offset": a})


def test_the_two_axle_wagon_publishes_a_quarter_of_its_weight_on_every_wheel(paths):
    loads, held = static_loads_and_held_forces(paths["TwoAxleWagon"], FORCES)
    assert loads == pytest.approx([STATIC_LOAD] * 2, rel=1e-12)
    assert STATIC_LOAD == pytest.approx(104329.35, abs=0.01)
    assert held == pytest.approx([STATIC_LOAD] * 4, rel=1e-9)


def test_the_two_axle_wagon_alone_at_rest_stays_at_rest(paths):
    names = ["carbody.z", "carbody.pitch", "carbody.roll", "wheelset[2].z", "sideframe.left.z"]
    for interface in (1, 2):
        drift = drift_alone_at_rest(paths["TwoAxleWagon"], names, interface)
        assert drift < 1e-8, (interface, drift)


def test_coupled_system_with_the_two_axle_wagon_on_a_level_track_stands_still(paths, two_axle):
    from fmpy import simulate_fmu
    start = dict(two_axle, **{"speed": 0.0, "flat.left[1].length": 0.0, "flat.left[1].depth": 0.0})
    r = simulate_fmu(paths["CoupledSystem"], stop_time=0.2, start_values=start, output=FORCES,
                     output_interval=0.01)
    for name in FORCES:
        assert np.max(np.abs(r[name] / STATIC_LOAD - 1)) < 1e-8, name


def test_the_reference_flat_on_the_leading_wheel_at_70_km_h(paths, two_axle):
    # CoupledSystem's defaults: the 100 x 1.5 mm haversine flat on the leading left
    # wheel, 70 km/h, the converged endless track. The impact is the flat's: more than
    # 2.5 times the static load on the flat wheel, the other wheels far below.
    from fmpy import simulate_fmu
    maxima = wf.every_wheelset(2, ("contact.left.max_force", "contact.right.max_force"))
    r = simulate_fmu(paths["CoupledSystem"], stop_time=0.3, start_values=two_axle, output=maxima + ["speed"])
    assert r["speed"][-1] == pytest.approx(70 / 3.6, rel=1e-9)
    peaks = [r[n][-1] for n in maxima]
    print("two-axle wagon, reference flat at 70 km/h: peaks (kN)", [round(p / 1e3, 1) for p in peaks])
    assert peaks[0] > 2.5 * STATIC_LOAD
    assert max(peaks[1:]) < 1.5 * STATIC_LOAD


def test_the_pair_at_the_tracks_step_is_coupled_system(paths, two_axle):
    worst, peak = at_the_tracks_step_against_coupled_system(paths, wf.run_two_axle, two_axle, FORCES)
    assert worst <= 1e-9 * STATIC_LOAD
    assert peak[0][0] > 2.5 * STATIC_LOAD


def test_the_two_axle_wagon_at_1_ms_couples_at_the_axle_boxes_within_one_percent(paths, two_axle):
    # fmpy's sequential loop every 1 ms, TrackContact carrying nothing above the axle
    # boxes (vehicle.model = two_axle): every wheel's largest force over 0.3 s within
    # 1 % of CoupledSystem's.
    errors, _ = axle_box_errors(paths, wf.run_two_axle_axle_box, two_axle)
    print("two-axle wagon at the axle boxes, 1 ms, fmpy:", [f"{100 * e:+.3f} %" for e in errors])
    assert max(abs(e) for e in errors) < 0.01, [f"{100 * e:+.3f} %" for e in errors]


@pytest.mark.parametrize("params, message", [
    ({"wheelsets": 1}, "`wheelsets` = 1 is out of range: allowed 2 with vehicle.model = two_axle at the axle boxes"),
    ({"wheelsets": 4, "wheelset[2].offset": 9.0, "wheelset[3].offset": 12.0, "wheelset[4].offset": 21.0},
     "`wheelsets` = 4 is out of range: allowed 2 with vehicle.model = two_axle at the axle boxes"),
    ({"wheelsets": 2, "wheelset[2].offset": 1.8},
     "`wheelset[2].offset` = 1.8 is out of range: allowed 4 m <= wheelset[2].offset <= 14 m"),
])
def test_track_contact_at_the_axle_boxes_refuses_what_the_two_axle_wagon_cannot_be(paths, params, message, capfd):
    # The breaker's finding: TrackContact carried a two-axle wagon on one or four
    # wheelsets, or at a bogie's wheelbase, without a word.
    from fmpy import simulate_fmu
    start = dict(ENDLESS, interface=2, **{"vehicle.model": wf.vehicle_kind("TwoAxleWagon")["value"]}, **params)
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["TrackContact"], stop_time=0.01, start_values=start)
    out = capfd.readouterr().out
    assert message in out, out


def test_coupled_system_names_the_wheelsets_before_the_offsets(paths, two_axle, capfd):
    # Three wheelsets at CoupledSystem's default offsets: the count is what is wrong.
    from fmpy import simulate_fmu
    start = {"vehicle.model": two_axle["vehicle.model"], "wheelsets": 3}
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["CoupledSystem"], stop_time=0.01, start_values=start)
    out = capfd.readouterr().out
    assert "`wheelsets` = 3 is out of range: allowed 2 with the two-axle wagon" in out, out


def test_a_suspension_too_soft_to_carry_the_wagon_is_named(paths, capfd):
    # At vehicle.primary.stiffness = 1e4 N/m (its declared least) the car body would
    # rest 9.9 m down: refused at fmi2ExitInitializationMode naming the stiffness, not
    # the forces.
    from fmpy import simulate_fmu
    with pytest.raises(Exception, match="fmi2ExitInitializationMode"):
        simulate_fmu(paths["TwoAxleWagon"], stop_time=0.01, start_values={"vehicle.primary.stiffness": 1e4})
    out = capfd.readouterr().out
    assert "the suspension is too soft to carry the vehicle (vehicle.primary.stiffness = 10000 N/m)" in out, out


def test_its_declared_static_heights_are_the_tracks(paths, two_axle):
    # The FMU starts at rest on static_wheel_z.* unless the master hands it the track's:
    # its declared starts are TrackContact's static heights under its own static load
    # and wheelbase (TrackContact's defaults otherwise), so a master that runs no
    # handshake starts it at rest.
    from fmpy import read_model_description
    starts = {v.name: float(v.start) for v in read_model_description(paths["TwoAxleWagon"]).modelVariables
              if v.start is not None}
    names = wf.every_wheelset(2, ("static_wheel_z.left", "static_wheel_z.right"))
    t = wf.Unit(paths["TrackContact"], "t")
    t.fmu.setupExperiment(startTime=0.0)
    t.set_parameters({"wheelsets": 2, "wheelset[2].offset": starts["wheelset[2].offset"],
                      "static_load.left": STATIC_LOAD, "static_load.right": STATIC_LOAD})
    t.fmu.enterInitializationMode()
    heights = t.get(*names)
    t.fmu.exitInitializationMode()
    t.close()
    assert [starts[n] for n in names] == pytest.approx(heights, abs=1e-12)
