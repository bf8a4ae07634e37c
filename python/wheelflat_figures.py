#!/usr/bin/env python3
"""Every figure README.md and the guide quote, printed by the build, not typed.

    python3 python/wheelflat_figures.py           # regenerate every figure in place
    python3 python/wheelflat_figures.py --check   # compare only: exit 1 naming each stale one
    python3 python/wheelflat_figures.py --only pair,speed_flat   # some sources only

Run it after a change that moves a result (a default, the model, a master's recipe),
read the diff, and commit it with a line in CHANGELOG.md. The test command checks
(tests/test_figures.py, tests/test_docs.py) that the committed figures are what the
current build gives. What it regenerates, from the FMUs in fmu/ and the runner in
target/release/ (built first if missing):

1. Figures in the prose, between markers ``<!--fig NAME-->301.92 kN<!--/fig-->``, and
   generated blocks (tables) between ``<!--generated NAME-->`` and ``<!--/generated-->``,
   in README.md, docs/guide/*.md, docs/STUDIES.md and python/quickstart/test_regression.py
   (in its comments). A marker left open, nested or mistyped stops the command, naming
   the page and line, before anything runs. NAME's first word names its
   source in SOURCES (``pair.left`` comes from ``pair``).
2. Transcripts: each ```console block of those pages whose first line is ``$ COMMAND``
   shows below it what COMMAND prints (cargo's status lines left out). A line that
   begins ``wall time`` is compared up to its colon only, and a time written as
   pytest writes it (``0.53s``) not at all.
3. The studies' plots in docs/studies/ (each studies/*.toml run serially), each PNG
   carrying the digest of its study's results table, so a plot from an older model is
   found.
4. The regression kit in regression/ (python/wheelflat_kit.py).
5. The track's receptance against the independent reference, docs/figures/receptance.png,
   and the drawn rail profiles against their spectra, docs/figures/track_spectra.png
   (issue 44; each carries the digest of what it draws, as the studies' plots do).

The stated rounding: a figure is compared as printed, number by number; a number may
differ from the committed one by one unit in its last printed digit (a rounding
boundary crossed on a machine with another vector width), no more.
"""

import argparse
import hashlib
import math
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import wheelflat_fmus as wf  # noqa: E402

ROOT = wf.ROOT
# The pages, with docs/guide/*.md after the first; a Python file quotes figures in its comments.
PAGES = ["README.md", "docs/STUDIES.md", "python/quickstart/test_regression.py"]
VENV_BIN = os.path.join(ROOT, ".venv", "bin")
NUMBER = re.compile(r"[+-]?\d[\d,]*(?:\.\d+)?(?:[eE][+-]?\d+)?")
# A marker's start or end, as written; anything that looks like one but is not is refused.
TOKEN = re.compile(r"<!--(/?)(fig|generated)(?: ([\w.\-\[\]]+))?-->")
LOOSE = re.compile(r"<!--\s*/?\s*(fig|generated)\b[^>]*-->")
# A time as pytest and cargo print it, "0.53s": not compared.
SECONDS = re.compile(r"\b\d+(?:\.\d+)?s\b")
CARGO_STATUS = re.compile(r"^\s+(Compiling|Finished|Running|Blocking|Updating|Downloaded|Downloading|Locking)\b")
STUDY_PLOTS = os.path.join(ROOT, "docs", "studies")
# The digest of a study's results, kept in each of its PNG plots (a tEXt chunk).
DIGEST_KEY = "wheelflat-results"


def read_pages():
    """Each page's text (UTF-8, its line ends as \\n; CRLF pages are written back so),
    its markers checked first: a bad marker stops the command before anything runs."""
    texts, crlf = {}, set()
    for p in pages():
        with open(os.path.join(ROOT, p), encoding="utf-8", newline="") as fh:
            text = fh.read()
        if "\r\n" in text:
            crlf.add(p)
            text = text.replace("\r\n", "\n")
        markers(text, p)
        transcripts(text, p)
        texts[p] = text
    return texts, crlf


def pages():
    guide = sorted(os.path.relpath(p, ROOT) for p in
                   __import__("glob").glob(os.path.join(ROOT, "docs", "guide", "*.md")))
    return PAGES[:1] + guide + PAGES[1:]


# ---------------------------------------------------------------------------- sources
# Each source runs once and returns {name: text}; the pages quote its names.

def kn(x, digits=2):
    return f"{x / 1e3:.{digits}f} kN"


def runner():
    """The command-line runner (target/release/wheelflat), built when missing."""
    path = os.path.join(wf.TARGET_DIR, "release", "wheelflat")
    if not os.path.exists(path):
        subprocess.run(["cargo", "build", "--release", "--bin", "wheelflat"], cwd=ROOT, check=True)
    return path


def fmu_paths():
    """The FMUs in fmu/ by name (the command builds them first; the tests use the
    test command's)."""
    return {name: os.path.join(wf.FMU_DIR, name + ".fmu") for name in wf.registry()["fmus"]}


def run_runner(*args):
    """The runner's case line, static load and peaks: {static, left, right} in N."""
    with tempfile.TemporaryDirectory() as tmp:
        p = subprocess.run([runner(), *args, "--output", os.path.join(tmp, "run.csv")], cwd=tmp,
                           check=True, capture_output=True, text=True)
        out = p.stdout + p.stderr
    static = float(re.search(r"static wheel load ([\d.]+) kN", out).group(1)) * 1e3
    m = re.search(r"peak impact force: left ([\d.]+) kN .*right ([\d.]+) kN", out)
    return {"static": static, "left": float(m.group(1)) * 1e3, "right": float(m.group(2)) * 1e3}


def source_pair():
    """The reference case (table 4.4, 70 km/h, 100 mm x 1.5 mm flat on the left wheel,
    the FMUs' defaults) through TrackContact + RollPlaneVehicle at the track's step,
    0.8 s (CoupledSystem's numbers: tests/test_fmu_coupling.py holds the two equal)."""
    r = wf.run_pair(fmu_paths(), 0.8)
    left = r["contact.left.max_force"][-1]
    return {"pair.static": kn(r["contact.left.force"][0]), "pair.left": kn(left), "pair.left.short": kn(left, 1)}


