"""Supports that lift, through the FMUs as fmpy drives them: tensionless pads and
ballast behind the reference flat's impacts, hanging sleepers on the endless track, and
the refusals of out-of-range voids (docs/MODEL.md, "Supports that lift")."""

import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
import wheelflat_fmus as wf  # noqa: E402

from fmpy import simulate_fmu  # noqa: E402
from fmpy.fmi1 import FMICallException  # noqa: E402

A = 0.685
SITES = {"sites": 8, **{f"site[{j + 1}].position": (16 + j) * A for j in range(8)}}


@pytest.fixture(scope="module")
def coupled():
    path = os.path.join(wf.FMU_DIR, "CoupledSystem.fmu")
    return path if os.path.exists(path) else wf.build_fmus()["CoupledSystem"]


def flat_run(path, **options):
    """CoupledSystem's defaults (the reference flat, 100 mm x 1.5 mm on the left wheel)
    for 0.7 s: four impacts, the third and fourth among the sites."""
    out = ["contact.left.force", "track.lifted.pads", "track.lifted.ballast",
           "track.lifted.longest", "track.lifted.position"]
    out += [f"site[{j}].{q}.{side}.{what}" for j in range(1, 9) for side in ("left", "right")
            for q, what in (("seat", "force.min"), ("ballast", "force.min"),
                            ("ballast", "lifted.max"), ("seat", "lifted.max"))]
    start = {**SITES, **options}
    return simulate_fmu(path, stop_time=0.7, output_interval=1e-3, start_values=start, output=out)


def smallest(r, q, what):
    return min(r[f"site[{j}].{q}.{side}.{what}"][-1] for j in range(1, 9) for side in ("left", "right"))


def largest(r, q, what):
    return max(r[f"site[{j}].{q}.{side}.{what}"][-1] for j in range(1, 9) for side in ("left", "right"))


def test_tensionless_supports_let_go_where_the_thesis_pads_pull(coupled):
    linear = flat_run(coupled)
    # The thesis' linear seats pull the rail down with over 30 kN behind the impacts.
    assert smallest(linear, "seat", "force.min") < -30e3
    assert smallest(linear, "ballast", "force.min") < -5e3
    assert linear["track.lifted.longest"][-1] == 0.0
    assert np.all(linear["track.lifted.pads"] == 0)

    lifting = flat_run(coupled, **{"track.supports": 2, "track.pad.preload": 20e3,
                                   "track.ballast.preload": 1.7e3})
    # No pad pulls harder than its clip, no ballast seat harder than its preload,
    # and some ballast seats reach it and let go.
    assert smallest(lifting, "seat", "force.min") >= -20e3
    assert smallest(lifting, "ballast", "force.min") == pytest.approx(-1.7e3, abs=1e-9)
    assert largest(lifting, "ballast", "lifted.max") > 0.0
    assert lifting["track.lifted.longest"][-1] > 1e-4
    assert 0.0 < lifting["track.lifted.position"][-1] < 30 * A
    assert lifting["track.lifted.ballast"].max() > 0
    # The impact's peak moves by under 2 %.
    assert lifting["contact.left.force"].max() == pytest.approx(linear["contact.left.force"].max(), rel=0.02)


