"""The documentation's commands and links.

Every shell command in the fenced ``bash``, ``sh`` and ``console`` blocks of README.md
and docs/guide/*.md (a block without a language that shows ``$ `` prompts counts as
``console``), and every ``python`` block there, is either run here from the repository
root with .venv first on PATH and must exit with status 0, or is named in ``MAPPED``
with the test of the test command that runs the same script with the same options and
the reason it is not run here. There is no third way: a new command is run (and must
be quick, under ``QUICK_S``) until it is mapped. Commands written inline in the prose
(``cargo run --release --example NAME`` and the like) must name a program that exists.
Every relative link of README.md and docs/**/*.md must point to a file that exists, and
an anchor into a Markdown file to one of its headings. The FMUs docs/ARCHITECTURE.md
and README.md name are the registry's (fmu/fmus.json), and every ``src/`` path
docs/ARCHITECTURE.md names exists.

Run by the README's test command, after the FMUs, fmu/systems and .venv are built. The
scripts the guide shows pack fmu/ again (``wheelflat_fmus.build_fmus``, the same build);
the FMUs the test command packed are put back afterwards.
"""

import ast
import glob
import os
import re
import shlex
import shutil
import subprocess
import sys
import time

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV_BIN = os.path.join(ROOT, ".venv", "bin")
# The guide's pages in reading order (a study's results are read after it has run);
# pages added later come after these.
PAGE_ORDER = ["README.md", "docs/guide/README.md", "docs/guide/quickstart.md", "docs/guide/couple-a-vehicle.md", "docs/guide/masters.md",
              "docs/guide/studies.md", "docs/guide/results.md", "docs/guide/fmus.md"]
# A command run here must finish within this (s); a longer one belongs in MAPPED.
QUICK_S = 60

# Commands not run here: the command (as written, comments left out; a Python block by
# its first line, "python: ...") -> (where the test command runs it: a file, or
# "tests/FILE.py::TEST", which must be on the test command's pytest line; the texts that
# place must contain, the script and its options; why it is not run here).
MAPPED = {
    "bash scripts/test.sh": (
        ".ci/run", ["exec bash scripts/test.sh"],
        "the test command itself; CI runs it through .ci/run"),
    "python3 python/wheelflat_fmus.py": (
        "scripts/test.sh", ["python3 python/wheelflat_fmus.py"],
        "sets up .venv, which this test runs in; the test command runs it before pytest"),
    "bash scripts/build_fmus_glibc228.sh fmu": (
        "scripts/test.sh", ["bash scripts/build_fmus_glibc228.sh fmu\n"],
        "the one build of the FMUs, minutes from a clean clone; the test command packs the FMUs every "
        "later test loads with it, and the main command that this test runs packs through it"),
    "python: vehicle.enterInitializationMode(); track.enterInitializationMode()": (
        "tests/test_fmu_coupling.py::test_static_handshake_puts_the_pair_at_rest", ["wf.run_pair("],
        "pseudo-code (value references by name) of wheelflat_fmus.static_handshake, which run_pair "
        "calls; the test runs it and checks that the pair starts at rest"),
    "python: z = vehicle.getReal(wheels); dz = vehicle.getRealOutputDerivatives(wheels, [1, 1, 1])": (
        "tests/test_fmu_derivatives.py::test_input_derivatives_reduce_the_error_at_five_and_ten_times_the_step",
        ["wf.run_pair(", "input_derivatives=derivs"],
        "pseudo-code of run_pair(..., input_derivatives=True), the loop the page names; the test "
        "runs it at 5 and 10 times the track's step"),
    "python: track.setReal(sideframe_z_and_v, bogie.side_frames())": (
        "tests/test_fmu_coupling.py::test_a_bogie_model_at_1_ms_couples_at_the_axle_boxes_within_two_percent",
        ["wf.run_axle_box_pair("],
        "pseudo-code for a third-party bogie model; run_axle_box_pair is that loop with "
        "RollPlaneVehicle as the bogie, which the test runs at 1 and 2 ms"),
    ".venv/bin/python -m pip wheel --no-deps --no-build-isolation -w dist python/": (
        "tests/test_study_runs.py::test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout",
        ['"pip", "wheel"', '"--no-deps", "--no-build-isolation"', 'os.path.join(ROOT, "python")'],
        "builds the wheel; the test builds it into a temporary folder, not the checkout's dist/"),
    "pip install dist/wheelflat-0.1.0-py3-none-linux_x86_64.whl": (
        "tests/test_study_runs.py::test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout",
        ['"pip", "--python", py, "install"', "wheelflat-*-py3-none-linux_*.whl"],
        "installs on a cluster's host; the test installs into a new environment, not this .venv"),
    "python -m distributed.cli.dask_scheduler --host 127.0.0.1 --port 8786 --no-dashboard &": (
        "tests/test_study_runs.py::test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout",
        ['"distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port"', '"--no-dashboard"'],
        "a scheduler that runs until stopped; the test starts it on a free port in an empty folder"),
    "python -m distributed.cli.dask_worker tcp://127.0.0.1:8786 --nworkers 1 --nthreads 1 --no-dashboard &": (
        "tests/test_study_runs.py::test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout",
        ['"distributed.cli.dask_worker", addr, "--nworkers", "1"', '"--nthreads", "1", "--no-dashboard"'],
        "a worker that runs until stopped; the test starts two, each in its own empty folder"),
    "wheelflat-study speed_flat.toml --scheduler tcp://127.0.0.1:8786": (
        "tests/test_study_runs.py::test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout",
        ['"wheelflat-study"', '"--scheduler", addr'],
        "needs the scheduler and workers above; the test runs it from an empty folder with only the "
        "installed wheel and compares the table with a serial run bit for bit"),
}
# A command that needs another to have run first: the study's tables are read after the
# study has run.
NEEDS = {
    "python: import pandas as pd": "cd python && ../.venv/bin/python -m wheelflat_study ../studies/speed_flat.toml",
}
PROGRAM = re.compile(r"^(cargo run|python3 python/|bash scripts/|\.venv/bin/python|cd python)")


