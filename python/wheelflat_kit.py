#!/usr/bin/env python3
"""The regression kit: reference results of every FMU of the registry (fmu/fmus.json),
laid out as the Modelica FMI Cross-Check lays out an exporting tool's FMUs, and the check
of a build against them.

    python3 python/wheelflat_kit.py write [--fmus fmu] [--kit KIT]
    python3 python/wheelflat_kit.py check [--fmus fmu | --beside] [--kit KIT]
                                          [--tolerance 1e-6] [--set MODEL:NAME=VALUE]...
    python3 python/wheelflat_kit.py copy  [--fmus fmu] [--kit KIT]

KIT is the tool version's folder, by default
regression/2.0/cs/linux64/wheelflat/<version of Cargo.toml>; each model has its folder
<Model>/ in it with the Cross-Check's files (FMI-CROSS-CHECK-RULES.md, 9.1.4):
<Model>_ref.csv (the reference: time and up to 10 outputs), <Model>_in.csv (the inputs
the FMU takes at its defaults), <Model>_ref.opt (StartTime, StopTime, StepSize, RelTol,
OutputIntervalLength), ReadMe.md (what the reference is and the fmpy commands that
reproduce it) and, once copied there, <Model>.fmu.

write   simulates each FMU of --fmus with fmpy.simulate_fmu on its case and writes the kit.
check   simulates each FMU as its _ref.opt and _in.csv say and compares the result with
        _ref.csv twice: by the Cross-Check's rule (fmpy.cross_check.validate_result's
        epsilon band: a signal fails with more than 10 % of its samples outside a band
        of 10 % of its range), and sample by sample within --tolerance (relative to the
        signal's largest magnitude or range; 0 or less: the band only). --set changes a
        parameter's start value for the check. Exit 1, naming the model and the signal,
        on a mismatch.
copy    puts each <Model>.fmu of --fmus beside its references (git ignores it there);
        check --beside then checks those.

Runs itself inside .venv (created on first use).
"""

import argparse
import os
import re
import shutil
import sys
import time
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

PLATFORM = "linux64"
TOOL = "wheelflat"
# Every case runs from START to STOP; its communication step (fmpy's output interval, the
# reference's sample spacing) is STEP, TrackContact's TRACK_STEP: one track step (the
# default solver.step is 14.41 us), as the FMU asks of a master that holds the wheel
# heights over a step (more than 1.5 track steps: fmi2Warning).
START, STOP, STEP, TRACK_STEP = 0.0, 0.05, 1e-4, 1.25e-5
T_FORCE_STEP = 0.01
# TrackContact's wheel heights: CoupledSystem's, sampled this often.
TRACK_INPUT_STEP = 1e-4
# The check's default sample-by-sample tolerance, relative to a signal's scale.
TOLERANCE = 1e-6
# The leading wheelset's contact forces after their step, times the static load.
FORCE_STEP = {"contact.left.force": 1.2, "contact.right.force": 0.9}

VEHICLE_CASE = ("the contact forces of the leading wheelset step at {step:g} s from the static wheel "
                "load to 1.2 times it on the left wheel and 0.9 times it on the right; ")

# The outputs each reference holds (at most 10, the Cross-Check's advice), per model.
OUTPUTS = {
    "TrackContact": ["contact.left.force", "contact.right.force", "contact.left.max_force", "rail.left.z",
                     "position"],
    "RollPlaneVehicle": ["wheel.left.z", "wheel.right.z", "wheel.rotation", "wheelset.z", "wheelset.roll",
                         "sideframe.left.z", "bolster.z", "bolster.roll", "primary.left.force",
                         "primary.right.force"],
    "HalfCarBogie": ["wheel.left.z", "wheel.right.z", "wheelset.z", "wheelset.roll", "wheelset[2].z",
                     "sideframe.left.pitch", "bolster.z", "bolster.roll", "primary.left.force",
                     "wheelset[2].primary.left.force"],
    "Wagon": ["wheel.left.z", "wheel.right.z", "wheelset.z", "wheelset.roll", "wheelset[2].z", "wheelset[4].z",
              "carbody.z", "carbody.pitch", "carbody.roll", "primary.left.force"],
    "TwoAxleWagon": ["wheel.left.z", "wheel.right.z", "wheelset.z", "wheelset.roll", "wheelset[2].z",
                     "carbody.z", "carbody.pitch", "carbody.roll", "primary.left.force",
                     "wheelset[2].primary.left.force"],
    "CoupledSystem": ["contact.left.force", "contact.right.force", "contact.left.max_force", "wheel.left.z",
                      "wheel.right.z", "rail.left.z", "wheelset.z", "bolster.z", "primary.left.force", "position"],
}


