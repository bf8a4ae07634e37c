"""Issue 41, "What must be shown": a third party's half-car bogie (the pythonfmu stand-in
of standin_half_car.py) coupled with the unpatched TrackContact at the axle boxes, in
four masters, at seven communication steps, with the stand-in's side frames scaled
while TrackContact keeps its copy of them at the defaults (nothing checks the copy), fed
either of TrackContact's primary-force outputs; and this project's Wagon likewise. Each
cell: the peak error against CoupledSystem, whether the run diverged, and the statuses
TrackContact returned (fmi2Warning, and its messages).

    .venv/bin/python python/partner_bogie/matrix.py [--quick] [--only K=V[,V] ...] [--json PATH]
        [--fmu-dir DIR]

prints a markdown table (one row per cell) and marks every row that breaks the rule "a
warning where the error is over 1 % or the run diverges, none where it is within 1 %".
The peak error is the largest over the wheels of |peak - CoupledSystem's| / CoupledSystem's
(for a run that stopped, its peaks until then; none where ecos gave no FMU's values); a
run diverged when it failed (fmi2Error or fmi2Discard; the message is kept) or its error
is over 100 %. ``--fmu-dir`` couples another build of TrackContact, Wagon and
CoupledSystem (one kept from before a change), the shipped systems' parameters still
read from fmu/systems/. The full matrix (184 cells) takes about a minute on 2 cores.

The case: the endless track of the shipped axle-box systems (20 m ahead and behind),
70 km/h, TrackContact's default (reference) flat, 0.6 s. TrackContact's parameters are
the shipped system's (fmu/systems/TrackContact_HalfCarBogie_axle_box, for the Wagon
TrackContact_Wagon_axle_box): interface = axle_box, vehicle.model = half_car (wagon),
its wheelsets and offsets; with the stand-in its wheelset[2].offset is the stand-in's
wheelbase and its static_load.* the stand-in's static wheel load (the stand-in's weight
above the primary suspension over four, plus half of TrackContact's wheelset), as the
recipe in docs/guide/couple-a-vehicle.md says; its vehicle.sideframe.* stay at their
defaults whatever the stand-in's sideframe_scale (the unchecked copy).

The masters:
* ``libcosim``: OSP libcosim (libcosimpy), fixed-step Jacobi, on an OSP system structure
  written for the cell (the shipped one as the model); TrackContact's warnings from
  libcosim's log (standard output, no instance name: attributed by their text, the
  stand-in never warns, the Wagon's own warnings are its step and static-load ones);
* ``ecos``: ecos (ecospy), Jacobi, on an SSP written for the cell; statuses from ecos'
  debug log, which names the FMU of every call that did not return fmi2OK (ecos itself
  ignores every status: a refused step shows only there and in outputs that stop);
* ``fmpy_jacobi``: an fmpy loop, both FMUs stepping from the same point, every output
  read before any input is set;
* ``fmpy_seq``: an fmpy loop, TrackContact first, the partner given the track's output
  after the track's step.
In the fmpy loops every call's status is recorded and the logger names the instance.

Every cell runs in a subprocess of this file (``--cell JSON``; libcosim can abort a
process, pythonfmu's model shares the interpreter, fmpy keeps one logger a process), two
at a time. :func:`run_cell` is the entry for tests.
"""

import argparse
import concurrent.futures
import functools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import zipfile

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.dirname(HERE)
sys.path.insert(0, PYTHON_DIR)
import wheelflat_fmus as wf  # noqa: E402

ROOT = wf.ROOT
# The FMUs coupled (TrackContact, Wagon, CoupledSystem): fmu/, or another folder of them
# (--fmu-dir: a build kept from before a change). The shipped systems, whose parameters
# the cells take, stay fmu/systems/.
FMU_DIR = os.path.join(ROOT, "fmu")
SYSTEMS = os.path.join(ROOT, "fmu", "systems")
STOP = 0.6
MASTERS = ("libcosim", "ecos", "fmpy_jacobi", "fmpy_seq")
STEPS = (0.5e-3, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3)
SCALES = (0.5, 1.0, 2.0)
OUTPUTS = ("force", "mean_force")
WAGON_STEPS = (1e-3, 4e-3)
BOXES = ("1L", "1R", "2L", "2R")
# The rule's threshold on the peak error, and beyond which a run counts as diverged.
TOLERANCE = 0.01
DIVERGED = 1.0
# A cell's wall-clock limit (s).
CELL_TIMEOUT = 300


