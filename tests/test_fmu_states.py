"""FMU tests with fmpy: misuse (calls out of order, unknown references, null pointers,
bad values, the state table, refused functions), reset, FMU states, interleaved
instances and instances on threads. Run by the README's test command (after the FMUs
are built); the helpers are in fmu_helpers.py, the ``paths`` fixture in conftest.py."""

import ctypes
import threading

import pytest

from fmpy.fmi1 import FMICallException

from fmu_helpers import Log, initialised, run_for, unit, wf



# ------------------------------------------------------------------ misuse

def test_calls_out_of_order_are_refused_and_logged(paths):
    log = Log()
    u = unit(paths, "TrackContact", log)
    with pytest.raises(FMICallException):
        u.fmu.doStep(0.0, 1e-5)
    assert log.last()[0] == 3 and "fmi2DoStep is not allowed in state Instantiated" in log.last()[2]
    with pytest.raises(FMICallException):
        u.fmu.exitInitializationMode()
    assert "fmi2ExitInitializationMode" in log.last()[2]
    with pytest.raises(FMICallException):
        u.get("contact.left.force")
    assert "fmi2GetReal is not allowed in state Instantiated" in log.last()[2]
    # still usable
    u.fmu.enterInitializationMode()
    u.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        u.set(["wheel.radius"], [0.5])
    assert "`wheel.radius`" in log.last()[2] and "cannot be set" in log.last()[2]
    u.fmu.doStep(0.0, 1e-5)
    u.close()


def test_unknown_value_reference_and_wrong_type(paths):
    log = Log()
    u = initialised(paths, "RollPlaneVehicle", log)
    with pytest.raises(FMICallException):
        u.fmu.getReal([999999])
    assert "unknown value reference 999999" in log.last()[2]
    # track.spans exists in TrackContact only
    with pytest.raises(FMICallException):
        u.fmu.getInteger([initialised_vr(paths, "track.spans")])
    assert "unknown value reference" in log.last()[2]
    with pytest.raises(FMICallException):
        u.fmu.getInteger([u.vr["speed"]])
    assert "`speed`" in log.last()[2] and "Real" in log.last()[2]
    with pytest.raises(FMICallException):
        u.fmu.getBoolean([0])
    u.close()


def initialised_vr(paths, name):
    from fmpy import read_model_description
    return wf.value_references(read_model_description(paths["TrackContact"]))[name]


def test_null_pointers_are_refused_even_with_zero_count(paths):
    log = Log()
    u = initialised(paths, "TrackContact", log)
    f = u.fmu
    vr = (ctypes.c_uint * 1)(u.vr["contact.left.force"])
    val = (ctypes.c_double * 1)()
    assert f.dll.fmi2GetReal(f.component, None, ctypes.c_size_t(1), val) == 3
    assert "argument `vr` is a null pointer" in log.last()[2]
    assert f.dll.fmi2GetReal(f.component, vr, ctypes.c_size_t(0), None) == 3
    assert "argument `value` is a null pointer (count 0)" in log.last()[2]
    assert f.dll.fmi2SetReal(f.component, vr, ctypes.c_size_t(1), None) == 3
    assert f.dll.fmi2GetFMUstate(f.component, None) == 3
    assert f.dll.fmi2DoStep(None, ctypes.c_double(0.0), ctypes.c_double(1e-5), 1) == 3
    # still usable after all that
    assert f.dll.fmi2GetReal(f.component, vr, ctypes.c_size_t(1), val) == 0
    assert val[0] == pytest.approx(107.66e3, rel=1e-3)
    u.close()


