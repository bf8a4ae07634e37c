"""FMU tests with fmpy: directional, input and output derivatives, and the warnings a
step returns (the axle-box exchange's step, a vehicle not carried at rest). Run by the
README's test command (after the FMUs are built); the helpers are in fmu_helpers.py, the
``paths`` fixture in conftest.py."""

import pytest

from fmpy.fmi1 import FMICallException

from fmu_helpers import Log, initialised, run_for, wf



# ------------------------------------------------------------------ derivatives (issue 16)

def test_the_directional_derivative_is_the_contact_stiffness_of_the_law(paths):
    # fmi2GetDirectionalDerivative of the contact forces with respect to the wheel
    # heights against a central difference of TrackContact's direct feedthrough, at
    # rest and as the flat passes the contact (partial contact): within 1e-6.
    t = initialised(paths, "TrackContact")
    force = [t.vr[n] for n in ("contact.left.force", "contact.right.force")]
    z = [t.vr[n] for n in ("wheel.left.z", "wheel.right.z")]
    checked = []
    # (The first inputs stand for the static state until the first step, inputs.datum
    # = first_step: from k = 1 on the forces follow the heights.)
    for k in range(2600):
        if k in (1, 2000, 2080, 2160, 2240):
            z0 = t.get("wheel.left.z", "wheel.right.z")
            p0 = t.get("contact.left.force")[0]
            exact = t.fmu.getDirectionalDerivative(force, [z[0]], [1.0])
            e = 1e-8
            t.set(["wheel.left.z"], [z0[0] + e])
            up = t.get("contact.left.force", "contact.right.force")
            t.set(["wheel.left.z"], [z0[0] - e])
            down = t.get("contact.left.force", "contact.right.force")
            t.set(["wheel.left.z"], [z0[0]])
            fd = (up[0] - down[0]) / (2 * e)
            if p0 > 0:
                assert exact[0] == pytest.approx(fd, rel=1e-6), (k, exact, fd)
                assert exact[0] < -1e8
                checked.append(exact[0])
            assert exact[1] == 0.0 and up[1] == down[1]
            # Seeds are linear: both wheels at once.
            both = t.fmu.getDirectionalDerivative(force, z, [2.0, -1.0])
            right = t.fmu.getDirectionalDerivative([force[1]], [z[1]], [1.0])[0]
            assert both[0] == pytest.approx(2 * exact[0], rel=1e-15)
            assert both[1] == pytest.approx(-right, rel=1e-15)
        t.fmu.doStep(k * 2e-5, 2e-5)
    # Contact stiffness varies as the flat passes (partial contact is softer).
    assert len(checked) >= 4 and max(checked) > 1.05 * min(checked), checked
    t.close()


def test_derivatives_are_refused_where_not_declared_and_for_wrong_orders(paths):
    log = Log()
    t = wf.Unit(paths["TrackContact"], "t", callbacks=log.callbacks)
    t.fmu.setupExperiment(startTime=0.0)
    t.fmu.enterInitializationMode()
    t.fmu.exitInitializationMode()
    z = t.vr["wheel.left.z"]
    with pytest.raises(FMICallException):
        t.fmu.setRealInputDerivatives([z], [0], [1.0])
    assert "order 0; allowed: 1 or more" in log.text()
    with pytest.raises(FMICallException):
        t.fmu.setRealInputDerivatives([t.vr["wheel.rotation"]], [2], [1.0])
    assert "derivative order of wheel.rotation" in log.text()
    with pytest.raises(FMICallException):
        t.fmu.setRealInputDerivatives([t.vr["contact.left.force"]], [1], [1.0])
    assert "is not a Real input of TrackContact" in log.text()
    with pytest.raises(FMICallException):
        t.fmu.setRealInputDerivatives([z], [1], [float("nan")])
    with pytest.raises(FMICallException):
        t.fmu.getRealOutputDerivatives([t.vr["contact.left.force"]], [1])
    assert "maxOutputDerivativeOrder is 0" in log.text()
    t.close()
    v = initialised(paths, "RollPlaneVehicle", log)
    with pytest.raises(FMICallException):
        v.fmu.getDirectionalDerivative([v.vr["wheel.left.z"]], [v.vr["contact.left.force"]], [1.0])
    assert "providesDirectionalDerivative is false" in log.text()
    with pytest.raises(FMICallException):
        v.fmu.getRealOutputDerivatives([v.vr["wheel.left.z"]], [2])
    assert "allowed: 1 to 1" in log.text()
    v.close()


