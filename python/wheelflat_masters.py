"""The shipped system structures (fmu/systems/, written by build_fmus) in the third-party
masters libcosim (PyPI libcosimpy) and ecos (PyPI ecospy), and the monolithic
CoupledSystem (fmpy) on the same endless track for STOP s: what tests/test_masters.py
checks and python/wheelflat_figures.py prints into docs/guide/masters.md. Both masters
are fixed-step Jacobi: every FMU steps from the same communication point.

Every master run is a subprocess of this file (``python python/wheelflat_masters.py
SPEC``): libcosim can abort the process. Runs are cached per process and two run at a
time (this project's machine has two cores)."""

import concurrent.futures
import functools
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time
import zipfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

ROOT = wf.ROOT
FMU_DIR = os.path.join(ROOT, "fmu")
SYSTEMS = os.path.join(FMU_DIR, "systems")


def registry():
    """The vehicle registry as the packer wrote it beside the FMUs (fmu/fmus.json)."""
    if not os.path.exists(os.path.join(FMU_DIR, "fmus.json")):
        wf.build_fmus()
    return {k["fmu"]: k for k in wf.registry(FMU_DIR)["vehicles"]}


# Every kind of vehicle's FMU and its wheelsets, from the registry.
VEHICLES = {name: k["wheelsets"] for name, k in registry().items()}
STOP = 0.6
# The first impact is at about 34 ms; the start is checked before it.
EARLY = 0.02


def system_name(vehicle, interface):
    return f"TrackContact_{vehicle}_{interface}"


def wheel_names(n, what):
    """`contact.<side>.<what>` of the n wheelsets' wheels, TrackContact's names."""
    names = [f"contact.{s}.{what}" for s in ("left", "right")]
    return names + [f"wheelset[{k}].{x}" for k in range(2, n + 1) for x in names]


def shipped_step(vehicle, interface):
    """The base step (s) of the shipped SSP's osp:FixedStepAlgorithm annotation."""
    with zipfile.ZipFile(os.path.join(SYSTEMS, system_name(vehicle, interface) + ".ssp")) as z:
        ssd = z.read("SystemStructure.ssd").decode()
    return float(re.search(r'<osp:FixedStepAlgorithm baseStepSize="([^"]+)"', ssd).group(1))


# ---------------------------------------------------------------------------------------
# The worker: one master run in this process, its result as one JSON line.


def _libcosim(spec, path, n):
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    # libcosim's default level, trace, prints every logCalls message of the FMUs.
    log_output_level(CosimLogLevel.WARNING)
    step_ns = None if spec["step"] is None else int(round(spec["step"] * 1e9))
    if spec["structure"] == "osp":
        if step_ns is not None:
            # The OSP file has no step override: a copy with another BaseStepSize and
            # absolute sources.
            xml = open(path).read()
            xml = re.sub(r"<BaseStepSize>[^<]*</BaseStepSize>", f"<BaseStepSize>{spec['step']!r}</BaseStepSize>", xml)
            xml = xml.replace('source="../../', f'source="{FMU_DIR}/')
            path = os.path.join(tempfile.mkdtemp(), "OspSystemStructure.xml")
            open(path, "w").write(xml)
        ex = CosimExecution.from_osp_config_file(path)
    elif step_ns is None:
        ex = CosimExecution.from_ssp_file(path)
    else:
        ex = CosimExecution.from_ssp_file(path, step_ns)
    # Every component is named after its FMU (OMSimulator needs it: build_fmus' systems.rs).
    track = ex.slave_index_from_instance_name("TrackContact")
    vr = {v.name.decode(): v.reference for v in ex.slave_variables(track)}
    last = CosimObserver.create_last_value()
    ex.add_observer(last)
    early = {}
    ok = True
    if spec["early"]:
        series = CosimObserver.create_time_series(buffer_size=1 << 16)
        ex.add_observer(series)
        forces = wheel_names(n, "force")
        for f in forces:
            series.start_time_series(track, vr[f], CosimVariableType.REAL)
        ok = ex.simulate_until(int(round(EARLY * 1e9)))
        for f in forces:
            t, _, x = series.time_series_real_samples(track, vr[f], from_step=0, sample_count=1 << 16)
            early[f] = [[ti * 1e-9 for ti in t], list(x)]
    ok = ok and ex.simulate_until(int(round(STOP * 1e9)))
    names = wheel_names(n, "max_force") + ["position"]
    vals = last.last_real_values(track, [vr[x] for x in names])
    return dict(ok=bool(ok), time=ex.status().current_time * 1e-9, peaks=vals[:-1], position=vals[-1], early=early)