# ---------------------------------------------------------------------------------------
# The cells and their systems.


def cell(master, step, output, scale=1.0, partner="standin", stop=STOP, track=None):
    """A cell of the matrix: `partner` "standin" (the pythonfmu stand-in, side frames
    scaled by `scale`) or "wagon" (this project's Wagon FMU, scale 1); `track`,
    TrackContact's parameters set apart from the shipped system's ({name: value}, an
    int for an Integer or Enumeration)."""
    c = dict(partner=partner, master=master, step=step, scale=scale, output=output, stop=stop)
    if track:
        c["track"] = dict(track)
    return c


def label(c):
    return (f"{c['partner']} {c['master']} {c['step'] * 1e3:g} ms scale {c['scale']:g} "
            f"primary.*.{c['output']}")


def matrix_cells(quick=False):
    """The full matrix, or the quick subset (libcosim and the sequential fmpy loop at 1
    and 4 ms, every scale and output; the Wagon at 1 and 4 ms in the same two)."""
    masters = ("libcosim", "fmpy_seq") if quick else MASTERS
    steps = (1e-3, 4e-3) if quick else STEPS
    cells = [cell(m, h, o, s) for m in masters for h in steps for s in SCALES for o in OUTPUTS]
    cells += [cell(m, h, o, partner="wagon") for m in masters for h in WAGON_STEPS for o in OUTPUTS]
    return cells


def shipped_initial_values(system, component, fmu):
    """A component's initial values in the shipped OSP system structure `system`:
    {name: (type, value)}, those the FMU at `fmu` has (a build from before a change may
    lack a parameter the packer writes now)."""
    from fmpy import read_model_description
    xml = open(os.path.join(SYSTEMS, system, "OspSystemStructure.xml")).read()
    part = re.search(rf'<Simulator name="{component}"[^>]*>(.*?)</Simulator>', xml, re.S).group(1)
    own = {v.name for v in read_model_description(fmu).modelVariables}
    return {n: (t, float(v) if t == "Real" else int(v))
            for n, t, v in re.findall(r'<InitialValue variable="([^"]+)"><(\w+) value="([^"]+)"/>', part)
            if n in own}


def standin_parameters(scale):
    from partner_bogie import standin_half_car as sh
    p = {name: value for name, value, *_ in sh.PARAMETERS}
    p["sideframe_scale"] = float(scale)
    return p


def standin_static_box_force(scale):
    """The primary force (N) that holds the stand-in at rest at each axle box."""
    from partner_bogie import standin_half_car as sh
    forces, _ = sh.statics(standin_parameters(scale))
    return float(forces[0])


def track_start_values():
    """TrackContact's start values (defaults) of the model description: {name: value}."""
    from fmpy import read_model_description
    md = read_model_description(os.path.join(FMU_DIR, "TrackContact.fmu"))
    return {v.name: v.start for v in md.modelVariables}


def system_of(c, standin_fmu=None):
    """What a cell couples: {"track": {name: (type, value)}, "partner": (component,
    fmu path, {name: (type, value)}), "connections": [(from component, from variable,
    to component, to variable)], "n": wheelsets, "forces": TrackContact's max-force
    names}."""
    track_fmu = os.path.join(FMU_DIR, "TrackContact.fmu")
    if c["partner"] == "wagon":
        track = shipped_initial_values("TrackContact_Wagon_axle_box", "TrackContact", track_fmu)
        partner_params = shipped_initial_values("TrackContact_Wagon_axle_box", "Wagon",
                                                os.path.join(FMU_DIR, "Wagon.fmu"))
        n = 4
        frames = wf.every_wheelset(n, wf.FRAMES)
        inputs = wf.every_wheelset(n, wf.AXLE_BOX)
        partner = ("Wagon", os.path.join(FMU_DIR, "Wagon.fmu"), partner_params)
        outputs = frames
    else:
        track = shipped_initial_values("TrackContact_HalfCarBogie_axle_box", "TrackContact", track_fmu)
        n = 2
        frames = wf.every_wheelset(n, wf.FRAMES)
        # TrackContact's order per wheelset: left.z, right.z, left.v, right.v.
        outputs = [f"{q}_frame_{k}{s}" for k in "12" for q in "zv" for s in "LR"]
        inputs = [f"F_box_{b}" for b in BOXES]
        p = standin_parameters(c["scale"])
        params = {"sideframe_scale": ("Real", float(c["scale"]))}
        partner = ("StandinHalfCar", standin_fmu, params)
        # TrackContact as the recipe: the partner's wheelbase, its static wheel load.
        start = track_start_values()
        load = standin_static_box_force(c["scale"]) + 0.5 * float(start["vehicle.wheelset.mass"]) \
            * float(start["gravity"])
        track["wheelset[2].offset"] = ("Real", p["wheelbase"])
        track["static_load.left"] = ("Real", load)
        track["static_load.right"] = ("Real", load)
    for name, value in c.get("track", {}).items():
        track[name] = ("Integer" if isinstance(value, int) else "Real", value)
    primary = wf.every_wheelset(n, tuple(f"primary.{s}.{c['output']}" for s in ("left", "right")))
    connections = [(partner[0], o, "TrackContact", f) for o, f in zip(outputs, frames)]
    connections += [("TrackContact", p, partner[0], i) for p, i in zip(primary, inputs)]
    forces = wf.every_wheelset(n, ("contact.left.max_force", "contact.right.max_force"))
    return dict(track=track, partner=partner, connections=connections, n=n, forces=forces)