def test_output_derivatives_are_the_vehicles_velocities(paths):
    # RollPlaneVehicle's wheel velocity after a step of its own base step is the
    # backward difference over that step; the axle's rate is speed / radius.
    v = initialised(paths, "RollPlaneVehicle")
    h = v.get("solver.step")[0]
    v.set(["contact.left.force"], [150e3])
    vrs = [v.vr[n] for n in ("wheel.left.z", "wheel.rotation", "sideframe.left.z")]
    for k in range(20):
        z0 = v.get("wheel.left.z")[0]
        v.fmu.doStep(k * h, h)
        z1 = v.get("wheel.left.z")[0]
        d = v.fmu.getRealOutputDerivatives(vrs, [1, 1, 1])
        assert d[0] == pytest.approx((z1 - z0) / h, rel=1e-9, abs=1e-15)
        assert d[1] == pytest.approx(v.get("speed")[0] / v.get("wheel.radius")[0], rel=1e-15)
        assert d[2] == v.get("sideframe.left.v")[0]
    assert d[0] != 0.0
    v.close()


def test_input_derivatives_reduce_the_error_at_five_and_ten_times_the_step(paths):
    # The pair at 5 and 10 times the track's step, the wheel inputs held or moved
    # along the vehicle's wheel velocities: the peak error against the track's own
    # step falls from +4.2 % (5x) and +12.1 % to +3.3 % (10x) (measured with the rail
    # between nodes as a beam; +5.5 % to +0.7 % and +12.2 % to +2.9 % with (3.23), the
    # table in docs/guide/couple-a-vehicle.md).
    def peak(mult, derivs):
        h = mult * wf.track_step(paths)
        out = wf.run_pair(paths, 0.3, h, input_derivatives=derivs)
        return out["contact.left.max_force"][-1]
    ref = peak(1, False)
    assert ref == pytest.approx(301.87e3, rel=1e-3)  # the reference run's peak
    for mult, held_at_least, ratio in [(5, 0.035, 0.2), (10, 0.10, 0.3)]:
        held = peak(mult, False) / ref - 1
        moved = peak(mult, True) / ref - 1
        assert held > held_at_least, (mult, held)
        assert abs(moved) < ratio * held, (mult, held, moved)


def test_input_derivatives_in_initialization_are_checked_kept_and_restored(paths):
    # Set in initialization mode, derivatives are checked at once (all or none), kept
    # when a parameter set afterwards rebuilds the model, and an FMU state saved then
    # continues bit for bit.
    log = Log()
    t = wf.Unit(paths["TrackContact"], "t", callbacks=log.callbacks)
    t.fmu.setupExperiment(startTime=0.0)
    with pytest.raises(FMICallException):  # not in Instantiated (FMI 2.0 state table)
        t.fmu.setRealInputDerivatives([t.vr["wheel.left.z"]], [1], [-0.01])
    t.fmu.enterInitializationMode()
    z = t.vr["wheel.left.z"]
    for order, value, said in [(1, float("nan"), "d^1/dt^1 wheel.left.z"), (3, 1.0, "derivative order of wheel.left.z")]:
        with pytest.raises(FMICallException):
            t.fmu.setRealInputDerivatives([z], [order], [value])
        assert said in log.text()
    # A wheelset the model does not have is checked too.
    with pytest.raises(FMICallException):
        t.fmu.setRealInputDerivatives([t.vr["wheelset[2].wheel.left.z"]], [3], [1.0])
    t.fmu.setRealInputDerivatives([z], [1], [-0.01])
    t.set(["static_load.left", "static_load.right"], [107664.75, 107664.75])  # rebuilds
    s = t.fmu.getFMUstate()
    blob = t.fmu.serializeFMUstate(s)
    t.fmu.exitInitializationMode()
    a = run_for(t, 0.0, 100)
    t.fmu.setFMUstate(s)
    t.fmu.exitInitializationMode()
    b = run_for(t, 0.0, 100)
    u = wf.Unit(paths["TrackContact"], "u")
    r = u.fmu.deSerializeFMUstate(blob)
    u.fmu.setFMUstate(r)
    u.fmu.exitInitializationMode()
    c = run_for(u, 0.0, 100)
    plain = initialised(paths, "TrackContact")
    d = run_for(plain, 0.0, 100)
    assert a == b == c
    assert a[-1][0] > d[-1][0] + 1e3  # the wheel moved down 20 um: a larger force (+2.3 kN)
    for x in (t, u, plain):
        x.close()


def test_setting_one_wheel_leaves_the_other_moving(paths):
    t = initialised(paths, "TrackContact")
    t.fmu.setRealInputDerivatives([t.vr["wheel.left.z"]], [1], [-0.002])
    run_for(t, 0.0, 100)
    before = t.get("contact.left.force", "contact.left.overlap")
    t.set(["wheel.right.z"], t.get("wheel.right.z"))
    after = t.get("contact.left.force", "contact.left.overlap")
    assert before == after
    # A seed that overflows is refused, not returned as inf.
    with pytest.raises(FMICallException):
        t.fmu.getDirectionalDerivative([t.vr["contact.left.force"]], [t.vr["wheel.left.z"]], [1e308])
    t.close()


