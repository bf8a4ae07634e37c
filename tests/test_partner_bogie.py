"""Issue 41: a third party's half-car bogie, the pythonfmu stand-in of
python/partner_bogie/standin_half_car.py (written apart from this project's code: its
own names, matrices and RK4), coupled with TrackContact at the axle boxes in fmpy
loops against CoupledSystem (vehicle.model = half_car), and checked alone against
closed forms. The whole matrix (four masters, seven steps, three side-frame scales, both
primary-force outputs) is python/partner_bogie/matrix.py; these are its cells that hold
today, and the stand-in's own checks."""

import math
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import wheelflat_fmus as wf  # noqa: E402
from partner_bogie import build, matrix  # noqa: E402
from fmu_helpers import initialised  # noqa: E402

BOXES = ("1L", "1R", "2L", "2R")
Z = [f"z_frame_{b}" for b in BOXES]
V = [f"v_frame_{b}" for b in BOXES]
F = [f"F_box_{b}" for b in BOXES]
# The stand-in's defaults (its model description's), table 4.4's half-car bogie.
M_ABOVE = 40300.0 + 465.0          # the car body's share and the bolster (kg)
M_SIDEFRAME = 447.5                # one whole side frame (kg)
J_SIDEFRAME = 180.0                # its pitch inertia (kg m^2)
WHEELBASE = 1.8                    # m
G = 9.81
K1 = 6.5e6                         # TrackContact's primary stiffness per axle box (N/m)


@pytest.fixture(scope="module")
def standin():
    """The stand-in FMU, built (or found up to date) under target/partner_bogie/."""
    path = build.build()
    stamp = os.path.getmtime(path)
    assert build.build() == path and os.path.getmtime(path) == stamp, "an up-to-date FMU is built again"
    return path


def test_its_model_description_is_its_own(standin):
    """Its own names and the inputs' start values: a quarter of the weight above the
    primary suspension, which is TrackContact's default static load less half a
    wheelset (107,664.75 - 1,120 g / 2 N)."""
    from fmpy import read_model_description
    md = read_model_description(standin)
    v = {x.name: x for x in md.modelVariables}
    assert md.coSimulation.modelIdentifier == "StandinHalfCar"
    assert md.generationTool.startswith("PythonFMU 0.7.0")
    assert {x.causality for n, x in v.items() if n in F} == {"input"}
    assert {x.causality for n, x in v.items() if n in Z + V} == {"output"}
    assert not any(n.startswith(("vehicle.", "sideframe.", "primary.")) for n in v)
    static = 0.25 * G * (M_ABOVE + 2 * M_SIDEFRAME)
    assert all(float(v[n].start) == pytest.approx(static, rel=1e-12) for n in F)
    assert static + 0.5 * 1120.0 * G == pytest.approx(107664.75, rel=1e-12)


def _alone(path, scale, forces, steps, h):
    """The stand-in alone, `forces` (N, the four boxes) held: its outputs after every step."""
    u = wf.Unit(path, "standin")
    try:
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters({"sideframe_scale": scale})
        u.fmu.enterInitializationMode()
        u.set(F, forces)
        u.fmu.exitInitializationMode()
        out = [u.get(*Z, *V)]
        for k in range(steps):
            u.fmu.doStep(k * h, h)
            out.append(u.get(*Z, *V))
        return np.array(out)
    finally:
        u.close()


@pytest.mark.parametrize("scale", [1.0, 2.0])
def test_alone_on_its_static_forces_it_stays_at_rest(standin, scale):
    """(c) Given the static forces of the closed form (a quarter of its weight at each
    box), it keeps its rest over 0.1 s: an independent check of the statics it
    computes with numpy (the rigid modes above the primary suspension have no spring to
    hide an error: a wrong force would drift quadratically)."""
    static = 0.25 * G * (M_ABOVE + 2 * scale * M_SIDEFRAME)
    out = _alone(standin, scale, [static] * 4, 100, 1e-3)
    z0 = out[0, :4]
    assert np.all(z0 == pytest.approx(-0.01725226666550715, abs=1e-15))
    assert np.max(np.abs(out[:, :4] - z0)) < 1e-9
    assert np.max(np.abs(out[:, 4:])) < 1e-8
    # One newton off at one box is seen: its drift over 0.1 s is far above the bound.
    off = _alone(standin, scale, [static + 1.0, static, static, static], 100, 1e-3)
    assert np.max(np.abs(off[:, :4] - z0)) > 1e-6