def test_hanging_sleepers_on_the_endless_track_close_their_gap_under_the_wheel(coupled):
    # Three sleepers hang 0.3 mm above the ballast from 20.55 m on; the wheelset
    # rolls over them at 70 km/h on the endless track.
    start = {"track.window.ahead": 20.0, "track.window.behind": 20.0, "speed": 70 / 3.6, "start_position": 10.0,
             "track.void.sleepers": 3, "track.void.position": 20.6, "track.void.gap": 3e-4,
             "sites": 1, "site[1].position": 31 * A}
    out = ["site[1].ballast.left.lifted", "site[1].ballast.left.lifted.max",
           "site[1].ballast.left.force.min", "site[1].ballast.left.force.max",
           "site[1].seat.left.z.min", "track.lifted.ballast", "track.lifted.position", "rail.left.z"]
    r = simulate_fmu(coupled, stop_time=0.9, output_interval=1e-3, start_values=start, output=out)
    # Hanging (all six seats of the three sleepers) until the wheel comes near.
    assert r["track.lifted.ballast"][0] == 6
    assert r["site[1].ballast.left.lifted"][100] == pytest.approx(r["time"][100], abs=2e-5)
    assert r["site[1].ballast.left.lifted.max"][-1] > 0.1
    # On the ballast under the wheel: the seat moved down by more than the gap, and
    # the ballast carried without ever pulling.
    assert r["site[1].seat.left.z.min"][-1] < -3e-4
    assert r["site[1].ballast.left.force.max"][-1] > 1e3
    assert r["site[1].ballast.left.force.min"][-1] >= 0.0
    assert abs(r["track.lifted.position"][-1] - 31 * A) < 1.5 * A
    # The rail under the wheel sinks deeper over them than the intact track's 1.49 mm.
    assert r["rail.left.z"].min() < -1.69e-3


@pytest.mark.parametrize("start, message", [
    # A gap above the table's range, refused when it is set.
    ({"track.void.gap": 0.1},
     "`track.void.gap` = 0.1 m is out of range; allowed: finite, 0 <= track.void.gap <= 0.01 m"),
    # Hanging sleepers beyond the fixed track's 31 sleepers, refused at initialisation.
    ({"track.window.ahead": 0.0, "track.void.sleepers": 3, "track.void.position": 50.0},
     "parameter `track.void.position` = 50 is out of range: allowed a run of track.void.sleepers = 3 "
     "sleepers within the fixed track's 31 sleepers: -0.3425 m <= track.void.position < 19.5225 m"),
    ({"track.window.ahead": 0.0, "track.void.sleepers": 40, "track.void.position": 1.0},
     "`track.void.sleepers` = 40 is out of range: allowed 1 <= track.void.sleepers <= 31"),
])
def test_hanging_sleepers_out_of_range_are_refused_by_name(coupled, capfd, start, message):
    with pytest.raises(FMICallException):
        simulate_fmu(coupled, stop_time=0.01, start_values=start, debug_logging=True)
    assert message in capfd.readouterr().out


def test_a_saved_state_of_lifting_supports_continues_bit_for_bit(coupled):
    # Tensionless supports and hanging sleepers on the endless track: an FMU state
    # saved at 0.3 s (serialized and read back) continues as the run did.
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(coupled)
    vrs = {v.name: v for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(coupled),
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="state")
    fmu.instantiate()
    start = {"track.window.ahead": 20.0, "track.window.behind": 20.0, "track.supports": 2, "track.pad.preload": 5e3,
             "track.void.sleepers": 4, "track.void.position": 14.0, "track.void.gap": 2e-4,
             "sites": 1, "site[1].position": 14.4}
    fmu.setupExperiment(startTime=0.0)
    for k, v in start.items():
        (fmu.setInteger if vrs[k].type in ("Integer", "Enumeration") else fmu.setReal)(
            [vrs[k].valueReference], [int(v) if vrs[k].type != "Real" else v])
    fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    names = ["contact.left.force", "track.lifted.longest", "track.lifted.position",
             "site[1].ballast.left.lifted.max", "site[1].seat.left.force.min"]
    refs = [vrs[n].valueReference for n in names]
    h = 1e-3
    t = 0.0
    while t < 0.3 - 1e-9:
        fmu.doStep(t, h)
        t += h
    saved = fmu.deSerializeFMUstate(fmu.serializeFMUstate(fmu.getFMUstate()))

    def run_on():
        out, s = [], 0.3
        while s < 0.6 - 1e-9:
            fmu.doStep(s, h)
            s += h
            out.append(fmu.getReal(refs))
        return np.array(out)

    first = run_on()
    fmu.setFMUstate(saved)
    again = run_on()
    fmu.terminate()
    fmu.freeInstance()
    assert np.array_equal(first, again)
    assert first[-1, 1] > 0.0 and first[-1, 3] > 0.0