def step_status(u, t, h):
    """fmi2DoStep's status (fmpy's doStep returns nothing; it raises above fmi2Warning)."""
    return u.fmu.fmi2DoStep(u.fmu.component, t, h, 1)


def test_a_bogie_step_beyond_the_axle_box_limit_is_warned(paths):
    # The half-car's estimated Jacobi limit with table 4.4 is 2.74 ms (sequential 20 ms):
    # 1 ms and 2 ms pass, 5 ms is warned of with fmi2Warning (issue 24).
    log = Log()
    b = wf.Unit(paths["HalfCarBogie"], "b", callbacks=log.callbacks)
    b.fmu.setupExperiment(startTime=0.0)
    b.set_parameters({"interface": 2})
    b.fmu.enterInitializationMode()
    b.fmu.exitInitializationMode()
    assert step_status(b, 0.0, 1e-3) == 0
    assert step_status(b, 1e-3, 2e-3) == 0
    assert "axle-box exchange" not in log.text()
    assert step_status(b, 3e-3, 5e-3) == 1
    assert "is above 0.0027" in log.text() and "0.020" in log.text(), log.text()
    b.close()


@pytest.mark.parametrize("vehicle", ["RollPlaneVehicle", "HalfCarBogie"])
@pytest.mark.parametrize("primary, warned", [
    ({}, False),
    # The thesis' chapter-5 stiffness: the springs alone limit the exchange (Jacobi
    # 0.41 ms roll-plane, 0.25 ms half-car; sequential 1.55 and 1.16 ms).
    ({"vehicle.primary.stiffness": 7.88e8}, True),
    # No primary damping: the springs exchanged explicitly (Jacobi 0.96 and 0.19 ms).
    ({"vehicle.primary.damping": 0.0}, True),
])
def test_the_axle_box_step_estimate_covers_the_primary_springs_and_dampers(paths, vehicle, primary, warned):
    log = Log()
    b = wf.Unit(paths[vehicle], "b", callbacks=log.callbacks)
    b.fmu.setupExperiment(startTime=0.0)
    b.set_parameters(dict(primary, interface=2))
    b.fmu.enterInitializationMode()
    b.fmu.exitInitializationMode()
    status = [step_status(b, k * 1e-3, 1e-3) for k in range(3)]
    if warned:
        # The first step beyond the estimate returns fmi2Warning with the message; the
        # steps after it, the same step beyond the same estimate, return fmi2OK and log
        # nothing (issue 38: a warning at every step stopped C fmusim, PyFMI and
        # OMSimulator).
        assert status == [1, 0, 0], status
        text = log.text()
        assert text.count("axle-box exchange stays stable") == 1 and "still" not in text, text
    else:
        assert status == [0, 0, 0] and "axle-box" not in log.text(), log.text()
    b.close()


@pytest.mark.parametrize("interface", [1, 2])
def test_a_vehicle_its_partner_does_not_carry_at_rest_is_warned_of(paths, interface):
    # The new user's heavier bogie (a 30 t car body: 155,979 N per wheel) on a track that
    # carries the default 107,664.75 N: the forces that drive the first step are a
    # third off its forces at rest, and the message names TrackContact's static_load.
    log = Log()
    b = wf.Unit(paths["HalfCarBogie"], "b", callbacks=log.callbacks)
    b.fmu.setupExperiment(startTime=0.0)
    b.set_parameters({"interface": interface, "vehicle.carbody_mass": 30000.0})
    b.fmu.enterInitializationMode()
    # What a track with the default static load hands it at rest: contact forces of
    # 107,664.75 N, or primary forces of 102,171.15 N (less the wheelset's weight).
    inputs = ["contact.left.force", "contact.right.force"] if interface == 1 else \
        ["axle_box.left.force", "axle_box.right.force"]
    inputs += ["wheelset[2]." + n for n in inputs]
    b.set(inputs, [107664.75 if interface == 1 else 102171.15] * 4)
    b.fmu.exitInitializationMode()
    load = b.get("static_load.left")[0]
    assert load == pytest.approx(155979, abs=1)
    assert step_status(b, 0.0, 1e-3) == 1
    assert f"static_load.left = {load:g} N" in log.text() and "off the" in log.text(), log.text()
    assert step_status(b, 1e-3, 1e-3) == 0
    b.close()
    # Carried at rest: no warning.
    log = Log()
    b = initialised(paths, "HalfCarBogie", log=log, params={"interface": interface})
    assert step_status(b, 0.0, 1e-3) == 0 and "static_load" not in log.text()
    b.close()

