"""The FMI 3.0 units (fmu/fmi3/*.fmu) through fmpy: they pass fmpy's validation and equal
the FMI 2.0 units bit for bit on the reference cases, their arrays of wheelsets element
by element, Enumerations set as Int64, FMU states serialized and restored."""

import os

import numpy as np
import pytest
from fmu_helpers import wf

import wheelflat_fmi3 as w3


@pytest.fixture(scope="module")
def paths3(paths):
    return w3.paths3()


@pytest.fixture(scope="module")
def paths2(paths):
    return {n: os.path.join(wf.FMU_DIR, n + ".fmu") for n in wf.registry()["fmus"]}


def test_every_fmi3_unit_passes_fmpys_validation_and_declares_fmi_3(paths3):
    from fmpy import read_model_description
    from fmpy.validation import validate_fmu
    for name, path in paths3.items():
        assert validate_fmu(path) == [], name
        md = read_model_description(path)
        assert md.fmiVersion == "3.0" and md.coSimulation.modelIdentifier == name
        arrays = [v for v in md.modelVariables if v.dimensions]
        assert arrays, name
        # Every array is sized by wheelsets, which is a structural parameter where the
        # FMU carries any number of wheelsets, else a constant.
        wheelsets = next(v for v in md.modelVariables if v.name == "wheelsets")
        assert all(d.valueReference == wheelsets.valueReference for v in arrays for d in v.dimensions)
        expect = "structuralParameter" if name in ("TrackContact", "CoupledSystem") else "local"
        assert (wheelsets.type, wheelsets.causality) == ("UInt64", expect), name


def test_coupled_system_equals_its_fmi2_unit_bit_for_bit_in_fmpys_simulate(paths2, paths3):
    from fmpy import simulate_fmu
    kw = dict(stop_time=0.15, output_interval=1e-3)
    r2 = simulate_fmu(paths2["CoupledSystem"], **kw)
    r3 = simulate_fmu(paths3["CoupledSystem"], **kw)
    common = [n for n in r3.dtype.names if n in r2.dtype.names and n != "time"]
    # Every output of the FMI 3.0 unit: a scalar of the FMI 2.0 unit or the leading
    # wheelset's element of an array.
    assert len(common) == len(r3.dtype.names) - 1 > 400
    for n in common:
        a, b = np.asarray(r2[n], dtype=float).ravel(), np.asarray(r3[n], dtype=float).ravel()
        assert np.array_equal(a, b), n
    # The impact is in it: the reference flat's peak, far above the static load.
    assert r3["contact.left.max_force"][-1] > 1.5 * r3["contact.left.force"][0]


@pytest.mark.parametrize("model,n", [("RollPlaneVehicle", 1), ("HalfCarBogie", 2), ("Wagon", 4)])
def test_track_and_vehicle_exchange_arrays_as_the_fmi2_units_exchange_scalars(paths2, paths3, model, n):
    stop = 0.06
    r2, r3 = [], []
    if n == 1:
        out = wf.run_pair(paths2, stop)
        r2 = [[t, x, y] for t, x, y in zip(out["time"], out["contact.left.force"], out["contact.right.force"])]
    else:
        wf.run_carrier(paths2, model, n, stop, record=r2)
    w3.run_carrier(paths3, model, n, stop, record=r3)
    # FMI 2.0 records each wheelset's left and right, FMI 3.0 the left array, then the right.
    r3 = [[row[0]] + [x for k in range(n) for x in (row[1 + k], row[1 + n + k])] for row in r3]
    assert len(r3) == len(r2) > 1000
    assert r3 == r2


def test_enumerations_and_strings_set_through_fmi3_give_the_fmi2_units_run(paths2, paths3):
    """TrackContact alone, its inputs held: the Hertz law (an Enumeration, Int64) and a
    measured out-of-roundness of the second wheelset's left wheel (a String array's
    element) on two wheelsets."""
    table = "0 0\n3.0 -2e-4\n3.2 0\n6.28 0"
    t2 = wf.Unit(paths2["TrackContact"], "t2")
    t3 = w3.Unit3(paths3["TrackContact"], "t3")
    try:
        t2.fmu.setupExperiment(startTime=0.0)
        t2.set_parameters({"wheelsets": 2, "contact.model": 2, "wheelset[2].wheel.left.out_of_roundness": table})
        t3.set_parameters({"wheelsets": 2, "contact.model": 2, "wheel.left.out_of_roundness": ["", table]})
        t2.fmu.enterInitializationMode()
        t3.fmu.enterInitializationMode(startTime=0.0)
        assert t3.fmu.getInt64([t3.vr["contact.model"]]) == [2]
        t2.fmu.exitInitializationMode()
        t3.fmu.exitInitializationMode()
        names = ("contact.left.force", "contact.right.force")
        for k in range(400):
            t2.fmu.doStep(k * 1e-4, 1e-4)
            t3.do_step(k * 1e-4, 1e-4)
        two = t2.get(*names, *wf.trailing(2, names))
        three = t3.get(*names)
        assert three == [two[0], two[2], two[1], two[3]]
        assert t3.fmu.getString([t3.vr["wheel.left.out_of_roundness"]], 2) == ["", table]
    finally:
        w3.close_all(t2, t3)