def version():
    """The package version of Cargo.toml ([package] version)."""
    text = open(os.path.join(wf.ROOT, "Cargo.toml")).read()
    package = text.split("[package]", 1)[1].split("\n[", 1)[0]
    return re.search(r'^version\s*=\s*"([^"]+)"', package, re.M).group(1)


def default_kit():
    """regression/2.0/cs/linux64/wheelflat/<version>: the Cross-Check's
    fmus/{FMI_Version}/{FMI_Type}/{Platform}/{Tool_Name}/{Tool_Version} under regression/."""
    return os.path.join(wf.ROOT, "regression", "2.0", "cs", PLATFORM, TOOL, version())


def in_layout(kit_dir):
    """Whether `kit_dir` ends in the Cross-Check's 2.0/cs/<platform>/<tool>/<version>,
    which fmpy's validate_test_fmu reads the FMI version and type from."""
    parts = os.path.abspath(kit_dir).split(os.sep)
    return len(parts) > 5 and parts[-5:-3] == ["2.0", "cs"]


def files(kit_dir, model):
    """The paths of a model's files in the kit, by kind (fmu, ref, in, opt, readme)."""
    d = os.path.join(kit_dir, model)
    return {"dir": d, "fmu": os.path.join(d, model + ".fmu"), "ref": os.path.join(d, model + "_ref.csv"),
            "in": os.path.join(d, model + "_in.csv"), "opt": os.path.join(d, model + "_ref.opt"),
            "readme": os.path.join(d, "ReadMe.md")}


def _md(path):
    from fmpy import read_model_description
    return read_model_description(path)


def step_of(model):
    """The model's communication step: TRACK_STEP for TrackContact, else STEP."""
    return TRACK_STEP if model == "TrackContact" else STEP


def in_use(model, name):
    """Whether the input `name` is one the model takes at its defaults, the contact
    interface with TrackContact carrying one wheelset: the FMUs refuse a value for an
    input of the other interface (axle_box.*, sideframe.*) and TrackContact for a
    wheelset it does not carry (wheelset[k].*), so the input file leaves those out."""
    other = "axle_box." in name or name.startswith("sideframe.") or ".sideframe." in name
    return not other and not (model == "TrackContact" and name.startswith("wheelset["))


def _inputs_at_start(model, md):
    """The inputs in use (:func:`in_use`), by name, at their start values."""
    return {v.name: float(v.start) for v in md.modelVariables if v.causality == "input" and in_use(model, v.name)}


def _table(rows, names):
    """A structured array (time first) from rows of (time, {name: value})."""
    import numpy as np
    dtype = [("time", np.float64)] + [(n, np.float64) for n in names]
    return np.array([(t,) + tuple(v[n] for n in names) for t, v in rows], dtype=dtype)


# fmpy (0.3.32) routes every FMI 2.0 logger through one native proxy that keeps the last
# logger given to it: simulate_fmu(logger=...) points it at a callback that dies with the
# call, and the next FMU that logs through fmpy's default callbacks (debug logging, a
# warning) then calls freed memory and crashes the process. After such a run the proxy is
# pointed back at fmpy's own printing logger, kept alive here.
_DEFAULT_LOGGER = []