def _value_xml(kind, value, prefix=""):
    text = repr(float(value)) if kind == "Real" else str(int(value))
    return f'<{prefix}{kind} value="{text}"/>'


def write_osp(system, step, folder):
    """An OSP system structure for libcosim (sources absolute), as the shipped ones."""
    sims = []
    for name, path, params in (("TrackContact", os.path.join(FMU_DIR, "TrackContact.fmu"), system["track"]),
                               system["partner"]):
        values = "".join(f'\n        <InitialValue variable="{n}">{_value_xml(t, v)}</InitialValue>'
                         for n, (t, v) in params.items())
        sims.append(f'    <Simulator name="{name}" source="{path}">\n      <InitialValues>{values}\n'
                    f'      </InitialValues>\n    </Simulator>')
    conns = "".join(f'\n    <VariableConnection><Variable simulator="{a}" name="{x}"/>'
                    f'<Variable simulator="{b}" name="{y}"/></VariableConnection>'
                    for a, x, b, y in system["connections"])
    xml = f"""<?xml version="1.0" encoding="utf-8"?>
<OspSystemStructure xmlns="http://opensimulationplatform.com/MSMI/OSPSystemStructure" version="0.1">
  <StartTime>0.0</StartTime>
  <BaseStepSize>{step!r}</BaseStepSize>
  <Algorithm>fixedStep</Algorithm>
  <Simulators>
{chr(10).join(sims)}
  </Simulators>
  <Connections>{conns}
  </Connections>
</OspSystemStructure>
"""
    path = os.path.join(folder, "OspSystemStructure.xml")
    with open(path, "w") as f:
        f.write(xml)
    return path


def write_ssp(system, step, folder):
    """An SSP archive for ecos, as the shipped ones: SystemStructure.ssd at the root, both
    FMUs under resources/, the parameters as the inline set ``wheelflat``."""
    from fmpy import read_model_description
    comps = []
    members = []
    for name, path, params in (("TrackContact", os.path.join(FMU_DIR, "TrackContact.fmu"), system["track"]),
                               system["partner"]):
        md = read_model_description(path)
        causality = {v.name: v.causality for v in md.modelVariables}
        used = {x for a, x, b, y in system["connections"] if a == name} | \
               {y for a, x, b, y in system["connections"] if b == name}
        connectors = "".join(f'\n          <ssd:Connector name="{v}" kind="{causality[v]}"><ssc:Real/></ssd:Connector>'
                             for v in sorted(used))
        values = "".join(f'\n                  <ssv:Parameter name="{n}">{_value_xml(t, v, "ssv:")}</ssv:Parameter>'
                         for n, (t, v) in params.items())
        source = f"resources/{os.path.basename(path)}"
        members.append((path, source))
        comps.append(f"""      <ssd:Component name="{name}" source="{source}">
        <ssd:Connectors>{connectors}
        </ssd:Connectors>
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="wheelflat">
                <ssv:Parameters>{values}
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>
      </ssd:Component>""")
    conns = "".join(f'\n      <ssd:Connection startElement="{a}" startConnector="{x}" endElement="{b}" '
                    f'endConnector="{y}"/>' for a, x, b, y in system["connections"])
    ssd = f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription
    xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription"
    xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon"
    xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"
    xmlns:osp="http://opensimulationplatform.com/SSP/OSPAnnotations"
    name="partner_bogie" version="1.0">
  <ssd:System name="partner_bogie">
    <ssd:Elements>
{chr(10).join(comps)}
    </ssd:Elements>
    <ssd:Connections>{conns}
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="{STOP!r}">
    <ssd:Annotations>
      <ssc:Annotation type="com.opensimulationplatform">
        <osp:Algorithm>
          <osp:FixedStepAlgorithm baseStepSize="{step!r}"/>
        </osp:Algorithm>
      </ssc:Annotation>
    </ssd:Annotations>
  </ssd:DefaultExperiment>