def test_non_finite_and_out_of_range_values(paths):
    log = Log()
    u = unit(paths, "TrackContact", log)
    with pytest.raises(FMICallException):
        u.set(["speed"], [-5.0])
    assert "`speed` = -5 m/s is out of range" in log.last()[2]
    with pytest.raises(FMICallException):
        u.set(["track.pad.stiffness"], [float("nan")])
    assert "`track.pad.stiffness` = NaN" in log.last()[2]
    # An engine-level check: a flat longer than a quarter of the circumference.
    u.set(["flat.left[2].length"], [0.9])
    u.fmu.enterInitializationMode()
    with pytest.raises(FMICallException):
        u.fmu.exitInitializationMode()
    assert "flat.left[2].length" in log.last()[2] and "quarter of the circumference" in log.last()[2]
    u.set(["flat.left[2].length"], [0.0])
    # An unstable step names the limit.
    u.set(["solver.dt"], [1e-4])
    with pytest.raises(FMICallException):
        u.fmu.exitInitializationMode()
    assert "exceeds the critical step" in log.last()[2]
    u.set(["solver.dt"], [0.0])
    u.fmu.exitInitializationMode()
    with pytest.raises(FMICallException):
        u.set(["wheel.left.z"], [float("inf")])
    assert "`wheel.left.z` = inf" in log.last()[2]
    with pytest.raises(FMICallException):
        u.fmu.doStep(0.0, float("nan"))
    assert "communicationStepSize = NaN" in log.last()[2]
    with pytest.raises(FMICallException):
        u.fmu.doStep(0.0, -1e-5)
    u.fmu.doStep(0.0, 1e-5)  # usable
    u.close()


def test_step_off_the_track_is_discarded_and_terminates(paths):
    log = Log()
    # The thesis' fixed 30-span track (the default is the endless one).
    u = initialised(paths, "CoupledSystem", log, params={"track.window.ahead": 0.0})
    u.fmu.doStep(0.0, 0.01)
    f = u.fmu
    status = f.dll.fmi2DoStep(f.component, ctypes.c_double(0.01), ctypes.c_double(5.0), 1)
    assert status == 2  # fmi2Discard
    # The fixed track's running length ends at its last sleeper but one, 29 spans.
    assert "outside the track's running length (0, 19.865" in log.last()[2], log.last()[2]
    terminated = ctypes.c_int(0)
    assert f.dll.fmi2GetBooleanStatus(f.component, 3, ctypes.byref(terminated)) == 0
    assert terminated.value == 1
    last = ctypes.c_double(-1)
    assert f.dll.fmi2GetRealStatus(f.component, 2, ctypes.byref(last)) == 0
    assert last.value == pytest.approx(0.01)
    # the state is intact: outputs can be read and the run terminated cleanly; the
    # track stands at its grid point nearest t = 0.01 s
    dt = u.get("solver.step")[0]
    k = round(0.01 / dt)
    assert abs(k * dt - 0.01) <= 0.5 * dt
    assert u.get("position")[0] == pytest.approx(1.37 + k * dt * 70 / 3.6, rel=1e-12)
    # stepFailed (FMI 2.0): no further step, each refusal says why
    for h in (1e-5, 5.0):
        assert f.dll.fmi2DoStep(f.component, ctypes.c_double(0.01), ctypes.c_double(h), 1) == 3
        assert log.last()[2].startswith("fmi2DoStep is not allowed in state StepFailed")
        assert "the model ended the run at t = 0.01 s" in log.last()[2] and "fmi2Reset" in log.last()[2]
    assert u.get("position")[0] == pytest.approx(1.37 + k * dt * 70 / 3.6, rel=1e-12)
    u.close()  # fmi2Terminate is allowed after the failed step


def test_terminate_and_status_follow_the_state_table(paths):
    log = Log()
    u = unit(paths, "TrackContact", log)
    f = u.fmu
    x, b = ctypes.c_double(), ctypes.c_int()
    assert f.dll.fmi2GetRealStatus(f.component, 2, ctypes.byref(x)) == 3
    assert log.last()[2].startswith("fmi2GetRealStatus is not allowed in state Instantiated")
    f.setupExperiment(startTime=0.0)
    f.enterInitializationMode()
    assert f.dll.fmi2GetBooleanStatus(f.component, 3, ctypes.byref(b)) == 3
    assert log.last()[2].startswith("fmi2GetBooleanStatus is not allowed in state Initialization")
    with pytest.raises(FMICallException):
        f.terminate()
    assert log.last()[2] == ("fmi2Terminate is not allowed in state Initialization; "
                             "allowed in: StepComplete, StepFailed")
    f.exitInitializationMode()
    f.doStep(0.0, 1e-5)
    f.terminate()
    with pytest.raises(FMICallException):
        f.terminate()
    assert log.last()[2].startswith("fmi2Terminate is not allowed in state Terminated")
    assert f.dll.fmi2GetBooleanStatus(f.component, 3, ctypes.byref(b)) == 0 and b.value == 0
    u.close(terminate=False)