def restore_fmpy_logger():
    """Points fmpy's FMI 2.0 logger proxy back at fmpy's default logger (see above); call
    after every simulate_fmu(logger=...) of an FMI 2.0 FMU. The proxy takes the logger of
    a callbacks structure whose logger is not the proxy already (it puts itself there):
    a fresh structure each time, its logger one callback kept alive here."""
    import ctypes
    import fmpy.fmi2 as fmi2
    from fmpy.logging import addLoggerProxy
    if not _DEFAULT_LOGGER:
        _DEFAULT_LOGGER.append(fmi2.fmi2CallbackLoggerTYPE(fmi2.printLogMessage))
    callbacks = fmi2.fmi2CallbackFunctions()
    callbacks.logger = _DEFAULT_LOGGER[0]
    addLoggerProxy(ctypes.byref(callbacks))


class Log:
    """The FMU's log messages of a run, for fmpy.simulate_fmu(logger=...)."""

    STATUS = {0: "OK", 1: "WARNING", 2: "DISCARD", 3: "ERROR", 4: "FATAL", 5: "PENDING"}

    def __init__(self):
        self.records = []

    def __call__(self, env, instance, status, category, message):
        self.records.append((self.STATUS.get(status, str(status)), message.decode(errors="replace")))

    def above_ok(self):
        return [f"[{s}] {m}" for s, m in self.records if s != "OK"]


def simulate(path, model, stop, step, inp, outputs, start_values=None, start=START):
    """fmpy.simulate_fmu as the kit runs it: the case's span and step, its input table,
    the outputs; fmpy's own notices (none expected) and the FMU's log kept, not printed.
    Returns the result and the FMU's messages above OK."""
    import contextlib
    import io
    from fmpy import simulate_fmu
    log = Log()
    try:
        with contextlib.redirect_stdout(io.StringIO()):
            r = simulate_fmu(path, start_time=start, stop_time=stop, output_interval=step, input=inp,
                             output=outputs, start_values=start_values or {}, logger=log)
    finally:
        restore_fmpy_logger()
    return r, log.above_ok()


def case_inputs(model, md, fmu_dir):
    """The model's input table (the inputs in use, held at their start values but for
    those the case drives), what it gives in words, and the driven inputs."""
    start = _inputs_at_start(model, md)
    names = list(start)
    if model == "TrackContact":
        driven = ("wheel.left.z", "wheel.right.z", "wheel.rotation")
        r, _ = simulate(os.path.join(fmu_dir, "CoupledSystem.fmu"), "CoupledSystem", STOP, TRACK_INPUT_STEP, None,
                        list(driven))
        rows = [(float(row["time"]), dict(start, **{n: float(row[n]) for n in driven})) for row in r]
        words = (f"the leading wheelset's `wheel.left.z`, `wheel.right.z` and `wheel.rotation` as CoupledSystem "
                 f"gives them with its defaults (table 4.4, 70 km/h, the 100 mm x 1.5 mm flat on the left wheel, "
                 f"90 degrees ahead of the contact at t = 0), every {TRACK_INPUT_STEP * 1e3:g} ms: the "
                 f"flat reaches the rail at about 34 ms, the wheel falls into it and strikes the rail")
    elif model == "CoupledSystem":
        rows = [(START, start), (STOP, start)]
        driven = ()
        words = "its defaults: `speed` 70 km/h (table 4.4, the 100 mm x 1.5 mm flat on the left wheel)"
    else:
        stepped = dict(start, **{n: start[n] * k for n, k in FORCE_STEP.items()})
        rows = [(START, start), (T_FORCE_STEP, start), (T_FORCE_STEP, stepped), (STOP, stepped)]
        driven = tuple(FORCE_STEP)
        words = (VEHICLE_CASE.format(step=T_FORCE_STEP)
                 + f"the static wheel load is the inputs' start value ({start['contact.left.force'] / 1e3:.2f} kN)"
                 + (", and the other wheelsets' contact forces stay there" if "wheelset[2].contact.left.force" in start
                    else ""))
    return _table(rows, names), words, driven


def write_opt(path, step):
    """The Cross-Check's _ref.opt (9.1.4): required StartTime, StopTime, StepSize (the
    communication step), RelTol (the FMUs step with a fixed explicit step and take no
    tolerance), and OutputIntervalLength."""
    with open(path, "w") as f:
        f.write(f"StartTime,{START!r}\nStopTime,{STOP!r}\nStepSize,{step!r}\nRelTol,0.0\n"
                f"OutputIntervalLength,{step!r}\n")