</ssd:SystemStructureDescription>
"""
    path = os.path.join(folder, "partner_bogie.ssp")
    with zipfile.ZipFile(path, "w", zipfile.ZIP_STORED) as z:
        z.writestr("SystemStructure.ssd", ssd)
        for src, arc in members:
            z.write(src, arc)
    return path


# ---------------------------------------------------------------------------------------
# The worker: one cell in this process.

STATUS_NAMES = ("ok", "warning", "discard", "error", "fatal", "pending")


def _fmpy_cell(c, system):
    """The fmpy loops: every call's status and every logged message, per instance."""
    import ctypes
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    logs = []
    statuses = {"TrackContact": {}, "partner": {}}

    def logger(env, name, status, category, message):
        logs.append((name.decode(errors="replace"), int(status), category.decode(errors="replace"),
                     message.decode(errors="replace")))

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(logger)
    callbacks.allocateMemory = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)(
        lambda n, s: None)
    callbacks.freeMemory = ctypes.CFUNCTYPE(None, ctypes.c_void_p)(lambda p: None)

    def watch(unit, key):
        """Counts the status of every FMI call of `unit` (fmpy raises above fmi2Warning)."""
        f = unit.fmu

        def wrapped(fname, *args):
            fn = f._functions[fname]
            res = fn(*args)
            if fn.restype == ctypes.c_int:
                name = STATUS_NAMES[res] if 0 <= res < len(STATUS_NAMES) else str(res)
                statuses[key][name] = statuses[key].get(name, 0) + 1
                if res > 1:
                    raise FMICallException(function=fname, status=res)
            return res
        f._call = wrapped

    pname, ppath, pparams = system["partner"]
    track = wf.Unit(os.path.join(FMU_DIR, "TrackContact.fmu"), "TrackContact", callbacks=callbacks)
    partner = wf.Unit(ppath, pname, callbacks=callbacks)
    watch(track, "TrackContact")
    watch(partner, "partner")
    frames_to = [y for a, x, b, y in system["connections"] if b == "TrackContact"]
    frames_from = [x for a, x, b, y in system["connections"] if b == "TrackContact"]
    prim_from = [x for a, x, b, y in system["connections"] if a == "TrackContact"]
    prim_to = [y for a, x, b, y in system["connections"] if a == "TrackContact"]
    h = c["step"]
    steps = int(round(c["stop"] / h))
    t = 0.0
    failure = None
    reached = 0.0
    peaks = None
    try:
        for u, params in ((track, system["track"]), (partner, pparams)):
            u.fmu.setupExperiment(startTime=0.0)
            u.set_parameters({n: v for n, (_, v) in params.items()})
        for u in (track, partner):
            u.fmu.enterInitializationMode()
        for u in (track, partner):
            u.fmu.exitInitializationMode()
        jacobi = c["master"] == "fmpy_jacobi"
        for k in range(steps):
            t = k * h
            if jacobi:  # every output of this point before any input is set
                f = track.get(*prim_from)
                z = partner.get(*frames_from)
                partner.set(prim_to, f)
                track.set(frames_to, z)
                track.fmu.doStep(t, h)
                partner.fmu.doStep(t, h)
            else:
                track.set(frames_to, partner.get(*frames_from))
                track.fmu.doStep(t, h)
                partner.set(prim_to, track.get(*prim_from))
                partner.fmu.doStep(t, h)
            reached = (k + 1) * h
            # The largest forces so far, kept for a run that fails later.
            peaks = track.get(*system["forces"])
    except FMICallException as e:
        failure = f"{e} at t = {t:g} s"
    try:
        wf.close_all(track, partner)
    except Exception:  # noqa: BLE001 - a unit that failed may refuse to terminate
        pass
    warn = [(n, s, m) for n, s, cat, m in logs if s >= 1]
    if failure:
        msgs = [m for n, s, m in warn if s >= 2]
        if msgs:
            failure += ": " + msgs[0][:300]
    return dict(peaks=peaks, failure=failure, time=reached,
                track_messages=[(STATUS_NAMES[s], m) for n, s, m in warn if n == "TrackContact"],
                partner_messages=[(STATUS_NAMES[s], m) for n, s, m in warn if n != "TrackContact"],
                statuses=statuses, statuses_known=True)


