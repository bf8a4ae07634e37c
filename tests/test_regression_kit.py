"""The regression kit (python/wheelflat_kit.py, regression/): every FMU of the registry
has its references in the Cross-Check's layout, the kit's check passes on the current
build, the references are what the build gives (written afresh they match; a stale one
fails), a scratch change is caught naming the model and the signal, and the commands of
each ReadMe.md run and reproduce the reference."""

import os
import re
import shutil
import subprocess
import sys

import numpy as np
import pytest

from fmu_helpers import wf

sys.path.insert(0, os.path.join(wf.ROOT, "python"))
import wheelflat_kit as kit  # noqa: E402

KIT = kit.default_kit()
SCRIPT = os.path.join(wf.ROOT, "python", "wheelflat_kit.py")
FMA = os.path.exists("/proc/cpuinfo") and " fma" in open("/proc/cpuinfo").read()



@pytest.fixture(scope="module")
def fmus():
    """fmu/ with every FMU of the registry (built first when one is missing)."""
    models = wf.registry()["fmus"] if os.path.isfile(os.path.join(wf.FMU_DIR, "fmus.json")) else []
    if not models or not all(os.path.isfile(os.path.join(wf.FMU_DIR, m + ".fmu")) for m in models):
        wf.build_fmus()
    return wf.FMU_DIR


@pytest.fixture(scope="module")
def models(fmus):
    return wf.registry(fmus)["fmus"]


def run(*args, **kw):
    return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True, cwd=wf.ROOT, **kw)


def in_layout_copy(tmp_path, fmus=None):
    """A copy of the kit under tmp_path in the Cross-Check's layout, the FMUs beside
    their references when `fmus` is given."""
    dst = os.path.join(tmp_path, "2.0", "cs", kit.PLATFORM, kit.TOOL, kit.version())
    shutil.copytree(KIT, dst, ignore=shutil.ignore_patterns("*.fmu", "*_out.csv"))
    if fmus:
        kit.copy_fmus(fmus, dst)
    return dst


def test_every_fmu_of_the_registry_has_its_references_in_the_cross_check_layout(models):
    from fmpy.cross_check.validate_vendor_repo import read_csv as xc_read_csv
    from fmpy.util import read_ref_opt_file
    assert os.path.relpath(KIT, wf.ROOT).split(os.sep) == ["regression", "2.0", "cs", "linux64", "wheelflat",
                                                           kit.version()]
    assert sorted(os.listdir(KIT)) == sorted(models), "a model folder for every FMU of the registry, no other"
    for m in models:
        f = kit.files(KIT, m)
        for k in ("ref", "in", "opt", "readme"):
            assert os.path.isfile(f[k]), f"{m}: no {os.path.basename(f[k])}"
        opt = read_ref_opt_file(f["opt"])
        assert (opt["StartTime"], opt["StopTime"], opt["StepSize"]) == (kit.START, kit.STOP, kit.step_of(m))
        for k in ("ref", "in"):
            assert os.path.getsize(f[k]) < 1e6, "the Cross-Check's limit on a CSV file"
            head = open(f[k]).readline().rstrip("\n")
            assert re.fullmatch(r'"time"(,"[^"]+")+', head), f"{m}: names quoted, time first: {head}"
            xc_read_csv(f[k])  # the Cross-Check's reader: numbers, time increasing
        ref = xc_read_csv(f["ref"])
        assert 5 <= len(ref.dtype.names) - 1 <= 10 and ref["time"][-1] == pytest.approx(kit.STOP)


def test_the_kit_is_checked_within_seconds_and_passes_for_every_fmu(fmus, models):
    import time
    t0 = time.perf_counter()
    report = kit.check(fmus, KIT)
    assert time.perf_counter() - t0 < 30
    assert list(report) == models
    assert all(p == [] for p in report.values()), report
    r = run("check", "--fmus", fmus)
    assert r.returncode == 0, r.stdout + r.stderr
    assert f"all {len(models)} FMUs match their references" in r.stdout


def test_the_references_are_what_the_current_build_gives(fmus, models, tmp_path):
    """Written afresh from the current build, the kit is the committed one: the option
    and ReadMe files the same bytes, the CSV files the same columns and times and every
    value within the check's tolerance (to rounding where the CPU lacks FMA)."""
    from fmpy.util import read_csv
    fresh = str(tmp_path / "kit")
    kit.write(fmus, fresh)
    assert sorted(os.listdir(fresh)) == sorted(os.listdir(KIT))
    for m in models:
        old, new = kit.files(KIT, m), kit.files(fresh, m)
        for k in ("opt", "readme"):
            assert open(new[k]).read() == open(old[k]).read(), \
                f"{m}: {os.path.basename(old[k])} is stale: python3 python/wheelflat_kit.py write"
        for k in ("in", "ref"):
            a, b = read_csv(old[k]), read_csv(new[k])
            assert a.dtype.names == b.dtype.names and len(a) == len(b), \
                f"{m}: {os.path.basename(old[k])} is stale: python3 python/wheelflat_kit.py write"
            assert np.array_equal(a["time"], b["time"])
            if FMA:
                assert open(new[k]).read() == open(old[k]).read(), f"{m}: {os.path.basename(old[k])} is stale"
        opt = {"StartTime": kit.START, "StopTime": kit.STOP}
        assert kit.compare(m, read_csv(new["ref"]), read_csv(old["ref"]), opt) == []