def pages():
    found = ["README.md"] + sorted(os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, "docs", "guide", "*.md")))
    return [p for p in PAGE_ORDER if p in found] + [p for p in found if p not in PAGE_ORDER]


def fenced_blocks(text):
    """(language, body, line number) of each fenced block of a Markdown text."""
    blocks, lines, i = [], text.split("\n"), 0
    while i < len(lines):
        m = re.match(r"^(\s*)(`{3,}|~{3,})\s*([\w+-]*)", lines[i])
        if not m:
            i += 1
            continue
        fence, lang, start = m.group(2), m.group(3).lower(), i + 1
        body = []
        i += 1
        while i < len(lines) and not lines[i].strip().startswith(fence):
            body.append(lines[i])
            i += 1
        blocks.append((lang, "\n".join(body), start))
        i += 1
    return blocks


def without_code(text):
    """The text with fenced blocks blanked out (line numbers kept)."""
    out, fence = [], None
    for line in text.split("\n"):
        m = re.match(r"^\s*(`{3,}|~{3,})", line)
        if fence is None and m:
            fence = m.group(1)
            out.append("")
        elif fence is not None:
            if line.strip().startswith(fence):
                fence = None
            out.append("")
        else:
            out.append(line)
    return "\n".join(out)


def key_of(command):
    """A shell command as MAPPED names it: its words, comments left out."""
    return " ".join(shlex.split(command, comments=True))


def shell_commands(lang, body):
    """The commands of a block: every line of a bash or sh block that is not a comment
    (backslash continuations joined); the ``$ `` lines of a console transcript."""
    if lang in ("bash", "sh", "shell"):
        joined = re.sub(r"\\\n", " ", body)
        return [ln.strip() for ln in joined.split("\n") if ln.strip() and not ln.strip().startswith("#")]
    if lang == "console" or (lang == "" and re.search(r"^\$ ", body, re.M)):
        return [ln[2:].strip() for ln in body.split("\n") if ln.startswith("$ ")]
    return []


def collect():
    """Every command of the pages, in order: (key, kind, text, where). A command that
    stands in several blocks is one; two Python blocks that begin alike but differ are
    two (the later keyed by its place too), so neither goes unrun."""
    items, seen, bodies = [], set(), {}
    for page in pages():
        text = open(os.path.join(ROOT, page)).read()
        for lang, body, line in fenced_blocks(text):
            if lang in ("python", "py"):
                first = next(ln for ln in body.split("\n") if ln.strip())
                key = "python: " + " ".join(re.sub(r"\s+#.*$", "", first).split())
                if bodies.setdefault(key, body) != body:
                    key = f"{key} ({page}:{line})"
                entries = [(key, "python", body)]
            else:
                entries = [(key_of(c), "shell", c) for c in shell_commands(lang, body)]
            for key, kind, cmd in entries:
                if key not in seen:
                    seen.add(key)
                    items.append((key, kind, cmd, f"{page}:{line}"))
    return items