def _libcosim_cell(c, system, folder):
    from libcosimpy import _internal
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    log_output_level(CosimLogLevel.WARNING)
    ex = CosimExecution.from_osp_config_file(write_osp(system, c["step"], folder))
    track = ex.slave_index_from_instance_name("TrackContact")
    vr = {v.name.decode(): v.reference for v in ex.slave_variables(track)}
    last = CosimObserver.create_last_value()
    ex.add_observer(last)
    sys.stdout.flush()
    ok = ex.simulate_until(int(round(c["stop"] * 1e9)))
    failure = None if ok else f"simulate_until false: {_internal.get_last_error_message()}"
    vals = last.last_real_values(track, [vr[x] for x in system["forces"]])
    reached = ex.status().current_time * 1e-9
    return dict(peaks=list(vals), failure=failure, time=reached, statuses_known=False)


def _ecos_cell(c, system, folder):
    from ecospy import EcosLib, EcosSimulation

    # Statuses other than fmi2OK show only at ecos' debug level.
    EcosLib.set_log_level("debug")
    sim = EcosSimulation(ssp_path=write_ssp(system, c["step"], folder), step_size=c["step"])
    sim.init(parameter_set="wheelflat")
    # sim.step(n), not step_until: ecos sums its clock and can stop one step short.
    sim.step(int(round(c["stop"] / c["step"])))
    vals = [sim.get_real("TrackContact::" + x) for x in system["forces"] + ["position"]]
    reached = sim.get_time()
    sim.terminate()
    sim.free()
    return dict(peaks=vals[:-1], position=vals[-1], failure=None, time=reached, statuses_known=True)


def worker(c, standin_fmu):
    system = system_of(c, standin_fmu)
    folder = tempfile.mkdtemp(prefix="partner_cell_")
    t0 = time.perf_counter()
    try:
        if c["master"] == "libcosim":
            r = _libcosim_cell(c, system, folder)
        elif c["master"] == "ecos":
            r = _ecos_cell(c, system, folder)
        else:
            r = _fmpy_cell(c, system)
    finally:
        shutil.rmtree(folder, ignore_errors=True)
    r["wall"] = time.perf_counter() - t0
    sys.stdout.flush()
    sys.stderr.flush()
    print("RESULT " + json.dumps(r), flush=True)


# ---------------------------------------------------------------------------------------
# The parent: references, a cell in a subprocess, its reading.


@functools.lru_cache(maxsize=None)
def reference(partner, scale=1.0, stop=STOP, fmu_dir=None):
    """CoupledSystem's largest contact force of every wheel (N) over `stop` s: the
    half-car (vehicle.model = half_car, the side frames' mass and pitch inertia scaled
    by `scale`; vehicle.sideframe.mass is per axle box, half a side frame) or the wagon,
    on the track, wheelsets and offsets the cell gives TrackContact (the shipped
    system's; wheelflat_masters.coupled_params gives the same)."""
    from fmpy import read_model_description, simulate_fmu

    coupled = os.path.join(fmu_dir or FMU_DIR, "CoupledSystem.fmu")
    own = {v.name for v in read_model_description(coupled).modelVariables if v.causality == "parameter"}
    system = system_of(cell("fmpy_seq", 1e-3, "force", scale, partner))
    # Not interface (CoupledSystem has none) nor static_load.* (it computes them).
    start = {n: v for n, (_, v) in system["track"].items() if n in own and not n.startswith("static_load.")}
    if partner != "wagon":
        p = standin_parameters(scale)
        start["vehicle.sideframe.mass"] = 0.5 * p["m_sideframe"] * scale
        start["vehicle.sideframe.pitch_inertia"] = p["J_sideframe"] * scale
    r = simulate_fmu(coupled, stop_time=stop, start_values=start, output=system["forces"], output_interval=1e-3)
    return tuple(float(r[x][-1]) for x in system["forces"])


