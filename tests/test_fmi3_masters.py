"""The FMI 3.0 FMUs (fmu/fmi3/) in the third-party masters (issue 43).

ecos (PyPI ecospy 0.7.2, fmi4c inside) loads and runs them, through its
EcosSimulationStructure (``add_model``, connections by ``instance::variable``) as
through an SSP 1.0 file, with what its FMI 3.0 import leaves out (ecos v.0.7.2,
src/fmilibcpp/fmi3/):

* Enumerations are skipped (``Variable named 'vehicle.model' is of unsupported type,
  skipping.``): ``vehicle.model``, ``interface``, ``contact.model``... stay at their
  start values; an SSP ``ssv:Enumeration`` parameter stops the load.
* No Configuration Mode: ``wheelsets`` (the structural parameter) stays at its start
  value 1; set in a parameter set it reaches the FMU in Initialization Mode, which
  refuses it.
* Every variable is a scalar (a ``<Dimension>`` is not read): an array of one element
  (one wheelset) reads, writes and connects as a scalar; one of two elements is refused
  by the FMU (nValues) and reads 0.0.

So of the shipped systems only the roll-plane pair at the contact interface (one
wheelset, every Enumeration at its default; fmu/systems/fmi3/, the packer's) runs in FMI
3.0; the axle-box systems need ``interface = axle_box`` (the shipped FMI 3.0 SSP of the
roll-plane pair at the axle boxes sets it as an ``ssv:Enumeration``, which ecos refuses)
and the others more than one wheelset (no FMI 3.0 SSP: SSP 1.0 connects scalars). It runs bit for bit as
the FMI 2.0 FMUs do. libcosim (PyPI libcosimpy 0.0.6) loads no FMI 3.0 FMU.

Each master run is a subprocess of this file (``python tests/test_fmi3_masters.py
SPEC``) with its own TMPDIR: ecos unpacks every SSP there and leaves it, and both
masters' libraries print to stdout."""

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FMU_DIR = os.path.join(ROOT, "fmu")
sys.path.insert(0, os.path.join(ROOT, "python"))

STOP = 0.1
# CoupledSystem's communication step in ecos and fmpy.
COUPLED_STEP = 1e-4
PAIR = ("TrackContact", "RollPlaneVehicle")
SHIPPED_PAIR = os.path.join(FMU_DIR, "systems", "TrackContact_RollPlaneVehicle_contact.ssp")
# The FMI 2.0 system's parameters that are Enumerations or structural parameters in FMI
# 3.0: ecos cannot set them, so the FMI 3.0 SSP leaves them out (at their start values).
LEFT_OUT = ("interface", "wheelsets", "vehicle.model")


SHIPPED_PAIR3 = os.path.join(FMU_DIR, "systems", "fmi3", "TrackContact_RollPlaneVehicle_contact.ssp")

PARAMETER = '                  <ssv:Parameter name="{}"><ssv:{} value="{}"/></ssv:Parameter>'


def shipped_parameters(ssd):
    """The FMI 2.0 SSD's parameter set of each component: {component: [(name, type, value)]}."""
    out = {}
    for comp, body in re.findall(r'<ssd:Component name="([^"]+)".*?>(.*?)</ssd:Component>', ssd, re.S):
        out[comp] = re.findall(r'<ssv:Parameter name="([^"]+)"><ssv:(\w+) value="([^"]*)"/>', body)
    return out


def shipped_step():
    with zipfile.ZipFile(SHIPPED_PAIR) as z:
        ssd = z.read("SystemStructure.ssd").decode()
    return float(re.search(r'<osp:FixedStepAlgorithm baseStepSize="([^"]+)"', ssd).group(1)), ssd


# ---------------------------------------------------------------------------------------
# The worker: the runs of one spec in this process, the result as one JSON line.


def _ecos_record(sim, steps, prefix):
    """[time, left force, right force] at every communication point."""
    names = [prefix + "contact.left.force", prefix + "contact.right.force"]
    rows = [[sim.get_time()] + [sim.get_real(x) for x in names]]
    for _ in range(steps):
        sim.step(1)
        rows.append([sim.get_time()] + [sim.get_real(x) for x in names])
    return rows


def _ecos_coupled(spec):
    from ecospy import EcosSimulation, EcosSimulationStructure

    ss = EcosSimulationStructure()
    ss.add_model("cs", spec["fmu"])
    sim = EcosSimulation(structure=ss, step_size=spec["h"])
    sim.init()
    rows = _ecos_record(sim, spec["steps"], "cs::")
    position = sim.get_real("cs::position")
    sim.terminate()
    sim.free()
    return dict(rows=rows, position=position)