COMMANDS = collect()
TO_RUN = [c for c in COMMANDS if c[0] not in MAPPED]


@pytest.fixture(scope="module", autouse=True)
def fmus_put_back(tmp_path_factory):
    """Keeps the FMUs the test command packed: the guide's scripts pack fmu/ again."""
    fmu = os.path.join(ROOT, "fmu")
    saved = tmp_path_factory.mktemp("fmu_saved") / "fmu"
    if os.path.isdir(fmu):
        shutil.copytree(fmu, saved, symlinks=True)
    yield
    if os.path.isdir(saved):
        shutil.copytree(saved, fmu, symlinks=True, dirs_exist_ok=True)


@pytest.fixture(scope="module")
def runner(tmp_path_factory):
    """Runs a command once (the same command may stand in several blocks)."""
    env = dict(os.environ, PATH=VENV_BIN + os.pathsep + os.environ.get("PATH", ""), MPLBACKEND="Agg",
               TMPDIR=str(tmp_path_factory.mktemp("docs_tmp")))
    env.pop("PYTHONPATH", None)
    done = {}
    by_key = {c[0]: c for c in COMMANDS}

    def run(key):
        if key in done:
            return done[key]
        _, kind, cmd, where = by_key[key]
        argv = [os.path.join(VENV_BIN, "python"), "-c", cmd] if kind == "python" else ["bash", "-c", cmd]
        t0 = time.perf_counter()
        try:
            # One stream, as a terminal shows it: a transcript's lines in their order.
            p = subprocess.run(argv, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True, timeout=QUICK_S)
            result = (p.returncode, p.stdout, time.perf_counter() - t0)
        except subprocess.TimeoutExpired:
            result = (None, f"still running after {QUICK_S} s: map it in MAPPED to the test that runs it", QUICK_S)
        done[key] = result
        return result
    return run


@pytest.mark.parametrize("key", [c[0] for c in TO_RUN], ids=[f"{c[3]} {c[0][:60]}" for c in TO_RUN])
def test_a_command_of_the_guide_runs(runner, key):
    if key in NEEDS:
        rc, out, _ = runner(NEEDS[key])
        assert rc == 0, f"{NEEDS[key]} (needed first) failed:\n{out[-3000:]}"
    rc, out, seconds = runner(key)
    assert rc == 0, f"`{key}` exited with {rc} after {seconds:.1f} s:\n{out[-3000:]}"


def transcript_items():
    """(key, page:line, the lines shown) of each console block that shows one command's output."""
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import wheelflat_figures as figures
    for page in pages():
        text = open(os.path.join(ROOT, page)).read()
        for cmd, shown, (first, _) in figures.transcripts(text):
            yield key_of(cmd), f"{page}:{first}", shown


TRANSCRIPTS = list(transcript_items())


@pytest.mark.parametrize("key,where,shown", TRANSCRIPTS, ids=[f"{w} {k[:50]}" for k, w, _ in TRANSCRIPTS])
def test_a_transcript_shows_what_its_command_prints(runner, key, where, shown):
    # Issue 40 (items 1, 2): a console block's output is what the command prints on this
    # build, figure by figure (python/wheelflat_figures.py writes it; the stated rounding
    # is its same_figure's). A block without output lines is filled by that command.
    import wheelflat_figures as figures
    assert shown, f"{where}: `{key}` shows no output: run python3 python/wheelflat_figures.py"
    # A transcript written in one checkout holds in every other.
    assert not [ln for ln in shown if ROOT in ln or "/work/" in ln], f"{where}: an absolute path in {shown}"
    rc, out, _ = runner(key)
    assert rc == 0, out[-3000:]
    diff = figures.same_transcript(shown, out)
    assert diff is None, f"{where}: `{key}`: {diff}\n(python3 python/wheelflat_figures.py writes what it prints)"


def test_every_python_test_file_is_on_the_test_commands_pytest_line():
    # tests/test_two_axle.py was left off it once, and ran nowhere.
    files = {os.path.relpath(p, ROOT) for p in glob.glob(os.path.join(ROOT, "tests", "test_*.py"))}
    assert files - pytest_line() == set()


def pytest_line():
    """The test files on the test command's pytest line."""
    text = open(os.path.join(ROOT, "scripts", "test.sh")).read()
    return set(re.findall(r"tests/\w+\.py", "\n".join(ln for ln in text.split("\n") if "pytest" in ln)))