# ------------------------------------------------------------------ issue 25

@pytest.mark.parametrize("name", ["RollPlaneVehicle", "HalfCarBogie", "Wagon"])
def test_every_real_output_of_the_vehicles_has_its_first_derivative(paths, name):
    # Issue 25: maxOutputDerivativeOrder = 1 is declared without restriction, so every
    # Real output answers: the rate over the next substep under the held inputs, which a
    # step of one substep then shows; the extremes are piecewise constant (0).
    from fmpy import read_model_description
    md = read_model_description(paths[name])
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    u = initialised(paths, name)
    dt = u.get("solver.step")[0]
    forces = [v.name for v in md.modelVariables if v.causality == "input" and v.name.endswith("contact.left.force")]
    u.set(forces, [1.3e5] * len(forces))
    t = 0.0
    for _ in range(20):
        u.fmu.doStep(t, dt)
        t += dt
    vrs = [v.valueReference for v in outputs]
    rates = u.fmu.getRealOutputDerivatives(vrs, [1] * len(vrs))
    before = u.fmu.getReal(vrs)
    u.fmu.doStep(t, dt)
    after = u.fmu.getReal(vrs)
    moving = 0
    for v, r, a, b in zip(outputs, rates, before, after):
        if v.name.endswith("max_force") or v.name.endswith("min_force"):
            assert r == 0.0, v.name
            continue
        if v.name in ("wheel.left.z", "wheel.right.z") or ".wheel." in v.name or "sideframe" in v.name and v.name.endswith(".z"):
            continue  # backward differences over the last substep (documented)
        assert r == pytest.approx((b - a) / dt, rel=1e-9, abs=1e-9), v.name
        moving += abs(r) > 1e-9
    assert moving >= 4, moving
    u.close()


def test_every_declared_directional_derivative_is_answered_and_the_rest_is_zero(paths):
    # Issue 25: 80 declared pairs (front/rear angle, length, extremes) were refused and
    # undeclared pairs refused instead of 0. Against a central difference of the
    # feedthrough, at rest and as the flat passes the contact (partial contact).
    from fmpy import read_model_description
    md = read_model_description(paths["TrackContact"])
    index = {i + 1: v for i, v in enumerate(md.modelVariables)}
    declared = {}
    for u in md.outputs:
        declared[u.variable.name] = {d.name for d in (u.dependencies or [])}
    t = initialised(paths, "TrackContact")
    h = t.get("solver.step")[0]
    knowns = ["wheel.left.z", "wheel.right.z", "wheel.rotation"]
    reals = [v.name for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    answered = 0
    for k in range(2161):
        if k in (1, 2160):
            z0 = t.get(*knowns)
            for known, e in zip(knowns, (1e-9, 1e-9, 1e-7)):
                i = knowns.index(known)
                t.set([known], [z0[i] + e])
                up = t.get(*reals)
                t.set([known], [z0[i] - e])
                down = t.get(*reals)
                t.set([known], [z0[i]])
                exact = t.fmu.getDirectionalDerivative([t.vr[n] for n in reals], [t.vr[known]], [1.0])
                for name, d, a, b in zip(reals, exact, up, down):
                    fd = (a - b) / (2 * e)
                    if known in declared.get(name, set()):
                        assert d == pytest.approx(fd, rel=1e-3, abs=1e-3 * max(1.0, abs(fd))), (k, name, known, d, fd)
                        answered += 1
                    else:
                        assert d == 0.0 and abs(fd) < 1e-6 * max(1.0, abs(a)), (k, name, known, d, fd)
        t.fmu.doStep(k * h, h)
    # The declared pairs of wheelset 1 at each of the two points: per wheel force, front
    # and rear angle, length, max and min, the overlap and the rail under the wheel
    # against its height and the rotation (16: the overlap and the rail follow the
    # rotation through the force and the rail's shear kink under it); and (issue 27)
    # the wheel's acceleration against its height, the rail's under it against the
    # height and the rotation: 19.
    assert answered == 2 * 2 * 19, answered
    t.close()
    # At the axle boxes the primary forces follow their side frame at once: -K_1, -C_1.
    t = initialised(paths, "TrackContact", params={"interface": 2})
    frames = ["sideframe.left.z", "sideframe.right.z"]
    t.set(frames, t.get(*frames))      # given, so they follow from the first step on
    t.fmu.doStep(0.0, 1e-3)
    f = [t.vr[n] for n in ("primary.left.force", "primary.left.mean_force", "primary.right.force")]
    for known, expected in (("sideframe.left.z", -6.5e6), ("sideframe.left.v", -1e5)):
        assert t.fmu.getDirectionalDerivative(f, [t.vr[known]], [1.0]) == [expected, expected, 0.0]
    t.close()