def source_seed():
    """The thesis' grid (n = 2, dt = 45 us) on its fixed track: the rail between nodes
    by (3.23), as the thesis, and by its shape (the default)."""
    linear = run_runner("--n", "2", "--dt-us", "45", "--between-nodes", "linear")
    beam = run_runner("--n", "2", "--dt-us", "45")
    return {
        "seed.left": kn(linear["left"], 1),
        "seed.right.ratio": f"{linear['right'] / linear['static']:.2f}",
        "seed.beam.left": kn(beam["left"], 1),
    }


def study_table(study_file):
    """Runs a study serially in a temporary folder: (the Study, its results table, the
    folder's plots {name: path}, the folder, kept until the caller removes it)."""
    sys.path.insert(0, os.path.join(ROOT, "python"))
    from wheelflat_study.spec import load_study
    from wheelflat_study.run import build_runner, run_study
    from wheelflat_study.__main__ import check_variables
    import shutil
    study = load_study(study_file)
    # As the command does: the variables checked, enumerations given by item name
    # turned into their numbers.
    check_variables(study, build_runner())
    tmp = tempfile.mkdtemp(prefix="figures_")
    try:
        table, _ = run_study(study, tmp, serial=True, progress=False, plots=True, log=lambda *a: None)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    return study, table, tmp


def digest(table, columns):
    text = table.sort_values(columns).to_csv(columns=columns, index=False, float_format="%.6e")
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def source_speed_flat():
    """studies/speed_flat.toml: the headline plot (README), its table in STUDIES.md and
    what the caption says of the study."""
    import shutil
    study, table, tmp = study_table(os.path.join(ROOT, "studies", "speed_flat.toml"))
    try:
        ok = table[table["status"] == "ok"]
        lengths = sorted(ok["flat.left[1].length"].unique())
        speeds = sorted(ok["speed"].unique())
        head = "| km/h | " + " | ".join(f"{l * 1e3:g} mm" for l in lengths) + " |"
        rows = [head, "|" + "---|" * (len(lengths) + 1)]
        for v in speeds:
            cells = [f"{ok[(ok['speed'] == v) & (ok['flat.left[1].length'] == l)]['peak.left'].iloc[0] / 1e3:.1f}"
                     for l in lengths]
            rows.append(f"| {v * 3.6:.0f} | " + " | ".join(cells) + " |")
        radius = wf_start("wheel.radius")
        depths = ", ".join(f"{l * l / (16 * radius) * 1e3:.2f}" for l in lengths)
        fixed = study.fixed
        at = lambda v, l: ok[(abs(ok["speed"] * 3.6 - v) < 1e-9) & (abs(ok["flat.left[1].length"] - l) < 1e-12)]
        figures = {
            "speed_flat.table": "\n\n" + "\n".join(rows) + "\n\n",
            "speed_flat.cases": f"{len(ok)}",
            "speed_flat.depths": f"{depths} mm",
            "speed_flat.window": f"{fixed['track.window.ahead']:g} m",
            "speed_flat.duration": f"{study.duration:g} s",
            "speed_flat.100mm_70": kn(at(70, 0.1)["peak.left"].iloc[0], 1),
        }
        write_plots(study, ok, tmp)
        return figures
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def wf_start(name):
    """A start value of TrackContact's model description."""
    from fmpy import read_model_description
    md = read_model_description(os.path.join(wf.FMU_DIR, "TrackContact.fmu"))
    return float(next(v.start for v in md.modelVariables if v.name == name))


# The plots each study draws into docs/studies/ (its [[plot]] names).
def write_plots(study, ok, tmp):
    """Puts the study's PNG plots into docs/studies/ (write mode) or checks that the
    committed ones carry the digest of these results and of their own [[plot]] entry,
    which says what each draws (check mode)."""
    import json
    from PIL import Image, PngImagePlugin, UnidentifiedImageError
    # The results, not the times they took.
    cols = [c for c in ok.columns if ok[c].dtype.kind == "f" and not c.endswith("wall_s")]
    results = digest(ok, sorted(cols))
    for p in study.plots:
        name = p.get("name")
        d = results + hashlib.sha256(json.dumps(p, sort_keys=True).encode()).hexdigest()[:8]
        committed = os.path.join(STUDY_PLOTS, f"{name}.png")
        if CHECKING:
            where = f"docs/studies/{name}.png"
            if not os.path.exists(committed):
                STALE.append(f"{where}: missing: run python3 python/wheelflat_figures.py")
                continue
            try:
                have = Image.open(committed).text.get(DIGEST_KEY)
            except (UnidentifiedImageError, OSError) as e:
                STALE.append(f"{where}: no PNG ({e}): run python3 python/wheelflat_figures.py")
                continue
            if have != d:
                STALE.append(f"{where}: drawn from other results or another [[plot]] entry (digest {have}, "
                             f"the current build's {d}): run python3 python/wheelflat_figures.py")
            continue
        info = PngImagePlugin.PngInfo()
        info.add_text(DIGEST_KEY, d)
        Image.open(os.path.join(tmp, f"{name}.png")).save(committed, pnginfo=info)