@pytest.mark.parametrize("scale", [1.0, 2.0])
def test_its_side_frames_pitch_on_rigid_axle_boxes_at_the_closed_form_frequency(standin, scale):
    """(d) On rigid axle boxes through primary springs K_1 (undamped, TrackContact's
    default stiffness) a side frame pitches at omega = sqrt(2 K_1 l^2 / J), l half the
    wheelbase (the secondary suspension acts at its centre: no pitch coupling): set going
    by a pitching pulse, the frequency of its zero crossings within 0.5 %. The springs'
    forces are exchanged every 20 us (omega h = 0.005)."""
    h, steps, pulse = 2e-5, 10000, 25
    j = scale * J_SIDEFRAME
    l2 = 0.25 * WHEELBASE ** 2
    omega = math.sqrt(2 * K1 * l2 / j)
    static = 0.25 * G * (M_ABOVE + 2 * scale * M_SIDEFRAME)
    u = initialised({"standin": standin}, "standin", params={"sideframe_scale": scale})
    try:
        rest = np.array(u.get(*Z))
        theta = []
        for k in range(steps):
            z = np.array(u.get(*Z))
            f = static - K1 * (z - rest)
            if k < pulse:  # a moment on both side frames: front up, rear down
                f += 2000.0 * np.array([1.0, 1.0, -1.0, -1.0])
            u.set(F, f)
            u.fmu.doStep(k * h, h)
            z = u.get(*Z)
            theta.append(((z[0] - z[2]) / WHEELBASE, (z[1] - z[3]) / WHEELBASE))
    finally:
        u.close()
    t = h * np.arange(1, steps + 1)
    for side in range(2):
        x = np.array([a[side] for a in theta])[pulse:]
        tt = t[pulse:]
        i = np.nonzero(np.sign(x[1:]) != np.sign(x[:-1]))[0]
        crossings = tt[i] - x[i] * (tt[i + 1] - tt[i]) / (x[i + 1] - x[i])
        assert len(crossings) >= 10
        measured = math.pi * (len(crossings) - 1) / (crossings[-1] - crossings[0])
        assert measured == pytest.approx(omega, rel=5e-3), (side, measured, omega)


def test_jacobi_fmpy_loop_with_the_force_at_the_point_within_one_per_cent(standin):
    """(a) The stand-in at the axle boxes of TrackContact (vehicle.model = half_car),
    an fmpy Jacobi loop handing it primary.*.force every 1 ms, 0.6 s, the reference flat
    on the endless track: every wheel's peak within 1 % of CoupledSystem's. (What
    TrackContact warns of in the matrix's cells is matrix.py's, not asserted here.)"""
    r = matrix.run_cell(matrix.cell("fmpy_jacobi", 1e-3, "force", 1.0), standin)
    assert not r["diverged"] and r["failure"] is None, r["failure"]
    assert r["error"] < 0.01, r["errors"]


def test_sequential_fmpy_loop_with_the_mean_force_within_a_fifth_of_a_per_cent(standin):
    """(b) The sequential fmpy loop (TrackContact first) handing it primary.*.mean_force
    every 1 ms: every wheel's peak within 0.2 % of CoupledSystem's."""
    r = matrix.run_cell(matrix.cell("fmpy_seq", 1e-3, "mean_force", 1.0), standin)
    assert not r["diverged"] and r["failure"] is None, r["failure"]
    assert r["error"] < 0.002, r["errors"]


def test_it_is_the_half_car_bogie_of_this_project(standin):
    """Written apart, the same physical model: in the same fmpy Jacobi loop at 1 ms the
    stand-in's and HalfCarBogie's peaks agree within 0.05 % (their integrators differ:
    RK4 on 0.1 ms substeps against central differences)."""
    paths = {n: os.path.join(wf.FMU_DIR, n + ".fmu") for n in ("TrackContact", "HalfCarBogie")}
    window = {"track.window.ahead": 20.0, "track.window.behind": 20.0}
    ours = [x for w in wf.run_carrier_axle_box(paths, "HalfCarBogie", 2, 0.6, 1e-3, track_params=window,
                                               jacobi=True, primary_output="force") for x in w]
    r = matrix.run_cell(matrix.cell("fmpy_jacobi", 1e-3, "force", 1.0), standin)
    assert r["peaks"] == pytest.approx(ours, rel=5e-4)


# ------------------------------------------------------------------ what TrackContact tells of it

def _set_to(message, name, unit):
    """The value a warning tells to set `name` to."""
    import re
    return float(re.search(rf"{re.escape(name)} = ([0-9.e+-]+) {unit}", message.split("; set ")[1]).group(1))