# Short names of TrackContact's warnings, by a phrase of their text; others are named
# by their first words.
KINDS = (("struck the rail", "exchange bounces"), ("inputs.datum", "input datum"),
         ("side frames, fitted from the exchange", "side-frame copy"),
         ("the bogie holds primary", "output choice"),
         ("estimated from what TrackContact carries", "axle-box step"),
         ("primary forces jumped", "axle-box jump"))


def _kind(message):
    """A short name for a warning (KINDS), else its text after "at t = ... s", its first words."""
    for phrase, name in KINDS:
        if phrase in message:
            return name
    m = re.sub(r"^\s*(fmi2\w+:?\s*)?(at t = \S+ s\s*)?", "", message)
    return " ".join(m.split()[:6])


# The Wagon's own warnings (a vehicle FMU's: its step above its estimate, its first
# step's forces off its rest), which libcosim's log prints without the instance name.
VEHICLE_WARNING = re.compile(r"the largest at which the axle-box exchange stays stable|that drove the first step")


def _partner_kind(message):
    """The Wagon's warnings by name: its step above its estimate, its first step's forces."""
    if "that drove the first step" in message:
        return "static load"
    if "axle-box exchange stays stable" in message or "communication step" in message:
        return "axle-box step"
    return _kind(message)


def _libcosim_log(log, partner):
    """TrackContact's and the partner's warnings and errors in libcosim's log."""
    track, other = [], []
    for line in log.splitlines():
        m = re.search(r"\[(warning|error)\]\s*\[FMI status=(\w+)[^\]]*\]\s*(.*)", line)
        if not m:
            continue
        status, text = m.group(2), m.group(3)
        mine = partner == "standin" or not VEHICLE_WARNING.search(text) or "what TrackContact carries" in text
        (track if mine else other).append((status, text))
    return track, other


def _ecos_log(log):
    """TrackContact's and the partner's non-OK statuses in ecos' debug log: lines
    ``[ecos] [debug] [<fmu path>] fmi2Warning <call>: <message>``."""
    track, other, counts = [], [], {}
    for line in log.splitlines():
        m = re.search(r"\[([^\]]*\.fmu)\]\s*fmi2(Warning|Discard|Error|Fatal)\b:?\s*(.*)", line)
        if not m:
            continue
        status = m.group(2).lower()
        is_track = os.path.basename(m.group(1)).startswith("TrackContact")
        (track if is_track else other).append((status, m.group(3)))
        key = "TrackContact" if is_track else "partner"
        counts.setdefault(key, {})
        counts[key][status] = counts[key].get(status, 0) + 1
    return track, other, counts