def test_a_stale_reference_fails_naming_the_model_and_the_signal(fmus, tmp_path):
    copy = in_layout_copy(tmp_path)
    path = kit.files(copy, "HalfCarBogie")["ref"]
    lines = open(path).read().splitlines()
    names = [n.strip('"') for n in lines[0].split(",")]
    col = names.index("wheelset[2].z")
    # One sample, as an older build might have left it: 1e-4 off.
    row = lines[300].split(",")
    row[col] = repr(float(row[col]) * (1 + 1e-4))
    lines[300] = ",".join(row)
    open(path, "w").write("\n".join(lines) + "\n")
    report = kit.check(fmus, copy)
    assert [m for m, p in report.items() if p] == ["HalfCarBogie"]
    (problem,) = report["HalfCarBogie"]
    assert problem.startswith("HalfCarBogie: wheelset[2].z: ") and "tolerance 1e-06" in problem, problem


def test_a_scratch_change_is_caught_naming_the_model_and_the_signal(fmus, models):
    # A parameter 5 % off: the wagon's primary springs.
    report = kit.check(fmus, KIT, start_values={"Wagon": {"vehicle.primary.stiffness": 6.5e6 * 1.05}})
    assert [m for m, p in report.items() if p] == ["Wagon"]
    signals = {p.split(": ")[1] for p in report["Wagon"]}
    assert "wheelset.z" in signals and signals <= set(kit.OUTPUTS["Wagon"]), report["Wagon"]
    # The same from the command line: exit 1, the model and the signal named.
    r = run("check", "--fmus", fmus, "--set", "Wagon:vehicle.primary.stiffness=6825000")
    assert r.returncode == 1, r.stdout + r.stderr
    assert "Wagon              FAILED" in r.stdout and "  Wagon: wheelset.z: " in r.stdout
    assert "1 of 6 FMUs differ from their references" in r.stderr and ": Wagon; wall time" in r.stderr
    # The Cross-Check's band alone lets a change of the impact through (the flat 0.1 mm
    # shallower: only the samples around it move), which the tolerance catches; a gross
    # one (the flat a third of a revolution earlier) fails it, signal by signal.
    shallower = {"CoupledSystem": {"flat.left[1].depth": 1.4e-3}}
    assert kit.check(fmus, KIT, start_values=shallower, tolerance=0, models=["CoupledSystem"]) == {"CoupledSystem": []}
    assert "CoupledSystem: contact.left.force: " in "\n".join(
        kit.check(fmus, KIT, start_values=shallower, models=["CoupledSystem"])["CoupledSystem"])
    band = kit.check(fmus, KIT, start_values={"TrackContact": {"flat.left[1].angle": 1.2}}, tolerance=0,
                     models=["TrackContact"])["TrackContact"]
    assert band and all("of the samples outside the Cross-Check's band" in p for p in band)
    assert "TrackContact: contact.left.force: " in "\n".join(band)


def test_the_check_refuses_to_set_an_input_and_names_a_model_it_lacks(fmus):
    report = kit.check(fmus, KIT, start_values={"CoupledSystem": {"speed": 15.0}, "Bogie": {"x": 1.0}},
                       models=["CoupledSystem"])
    assert report["CoupledSystem"] == ["CoupledSystem: speed: not a parameter the check may set: "
                                       "CoupledSystem_in.csv gives it"]
    assert report["Bogie"][0].startswith("Bogie: --set names no FMU of the kit")


def test_the_readme_commands_reproduce_the_references(fmus, models, tmp_path):
    """Each ReadMe.md's fmpy command line, run in a copy of its folder with the FMU
    beside it: no FMU warning, the reference again (byte for byte on a CPU with FMA)."""
    from fmpy.util import read_csv, read_ref_opt_file
    copy = in_layout_copy(tmp_path, fmus)
    env = dict(os.environ, PATH=os.path.dirname(sys.executable) + os.pathsep + os.environ.get("PATH", ""))
    for m in models:
        f = kit.files(copy, m)
        text = open(f["readme"]).read()
        (command,) = re.findall(r"```sh\n(fmpy simulate [^\n]*)\n```", text)
        r = subprocess.run(command, shell=True, cwd=f["dir"], capture_output=True, text=True, env=env)
        assert r.returncode == 0, r.stdout + r.stderr
        assert "[WARNING]" not in r.stdout + r.stderr and "[ERROR]" not in r.stdout + r.stderr
        out = os.path.join(f["dir"], m + "_out.csv")
        if FMA:
            assert open(out).read() == open(f["ref"]).read(), m
        assert kit.compare(m, read_csv(out), read_csv(f["ref"]), read_ref_opt_file(f["opt"])) == []
        assert "python3 python/wheelflat_kit.py check\n" in text