def _unit(v):
    return v.unit or (v.declaredType.unit if v.declaredType is not None else None) or ""


def fmpy_command(model, outputs):
    """The fmpy command line that reproduces the reference, run in the model's folder
    with the FMU beside it."""
    quoted = " ".join(f"'{n}'" if "[" in n else n for n in outputs)
    return (f"fmpy simulate {model}.fmu --input-file {model}_in.csv"
            + f" --start-time {START:g} --stop-time {STOP:g} --output-interval {step_of(model):g}"
            + f" --output-variables {quoted} --output-file {model}_out.csv")


def readme(model, md, words, driven, ref):
    """The model's ReadMe.md: what the reference is, its inputs and outputs, and the
    commands that check a build against it."""
    import numpy as np
    var = {v.name: v for v in md.modelVariables}
    outputs = list(ref.dtype.names[1:])
    lines = [
        f"# {model}: regression reference of wheelflat {version()}", "",
        "## Model Info", "",
        f"|Model Name|{model}|", "|-|-|",
        f"|Description|{md.description.split(':')[0].split('. ')[0]}|" if md.description else f"|Description|{model}|",
        "|FMI Version|2.0|", "|FMI Type|Co-Simulation|", f"|Platform|{PLATFORM}|",
        f"|Generation Tool|wheelflat {version()} ({md.generationTool})|", "",
        "## The reference", "",
        f"`{model}_ref.csv` is what `fmpy.simulate_fmu` gives for this FMU from {START:g} s to {STOP:g} s, "
        f"one communication step of {step_of(model) * 1e3:g} ms per sample (`{model}_ref.opt`: StartTime, "
        f"StopTime, StepSize = OutputIntervalLength = the communication step; RelTol 0: the FMU steps with a "
        f"fixed explicit step of its own and takes no tolerance), every parameter at its start value, with "
        f"the inputs of `{model}_in.csv`: {words}."
        + (" One communication step is one track step (`solver.step`, 14.41 us by default, shortened to fit "
           "the step): TrackContact warns (`fmi2Warning`) of a master that holds the wheel heights over "
           "more than 1.5 track steps. fmpy records the outputs after each step, before it sets the next "
           "heights: `contact.*.force` there is the force under the heights held over the step, while "
           "`contact.*.max_force` also counts the force that each newly set height gives at its point (the "
           "direct feedthrough), which at the impact is about 2 % higher." if model == "TrackContact" else "")
        + " The inputs are interpolated linearly in time, and a time given twice is a step.", "",
        "| input | unit | in the case |", "|---|---|---|",
    ]
    left_out = []
    for n in md.modelVariables:
        if n.causality != "input":
            continue
        if not in_use(model, n.name):
            left_out.append(f"`{n.name}`")
            continue
        what = "driven (above)" if n.name in driven else f"{float(n.start):.10g} (its start value)"
        lines.append(f"| `{n.name}` | {_unit(n) or '-'} | {what} |")
    if left_out:
        why = ("the inputs of the axle-box interface (`interface = axle_box`) and of the wheelsets that "
               "TrackContact carries with `wheelsets` > 1" if model == "TrackContact"
               else "the inputs of the axle-box interface (`interface = axle_box`)")
        lines += ["", f"The file leaves out {why}: {', '.join(left_out)}. The FMU refuses a value for them "
                  "at its defaults (`fmi2Error`: the interface or the wheelset is not in use), and fmpy "
                  "prints `Warning: missing input for variable ...` for each."]
    lines += ["", "| output | unit | range in the reference | description |", "|---|---|---|---|"]
    for n in outputs:
        y = ref[n]
        lines.append(f"| `{n}` | {_unit(var[n]) or '-'} | {np.min(y):.5g} to {np.max(y):.5g} | "
                     f"{(var[n].description or '').replace('|', '/')} |")
    lines += [
        "", "## Check a build", "",
        "With the FMU beside the references (from the repository's root, "
        "`python3 python/wheelflat_kit.py copy` puts each `fmu/<Model>.fmu` there), in this folder, fmpy's "
        "command line (`fmpy`; `.venv/bin/fmpy` in the repository) simulates it as the reference was made:",
        "", "```sh", fmpy_command(model, outputs), "```", "",
        f"With the build that wrote the reference, on an x86-64 CPU with FMA (AVX2 or AVX-512: the track's "
        f"loops round alike at both), `{model}_out.csv` is the reference byte for byte (`cmp {model}_out.csv "
        f"{model}_ref.csv` is silent); without FMA the track's products round apart, and the numbers agree "
        f"to rounding: compare them as below.", "",
        "The kit's check, from the repository's root (every FMU of `fmu/`; `--beside` for those copied "
        "here): the Cross-Check's rule (`fmpy.cross_check.validate_result`'s band: a signal fails with more "
        "than 10 % of its samples outside 10 % of its range) and each sample within 1e-6 of the signal's "
        "scale; exit 1 naming the model and the signal on a mismatch:", "",
        "```sh", "python3 python/wheelflat_kit.py check", "```", "",
        "The Cross-Check's comparison alone, in Python with fmpy (its `validate_result` needs scipy), in "
        "this folder:", "",
        "```python",
        "from fmpy import simulate_fmu",
        "from fmpy.util import read_csv, read_ref_opt_file",
        "from fmpy.cross_check import validate_result",
        "",
        f"opt = read_ref_opt_file('{model}_ref.opt')",
        f"ref = read_csv('{model}_ref.csv')",
        f"res = simulate_fmu('{model}.fmu', start_time=opt['StartTime'], stop_time=opt['StopTime'],",
        f"                   output_interval=opt['StepSize'], input=read_csv('{model}_in.csv'),",
        "                   output=list(ref.dtype.names[1:]))",
        "print(validate_result(res, ref, opt['StartTime'], opt['StopTime']) or 'passed')",
        "```", "",
    ]
    return "\n".join(lines)