def _ecos_pair(spec):
    """The roll-plane pair: from an SSP (spec["ssp"]) or built with add_model and
    connections by name (spec["fmu3_dir"]), at spec["h"] for spec["steps"] steps."""
    from ecospy import EcosSimulation, EcosSimulationStructure

    if spec.get("ssp"):
        sim = EcosSimulation(ssp_path=spec["ssp"], step_size=spec["h"])
    else:
        ss = EcosSimulationStructure()
        for comp in PAIR:
            ss.add_model(comp, os.path.join(spec["fmu3_dir"], comp + ".fmu"))
        for x in ("wheel.left.z", "wheel.right.z", "wheel.rotation"):
            ss.make_real_connection("RollPlaneVehicle::" + x, "TrackContact::" + x)
        for x in ("contact.left.force", "contact.right.force"):
            ss.make_real_connection("TrackContact::" + x, "RollPlaneVehicle::" + x)
        ss.add_parameter_set("wheelflat", {f"{c}::{n}": float(v) for c, n, v in spec["params"]})
        sim = EcosSimulation(structure=ss, step_size=spec["h"])
    sim.init(parameter_set="wheelflat")
    solver_step = sim.get_real("TrackContact::solver.step")
    rows = _ecos_record(sim, spec["steps"], "TrackContact::")
    peaks = [sim.get_real(f"TrackContact::contact.{s}.max_force") for s in ("left", "right")]
    sim.terminate()
    sim.free()
    return dict(rows=rows, peaks=peaks, solver_step=solver_step)


def _ecos_limits(spec):
    """What ecos leaves out of our FMI 3.0 FMUs (its FMU errors come through its log at
    debug level only; it ignores every status)."""
    from ecospy import EcosLib, EcosSimulation, EcosSimulationStructure

    EcosLib.set_log_level("debug")
    r = {}
    ss = EcosSimulationStructure()
    ss.add_model("cs", spec["coupled"])
    ss.add_model("hc", spec["half_car"])
    ss.add_parameter_set("p", {"cs::vehicle.model": 2, "cs::wheelsets": 2})
    sim = EcosSimulation(structure=ss, step_size=1e-4)
    try:
        sim.set_integer("cs::vehicle.model", 2)
    except Exception as e:
        r["set_enum"] = str(e)
    sim.init(parameter_set="p")
    # Two values an array (HalfCarBogie's wheelsets = 2): ecos asks for one.
    r["half_car_z"] = sim.get_real("hc::wheel.left.z")
    sim.terminate()
    sim.free()
    try:
        EcosSimulation(ssp_path=spec["enum_ssp"], step_size=1e-4)
    except Exception as e:
        r["ssv_enumeration"] = str(e)
    return r


def _libcosim(spec):
    from libcosimpy._internal import get_last_error_message
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    r = {}
    # libcosimpy does not check the pointer: add_local_slave would crash the process.
    s = CosimLocalSlave(fmu_path=spec["fmu"], instance_name="cs")
    r["slave_null"] = not bool(s.ptr())
    r["slave_error"] = get_last_error_message()
    try:
        CosimExecution.from_ssp_file(spec["ssp"], int(round(spec["h"] * 1e9)))
        r["ssp_error"] = None
    except AssertionError:
        r["ssp_error"] = get_last_error_message()
    return r


def worker(spec):
    fn = {"coupled": _ecos_coupled, "pair": _ecos_pair, "limits": _ecos_limits, "libcosim": _libcosim}[spec["kind"]]
    print("RESULT " + json.dumps(fn(spec)), flush=True)


def run(spec, tmp):
    """One worker run in a subprocess with a private TMPDIR under `tmp`: (result, log)."""
    tmpdir = tempfile.mkdtemp(dir=tmp)
    try:
        p = subprocess.run([sys.executable, os.path.abspath(__file__), json.dumps(spec)], cwd=ROOT,
                           capture_output=True, text=True, timeout=120, env=dict(os.environ, TMPDIR=tmpdir))
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)
    log = p.stdout + p.stderr
    line = next((x for x in p.stdout.splitlines() if x.startswith("RESULT ")), None)
    assert p.returncode == 0 and line, f"{spec['kind']}: exit {p.returncode}\n{log[-3000:]}"
    return json.loads(line[len("RESULT "):]), log


# ---------------------------------------------------------------------------------------
# The tests.


@pytest.fixture(scope="module")
def fmu3():
    from wheelflat_fmi3 import paths3

    return paths3()