def test_a_serialized_fmi3_state_restores_in_a_fresh_instance_and_continues_bit_for_bit(paths3):
    a = w3.Unit3(paths3["CoupledSystem"], "a")
    b = w3.Unit3(paths3["CoupledSystem"], "b")
    try:
        a.configure(2)
        a.fmu.enterInitializationMode(startTime=0.0)
        a.fmu.exitInitializationMode()
        for k in range(50):
            a.do_step(k * 1e-3, 1e-3)
        state = a.fmu.getFMUState()
        data = a.fmu.serializeFMUState(state)
        a.fmu.freeFMUState(state)
        restored = b.fmu.deserializeFMUState(data)
        b.fmu.setFMUState(restored)
        b.fmu.freeFMUState(restored)
        assert b.fmu.getUInt64([b.vr["wheelsets"]]) == [2]
        b.wheelsets = 2
        for u in (a, b):
            u.do_step(0.05, 1e-3)
        names = ("contact.left.force", "contact.left.max_force", "wheel.left.z")
        assert a.get(*names) == b.get(*names)
        assert len(a.get(*names)) == 6
    finally:
        w3.close_all(a, b)


def test_a_refusal_names_the_call_the_variable_and_the_allowed_values_in_fmi3_terms(paths3):
    from fmpy.fmi1 import FMICallException
    records = []

    def log(env, status, category, message):
        records.append(message.decode())

    t = w3.Unit3(paths3["TrackContact"], "t", log_message=log)
    try:
        with pytest.raises(FMICallException):
            t.fmu.setUInt64([t.vr["wheelsets"]], [2])
        t.configure(2)
        t.fmu.enterInitializationMode(startTime=0.0)
        with pytest.raises(FMICallException):
            t.fmu.setFloat64([t.vr["wheel.left.z"]], [0.0, 0.5])
        with pytest.raises(FMICallException):
            t.fmu.setFloat64([t.vr["wheel.left.z"]], [0.0])
    finally:
        t.close(terminate=False)
    text = "\n".join(records)
    assert "fmi3SetUInt64 is not allowed in state Instantiated" in text and "ConfigurationMode" in text
    assert "fmi3SetFloat64: `wheel.left.z[2]` = 0.5" in text, text
    assert "nValues = 1" in text and "wheelsets = 2" in text
    assert "fmi2" not in text, text


def test_early_return_through_fmpy_stops_at_each_loss_and_regain_of_contact_and_keeps_the_bits(paths3):
    """CoupledSystem instantiated with earlyReturnAllowed, 20 ms communication steps over
    0.3 s: the steps end early where the flat lifts the wheel and where it hits the rail
    again (each turn, 0.153 s at 70 km/h), on the engine's grid, and the run ends where
    the same run without early return ends, bit for bit."""
    names = ("contact.left.max_force", "contact.left.force", "wheel.left.z", "position")
    results, stops = [], []
    for early in (False, True):
        u = w3.Unit3(paths3["CoupledSystem"], "cs", early_return=early)
        try:
            u.initialize(stop_time=0.3)
            u.fmu.exitInitializationMode()
            h_engine = u.get("solver.step")[0]
            t = 0.0
            while t < 0.3 - 1e-12:
                terminate, returned_early, last = u.do_step(t, min(0.02, 0.3 - t))
                assert not terminate
                if returned_early:
                    assert last < t + 0.02 and abs(last / h_engine - round(last / h_engine)) < 1e-6
                    stops.append(last)
                t = last
            results.append(u.get(*names))
        finally:
            u.close()
    assert results[0] == results[1]
    # Two turns of the wheel: each loses contact and hits once.
    assert len(stops) == 4, stops
    assert 0.03 < stops[0] < stops[1] < 0.05 and 0.18 < stops[2] < stops[3] < 0.2, stops