def write(fmu_dir=None, kit_dir=None):
    """Writes the kit: each FMU of the registry in `fmu_dir` simulated on its case; the
    kit's folders by model. Returns {model: its folder}."""
    import numpy as np
    from fmpy.util import write_csv
    fmu_dir = fmu_dir or wf.FMU_DIR
    kit_dir = kit_dir or default_kit()
    written = {}
    for model in wf.registry(fmu_dir)["fmus"]:
        if model not in OUTPUTS:
            raise SystemExit(f"{model}: no case in python/wheelflat_kit.py (OUTPUTS); add its outputs there")
        path = os.path.join(fmu_dir, model + ".fmu")
        md = _md(path)
        missing = [n for n in OUTPUTS[model] if n not in {v.name for v in md.modelVariables if v.causality == "output"}]
        if missing:
            raise SystemExit(f"{model}: no output {', '.join(missing)} (OUTPUTS in python/wheelflat_kit.py)")
        inp, words, driven = case_inputs(model, md, fmu_dir)
        ref, messages = simulate(path, model, STOP, step_of(model), inp, OUTPUTS[model])
        if messages:
            raise SystemExit(f"{model}: the FMU logged on its case, which must run clean:\n" + "\n".join(messages))
        if model in ("TrackContact", "CoupledSystem"):
            i = int(np.argmax(ref["contact.left.force"]))
            words += (f"; in the reference the left contact force peaks at {ref['contact.left.force'][i] / 1e3:.1f} "
                      f"kN at {ref['time'][i] * 1e3:.1f} ms")
        f = files(kit_dir, model)
        os.makedirs(f["dir"], exist_ok=True)
        write_csv(f["in"], inp)
        write_csv(f["ref"], ref)
        write_opt(f["opt"], step_of(model))
        with open(f["readme"], "w") as fh:
            fh.write(readme(model, md, words, driven, ref))
        written[model] = f["dir"]
    return written