def test_trackcontact_fits_a_third_party_bogies_side_frames(standin):
    # Issue 41 (item 2): the stand-in's side frames twice TrackContact's copy (895 kg,
    # 360 kg m^2 against 447.5 kg and 180): fitted from the exchange in an fmpy Jacobi
    # loop at 1 ms, the warning names per axle box half the mass within 1 % and the pitch
    # inertia within 0.1 %.
    r = matrix.run_cell(matrix.cell("fmpy_jacobi", 1e-3, "force", 2.0, stop=0.15), standin)
    assert r["warning_kinds"] == ["side-frame copy"], r["warnings"]
    w = r["warnings"][0]
    assert _set_to(w, "vehicle.sideframe.mass", "kg") == pytest.approx(447.5, rel=0.01), w
    assert _set_to(w, "vehicle.sideframe.pitch_inertia", "kg m") == pytest.approx(360.0, rel=1e-3), w


def test_auto_takes_the_fitted_side_frames_in_a_third_party_master(standin):
    # Issue 41 (item 5): side frames half as heavy as TrackContact's copy, OSP libcosim at
    # 1 ms: 2.15 % off CoupledSystem with the copy, warned of; with
    # vehicle.sideframe.source = auto within 1 %, nothing to warn of.
    copy = matrix.run_cell(matrix.cell("libcosim", 1e-3, "force", 0.5), standin)
    assert copy["error"] > 0.02 and copy["warning_kinds"] == ["side-frame copy"], copy["warnings"]
    auto = matrix.run_cell(matrix.cell("libcosim", 1e-3, "force", 0.5, track={"vehicle.sideframe.source": 2}),
                           standin)
    assert auto["error"] < 0.01 and auto["warnings"] == [], (auto["errors"], auto["warnings"])


def test_ecos_handing_on_the_mean_force_is_told_to_hand_on_the_force(standin):
    # Issue 41 (item 3): ecos (Jacobi) connected to primary.*.mean_force: TrackContact
    # tells, once, to connect primary.*.force (seen in ecos' debug log).
    r = matrix.run_cell(matrix.cell("ecos", 1e-3, "mean_force", 1.0, stop=0.15), standin)
    assert r["warning_kinds"] == ["output choice"], r["warnings"]
    assert "connect primary.*.force" in r["warnings"][0]


def test_the_quick_matrix_warns_where_the_exchange_is_off_and_only_there(standin):
    # Issue 41 ("what must be shown"): libcosim and the sequential fmpy loop at 1 and 4 ms,
    # side frames 0.5, 1 and 2 times TrackContact's copy, either output, and the Wagon:
    # every run more than 1 % off CoupledSystem, or diverged, is warned of; a run within
    # 1 % is warned of only for what is wrong in it (a copy off the bogie's, an output
    # that does not suit the master) or for a step above three quarters of the Jacobi
    # estimate (conservative: the stand-in at 4 ms, 1.46 times the estimate, is 0.63 %
    # off; python/partner_bogie/matrix.py runs the whole matrix).
    cells = matrix.matrix_cells(quick=True)
    results = matrix.run_cells(cells, standin, progress=False)
    right = {"libcosim": "force", "fmpy_seq": "mean_force"}
    for c, r in zip(cells, results):
        kinds = set(r["warning_kinds"])
        if r["diverged"] or r["error"] > 0.01:
            assert kinds, (matrix.label(c), r["errors"])
            continue
        allowed = {"axle-box step"} if c["master"] == "libcosim" and c["step"] > 2.1e-3 else set()
        if c["scale"] != 1.0:
            allowed.add("side-frame copy")
            assert "side-frame copy" in kinds, (matrix.label(c), r["warnings"])
        if c["output"] != right[c["master"]]:
            allowed.add("output choice")
            assert "output choice" in kinds, (matrix.label(c), r["warnings"])
        assert kinds <= allowed, (matrix.label(c), r["errors"], r["warnings"])


def test_trackcontact_tells_the_bogies_static_wheel_load_from_its_first_step(standin):
    # Issue 41 (a load that does not hold the partner at rest was silent): static_load.*
    # 1 % above the stand-in's 107,664.75 N. The side frames move off at the first step as
    # under the difference; TrackContact names the bogie's wheel load within 0.2 %.
    load = 1.01 * 107664.75
    r = matrix.run_cell(matrix.cell("fmpy_jacobi", 1e-3, "force", 1.0, stop=0.05,
                                    track={"static_load.left": load, "static_load.right": load}), standin)
    told = [w for w in r["warnings"] if "moved off at the first step" in w]
    assert len(told) == 1, r["warnings"]
    import re
    left = float(re.search(r"static wheel loads are about ([0-9.e+-]+) N left", told[0]).group(1))
    assert left == pytest.approx(107664.75, rel=2e-3), told[0]