def markdown_table(head, rows):
    return "\n".join(["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
                     + ["| " + " | ".join(r) + " |" for r in rows])


def study_source(study_name, tables):
    """A source that runs studies/<study_name>.toml, puts its plots into docs/studies/
    and gives `tables(ok)`'s figures ({name: text}, names under `study_name.`)."""
    def source():
        import shutil
        study, table, tmp = study_table(os.path.join(ROOT, "studies", f"{study_name}.toml"))
        try:
            ok = table[table["status"] == "ok"]
            write_plots(study, ok, tmp)
            return {f"{study_name}.{k}": v for k, v in tables(study, ok).items()}
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    return source


def impact_position_tables(study, ok):
    rows, spreads = [], []
    for v, g in ok.groupby("speed", sort=True):
        lo = g.loc[g["first_impact_peak.left"].idxmin()]
        hi = g.loc[g["first_impact_peak.left"].idxmax()]
        spread = hi["first_impact_peak.left"] / lo["first_impact_peak.left"] - 1
        spreads.append(spread)
        rows.append([f"{v * 3.6:.0f}",
                     f"{lo['first_impact_peak.left'] / 1e3:.1f}, {lo['first_impact_span_position.left']:.2f}",
                     f"{hi['first_impact_peak.left'] / 1e3:.1f}, {hi['first_impact_span_position.left']:.2f}",
                     f"{100 * spread:.0f} %"])
    head = ["km/h", "least peak (kN), at", "largest peak (kN), at", "spread"]
    return {"table": "\n\n" + markdown_table(head, rows) + "\n\n",
            "spread": f"{100 * min(spreads):.0f} to {100 * max(spreads):.0f} %"}


def flat_phase_tables(study, ok):
    import math
    rows, ratios = [], []
    for v, g in ok.groupby("speed", sort=True):
        phase = ((g["flat.right[1].angle"] - g["flat.left[1].angle"]) % (2 * math.pi))
        zero = g[phase.abs() < 1e-9]["peak.max"].iloc[0]
        worst = g.loc[g["peak.max"].idxmax()]
        ratios.append(worst["peak.max"] / zero)
        at = math.degrees((worst["flat.right[1].angle"] - worst["flat.left[1].angle"]) % (2 * math.pi))
        rows.append([f"{v * 3.6:.0f}", f"{zero / 1e3:.1f}", f"{worst['peak.max'] / 1e3:.1f}, {at:.0f} deg",
                     f"{worst['peak.max'] / zero:.2f}"])
    head = ["km/h", "phase 0 (kN)", "worst phase (kN), at", "worst / phase 0"]
    return {"table": "\n\n" + markdown_table(head, rows) + "\n\n",
            "most": f"{100 * (max(ratios) - 1):.0f} %"}


def primary_stiffness_tables(study, ok):
    speeds = sorted(ok["speed"].unique())
    rows = []
    for k, g in ok.groupby("vehicle.primary.stiffness", sort=True):
        by = {v: g[g["speed"] == v].iloc[0] for v in speeds}
        rows.append([f"{k / 1e6:g}"] + [f"{by[v]['bearing.left.max'] / 1e3:.1f}" for v in speeds]
                    + [f"{by[v]['peak.left'] / 1e3:.1f}" for v in speeds])
    head = (["K_1 (MN/m)"] + [f"bearing, {v * 3.6:.0f} km/h" for v in speeds]
            + [f"contact, {v * 3.6:.0f} km/h" for v in speeds])
    # From the thesis' chapter-5 stiffness to table 4.4's, at each speed.
    at = lambda k, v: ok[(abs(ok["vehicle.primary.stiffness"] - k) < 1) & (ok["speed"] == v)].iloc[0]
    stiff, soft = 788e6, 6.5e6
    falls = [(at(stiff, v)["bearing.left.max"], at(soft, v)["bearing.left.max"], v) for v in speeds]
    rises = [at(soft, v)["peak.left"] / at(stiff, v)["peak.left"] - 1 for v in speeds]
    fall = " and ".join(f"from {a / 1e3:.0f} to {b / 1e3:.0f} kN ({v * 3.6:.0f} km/h)" for a, b, v in falls)
    pct = sorted(100 * (1 - b / a) for a, b, _ in falls)
    return {"table": "\n\n" + markdown_table(head, rows) + "\n\n",
            "bearing_fall": f"{fall}, {pct[0]:.0f} to {pct[-1]:.0f} %",
            "contact_rise": f"{100 * min(rises):.0f} to {100 * max(rises):.0f} %"}


def track_class_flat_tables(study, ok):
    """The flat wheel's peak over the seeds, per FRA class, from the study command's own
    summary (python/wheelflat_study/summary.py), as STUDIES.md quotes it."""
    from wheelflat_study.summary import percentile_column, summarise
    rows, pcol = [], percentile_column(study)
    for r in summarise(study, ok):
        if r["result"] != "peak.left":
            continue
        rows.append([study.shown("rail.spectrum", r["rail.spectrum"]), str(r["count"]),
                     f"{r['mean'] / 1e3:.1f}", f"{r['std'] / 1e3:.2f}", f"{r[pcol] / 1e3:.1f}",
                     f"{r['min'] / 1e3:.1f}", f"{r['max'] / 1e3:.1f}"])
    head = ["track", "seeds", "mean (kN)", "std (kN)", f"{pcol} (kN)", "min (kN)", "max (kN)"]
    return {"table": "\n\n" + markdown_table(head, rows) + "\n\n"}


def source_quickstart():
    """The quick starts' lengths (lines), as quickstart.md quotes them."""
    folder = os.path.join(ROOT, "python", "quickstart")
    return {f"quickstart.lines.{name[:-3]}": str(sum(1 for _ in open(os.path.join(folder, name))))
            for name in sorted(os.listdir(folder)) if name.endswith(".py")}


def source_regression():
    """The references of quick start (d), python/quickstart/test_regression.py: each of
    its cases through CoupledSystem, as the test runs it."""
    sys.path.insert(0, os.path.join(ROOT, "python", "quickstart"))
    import test_regression as t
    lines = []
    for case in sorted(t.REFERENCE):
        r = t.run(*case)
        left, right = r["contact.left.max_force"][-1], r["contact.right.max_force"][-1]
        lines.append(f"    {case}: ({left / 1e3:.1f}e3, {right / 1e3:.1f}e3),")
    # Between the markers' comment lines, in the dict's indentation.
    return {"regression.references": "\n" + "\n".join(lines) + "\n    # "}


def percent(x):
    """A relative difference in per cent, two decimals below 10 %, one below 100 %."""
    x *= 100
    return f"{x:+.2f} %" if abs(x) < 10 else (f"{x:+.1f} %" if abs(x) < 100 else f"{x:+.0f} %")


def source_comm_step():
    """couple-a-vehicle.md's held-input table: the pair's peak of the left wheel (first
    impact, 0.06 s) against the communication step, inputs held (python/comm_step_study.py)."""
    paths = fmu_paths()
    h = wf.track_step(paths)
    multiples = [1, 2, 3, 5, 7, 14, 28]
    peaks = [wf.run_pair(paths, 0.06, comm_step=m * h)["contact.left.max_force"][-1] for m in multiples]
    steps = [f"{m * h * 1e6:.3g} us" + (" (= dt)" if m == 1 else "") for m in multiples]
    errors = ["0"] + [percent(p / peaks[0] - 1) for p in peaks[1:]]
    table = markdown_table(["comm step"] + steps, [["peak (kN)"] + [f"{p / 1e3:.2f}" for p in peaks],
                                                   ["error"] + errors])
    return {"comm_step.table": "\n\n" + table + "\n\n"}


def source_derivatives():
    """couple-a-vehicle.md's input-derivative table: the pair at multiples of the track's
    step, 0.3 s, inputs held or moved with the wheel velocities (order 1), against the
    pair at the track's step: the peak of the left wheel and the largest error of its
    force over the history at the communication points."""
    import numpy as np
    paths = fmu_paths()
    h = wf.track_step(paths)
    ref = wf.run_pair(paths, 0.3)
    ref_force = np.asarray(ref["contact.left.force"])
    ref_peak = ref["contact.left.max_force"][-1]
    multiples = [2, 5, 10, 20, 50]
    rows = {False: [], True: []}
    worst = {False: [], True: []}
    for m in multiples:
        for derivs in (False, True):
            r = wf.run_pair(paths, 0.3, comm_step=m * h, input_derivatives=derivs)
            f = np.asarray(r["contact.left.force"])
            n = min(len(f), (len(ref_force) - 1) // m + 1)
            rows[derivs].append(percent(r["contact.left.max_force"][-1] / ref_peak - 1))
            e = np.max(np.abs(f[:n] - ref_force[:n * m:m])) / 1e3
            worst[derivs].append(f"{e:.1f} kN" if e < 100 else f"{e:.0f} kN")
    head = ["comm step"] + [f"{m} x ({m * h * 1e6:.3g} us)" if m * h < 5e-4 else f"{m} x ({m * h * 1e3:.2g} ms)"
                            for m in multiples]
    table = markdown_table(head, [["inputs held"] + rows[False],
                                  ["with the wheel velocities (order 1)"] + rows[True],
                                  ["largest force error over the history, held"] + worst[False],
                                  ["the same, with the velocities"] + worst[True]])
    return {"derivatives.table": "\n\n" + table + "\n\n", "derivatives.reference": kn(ref_peak)}


def source_wagon():
    """couple-a-vehicle.md's Wagon block: at the axle boxes, fmpy's loop every 1 ms,
    0.3 s, and CoupledSystem alike (the shipped systems' parameters)."""
    import wheelflat_masters as wm
    got, ref = wf.axle_box_against_coupled_system(fmu_paths(), wf.run_wagon_axle_box, wm.coupled_params("Wagon"))
    rear = max(got[4:])
    return {"wagon.left": kn(got[0], 1), "wagon.coupled_left": kn(ref[0], 1),
            "wagon.trailing_left": kn(got[2], 1), "wagon.rear": kn(1e3 * math.ceil(rear / 1e3), 0)}


def source_two_axle():
    """couple-a-vehicle.md's TwoAxleWagon block, as the Wagon's, and its static wheel load."""
    import wheelflat_masters as wm
    got, _ = wf.axle_box_against_coupled_system(fmu_paths(), wf.run_two_axle_axle_box,
                                                wm.coupled_params("TwoAxleWagon"))
    unit = wf.Unit(fmu_paths()["TwoAxleWagon"], "static")
    try:
        unit.fmu.setupExperiment(startTime=0.0)
        unit.fmu.enterInitializationMode()
        static = unit.get("static_load.left")[0]
    finally:
        unit.close(terminate=False)
    return {"two_axle.left": kn(got[0], 1), "two_axle.right": kn(got[1], 1),
            "two_axle.trailing": kn(1e3 * math.ceil(max(got[2:4]) / 1e3), 0), "two_axle.static": kn(static)}


def source_masters():
    """docs/guide/masters.md's tables: the shipped systems in libcosim and ecos (Jacobi)
    and fmpy's sequential loop against CoupledSystem, 0.6 s on the 20 m window, per
    cent per wheel (python/wheelflat_masters.py runs them as tests/test_masters.py)."""
    import contextlib
    import io
    import wheelflat_masters as wm
    kinds = ["RollPlaneVehicle", "HalfCarBogie"]
    figures = {}
    for k in wm.VEHICLES:
        figures[f"masters.monolithic.{k}"] = ", ".join(f"{p / 1e3:.2f}" for p in wm.monolithic(k)["peaks"]) + " kN"

    def errors(r, kind):
        mono = wm.monolithic(kind)["peaks"]
        if not r["ok"] or abs(r["time"] - wm.STOP) > 1e-4 or not all(map(math.isfinite, r["peaks"])):
            return None
        return [p / m - 1 for p, m in zip(r["peaks"], mono)]

    def cell(e, warned):
        return " ".join(f"{100 * x:+.2f}" for x in e) + (" (W)" if warned else "")

    def warned_in(log):
        return any("[warning]" in x.lower() for x in log.splitlines())

    # The axle-box interface: Jacobi in libcosim (ecos gives the same bits), fmpy sequential.
    steps = [0.5e-3, 1e-3, 2e-3, 3e-3, 4e-3, 5e-3, 6e-3, 8e-3, 16e-3, 50e-3]
    specs = [wm.spec("libcosim", "ssp", k, "axle_box", step=h) for h in steps for k in kinds]
    runs = dict(zip([(sp["vehicle"], sp["step"]) for sp in specs], wm.run_all(specs)))
    paths = fmu_paths()
    endless = {"track.window.ahead": 20.0, "track.window.behind": 20.0}
    rows, stable = [], {k: 0.0 for k in kinds}
    for h in steps:
        row = [f"{h * 1e3:g} ms"]
        for k in kinds:
            r = runs[(k, h)]
            e = errors(r, k)
            if e is None:
                row.append(f"diverges (stops at {r['time']:.3g} s)" if r["time"] < wm.STOP - 1e-4 else "diverges")
            else:
                row.append(cell(e, warned_in(r["log"])))
                if h > stable[k] and all(x > -1 for x in e) and max(map(abs, e)) < 0.05:
                    stable[k] = h
        for k in kinds:
            log = io.StringIO()
            with contextlib.redirect_stdout(log):
                peaks = wf.run_carrier_axle_box(paths, k, wm.VEHICLES[k], wm.STOP, h, track_params=endless)
            mono = wm.monolithic(k)["peaks"]
            e = [p / m - 1 for p, m in zip([x for pair in peaks for x in pair], mono)]
            row.append(cell(e, warned_in(log.getvalue())) if all(map(math.isfinite, e)) else "diverges")
        rows.append(["**1 ms**" if h == 1e-3 else row[0]] + [f"**{c}**" if h == 1e-3 else c for c in row[1:]])
    head = ["step", "Jacobi (libcosim = ecos), roll-plane", "half-car", "fmpy sequential, `mean_force`, roll-plane",
            "half-car"]
    figures["masters.axle_box"] = "\n\n" + markdown_table(head, rows) + "\n\n"
    figures["masters.stable"] = f"{stable['RollPlaneVehicle'] * 1e3:g} ms roll-plane, {stable['HalfCarBogie'] * 1e3:g} ms half-car"

    # The Wagon at the axle boxes: the shipped files at 1 ms, libcosim at 2 to 5 ms.
    wagon = wm.run_all([wm.spec("libcosim", "osp", "Wagon", "axle_box"), wm.spec("libcosim", "ssp", "Wagon", "axle_box"),
                        wm.spec("ecos", "ssp", "Wagon", "axle_box")]
                       + [wm.spec("libcosim", "ssp", "Wagon", "axle_box", step=h) for h in (2e-3, 3e-3, 4e-3, 5e-3)])
    e1 = [errors(r, "Wagon") for r in wagon[:3]]
    figures["masters.wagon_1ms"] = " ".join(f"{100 * x:+.2f}" for x in e1[0]) + " %"
    figures["masters.wagon_1ms_same"] = "the same" if e1[0] == e1[1] == e1[2] else "not the same"
    log = io.StringIO()
    with contextlib.redirect_stdout(log):
        peaks = wf.run_carrier_axle_box(paths, "Wagon", 4, wm.STOP, 1e-3, track_params=endless)
    mono = wm.monolithic("Wagon")["peaks"]
    seq = max(abs(p / m - 1) for p, m in zip([x for pair in peaks for x in pair], mono))
    figures["masters.wagon_sequential"] = f"{100 * seq:.2f} %"
    figures["masters.wagon_1ms_max"] = f"{100 * max(map(abs, e1[0])):.2f} %"
    # The two-axle wagon alike: fmpy's sequential loop and libcosim at 1 ms.
    with contextlib.redirect_stdout(io.StringIO()):
        peaks = wf.run_carrier_axle_box(paths, "TwoAxleWagon", 2, wm.STOP, 1e-3, track_params=endless)
    mono = wm.monolithic("TwoAxleWagon")["peaks"]
    seq = max(abs(p / m - 1) for p, m in zip([x for pair in peaks for x in pair], mono))
    jac = errors(wm.run_all([wm.spec("libcosim", "ssp", "TwoAxleWagon", "axle_box")])[0], "TwoAxleWagon")
    figures["masters.two_axle_sequential"] = f"{100 * seq:.3f} %"
    figures["masters.two_axle_1ms_max"] = f"{100 * max(map(abs, jac)):.3f} %"
    later = []
    for h, r in zip((2e-3, 3e-3, 4e-3, 5e-3), wagon[3:]):
        e = errors(r, "Wagon")
        later.append(f"at {h * 1e3:g} ms " + ("diverges" if e is None or max(map(abs, e)) > 0.05 else
                                              f"within {100 * max(map(abs, e)):.2f} %"
                                              + (" with the warning" if warned_in(r["log"]) else "")))
    figures["masters.wagon_later"] = "; ".join(later)

    # The contact interface: multiples of the track's step, libcosim; ecos alike at 1 x.
    multiples = [1, 2, 3, 5, 10]
    h = {k: wm.shipped_step(k, "contact") for k in kinds}
    specs = [wm.spec("libcosim", "ssp", k, "contact", step=m * h[k]) for m in multiples for k in kinds]
    runs = wm.run_all(specs + [wm.spec("ecos", "ssp", k, "contact") for k in kinds])
    rows = []
    for i, m in enumerate(multiples):
        row = [f"**{m} x `solver.step`**" if m == 1 else f"{m} x"]
        for j, k in enumerate(kinds):
            r = runs[i * len(kinds) + j]
            e = errors(r, k)
            c = "diverges" if e is None else " ".join(percent(x)[:-2] for x in e)
            # TrackContact's warning of forces that jump up and down at every point.
            if e is not None and any("jumped up and down" in x for x in r["log"].splitlines()):
                c += " (the contact chatters)"
            row.append(f"**{c}**" if m == 1 else c)
        rows.append(row)
    figures["masters.contact"] = "\n\n" + markdown_table(["step", "roll-plane", "half-car"], rows) + "\n\n"
    agree = max(abs(a / b - 1) for j, k in enumerate(kinds)
                for a, b in zip(runs[len(specs) + j]["peaks"], runs[j]["peaks"]))
    figures["masters.contact_agree"] = f"{agree:.1e}"
    return figures


def source_simulate_ssp():
    """masters.md's fmpy.ssp.simulate_ssp paragraph: the shipped roll-plane contact pair
    at the track's step and the two-axle wagon at the axle boxes, 0.6 s, the peaks of
    the recorded connectors against CoupledSystem's."""
    import contextlib
    import io
    from fmpy import simulate_fmu
    from fmpy.ssp.simulation import simulate_ssp
    import wheelflat_masters as wm

    from types import SimpleNamespace
    from fmpy.ssp.ssd import read_ssd

    def run(kind, interface):
        # With the SSP's own parameter bindings, as masters.md's recipe passes them.
        path = os.path.join(wm.SYSTEMS, wm.system_name(kind, interface) + ".ssp")
        params = [SimpleNamespace(name=f"{c.name}.{p.name}", value=float(p.value) if p.type == "Real" else int(p.value))
                  for c in read_ssd(path).system.elements for b in c.parameterBindings
                  for v in b.parameterValues for p in v.parameters]
        with contextlib.redirect_stdout(io.StringIO()):
            return simulate_ssp(path, stop_time=wm.STOP, step_size=wm.shipped_step(kind, interface),
                                parameter_set=SimpleNamespace(parameters=params))
    r = run("RollPlaneVehicle", "contact")
    left, right = (r[f"TrackContact.contact.{s}.force"].max() for s in ("left", "right"))
    mono = wm.monolithic("RollPlaneVehicle")["peaks"]
    r2 = run("TwoAxleWagon", "axle_box")
    c = simulate_fmu(fmu_paths()["CoupledSystem"], stop_time=wm.STOP, output=["primary.left.force"],
                     start_values=wm.coupled_params("TwoAxleWagon"), output_interval=1e-3)
    prim, prim_ref = r2["TrackContact.primary.left.force"].max(), c["primary.left.force"].max()
    return {"simulate_ssp.pair": f"{left / 1e3:.2f} / {right / 1e3:.2f} kN",
            "simulate_ssp.coupled": f"{mono[0] / 1e3:.2f} / {mono[1] / 1e3:.2f} kN",
            "simulate_ssp.pair_error": f"{percent(left / mono[0] - 1)}, {percent(right / mono[1] - 1)}",
            "simulate_ssp.two_axle": kn(prim, 1), "simulate_ssp.two_axle_coupled": kn(prim_ref, 1),
            "simulate_ssp.two_axle_error": percent(prim / prim_ref - 1)}


def source_axle_box_masters():
    """couple-a-vehicle.md's table of the engine's units coupled in Rust at the axle
    boxes (`cargo run --release --example axle_box_masters`): each wheel's peak error
    and the history's largest difference over the static load, per step and master."""
    out = run_command("cargo run --release --example axle_box_masters")
    runs, vehicle = {}, None
    for line in out.split("\n"):
        if "monolithic peaks" in line:
            vehicle = "roll-plane" if line.startswith("roll-plane") else "half-car"
        m = re.match(r"\| (sequential|Jacobi) \| ([\d.]+) ms \| (.*?) \|\s*(.*?)\s*\|$", line)
        if m and vehicle:
            peaks, history = m.group(3), m.group(4)
            cell = "unstable" if peaks.startswith("unstable") else f"{peaks} ({float(history):.2g} %)"
            runs[(vehicle, m.group(1), float(m.group(2)))] = cell
    rows = []
    for h in (0.5, 1.0, 2.0, 4.0, 6.0):
        cells = [runs[(v, master, h)] for v in ("roll-plane", "half-car") for master in ("sequential", "Jacobi")]
        first = f"{h:g} ms"
        rows.append([f"**{first}**"] + [f"**{c}**" for c in cells] if h == 1.0 else [first] + cells)
    head = ["step", "sequential, roll-plane", "Jacobi, roll-plane", "sequential, half-car", "Jacobi, half-car"]
    return {"axle_box_masters.table": "\n\n" + markdown_table(head, rows) + "\n\n"}


RECEPTANCE_PNG = os.path.join(ROOT, "docs", "figures", "receptance.png")
SPECTRA_PNG = os.path.join(ROOT, "docs", "figures", "track_spectra.png")


def source_receptance():
    """Issue 44: the default track's point receptance (one rail) at mid-span and at a
    sleeper from the runner (`wheelflat receptance`, 800 frequencies) against the
    independent reference (python/receptance_reference.py), the resonances marked:
    docs/figures/receptance.png (carrying the digest of both curves, as the studies'
    plots do), and the resonances the guide quotes."""
    import numpy as np
    import receptance_reference as reference
    import wheelflat_receptance as wr
    panels, figures, text = [], {}, []
    with tempfile.TemporaryDirectory() as tmp:
        for at, words in (("midspan", "at mid-span"), ("sleeper", "at a sleeper")):
            csv = os.path.join(tmp, f"{at}.csv")
            wr.run(csv, "--at", at, "--points", 800)
            f, a = wr.read_csv(csv)
            ref = reference.receptance(f, at, "one")
            text.append("\n".join(f"{x:.4e},{abs(y):.4e},{abs(z):.4e}" for x, y, z in zip(f, a, ref)))
            panels.append((f"point receptance {words}, one rail; the FMUs' default track (n = 8)",
                           [("model (wheelflat receptance)", f, a, "C0-"),
                            ("reference (exact Timoshenko, frequency domain)", f, ref, "k--")]))
            peaks, ref_peaks = wr.extrema(f, a), wr.extrema(f, ref)
            marks = [x for x, _ in ref_peaks + wr.extrema(f, ref, "min")]
            away = np.array([all(abs(fi / x - 1) > 0.15 for x in marks) for fi in f])
            figures[f"receptance.{at}.worst"] = f"{100 * float(max(abs(abs(a[away]) / abs(ref[away]) - 1))):.1f} %"
            for kind, lo, hi in (("full_track", 20, 150), ("rail_pads", 150, 600), ("pp", 700, 1500)):
                m = [x for x, _ in peaks if lo < x < hi][0]
                r = [x for x, _ in ref_peaks if lo < x < hi][0]
                figures[f"receptance.{at}.{kind}"] = f"{m:.1f} Hz"
                figures[f"receptance.{at}.{kind}.reference"] = f"{r:.1f} Hz"
                figures[f"receptance.{at}.{kind}.error"] = f"{100 * (m / r - 1):+.2f} %"
    d = hashlib.sha256("\n".join(text).encode()).hexdigest()[:16]
    digest_png(RECEPTANCE_PNG, d, "receptances", lambda: wr.plot_panels(RECEPTANCE_PNG, panels,
                                                                          metadata={DIGEST_KEY: d}))
    return figures


def digest_png(path, d, what, draw):
    """A figure that carries the digest `d` of what it draws: checks the committed one's
    (check mode, naming `what` it was drawn from when it differs) or calls `draw`."""
    where = os.path.relpath(path, ROOT)
    if not CHECKING:
        draw()
        return
    from PIL import Image, UnidentifiedImageError
    try:
        have = Image.open(path).text.get(DIGEST_KEY)
    except (FileNotFoundError, UnidentifiedImageError, OSError) as e:
        STALE.append(f"{where}: missing or no PNG ({e}): run python3 python/wheelflat_figures.py")
        return
    if have != d:
        STALE.append(f"{where}: drawn from other {what} (digest {have}, the current build's {d}): "
                     "run python3 python/wheelflat_figures.py")


def source_spectra():
    """Issue 44: the drawn rail profiles against their spectra, 20 seeds of each, band by
    band (python/wheelflat_spectra.py): docs/figures/track_spectra.png, carrying the
    digest of the estimates as the studies' plots do."""
    import numpy as np
    import wheelflat_spectra as ws
    results = ws.main(["--seeds", "20"])
    d = ws.digest(results)
    digest_png(SPECTRA_PNG, d, "profiles", lambda: ws.plot(results, SPECTRA_PNG, metadata={DIGEST_KEY: d}))
    worst = max(float(np.max(np.abs(10 * np.log10(e / t)))) for _, t, e, _ in results.values())
    return {"spectra.worst_band": f"{worst:.2f} dB"}


SOURCES = {
    "regression": source_regression,
    "quickstart": source_quickstart,
    "comm_step": source_comm_step,
    "derivatives": source_derivatives,
    "wagon": source_wagon,
    "two_axle": source_two_axle,
    "masters": source_masters,
    "axle_box_masters": source_axle_box_masters,
    "simulate_ssp": source_simulate_ssp,
    "pair": source_pair,
    "seed": source_seed,
    "speed_flat": source_speed_flat,
    "impact_position": study_source("impact_position", impact_position_tables),
    "flat_phase": study_source("flat_phase", flat_phase_tables),
    "primary_stiffness": study_source("primary_stiffness", primary_stiffness_tables),
    "receptance": source_receptance,
    "track_class_flat": study_source("track_class_flat", track_class_flat_tables),
    "spectra": source_spectra,
}
CHECKING = False
STALE = []


# ---------------------------------------------------------------------------- markers

class MarkerError(ValueError):
    pass


def markers(text, page="the page"):
    """(kind, name, committed text, span) of each marker of a page. A marker left open,
    closed by the other kind, nested, or written almost as one is refused (MarkerError,
    naming the page and line), before anything is compared or written."""
    line = lambda at: text.count("\n", 0, at) + 1
    strict = {m.span() for m in TOKEN.finditer(text)}
    for m in LOOSE.finditer(text):
        if m.span() not in strict:
            raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)} is no marker: "
                              "<!--fig NAME-->...<!--/fig--> or <!--generated NAME-->...<!--/generated-->")
    found, open_ = [], None
    for m in TOKEN.finditer(text):
        closing, kind, name = m.group(1) == "/", m.group(2), m.group(3)
        if not closing and name is None:
            raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)} names no figure")
        if closing and name is not None:
            raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)}: an end marker names nothing")
        if not closing:
            if open_ is not None:
                raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)} inside {open_[0].group(0)} "
                                  f"(line {line(open_[0].start())}), which is not closed")
            open_ = (m, kind, name)
        else:
            if open_ is None:
                raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)} closes no marker")
            if kind != open_[1]:
                raise MarkerError(f"{page}:{line(m.start())}: {m.group(0)} closes {open_[0].group(0)} "
                                  f"(line {line(open_[0].start())}): it takes <!--/{open_[1]}-->")
            found.append((kind, open_[2], text[open_[0].end():m.start()], (open_[0].end(), m.start())))
            open_ = None
    if open_ is not None:
        raise MarkerError(f"{page}:{line(open_[0].start())}: {open_[0].group(0)} is never closed "
                          f"(<!--/{open_[1]}-->)")
    return found


