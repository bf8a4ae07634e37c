"""Issue 43: a stand-in third-party bogie of our own exported with pythonfmu3 (FMI 3.0,
python/partner_bogie/standin_half_car3.py, its own 2 x 2 arrays) couples to the FMI 3.0
TrackContact (fmu/fmi3/TrackContact.fmu, wheelsets = 2 set in Configuration Mode) at the
axle boxes within 1 % of CoupledSystem at 1 ms, in an fmpy master that maps the names
element by element (python/partner_bogie/couple3.py). Issue 41's case: 70 km/h, the
reference flat, the endless track (20 m a side), 0.6 s. The stand-in steps the same
model class as issue 41's FMI 2.0 export (standin_bogie.py), and TrackContact's FMI 3.0
layer runs over its FMI 2.0 one: the FMI 3.0 pair's run is the FMI 2.0 pair's in the
same master, bit for bit."""

import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
from partner_bogie import build, couple3  # noqa: E402

G = 9.81
# The stand-in's weight above the primary suspension (kg): the car body's share, the
# bolster, two whole side frames (table 4.4's half-car bogie).
M_ABOVE = 40300.0 + 465.0 + 2 * 447.5


@pytest.fixture(scope="module")
def standin3():
    """The FMI 3.0 stand-in, built (or found up to date) under target/partner_bogie/."""
    path = build.build3()
    stamp = os.path.getmtime(path)
    assert build.build3() == path and os.path.getmtime(path) == stamp, "an up-to-date FMU is built again"
    return path


@pytest.fixture(scope="module")
def standin2():
    return build.build(fmi=2)


def test_it_is_a_pythonfmu3_fmi3_fmu_with_arrays_of_its_own(standin3):
    """FMI 3.0 from pythonfmu3 (pinned), its own names and layout: ``F_box`` in,
    ``z_frame`` and ``v_frame`` out, each 2 x 2 [wheelset][side]; the forces start at a
    quarter of its weight each; nothing of TrackContact's names."""
    from fmpy import read_model_description
    md = read_model_description(standin3)
    v = {x.name: x for x in md.modelVariables}
    assert md.fmiVersion == "3.0"
    assert md.generationTool.startswith("PythonFMU3 0.3.4")
    assert md.coSimulation.modelIdentifier == "StandinHalfCar3"
    assert md.coSimulation.canHandleVariableCommunicationStepSize
    for name, causality in (("F_box", "input"), ("z_frame", "output"), ("v_frame", "output")):
        assert v[name].type == "Float64" and v[name].causality == causality
        assert [int(d.start) for d in v[name].dimensions] == [2, 2]
    starts = [float(x) for x in str(v["F_box"].start).split()]
    assert starts == pytest.approx([0.25 * G * M_ABOVE] * 4, rel=1e-12)
    assert not any(n.startswith(("sideframe.", "primary.", "vehicle.", "wheelset")) for n in v)


def test_both_exports_step_one_model_class():
    """The FMI 2.0 and FMI 3.0 exports share standin_bogie.py's class: they cannot drift."""
    from partner_bogie import standin_bogie, standin_half_car, standin_half_car3
    assert standin_half_car.StandinBogie is standin_bogie.StandinBogie
    assert standin_half_car3.StandinBogie is standin_bogie.StandinBogie
    assert standin_half_car.PARAMETERS is standin_half_car3.PARAMETERS


def test_the_master_maps_its_arrays_to_trackcontacts_element_by_element():
    links = couple3.connections(2, "mean_force")
    assert ("partner", "z_frame", 1, "track", "sideframe.right.z", 0) in links   # [1][R] -> right[ws 1]
    assert ("partner", "v_frame", 2, "track", "sideframe.left.v", 1) in links    # [2][L] -> left[ws 2]
    assert ("track", "primary.right.mean_force", 1, "partner", "F_box", 3) in links
    assert len(links) == 12


@pytest.mark.parametrize("jacobi", [False, True], ids=["sequential", "jacobi"])
def test_fmi3_pair_within_one_per_cent_of_coupledsystem_and_the_fmi2_pair_bit_for_bit(standin3, standin2, jacobi):
    """Every 1 ms for 0.6 s: sequential (TrackContact first, primary.*.mean_force handed
    on) or Jacobi (primary.*.force). Every wheel's peak within 1 % of CoupledSystem's
    (FMI 2.0, vehicle.model = half_car; measured +0.035 to +0.102 % sequential, -0.59 to
    +0.05 % Jacobi); every call of both FMUs fmi3OK and nothing logged; and at every
    communication point the contact forces, the primary forces and the side frames handed
    on are the FMI 2.0 pair's in the same master, bit for bit."""
    r3 = couple3.run(3, jacobi=jacobi, standin_fmu=standin3, record=True)
    assert r3["failure"] is None, r3["failure"]
    assert set(r3["statuses"]["track"]) == {"ok"} and set(r3["statuses"]["partner"]) == {"ok"}, r3["statuses"]
    assert r3["messages"] == {"track": [], "partner": []}, r3["messages"]
    assert len(r3["history"]) == 600 and len(r3["history"][-1]) == 1 + 4 + 4 + 8
    errors = couple3.errors(r3["peaks"])
    assert max(abs(e) for e in errors) < 0.01, errors
    r2 = couple3.run(2, jacobi=jacobi, standin_fmu=standin2, record=True)
    assert r2["failure"] is None, r2["failure"]
    assert r3["peaks"] == r2["peaks"]
    worst = max(abs(x - y) for a, b in zip(r3["history"], r2["history"]) for x, y in zip(a, b))
    assert r3["history"] == r2["history"], f"largest difference {worst}"