def _ecos(spec, path, n):
    from ecospy import EcosLib, EcosSimulation

    EcosLib.set_log_level("warn")
    h = spec["step"] if spec["step"] is not None else shipped_step(spec["vehicle"], spec["interface"])
    sim = EcosSimulation(ssp_path=path, step_size=h)
    # ecos applies an SSP parameter set only when init() names it.
    sim.init(parameter_set="wheelflat")
    steps = int(round(STOP / h))
    early = {}
    done = 0
    if spec["early"]:
        forces = wheel_names(n, "force")
        early = {f: [[], []] for f in forces}
        done = int(round(EARLY / h))
        for k in range(done + 1):
            t = sim.get_time()
            for f in forces:
                early[f][0].append(t)
                early[f][1].append(sim.get_real("TrackContact::" + f))
            if k < done:
                sim.step(1)
    # sim.step(n), not step_until: ecos sums its clock and can stop one step short.
    sim.step(steps - done)
    names = wheel_names(n, "max_force") + ["position"]
    vals = [sim.get_real("TrackContact::" + x) for x in names]
    t = sim.get_time()
    sim.terminate()
    sim.free()
    # ecos ignores every status: "ok" here means only that the calls returned.
    return dict(ok=True, time=t, peaks=vals[:-1], position=vals[-1], early=early)


def worker(spec):
    name = system_name(spec["vehicle"], spec["interface"])
    n = VEHICLES[spec["vehicle"]]
    if spec["structure"] == "osp":
        path = os.path.join(SYSTEMS, name, "OspSystemStructure.xml")
    else:
        path = os.path.join(SYSTEMS, name + ".ssp")
    t0 = time.perf_counter()
    r = (_libcosim if spec["engine"] == "libcosim" else _ecos)(spec, path, n)
    r["wall"] = time.perf_counter() - t0
    print("RESULT " + json.dumps(r), flush=True)


# ---------------------------------------------------------------------------------------
# The tests.

_cache = {}
_lock = threading.Lock()


def _run(spec):
    key = json.dumps(spec, sort_keys=True)
    with _lock:
        if key in _cache:
            return _cache[key]
    # ecos unpacks each SSP under $TMPDIR and leaves it there (1.3 MB a run): a private one.
    tmp = tempfile.mkdtemp(prefix="wheelflat_masters_")
    try:
        p = subprocess.run([sys.executable, os.path.abspath(__file__), key], cwd=ROOT, capture_output=True, text=True,
                           timeout=300, env=dict(os.environ, TMPDIR=tmp))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    # libcosim logs to stdout, ecos to stderr: both are kept.
    log = p.stdout + p.stderr
    line = next((x for x in p.stdout.splitlines() if x.startswith("RESULT ")), None)
    if p.returncode != 0 or not line:
        raise RuntimeError(f"{spec}: exit {p.returncode}\n{log[-3000:]}")
    r = json.loads(line[len("RESULT "):])
    r["log"] = log
    with _lock:
        _cache[key] = r
    return r


def run_all(specs):
    """Runs the specs, two at a time (this project's machine has two cores)."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=2) as pool:
        return list(pool.map(_run, specs))


def spec(engine, structure, vehicle, interface, step=None, early=False):
    """step None: the shipped file's base step."""
    return dict(engine=engine, structure=structure, vehicle=vehicle, interface=interface, step=step, early=early)


@functools.lru_cache(maxsize=None)
def monolithic(vehicle):
    """CoupledSystem with the shipped systems' track and vehicle for STOP: the largest
    force of every wheel and the track position at the end."""
    from fmpy import simulate_fmu

    n = VEHICLES[vehicle]
    out = wheel_names(n, "max_force") + ["position"]
    r = simulate_fmu(os.path.join(FMU_DIR, "CoupledSystem.fmu"), stop_time=STOP, start_values=coupled_params(vehicle),
                     output=out, output_interval=1e-3)
    return dict(peaks=[float(r[x][-1]) for x in out[:-1]], position=float(r["position"][-1]))


@functools.lru_cache(maxsize=None)
def monolithic_start(vehicle, h):
    """CoupledSystem's contact forces over the first EARLY s, every h: (times, {name: forces})."""
    from fmpy import simulate_fmu

    n = VEHICLES[vehicle]
    out = wheel_names(n, "force")
    r = simulate_fmu(os.path.join(FMU_DIR, "CoupledSystem.fmu"), stop_time=EARLY + 2 * h,
                     start_values=coupled_params(vehicle), output=out, output_interval=h)
    return list(r["time"]), {x: list(r[x]) for x in out}


def coupled_params(vehicle):
    """CoupledSystem's parameters for the vehicle FMU `vehicle` at its defaults: its
    registry entry's vehicle.model, its wheelsets at the offsets its own parameters give."""
    from fmpy import read_model_description

    kind = registry()[vehicle]
    p = {"track.window.ahead": 20.0, "track.window.behind": 20.0, "vehicle.model": kind["value"]}
    if kind["wheelsets"] > 1:
        md = read_model_description(os.path.join(FMU_DIR, vehicle + ".fmu"))
        start = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
        p["wheelsets"] = kind["wheelsets"]
        for k, names in enumerate(kind["offsets"], start=2):
            p[f"wheelset[{k}].offset"] = sum(start[x] for x in names)
    return p


if __name__ == "__main__":
    worker(json.loads(sys.argv[1]))