def test_the_readme_python_check_passes(fmus, tmp_path):
    copy = in_layout_copy(tmp_path, fmus)
    f = kit.files(copy, "TrackContact")
    (code,) = re.findall(r"```python\n(.*?)```", open(f["readme"]).read(), re.S)
    r = subprocess.run([sys.executable, "-c", code], cwd=f["dir"], capture_output=True, text=True)
    assert r.returncode == 0 and r.stdout.splitlines()[-1] == "passed", r.stdout + r.stderr


def test_the_fmus_copied_beside_pass_and_git_keeps_them_out(fmus, models, tmp_path):
    """copy puts the FMUs beside their references; check --beside simulates those and
    validates each folder as the Cross-Check's validate_vendor_repo does; in regression/
    git ignores the copies and the fmpy commands' outputs, not the references."""
    copy = in_layout_copy(tmp_path, fmus)
    assert kit.in_layout(copy)
    report = kit.check(None, copy, beside=True)
    assert sorted(report) == sorted(models) and all(p == [] for p in report.values()), report
    r = run("check", "--beside", "--kit", copy)
    assert r.returncode == 0, r.stdout + r.stderr
    rel = os.path.relpath(KIT, wf.ROOT)
    ignored = subprocess.run(["git", "check-ignore", "--no-index", f"{rel}/Wagon/Wagon.fmu",
                              f"{rel}/Wagon/Wagon_out.csv", f"{rel}/Wagon/Wagon_ref.csv", f"{rel}/Wagon/Wagon_in.csv"],
                             cwd=wf.ROOT, capture_output=True, text=True).stdout.split()
    assert ignored == [f"{rel}/Wagon/Wagon.fmu", f"{rel}/Wagon/Wagon_out.csv"]


def test_the_command_line(fmus, tmp_path):
    r = run("--help")
    assert r.returncode == 0 and "{write,check,copy}" in r.stdout and "--tolerance" in r.stdout
    r = run("verify")
    assert r.returncode == 2 and "invalid choice" in r.stderr
    r = run("check", "--fmus", fmus, "--kit", str(tmp_path / "none"))
    assert r.returncode == 2 and "none: no such folder" in r.stderr
    (tmp_path / "empty").mkdir()
    r = run("check", "--fmus", fmus, "--kit", str(tmp_path / "empty"))
    assert r.returncode == 1 and "TrackContact: no reference" in r.stdout
    r = run("check", "--fmus", str(tmp_path))
    assert r.returncode == 1 and "build the FMUs first" in r.stderr
    r = run("check", "--set", "Wagon=1")
    assert r.returncode == 1 and "expected MODEL:NAME=VALUE" in r.stderr


def test_a_kit_file_that_does_not_read_is_named(fmus, tmp_path):
    # The breaker's findings: a cut or empty reference ended in a bare ValueError or
    # IndexError, and a missing input file was never named.
    import shutil
    copy = tmp_path / "kit"
    shutil.copytree(KIT, copy)
    f = kit.files(str(copy), "RollPlaneVehicle")
    text = open(f["ref"]).read()
    open(f["ref"], "w").write(text[: len(text) // 2 - 7])
    os.remove(kit.files(str(copy), "Wagon")["in"])
    open(kit.files(str(copy), "HalfCarBogie")["ref"], "w").write("")
    report = kit.check(fmus, str(copy), models=["RollPlaneVehicle", "Wagon", "HalfCarBogie"])
    assert "RollPlaneVehicle_ref.csv does not read as a CSV table" in report["RollPlaneVehicle"][0], report
    assert "no Wagon_in.csv" in report["Wagon"][0], report
    assert "HalfCarBogie_ref.csv" in report["HalfCarBogie"][0], report


def test_a_run_with_the_kits_logger_leaves_fmpys_default_logger_working(paths, tmp_path):
    """fmpy's FMI 2.0 logger proxy keeps the last logger given to simulate_fmu: after the
    kit's run (its own logger) the next FMU that logs through fmpy's default callbacks
    called a dead callback and crashed the process (found when the fmusim test ran before
    test_supports.py; the first fix held for one run only, the proxy keeping a logger that
    is not itself). In a fresh process, as a user's script would: two of the kit's runs,
    then a run with debug logging that logs every call."""
    script = tmp_path / "two_runs.py"
    script.write_text(
        "import sys\n"
        f"sys.path.insert(0, {os.path.join(wf.ROOT, 'python')!r})\n"
        "import gc\n"
        "import wheelflat_kit as kit\n"
        "from fmpy import simulate_fmu\n"
        f"path = {paths['CoupledSystem']!r}\n"
        "for _ in range(2):\n"
        "    kit.simulate(path, 'CoupledSystem', 0.01, 1e-3, None, ['contact.left.force'], start=0.0)\n"
        "gc.collect()\n"
        "simulate_fmu(path, stop_time=0.01, debug_logging=True)\n"
        "print('both runs done')\n")
    p = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and "both runs done" in p.stdout, (p.returncode, p.stderr[-2000:])