def copy_fmus(fmu_dir=None, kit_dir=None):
    """Puts each FMU of the registry in `fmu_dir` beside its references; returns the copies."""
    fmu_dir = fmu_dir or wf.FMU_DIR
    kit_dir = kit_dir or default_kit()
    copies = []
    for model in wf.registry(fmu_dir)["fmus"]:
        f = files(kit_dir, model)
        if not os.path.isdir(f["dir"]):
            raise SystemExit(f"{model}: no references in {kit_dir} (run write first)")
        shutil.copyfile(os.path.join(fmu_dir, model + ".fmu"), f["fmu"])
        copies.append(f["fmu"])
    return copies


def validate_signal(**kw):
    """fmpy.cross_check.validate_signal, the Cross-Check's band (it needs scipy, which
    python/requirements.txt pins)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)  # its scipy.ndimage.filters
        from fmpy.cross_check import validate_signal as fmpy_validate_signal
        return fmpy_validate_signal(**kw)


def compare(model, result, reference, opt, tolerance=TOLERANCE, units=None):
    """The problems of `result` against `reference`, each naming the model and the
    signal: the Cross-Check's rule (fmpy.cross_check.validate_result, signal by
    signal), then every sample within `tolerance` of the signal's scale (its largest
    magnitude or its range, whichever is larger) where `tolerance` > 0."""
    import numpy as np
    units = units or {}
    t_start, t_stop = opt["StartTime"], opt["StopTime"]
    t_res, t_ref = result["time"], reference["time"]
    if result.size < 2:
        return [f"{model}: the result has fewer than two samples"]
    if t_res[0] > t_start:
        return [f"{model}: the result starts at {t_res[0]:g} s, after the start time {t_start:g} s"]
    if t_res[-1] < t_stop and not np.isclose(t_res[-1], t_stop):
        return [f"{model}: the result ends at {t_res[-1]:g} s, before the stop time {t_stop:g} s"]
    problems = []
    same_grid = len(t_res) == len(t_ref) and np.allclose(t_res, t_ref, rtol=0, atol=1e-12)
    if tolerance and tolerance > 0 and not same_grid:
        problems.append(f"{model}: time: the result has {len(t_res)} samples, the reference {len(t_ref)} "
                        f"(or at other times)")
    for name in reference.dtype.names[1:]:
        if name not in result.dtype.names:
            problems.append(f"{model}: {name}: missing from the result")
            continue
        y, y_ref = np.asarray(result[name], float), np.asarray(reference[name], float)
        _, _, _, out = validate_signal(t=t_res, y=y, t_ref=t_ref.copy(), y_ref=y_ref, t_start=t_start, t_stop=t_stop)
        share = np.sum(out) / float(len(out))
        if share > 0.1:
            k = int(np.argmax(out))
            problems.append(f"{model}: {name}: {share:.0%} of the samples outside the Cross-Check's band "
                            f"(more than 10 %), the first at t = {t_res[k]:.6g} s")
        if tolerance and tolerance > 0 and same_grid:
            scale = max(np.max(np.abs(y_ref)), np.max(y_ref) - np.min(y_ref)) or 1.0
            err = np.abs(y - y_ref)
            k = int(np.argmax(err))
            if not np.all(np.isfinite(y)) or err[k] > tolerance * scale:
                unit = units.get(name, "")
                problems.append(f"{model}: {name}: {y[k]:.10g} {unit} at t = {t_ref[k]:.6g} s, the reference "
                                f"{y_ref[k]:.10g} {unit} (off by {err[k] / scale:.3g} of its scale "
                                f"{scale:.4g} {unit}; tolerance {tolerance:g})".replace("  ", " "))
    return problems


def check(fmu_dir=None, kit_dir=None, start_values=None, tolerance=TOLERANCE, beside=False, models=None):
    """Simulates each FMU of the registry in `fmu_dir` (with `beside`, the copy beside
    its references) as its _ref.opt and _in.csv say, with `start_values` ({model: {name:
    value}}) set, and compares the result with its _ref.csv (:func:`compare`). With
    `beside`, in the Cross-Check's layout (:func:`in_layout`), each folder is validated
    as the Cross-Check's validate_vendor_repo validates an exporter's
    (fmpy.cross_check.validate_vendor_repo.validate_test_fmu: file sizes, the model
    description, the option file, the CSV files' names). Returns {model: [problems]},
    an empty list where it matches."""
    from fmpy.util import read_ref_opt_file
    fmu_dir = fmu_dir or wf.FMU_DIR
    kit_dir = kit_dir or default_kit()
    if models is None:
        if os.path.isfile(os.path.join(fmu_dir, "fmus.json")):
            models = wf.registry(fmu_dir)["fmus"]
        else:
            models = sorted(m for m in os.listdir(kit_dir) if os.path.isdir(os.path.join(kit_dir, m)))
    report = {m: [f"{m}: --set names no FMU of the kit ({', '.join(models)})"]
              for m in (start_values or {}) if m not in models}
    for model in models:
        f = files(kit_dir, model)
        path = f["fmu"] if beside else os.path.join(fmu_dir, model + ".fmu")
        if not os.path.isfile(f["ref"]):
            report[model] = [f"{model}: no reference {os.path.relpath(f['ref'])} (write the kit: "
                             f"python3 python/wheelflat_kit.py write)"]
            continue
        if not os.path.isfile(path):
            report[model] = [f"{model}: no FMU {os.path.relpath(path)}"
                             + (" (python3 python/wheelflat_kit.py copy puts it there)" if beside else "")]
            continue
        problems = []
        if beside and in_layout(kit_dir):
            from fmpy.cross_check.validate_vendor_repo import validate_test_fmu
            problems += [f"{model}: {p}" for p in validate_test_fmu(f["dir"])]
        for key in ("opt", "in"):
            if not os.path.isfile(f[key]):
                problems.append(f"{model}: no {os.path.basename(f[key])} in {os.path.relpath(f['dir'])} (write the kit: "
                                f"python3 python/wheelflat_kit.py write)")
        if problems:
            report[model] = problems
            continue
        try:
            opt = read_ref_opt_file(f["opt"])
            ref, inp = (read_kit_csv(f[key]) for key in ("ref", "in"))
            md = _md(path)
            variables = {v.name: v for v in md.modelVariables}
            problems += [f"{model}: {n}: in {os.path.basename(f['in'])} but not an input of the FMU"
                         for n in (inp.dtype.names[1:] if inp is not None else ())
                         if n not in variables or variables[n].causality != "input"]
            problems += [f"{model}: {n}: in {os.path.basename(f['ref'])} but not an output of the FMU"
                         for n in ref.dtype.names[1:] if n not in variables or variables[n].causality != "output"]
            given = inp.dtype.names[1:] if inp is not None else ()
            problems += [f"{model}: {n}: not a parameter the check may set: {os.path.basename(f['in'])} gives it"
                         for n in (start_values or {}).get(model, {}) if n in given]
            if problems:
                report[model] = problems
                continue
            res, messages = simulate(path, model, opt["StopTime"], opt["StepSize"], inp, list(ref.dtype.names[1:]),
                                     (start_values or {}).get(model), start=opt["StartTime"])
        except KitFileError as e:
            report[model] = problems + [f"{model}: {e}"]
            continue
        except Exception as e:  # a refusal of the FMU (its message logged above)
            report[model] = problems + [f"{model}: {type(e).__name__}: {e}"]
            continue
        problems += [f"{model}: the FMU logged {m}" for m in messages]
        units = {n: _unit(variables[n]) for n in ref.dtype.names[1:]}
        report[model] = problems + compare(model, res, ref, opt, tolerance, units)
    return report


class KitFileError(ValueError):
    pass


def read_kit_csv(path):
    """A kit's CSV file through fmpy's reader; one that does not read (cut mid-line,
    empty, only a header) is refused naming the file."""
    from fmpy.util import read_csv
    try:
        table = read_csv(path)
    except Exception as e:
        raise KitFileError(f"{os.path.relpath(path)} does not read as a CSV table ({type(e).__name__}: {e})") from None
    if table.dtype.names is None or table.dtype.names[0] != "time" or len(table) < 2:
        raise KitFileError(f"{os.path.relpath(path)}: a table of time and signals with two rows or more is needed")
    return table


def _parse_set(items):
    """--set MODEL:NAME=VALUE (a number, else a string) into {model: {name: value}}."""
    out = {}
    for item in items or ():
        m = re.fullmatch(r"([^:=]+):([^=]+)=(.*)", item)
        if not m:
            raise SystemExit(f"--set {item}: expected MODEL:NAME=VALUE, "
                             f"e.g. RollPlaneVehicle:vehicle.wheelset.mass=1200")
        try:
            value = float(m.group(3))
        except ValueError:
            value = m.group(3)
        if isinstance(value, float) and value != value:
            raise SystemExit(f"--set {item}: {m.group(2)} = nan is no value")
        out.setdefault(m.group(1), {})[m.group(2)] = value
    return out


def main(argv=None):
    wf.ensure_venv()
    ap = argparse.ArgumentParser(prog="wheelflat_kit.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=["write", "check", "copy"])
    ap.add_argument("--fmus", default=wf.FMU_DIR, help="the folder of the built FMUs and fmus.json (default: fmu/)")
    ap.add_argument("--kit", default=None, help="the kit's tool version folder "
                    "(default: regression/2.0/cs/linux64/wheelflat/<version of Cargo.toml>)")
    ap.add_argument("--beside", action="store_true", help="check: the FMUs copied beside their references")
    ap.add_argument("--tolerance", type=float, default=TOLERANCE,
                    help=f"check: largest difference of a sample, relative to the signal's scale (default "
                         f"{TOLERANCE:g}; 0: the Cross-Check's band only)")
    ap.add_argument("--set", action="append", metavar="MODEL:NAME=VALUE",
                    help="check: a parameter's start value for that model (repeatable)")
    args = ap.parse_args(argv)
    if args.kit is not None and not args.kit.strip():
        ap.error("--kit '': give the kit's folder, or leave the option out for the default")
    kit = os.path.abspath(args.kit) if args.kit else default_kit()
    if args.command == "check" and not os.path.isdir(kit):
        ap.error(f"--kit {args.kit}: no such folder (the default is {os.path.relpath(default_kit())})")
    if not (args.tolerance == args.tolerance):
        ap.error("--tolerance nan: give a number (0: the Cross-Check's band only)")
    missing = [m for m in wf.registry(args.fmus)["fmus"] if not os.path.isfile(os.path.join(args.fmus, m + ".fmu"))] \
        if os.path.isfile(os.path.join(args.fmus, "fmus.json")) else ["fmus.json"]
    if missing and not (args.command == "check" and args.beside):
        raise SystemExit(f"{args.fmus} lacks {', '.join(missing)}: build the FMUs first "
                         f"(bash scripts/build_fmus_glibc228.sh fmu)")
    t0 = time.perf_counter()
    if args.command == "write":
        for model, d in write(args.fmus, kit).items():
            print(f"{model:<18} wrote {os.path.relpath(d)}")
        print(f"wall time {time.perf_counter() - t0:.1f} s")
        return 0
    if args.command == "copy":
        for p in copy_fmus(args.fmus, kit):
            print(f"copied {os.path.relpath(p)}")
        return 0
    report = check(args.fmus, kit, _parse_set(args.set), args.tolerance, args.beside)
    bad = [m for m, p in report.items() if p]
    for model, problems in report.items():
        print(f"{model:<18} {'FAILED' if problems else 'ok'}")
        for p in problems:
            print(f"  {p}")
    sys.stdout.flush()
    what = "the Cross-Check's band" + (f" and each sample within {args.tolerance:g}" if args.tolerance > 0 else "")
    wall = f"wall time {time.perf_counter() - t0:.1f} s"
    if bad:
        print(f"{len(bad)} of {len(report)} FMUs differ from their references in {os.path.relpath(kit)} ({what}): "
              f"{', '.join(bad)}; {wall}", file=sys.stderr)
        return 1
    print(f"all {len(report)} FMUs match their references in {os.path.relpath(kit)} ({what}); {wall}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