@pytest.mark.parametrize("key", sorted(MAPPED))
def test_a_mapped_command_is_in_the_guide_and_run_by_the_test_command(key):
    where, texts, reason = MAPPED[key]
    assert reason.strip()
    assert key in {c[0] for c in COMMANDS}, f"`{key}` is mapped but no page shows it any more: drop it from MAPPED"
    path, _, test = where.partition("::")
    source = open(os.path.join(ROOT, path)).read()
    if test:
        assert path in pytest_line(), f"{path} is not on the pytest line of scripts/test.sh"
        fn = next((n for n in ast.walk(ast.parse(source)) if isinstance(n, ast.FunctionDef) and n.name == test), None)
        assert fn is not None, f"{where}: no such test"
        source = ast.get_source_segment(source, fn)
    else:
        assert path in (".ci/run", "scripts/test.sh"), where
    for t in texts:
        assert t in source, f"{where} does not run `{t.strip()}`"


def test_the_readme_is_a_landing_page_with_the_test_command_ci_runs():
    readme = open(os.path.join(ROOT, "README.md")).read()
    # Issue 40 (item 5): at most 120 lines.
    assert readme.count("\n") <= 120
    assert "bash scripts/test.sh" in {c[0] for c in COMMANDS if c[3].startswith("README.md")}
    assert "exec bash scripts/test.sh" in open(os.path.join(ROOT, ".ci", "run")).read()


def inline_commands():
    for page in pages():
        text = without_code(open(os.path.join(ROOT, page)).read())
        for span in re.findall(r"`([^`]+)`", text):
            span = " ".join(span.split())
            if PROGRAM.match(span):
                yield page, span


def test_commands_in_the_prose_name_programs_that_exist():
    cargo = open(os.path.join(ROOT, "Cargo.toml")).read()
    missing = []
    for page, cmd in inline_commands():
        words = shlex.split(cmd)
        if words[:2] == ["cargo", "run"]:
            for flag, folder in (("--example", "examples"), ("--bin", "src/bin")):
                if flag in words:
                    name = words[words.index(flag) + 1]
                    ok = (os.path.exists(os.path.join(ROOT, folder, name + ".rs"))
                          or os.path.exists(os.path.join(ROOT, folder, name, "main.rs"))
                          or f'name = "{name}"' in cargo)
                    if not ok:
                        missing.append((page, cmd))
        else:
            paths = [w for w in words if "/" in w and not w.startswith("-") and not w.startswith(".venv")
                     and w != "../.venv/bin/python"]
            for w in paths[:1]:
                base = os.path.join(ROOT, "python") if words[0] == "cd" else ROOT
                if not os.path.exists(os.path.normpath(os.path.join(base, w))):
                    missing.append((page, cmd))
    assert not missing, missing


def slug(heading, counts):
    """GitHub's anchor of a heading."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading).replace("`", "").replace("*", "")
    s = re.sub(r"[^\w\- ]", "", text.strip().lower()).replace(" ", "-")
    n = counts.get(s, 0)
    counts[s] = n + 1
    return s if n == 0 else f"{s}-{n}"


def anchors(path):
    counts = {}
    return {slug(m.group(1), counts)
            for m in re.finditer(r"^#{1,6}\s+(.*?)\s*#*\s*$", without_code(open(path).read()), re.M)}


def markdown_files():
    return ["README.md"] + sorted(os.path.relpath(p, ROOT)
                                  for p in glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))


LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)|^\s*\[[^\]]+\]:\s*(\S+)", re.M)


@pytest.mark.parametrize("page", markdown_files())
def test_every_relative_link_points_to_what_exists(page):
    text = without_code(open(os.path.join(ROOT, page)).read())
    text = re.sub(r"`[^`\n]*`", "", text)
    broken = []
    for m in LINK.finditer(text):
        target = m.group(1) or m.group(2)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target, re.I):
            continue
        path, _, anchor = target.partition("#")
        full = os.path.normpath(os.path.join(ROOT, os.path.dirname(page), path)) if path else os.path.join(ROOT, page)
        if not os.path.exists(full):
            broken.append(f"{target}: no such file")
        elif anchor and full.endswith(".md") and anchor not in anchors(full):
            broken.append(f"{target}: no heading with that anchor")
    assert not broken, broken


# The pages that name the FMUs, and the most lines docs/ARCHITECTURE.md may have.
FMU_PAGES = ["docs/ARCHITECTURE.md", "README.md", "docs/guide/fmus.md"]
ARCHITECTURE_LINES = 150
# The shape of an FMU's model identifier where no list knows it: a CamelCase word in the
# prose (outside code) ending as the FMUs' names end.
FMU_SHAPE = re.compile(r"(?<![\w.`])[A-Z][a-z]+(?:[A-Z][a-z]+)*(?:Contact|System|Vehicle|Bogie|Wagon)(?![\w`])")


def registry_fmus():
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import wheelflat_fmus as wf
    return set(wf.registry()["fmus"])


def fmu_names_in(text, known):
    """The FMU model identifiers a page names: each name of ``known`` (the registry's,
    the table's <Fmu> elements, the FMUs' pages) found as a whole word, and any word of
    an FMU's shape in its prose."""
    named = {n for n in known if re.search(r"(?<![\w.])" + re.escape(n) + r"(?!\w)", text)}
    prose = re.sub(r"`[^`\n]*`", "", without_code(text))
    return named | set(FMU_SHAPE.findall(prose))