def rewrite(text, figures, page):
    """The text with each marker's content replaced by its figure (markers checked first)."""
    out, at = [], 0
    for _, name, _, (a, b) in markers(text, page):
        out.append(text[at:a])
        out.append(figures[name])
        at = b
    return "".join(out) + text[at:]


def same_figure(committed, current):
    """Equal as printed, but for one unit in the last printed digit of a number (its
    mantissa; the exponent and the digits printed must agree)."""
    if committed == current:
        return True
    a, b = NUMBER.findall(committed), NUMBER.findall(current)
    if len(a) != len(b) or NUMBER.sub("#", committed) != NUMBER.sub("#", current):
        return False
    for x, y in zip(a, b):
        (mx, _, ex), (my, _, ey) = (v.replace(",", "").lower().partition("e") for v in (x, y))
        digits = len(mx.split(".")[1]) if "." in mx else 0
        if ex != ey or (len(my.split(".")[1]) if "." in my else 0) != digits:
            return False
        if abs(float(mx) - float(my)) > 1.01 * 10 ** -digits:
            return False
    return True


# ---------------------------------------------------------------------------- transcripts

def transcripts(text, page="the page"):
    """(command, output lines, (first, last) line index of the output) of each console
    block whose first line is ``$ COMMAND`` and that shows one command."""
    out, lines, i = [], text.split("\n"), 0
    while i < len(lines):
        if lines[i].strip() == "```console":
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            if j == len(lines):
                raise MarkerError(f"{page}:{i + 1}: a ```console block that is never closed")
            body = lines[i + 1:j]
            if body and body[0].startswith("$ ") and sum(ln.startswith("$ ") for ln in body) == 1:
                out.append((body[0][2:].strip(), body[1:], (i + 2, j)))
            i = j
        i += 1
    return out