def test_booleans_other_than_0_and_1_are_refused(paths):
    log = Log()
    u = initialised(paths, "TrackContact", log)
    f = u.fmu
    assert f.dll.fmi2SetDebugLogging(f.component, 2, ctypes.c_size_t(0), None) == 3
    assert log.last()[2] == ("fmi2SetDebugLogging: argument `loggingOn` = 2 is not an fmi2Boolean; "
                             "allowed: fmi2True (1) or fmi2False (0)")
    assert f.dll.fmi2DoStep(f.component, ctypes.c_double(0.0), ctypes.c_double(1e-5), -1) == 3
    assert "argument `noSetFMUStatePriorToCurrentPoint` = -1" in log.last()[2]
    u.fmu.doStep(0.0, 1e-5)
    u.close()


def test_fmu_states_are_used_only_by_their_instance(paths):
    log_a, log_b = Log(), Log()
    a = initialised(paths, "TrackContact", log_a)
    b = unit(paths, "TrackContact", log_b, instance="b")
    a.fmu.doStep(0.0, 1e-3)
    s = a.fmu.getFMUstate()
    with pytest.raises(FMICallException):
        b.fmu.setFMUstate(s)
    assert log_b.last()[2].startswith("fmi2SetFMUstate: argument `FMUstate`")
    assert "is not an FMU state of this instance" in log_b.last()[2]
    copy = ctypes.c_void_p(s.value)
    assert b.fmu.dll.fmi2FreeFMUstate(b.fmu.component, ctypes.byref(copy)) == 3
    assert copy.value == s.value
    a.fmu.setFMUstate(s)  # still a's
    assert a.fmu.dll.fmi2FreeFMUstate(a.fmu.component, ctypes.byref(copy)) == 0
    assert copy.value is None
    again = ctypes.c_void_p(s.value)  # a second free of the same state
    assert a.fmu.dll.fmi2FreeFMUstate(a.fmu.component, ctypes.byref(again)) == 3
    assert "is not an FMU state of this instance" in log_a.last()[2]
    assert a.fmu.dll.fmi2SetFMUstate(a.fmu.component, s) == 3
    a.fmu.doStep(1e-3, 1e-3)
    kept = a.fmu.getFMUstate()  # left for fmi2FreeInstance
    assert kept.value
    a.close()
    b.close(terminate=False)


def test_unsupported_functions_return_error_with_reason(paths):
    log = Log()
    u = initialised(paths, "TrackContact", log)
    f = u.fmu
    assert f.dll.fmi2CancelStep(f.component) == 3
    assert "fmi2CancelStep is not supported" in log.last()[2]
    u.close()
    # The derivative functions an FMU does not declare, before their arguments are read.
    v = initialised(paths, "RollPlaneVehicle", log)
    f = v.fmu
    assert f.dll.fmi2GetDirectionalDerivative(f.component, None, 0, None, 0, None, None) == 3
    assert "providesDirectionalDerivative is false" in log.last()[2]
    assert f.dll.fmi2SetRealInputDerivatives(f.component, None, 0, None, None) == 3
    assert "canInterpolateInputs is false" in log.last()[2]
    v.close()


def test_setup_experiment_logs_no_undefined_stop_time(paths):
    log = Log()
    u = wf.Unit(paths["CoupledSystem"], "u", callbacks=log.callbacks, logging_on=True)
    u.fmu.setDebugLogging(True, ["logCalls"])
    u.fmu.setupExperiment(startTime=0.0)
    assert "stopTime undefined" in log.text() and "stopTime=0" not in log.text(), log.text()
    u.close(terminate=False)


# ------------------------------------------------------------------ reset, states, instances