@pytest.fixture(scope="module")
def pair_ssp(fmu3):
    """The shipped FMI 3.0 pair's SSP (fmu/systems/fmi3/, the packer's): (path, SSD,
    step). Its step is the FMI 2.0 system's, its parameters the FMI 2.0 system's less
    LEFT_OUT, which are at their FMI 3.0 start values."""
    from fmpy import read_model_description

    with zipfile.ZipFile(SHIPPED_PAIR3) as z:
        ssd = z.read("SystemStructure.ssd").decode()
    h = float(re.search(r'<osp:FixedStepAlgorithm baseStepSize="([^"]+)"', ssd).group(1))
    h2, ssd2 = shipped_step()
    assert h == h2
    p2, p3 = shipped_parameters(ssd2), shipped_parameters(ssd)
    for comp in PAIR:
        md = {v.name: v for v in read_model_description(fmu3[comp]).modelVariables}
        kept = []
        for name, ty, value in p2[comp]:
            v = md[name]
            if name in LEFT_OUT:
                assert v.type == "Enumeration" or v.causality == "structuralParameter", (comp, name, v.type)
                assert int(v.start) == int(value), f"{comp}.{name}: the system wants {value}, FMI 3.0 starts at {v.start}"
                continue
            assert v.type == "Float64" and ty == "Real", (comp, name, v.type, ty)
            kept.append((name, ty, value))
        assert p3[comp] == kept, comp
    return SHIPPED_PAIR3, ssd, h


def test_coupled_system_fmi3_in_ecos_is_fmpy_fmi2_bit_for_bit(fmu3, tmp_path):
    """CoupledSystem FMI 3.0 alone in ecos (EcosSimulationStructure.add_model) at 1e-4 s
    for 0.1 s: the contact forces at every communication point are those of the FMI 2.0
    CoupledSystem in fmpy (simulate_fmu at the same step), bit for bit."""
    from fmpy import simulate_fmu

    steps = int(round(STOP / COUPLED_STEP))
    r, _ = run(dict(kind="coupled", fmu=fmu3["CoupledSystem"], h=COUPLED_STEP, steps=steps), str(tmp_path))
    rows = np.array(r["rows"])
    ref = simulate_fmu(os.path.join(FMU_DIR, "CoupledSystem.fmu"), stop_time=STOP, output_interval=COUPLED_STEP,
                       output=["contact.left.force", "contact.right.force", "position"])
    assert rows.shape == (steps + 1, 3) and len(ref) == steps + 1, (rows.shape, len(ref))
    # ecos sums its clock, fmpy multiplies: the points agree to rounding.
    assert np.max(np.abs(rows[:, 0] - ref["time"])) < 1e-12
    for k, name in ((1, "contact.left.force"), (2, "contact.right.force")):
        differ = np.flatnonzero(rows[:, k] != ref[name])
        assert differ.size == 0, f"{name}: {differ.size} points differ, the first at t = {rows[differ[0], 0]} s " \
                                 f"({rows[differ[0], k]} N, FMI 2.0 {ref[name][differ[0]]} N)"
    assert r["position"] == ref["position"][-1]
    # The run passed the first impact (at about 34 ms).
    assert rows[:, 1].max() > 2.5 * rows[0, 1]