def printed(output):
    """What a transcript shows of a command's output: cargo's status lines left out
    (nothing for an output of nothing)."""
    lines = output.rstrip("\n").split("\n") if output.strip("\n") else []
    return [ln.rstrip() for ln in lines if not CARGO_STATUS.match(ln)]


def same_transcript(shown, output):
    """Whether a transcript shows `output` (a line beginning ``wall time`` compared up
    to its colon); the first difference in words, or None."""
    got = printed(output)
    if len(shown) != len(got):
        return f"{len(shown)} lines shown, {len(got)} printed:\n" + "\n".join(got)
    for s, g in zip(shown, got):
        if s.startswith("wall time") and g.startswith("wall time"):
            if s.split(":")[0] != g.split(":")[0]:
                return f"shown `{s}`, printed `{g}`"
        elif not same_figure(SECONDS.sub("#s", s.rstrip()), SECONDS.sub("#s", g)):
            return f"shown `{s}`, printed `{g}`"
    return None


def run_command(cmd, timeout=600):
    env = dict(os.environ, PATH=VENV_BIN + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg")
    env.pop("PYTHONPATH", None)
    # One stream, as a terminal shows it (what test_docs.py compares too).
    p = subprocess.run(["bash", "-c", cmd], cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True, timeout=timeout)
    if p.returncode != 0:
        raise RuntimeError(f"`{cmd}` exited with {p.returncode}:\n{p.stdout[-3000:]}")
    return p.stdout


# ---------------------------------------------------------------------------- the command

def figures_wanted(texts, only=None):
    names = {(name, page) for page, t in texts.items() for _, name, _, _ in markers(t, page)}
    sources = {n.split(".")[0] for n, _ in names} | {s for s in SOURCES if not s.startswith(("pair", "seed"))}
    unknown = sorted(f"{page}: {n}" for n, page in names if n.split(".")[0] not in SOURCES)
    if unknown:
        raise MarkerError(f"figures of no source (SOURCES: {', '.join(SOURCES)}): {'; '.join(unknown)}")
    return sorted(s for s in sources if only is None or s in only)


def compute(sources, log=print):
    import contextlib
    import io
    figures = {}
    for s in sources:
        t0 = time.perf_counter()
        # The FMUs' warnings, which fmpy prints, are part of what the figures show, not news.
        with contextlib.redirect_stdout(io.StringIO()):
            figures.update(SOURCES[s]())
        log(f"{s}: {time.perf_counter() - t0:.1f} s")
    return figures


def check(only=None, log=print, transcripts_too=True):
    """The stale figures, plots and transcripts, as messages (empty when all are
    current). tests/test_figures.py leaves the transcripts to tests/test_docs.py."""
    global CHECKING
    CHECKING, STALE[:] = True, []
    texts, _ = read_pages()
    figures = compute(figures_wanted(texts, only), log)
    stale = list(STALE)
    for page, text in texts.items():
        for kind, name, committed, _ in markers(text, page):
            if name in figures and not same_figure(committed, figures[name]):
                stale.append(f"{page}: {name} {differs(committed, figures[name])}")
            elif name not in figures and (only is None or name.split(".")[0] in only):
                stale.append(f"{page}: {name}: its source gives no such figure")
        if transcripts_too and only is None:
            for cmd, shown, (first, _) in transcripts(text):
                try:
                    diff = same_transcript(shown, run_command(cmd))
                except (RuntimeError, subprocess.TimeoutExpired) as e:
                    diff = str(e)
                if diff is not None:
                    stale.append(f"{page}:{first}: `$ {cmd}`: {diff}")
    CHECKING = False
    return stale


def differs(committed, current):
    """How a committed figure differs from the build's: the whole figure, or a table's
    first row that differs."""
    a, b = committed.strip().split("\n"), current.strip().split("\n")
    row = next((i for i, (x, y) in enumerate(zip(a, b)) if not same_figure(x, y)), None)
    if len(a) == len(b) > 1 and row is not None:
        return f"row {row + 1} reads {a[row]!r}; the current build gives {b[row]!r}"
    return f"reads {committed.strip()!r}; the current build gives {current.strip()!r}"


def write(only=None, transcripts_too=True, log=print):
    """Rewrites every figure, transcript, plot and the kit; the transcripts whose command
    failed (left as they were), as messages."""
    failed = []
    texts, crlf = read_pages()
    figures = compute(figures_wanted(texts, only), log)
    for page, text in texts.items():
        missing = [n for _, n, _, _ in markers(text, page) if n not in figures and (only is None or n.split(".")[0] in only)]
        if missing:
            failed.append(f"{page}: its source gives no figure {', '.join(missing)}")
        new = rewrite(text, {n: figures.get(n, c) for _, n, c, _ in markers(text, page)}, page)
        if transcripts_too and only is None:
            lines = new.split("\n")
            for cmd, shown, (a, b) in reversed(transcripts(new)):
                t0 = time.perf_counter()
                try:
                    output = run_command(cmd)
                    if ROOT in output:
                        raise RuntimeError(f"`{cmd}` prints this checkout's path {ROOT}: print paths "
                                           "relative to the repository, as couple.py does")
                    if "```" in output:
                        raise RuntimeError(f"`{cmd}` prints a code fence, which would end its block")
                    # A transcript that shows what the command prints (times apart) stays as it is.
                    if not shown or same_transcript(shown, output) is not None:
                        lines[a:b] = printed(output)
                except (RuntimeError, subprocess.TimeoutExpired) as e:
                    failed.append(f"{page}: {e}")
                    continue
                log(f"{page}: $ {cmd}: {time.perf_counter() - t0:.1f} s")
            new = "\n".join(lines)
        if new != text:
            with open(os.path.join(ROOT, page), "w", encoding="utf-8", newline="") as fh:
                fh.write(new.replace("\n", "\r\n") if page in crlf else new)
            log(f"wrote {page}")
    kit = os.path.join(ROOT, "python", "wheelflat_kit.py")
    if os.path.exists(kit) and only is None:
        run_command("python3 python/wheelflat_kit.py write")
        log("wrote the regression kit (regression/)")
    return failed


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare only; exit 1 naming each stale figure")
    ap.add_argument("--only", default=None, help=f"comma-separated sources of {', '.join(SOURCES)}")
    args = ap.parse_args(argv)
    only = None if args.only is None else set(args.only.split(","))
    if only is not None and (not only or only - set(SOURCES)):
        ap.error(f"--only: unknown source {sorted(only - set(SOURCES)) or repr(args.only)}; known: {', '.join(SOURCES)}")
    try:
        read_pages()
    except MarkerError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    wf.ensure_venv()
    wf.build_fmus()
    if args.check:
        stale = check(only)
        for s in stale:
            print(f"stale: {s}")
        print("every figure is current" if not stale else f"{len(stale)} stale figures")
        return 1 if stale else 0
    failed = write(only)
    for f in failed:
        print(f"not regenerated: {f}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