def run_cell(c, standin_fmu=None, keep_log=False, fmu_dir=None):
    """Runs the cell `c` (:func:`cell`) in a subprocess; returns a dict: ``error`` (the
    largest relative peak error over the wheels, None when the run gave no peaks),
    ``errors`` (per wheel), ``peaks`` and ``reference`` (N), ``diverged`` (a failed run,
    or an error over 100 %), ``failure`` (the message), ``time`` (s reached),
    ``warnings`` (TrackContact's fmi2Warning messages, first 100 characters each, in
    order), ``track_statuses`` (non-OK statuses TrackContact returned, as far as the
    master reports them: "warning", "discard", "error" with counts; in the fmpy loops
    every call's, ``ok`` included), ``statuses_known`` (False for libcosim, whose log
    shows warnings and errors but no per-call status), ``warned`` (TrackContact
    returned fmi2Warning), ``partner_warnings``, ``wall`` (s). `fmu_dir`: the folder of
    TrackContact, Wagon and CoupledSystem (default FMU_DIR, fmu/)."""
    fmu_dir = os.path.abspath(fmu_dir or FMU_DIR)
    if c["partner"] == "standin" and standin_fmu is None:
        from partner_bogie import build
        standin_fmu = build.build()
    tmp = tempfile.mkdtemp(prefix="partner_matrix_")
    t0 = time.perf_counter()
    try:
        try:
            p = subprocess.run([sys.executable, os.path.abspath(__file__), "--cell", json.dumps(c),
                                "--standin", standin_fmu or "", "--fmu-dir", fmu_dir], cwd=ROOT,
                               capture_output=True, text=True, timeout=CELL_TIMEOUT, env=dict(os.environ, TMPDIR=tmp))
            out, err, rc = p.stdout, p.stderr, p.returncode
        except subprocess.TimeoutExpired as e:
            out = (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
            err = (e.stderr or b"").decode(errors="replace") if isinstance(e.stderr, bytes) else (e.stderr or "")
            rc = "timeout"
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    log = out + err
    line = next((x for x in out.splitlines() if x.startswith("RESULT ")), None)
    ref = reference(c["partner"], c["scale"], c["stop"], fmu_dir)
    if line is None:
        r = dict(peaks=None, failure=f"the cell's process ended without a result (exit {rc}): {log[-500:]}",
                 time=None, statuses_known=False)
    else:
        r = json.loads(line[len("RESULT "):])
    if c["master"] in ("fmpy_jacobi", "fmpy_seq") and "track_messages" in r:
        track_msgs = r.pop("track_messages")
        partner_msgs = r.pop("partner_messages")
        track_statuses = {k: v for k, v in r.pop("statuses")["TrackContact"].items()}
    elif c["master"] == "ecos":
        track_msgs, partner_msgs, counts = _ecos_log(log)
        track_statuses = counts.get("TrackContact", {})
        # ecos steps on past a refused step: the failure is what its log says.
        errors = [m for s, m in track_msgs + partner_msgs if s in ("error", "fatal", "discard")]
        if errors and not r.get("failure"):
            r["failure"] = f"fmi2 {[s for s, m in track_msgs + partner_msgs if s != 'warning'][0]}: {errors[0][:300]}"
            at = re.search(r"at t = (\S+) s", errors[0])
            r["time"] = float(at.group(1)) if at else None
            # After a refused call ecos' get_real returns no FMU's values.
            r["peaks"] = None
    else:
        track_msgs, partner_msgs = _libcosim_log(log, c["partner"])
        track_statuses = {}
        for s, _ in track_msgs:
            track_statuses[s] = track_statuses.get(s, 0) + 1
    peaks = r.get("peaks")
    errors = None
    error = None
    if peaks and all(x is not None and math.isfinite(x) for x in peaks):
        errors = [x / m - 1 for x, m in zip(peaks, ref)]
        error = max(abs(e) for e in errors)
    failure = r.get("failure")
    diverged = bool(failure) or error is None or error > DIVERGED
    warnings = [m for s, m in track_msgs if s == "warning"]
    res = dict(cell=c, error=error, errors=errors, peaks=peaks, reference=list(ref), diverged=diverged,
               failure=failure, time=r.get("time"), warnings=warnings,
               warning_kinds=sorted({_kind(m) for s, m in track_msgs if s == "warning"}),
               track_statuses=track_statuses, statuses_known=r.get("statuses_known", False),
               warned=bool(warnings), partner_warnings=[m for s, m in partner_msgs if s == "warning"],
               wall=time.perf_counter() - t0)
    res["rule_broken"] = rule_broken(res)
    if keep_log:
        res["log"] = log
    return res


def rule_broken(r):
    """The rule: TrackContact warns where the error is over 1 % or the run diverges,
    and not where it is within 1 %."""
    bad = r["diverged"] or r["error"] is None or r["error"] > TOLERANCE
    return bad != r["warned"]


def run_cells(cells, standin_fmu=None, workers=2, progress=True):
    if any(c["partner"] == "standin" for c in cells) and standin_fmu is None:
        from partner_bogie import build
        standin_fmu = build.build()
    # The references first, in this process (one CoupledSystem run each).
    for c in cells:
        reference(c["partner"], c["scale"], c["stop"], FMU_DIR)
    results = [None] * len(cells)
    with concurrent.futures.ThreadPoolExecutor(max_workers=workers) as pool:
        futures = {pool.submit(run_cell, c, standin_fmu, False, FMU_DIR): i for i, c in enumerate(cells)}
        for done, f in enumerate(concurrent.futures.as_completed(futures), 1):
            i = futures[f]
            results[i] = f.result()
            if progress:
                r = results[i]
                what = "diverged" if r["diverged"] else f"{100 * r['error']:.2f} %"
                print(f"[{done}/{len(cells)}] {label(cells[i])}: {what}{', warned' if r['warned'] else ''} "
                      f"({r['wall']:.1f} s)", file=sys.stderr, flush=True)
    return results


MASTER_NAMES = {"libcosim": "OSP libcosim (Jacobi)", "ecos": "ecos (Jacobi)", "fmpy_jacobi": "fmpy Jacobi",
                "fmpy_seq": "fmpy sequential"}


def table(results):
    """The markdown table: one row per cell."""
    rows = ["| partner | master | step | scale | output | peak error | diverged | TrackContact warned | partner warned "
            "| rule |",
            "|---|---|---|---|---|---|---|---|---|---|"]
    for r in results:
        c = r["cell"]
        err = "-" if r["error"] is None else f"{100 * r['error']:.2f} %"
        div = "no"
        if r["diverged"]:
            div = "yes" + (f" (t = {r['time']:.3g} s)" if r.get("failure") and r.get("time") is not None else "")
        if r["warned"]:
            warned = "yes: " + "; ".join(r["warning_kinds"])
        else:
            warned = "no"
        if c["master"] == "libcosim":
            warned += " (log)"
        others = sorted({k for k in r["track_statuses"] if k not in ("ok", "warning")})
        if others:
            warned += " [" + ", ".join(others) + "]"
        rule = "**BROKEN**" if r["rule_broken"] else "ok"
        theirs = "yes: " + "; ".join(sorted({_partner_kind(m) for m in r["partner_warnings"]})) \
            if r["partner_warnings"] else "no"
        rows.append(f"| {c['partner']} | {MASTER_NAMES[c['master']]} | {c['step'] * 1e3:g} ms | {c['scale']:g} | "
                    f"`{c['output']}` | {err} | {div} | {warned} | {theirs} | {rule} |")
    return "\n".join(rows)


def parse_only(specs):
    """``--only master=libcosim,ecos --only step=1,4 --only scale=1 --only output=force
    --only partner=wagon``: keep the cells with those values (steps in ms)."""
    keep = {}
    for s in specs or []:
        k, _, v = s.partition("=")
        vals = v.split(",")
        if k == "step":
            keep[k] = {round(float(x) * 1e-3, 12) for x in vals}
        elif k == "scale":
            keep[k] = {float(x) for x in vals}
        elif k in ("master", "output", "partner"):
            keep[k] = set(vals)
        else:
            raise SystemExit(f"--only {s}: the keys are master, step (ms), scale, output, partner")
    return lambda c: all((round(c[k], 12) if k == "step" else c[k]) in vals for k, vals in keep.items())


def main():
    ap = argparse.ArgumentParser(description="Issue 41's coupling matrix: the pythonfmu stand-in half-car bogie "
                                             "and the Wagon with TrackContact at the axle boxes in four masters.")
    ap.add_argument("--quick", action="store_true", help="libcosim and fmpy sequential at 1 and 4 ms only")
    ap.add_argument("--only", action="append", metavar="KEY=V[,V]",
                    help="keep cells with these values: master, step (ms), scale, output, partner")
    ap.add_argument("--json", metavar="PATH", help="write the results as JSON")
    ap.add_argument("--workers", type=int, default=2, help="cells at once (at most 2 on this machine)")
    ap.add_argument("--fmu-dir", help="the folder of TrackContact.fmu, Wagon.fmu and CoupledSystem.fmu "
                                      "(default fmu/; the shipped systems' parameters are read from fmu/systems/)")
    ap.add_argument("--cell", help=argparse.SUPPRESS)
    ap.add_argument("--standin", help=argparse.SUPPRESS)
    a = ap.parse_args()
    global FMU_DIR
    if a.fmu_dir:
        FMU_DIR = os.path.abspath(a.fmu_dir)
    if a.cell:
        worker(json.loads(a.cell), a.standin or None)
        return
    wf.ensure_venv()
    cells = [c for c in matrix_cells(a.quick) if parse_only(a.only)(c)]
    t0 = time.perf_counter()
    results = run_cells(cells, workers=min(max(a.workers, 1), 2))
    wall = time.perf_counter() - t0
    print(f"case: 70 km/h, TrackContact's reference flat, endless track (20 m a side), {STOP} s; "
          f"{len(cells)} cells in {wall:.0f} s; FMUs of {os.path.relpath(FMU_DIR, ROOT)}")
    for partner, scale in sorted({(c["partner"], c["scale"]) for c in cells}):
        ref = reference(partner, scale, STOP, FMU_DIR)
        print(f"CoupledSystem {partner}{'' if partner == 'wagon' else f' scale {scale:g}'}: "
              + ", ".join(f"{x / 1e3:.2f}" for x in ref) + " kN")
    print()
    print(table(results))
    broken = sum(r["rule_broken"] for r in results)
    print(f"\nrule broken in {broken} of {len(results)} cells")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(dict(cells=len(cells), wall=wall, results=results), f, indent=1)


if __name__ == "__main__":
    main()