@pytest.mark.parametrize("page", FMU_PAGES)
def test_the_fmus_a_page_names_are_the_registrys(page):
    fmus = registry_fmus()
    table = open(os.path.join(ROOT, "modelDescription", "variables.xml")).read()
    known = (fmus | set(re.findall(r'<Fmu\s+modelIdentifier="(\w+)"', table))
             | {os.path.basename(p)[:-5] for p in glob.glob(os.path.join(ROOT, "build", "pages", "[A-Z]*.html"))})
    named = fmu_names_in(open(os.path.join(ROOT, page)).read(), known)
    assert named == fmus, (f"{page} names FMUs the registry lacks: {sorted(named - fmus)}; "
                           f"leaves out: {sorted(fmus - named)}")


def test_the_architecture_page_is_short_and_its_source_paths_exist():
    text = open(os.path.join(ROOT, "docs", "ARCHITECTURE.md")).read()
    assert text.count("\n") < ARCHITECTURE_LINES
    paths = {p.rstrip(".") for p in re.findall(r"(?<![\w/])src/[\w/.-]*", text)}
    assert paths
    assert not [p for p in sorted(paths) if not os.path.exists(os.path.join(ROOT, p))]


if __name__ == "__main__":
    for key, kind, cmd, where in COMMANDS:
        print(f"{where:40} {'mapped' if key in MAPPED else 'run':7} {key}")
    sys.exit(0)


RELEASE = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR") or "target", "release")


@pytest.mark.parametrize("command", [
    [os.path.join(RELEASE, "wheelflat")], [os.path.join(RELEASE, "wheelflat_case")],
    [os.path.join(RELEASE, "build_fmus")],
    [VENV_BIN + "/python", "python/couple.py"], [VENV_BIN + "/python", "python/wheelflat_fmus.py"],
    [VENV_BIN + "/python", "-m", "wheelflat_study"],
])
def test_every_command_answers_help(command):
    # Issue 40 (item 4): `--help` on every command prints its usage and changes nothing
    # (build_fmus took it for its output folder).
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    r = subprocess.run(command + ["--help"], cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "usage" in r.stdout.lower(), (r.returncode, r.stdout, r.stderr)
    assert not os.path.exists(os.path.join(ROOT, "--help"))


@pytest.mark.parametrize("args,rc,said", [
    (["--speed", "1000"], 1, "`speed` = 277.77777777777777 m/s is out of range"),
    (["--flat-length", "-1"], 1, "flat.left[1].length"),
    (["--stop", "-1"], 2, "--stop -1.0: the simulated time must be finite, 0 < stop <= 60 s"),
    (["--stop", "nan"], 2, "--stop nan"),
    (["--step", "0", "--stop", "0.01"], 2, "--step 0.0: the communication step must be finite"),
])
def test_couple_py_refuses_bad_values_naming_them_without_a_traceback(args, rc, said, tmp_path):
    # The breaker's findings: tracebacks, a misleading fmi2Terminate error after the
    # FMU's own message, and the vehicle's unpacked FMU left in $TMPDIR.
    env = dict(os.environ, TMPDIR=str(tmp_path))
    r = subprocess.run([VENV_BIN + "/python", "python/couple.py", "--out", str(tmp_path / "out")] + args, cwd=ROOT,
                       env=env, capture_output=True, text=True, timeout=300)
    out = r.stdout + r.stderr
    assert r.returncode == rc and said in out and "Traceback" not in out and "fmi2Terminate" not in out, out
    assert [p for p in os.listdir(tmp_path) if p != "out"] == []