def test_reset_then_rerun_gives_identical_results(paths):
    u = initialised(paths, "CoupledSystem", params={"speed": 25.0})
    a = run_for(u, 0.0, 2500)
    u.fmu.reset()
    u.fmu.setupExperiment(startTime=0.0)
    u.set_parameters({"speed": 25.0})
    u.fmu.enterInitializationMode()
    u.fmu.exitInitializationMode()
    b = run_for(u, 0.0, 2500)
    u.close()
    assert a == b
    assert max(x[0] for x in a) > 200e3


@pytest.mark.parametrize("name", ["CoupledSystem", "TrackContact", "RollPlaneVehicle", "HalfCarBogie", "Wagon"])
def test_state_restore_and_serialisation_continue_bit_identically(paths, name):
    u = initialised(paths, name)
    inputs = {"TrackContact": ("wheel.left.z", -1.3e-3), "RollPlaneVehicle": ("contact.left.force", 150e3),
              "HalfCarBogie": ("wheelset[2].contact.left.force", 150e3),
              "Wagon": ("wheelset[4].contact.left.force", 150e3), "CoupledSystem": None}[name]
    if inputs:
        u.set([inputs[0]], [inputs[1]])
    outs = {"TrackContact": ("contact.left.force", "rail.left.z"),
            "RollPlaneVehicle": ("wheel.left.z", "bolster.z"),
            "HalfCarBogie": ("wheelset[2].wheel.left.z", "sideframe.left.pitch"),
            "Wagon": ("wheelset[4].wheel.left.z", "carbody.pitch"),
            "CoupledSystem": ("contact.left.force", "wheel.right.z")}[name]
    run_for(u, 0.0, 1500, names=outs)  # into the first impact
    t = 1500 * 2e-5
    state = u.fmu.getFMUstate()
    blob = u.fmu.serializeFMUstate(state)
    first = run_for(u, t, 800, names=outs)
    u.fmu.setFMUstate(state)
    second = run_for(u, t, 800, names=outs)
    restored = u.fmu.deSerializeFMUstate(blob)
    u.fmu.setFMUstate(restored)
    third = run_for(u, t, 800, names=outs)
    u.fmu.freeFMUstate(state)
    u.fmu.freeFMUstate(restored)
    # a fresh instance from the serialised bytes
    v = unit(paths, name, instance="other")
    s = v.fmu.deSerializeFMUstate(blob)
    v.fmu.setFMUstate(s)
    fourth = run_for(v, t, 800, names=outs)
    v.fmu.freeFMUstate(s)
    v.close()
    u.close()
    assert first == second == third == fourth
    assert len(set(x[0] for x in first)) > 100  # the continuation is not trivial


def test_interleaved_instances_give_what_each_gives_alone(paths):
    params = [{"speed": 20.0}, {"speed": 15.0, "flat.left[1].depth": 0.001}]
    alone = []
    for p in params:
        u = initialised(paths, "CoupledSystem", params=p)
        alone.append(run_for(u, 0.0, 2000))
        u.close()
    a = initialised(paths, "CoupledSystem", params=params[0])
    b = wf.Unit(paths["CoupledSystem"], "b")
    b.fmu.setupExperiment(startTime=0.0)
    b.set_parameters(params[1])
    b.fmu.enterInitializationMode()
    b.fmu.exitInitializationMode()
    ra, rb = [], []
    for k in range(2000):
        ra += run_for(a, k * 2e-5, 1)
        rb += run_for(b, k * 2e-5, 1)
    a.close()
    b.close()
    assert ra == alone[0] and rb == alone[1]
    assert ra != rb


def test_instances_on_threads_give_what_each_gives_alone(paths):
    params = [{"speed": 20.0 + 2 * i} for i in range(4)]
    alone = []
    for p in params:
        u = initialised(paths, "CoupledSystem", params=p)
        alone.append(run_for(u, 0.0, 1500))
        u.close()
    results = [None] * len(params)
    # One extracted FMU: every thread's instance lives in the same loaded library.
    from fmpy import extract
    shared = extract(paths["CoupledSystem"])

    def work(i):
        u = wf.Unit(paths["CoupledSystem"], f"t{i}", unzip_dir=shared)
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters(params[i])
        u.fmu.enterInitializationMode()
        u.fmu.exitInitializationMode()
        results[i] = run_for(u, 0.0, 1500)
        u.close()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(len(params))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert results == alone