def test_contact_pair_fmi3_in_ecos(fmu3, pair_ssp, tmp_path):
    """TrackContact + RollPlaneVehicle FMI 3.0 (arrays of one element) at the contact in
    ecos at the track's step for 0.1 s, connected by name (EcosSimulationStructure) and
    through the shipped FMI 3.0 SSP: both are the shipped FMI 2.0 SSP in ecos bit for bit,
    start at the static load, and peak within 1 % of the monolithic CoupledSystem."""
    from fmpy import simulate_fmu

    from wheelflat_masters import coupled_params

    path, ssd, h = pair_ssp
    steps = int(round(STOP / h))
    params = [(c, n, v) for c, ps in shipped_parameters(ssd).items() for n, _, v in ps]
    runs = {
        "FMI 3.0, by name": dict(kind="pair", fmu3_dir=os.path.dirname(fmu3["TrackContact"]), params=params, h=h,
                                 steps=steps),
        "FMI 3.0, SSP": dict(kind="pair", ssp=path, h=h, steps=steps),
        "FMI 2.0, shipped SSP": dict(kind="pair", ssp=SHIPPED_PAIR, h=h, steps=steps),
    }
    res = {k: run(s, str(tmp_path))[0] for k, s in runs.items()}
    ref = np.array(res["FMI 2.0, shipped SSP"]["rows"])
    for label in ("FMI 3.0, by name", "FMI 3.0, SSP"):
        r = res[label]
        assert r["solver_step"] == h, f"{label}: TrackContact's solver.step {r['solver_step']} s, the SSP's {h} s"
        rows = np.array(r["rows"])
        assert rows.shape == ref.shape, (label, rows.shape, ref.shape)
        differ = np.flatnonzero(np.any(rows != ref, axis=1))
        assert differ.size == 0, f"{label}: {differ.size} points differ from FMI 2.0, the first {rows[differ[0]]} " \
                                 f"against {ref[differ[0]]}"
        assert r["peaks"] == res["FMI 2.0, shipped SSP"]["peaks"], label
    r = res["FMI 3.0, SSP"]
    static = float(dict((n, v) for _, n, v in params)["static_load.left"])
    assert abs(r["rows"][0][1] / static - 1) < 0.005, r["rows"][0]
    mono = simulate_fmu(os.path.join(FMU_DIR, "CoupledSystem.fmu"), stop_time=STOP,
                        start_values=coupled_params("RollPlaneVehicle"),
                        output=["contact.left.max_force", "contact.right.max_force"], output_interval=1e-3)
    for p, name in zip(r["peaks"], ("contact.left.max_force", "contact.right.max_force")):
        m = float(mono[name][-1])
        assert abs(p / m - 1) < 0.01, f"{name}: {p:.0f} N in ecos, {m:.0f} N monolithic ({100 * (p / m - 1):+.2f} %)"


def test_what_ecos_leaves_out_of_fmi3(fmu3, pair_ssp, tmp_path):
    """ecos registers no Enumeration (vehicle.model cannot be set: by name nor in a
    parameter set, and an SSP ssv:Enumeration stops the load), has no Configuration
    Mode (wheelsets reaches the FMU in Initialization Mode, refused) and treats arrays as
    scalars (HalfCarBogie's two-element wheel.left.z is refused and reads 0.0)."""
    path, ssd, h = pair_ssp
    enum_ssp = str(tmp_path / "enum.ssp")
    with zipfile.ZipFile(path) as src, zipfile.ZipFile(enum_ssp, "w", zipfile.ZIP_STORED) as z:
        for item in src.namelist():
            data = src.read(item)
            if item == "SystemStructure.ssd":
                data = ssd.replace(PARAMETER.format("speed", "Real", "19.444444444444443"),
                                   PARAMETER.format("interface", "Enumeration", "contact"), 1).encode()
                assert b"ssv:Enumeration" in data
            z.writestr(item, data)
    r, log = run(dict(kind="limits", coupled=fmu3["CoupledSystem"], half_car=fmu3["HalfCarBogie"], enum_ssp=enum_ssp),
                 str(tmp_path))
    assert "Variable named 'vehicle.model' is of unsupported type, skipping." in log
    assert r["set_enum"] == "No int property cs::vehicle.model found!", r
    assert "No variable named 'vehicle.model' of type int registered for instance 'cs'" in log
    # The FMUs' refusals (CoupledSystem's of wheelsets, HalfCarBogie's of the array),
    # in ecos's debug log only.
    lines = log.splitlines()
    assert any("fmi3SetUInt64" in x and "InitializationMode" in x and "ConfigurationMode" in x
               for x in lines), log[-3000:]
    assert r["half_car_z"] == 0.0
    assert any("fmi3GetFloat64" in x and "nValues = 1" in x and "2 values" in x for x in lines), log[-3000:]
    assert r["ssv_enumeration"] == "Unknown XML node in ssv:Parameter encountered!", r


def test_libcosim_loads_no_fmi3(fmu3, pair_ssp, tmp_path):
    """libcosim (libcosimc 0.11.2) reads fmiVersion 1.0 and 2.0 only: an FMI 3.0 FMU
    is refused, alone (a null slave: libcosimpy passes it on unchecked) and in an SSP."""
    path, _, h = pair_ssp
    r, _ = run(dict(kind="libcosim", fmu=fmu3["CoupledSystem"], ssp=path, h=h), str(tmp_path))
    assert r["slave_null"], r
    assert r["slave_error"] == f"Unsupported feature: Unsupported FMI version for FMU '{fmu3['CoupledSystem']}'", r
    assert r["ssp_error"] is not None and r["ssp_error"].startswith("Unsupported feature: Unsupported FMI version "
                                                                    "for FMU '"), r
    assert r["ssp_error"].endswith(".fmu'"), r


if __name__ == "__main__":
    worker(json.loads(sys.argv[1]))
