"""The sweep command (wheelflat-study, or python -m wheelflat_study in a checkout): the
ways a study could lose, mix or invent a case (a failing case, a case without a result,
results of another version, two runs at once, damaged results, shifted answers, a case
past its time limit, the case ids) and the refusals of bad runners, counts and study
files (issue 26). The runs on Dask are in test_study_runs.py; the helpers in
study_helpers.py, the ``runner`` and ``study`` fixtures in conftest.py."""

import json
import os
import subprocess
import sys
import time

import pytest

from study_helpers import LOSING_RUNNER, ROOT, comparable, fake_runner, load_study, run_study


def test_a_failing_case_is_recorded_and_the_study_goes_on(tmp_path, runner):
    p = tmp_path / "bad.toml"
    p.write_text('name = "bad"\nduration = 0.01\n[sweep]\nspeed = [20.0, -5.0, 30.0]\n')
    table, n = run_study(load_study(p), str(tmp_path / "bad"), serial=True, runner_path=runner, progress=False,
                         plots=False, log=lambda *_: None)
    assert n == 3 and list(table["status"]) == ["ok", "error", "ok"]
    assert "`speed` = -5 m/s is out of range" in table["error"][1]



# A runner lost on the first try of the 30 m/s case only (the marker file says it was).
LOSING_ONCE_RUNNER = """\
import json
import os
for line in sys.stdin:
    if "speed=30" in line and not os.path.exists({marker!r}):
        open({marker!r}, "w").close()
        sys.exit(9)
    child.stdin.write(line)
    child.stdin.flush()
    sys.stdout.write(child.stdout.readline())
    sys.stdout.flush()
"""


def test_a_lost_case_runs_again_in_the_same_run_and_fails_by_name_after_three_tries(tmp_path, runner):
    # Issue 26 item 1: killed runners' cases were left out with "195 of 200 cases, 0
    # failed" and exit status 0. Issue 38 (N13, N14): lost cases ran again only at the
    # next start, and "ran 3 cases" was said when none had finished. Now a lost case
    # runs again at once, at most MAX_TRIES = 3 times in all, then fails by name.
    import json
    from wheelflat_study.run import MAX_TRIES
    assert MAX_TRIES == 3
    losing = tmp_path / "losing_runner"
    fake_runner(losing, runner, LOSING_RUNNER)
    p = tmp_path / "lost.toml"
    p.write_text('name = "lost"\nduration = 0.01\n[sweep]\nspeed = [20.0, 30.0, 40.0]\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
           "--no-progress", "--no-plots", "--runner"]
    r = subprocess.run(cmd + [str(losing)], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, (r.stdout, r.stderr)
    assert "3 of 3 cases, 1 failed)" in r.stdout, r.stdout
    assert ("ran 3 cases in" in r.stdout and "2 finished, 1 failed (1 of them lost 3 times" in r.stdout
            and "2 runs lost (a runner or worker stopped) and run again" in r.stdout), r.stdout
    records = [json.loads(line) for line in open(tmp_path / "o" / "cases.jsonl")]
    lost = [rec for rec in records if rec["params"]["speed"] == 30.0]
    assert [bool(rec["result"].get("transient")) for rec in lost] == [True, True, False]
    assert lost[-1]["result"]["error"].startswith("lost 3 times in one run"), lost[-1]
    assert "exit status 9" in lost[-1]["result"]["error"]
    import pandas as pd
    t = pd.read_parquet(tmp_path / "o" / "results.parquet")
    assert list(t["status"]) == ["ok", "error", "ok"] and "lost 3 times" in t["error"][1]
    # A failure like any other: the next start keeps it, --retry-failed runs it again.
    r = subprocess.run(cmd + [runner], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "0 to run" in r.stdout and "ran " not in r.stdout, r.stdout
    r = subprocess.run(cmd + [runner, "--retry-failed"], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "1 to run" in r.stdout and "3 of 3 cases, 0 failed)" in r.stdout, r.stdout
    assert "ran 1 cases in" in r.stdout and "1 finished, 0 failed" in r.stdout, r.stdout
    # Lost once: it runs again within the same run, and the run is whole.
    once = tmp_path / "losing_once_runner"
    fake_runner(once, runner, LOSING_ONCE_RUNNER.format(marker=str(tmp_path / "lost_once")))
    r = subprocess.run(cmd[:6] + [str(tmp_path / "o2")] + cmd[7:] + [str(once)], env=env, capture_output=True,
                       text=True, timeout=120)
    assert (tmp_path / "lost_once").exists()
    assert r.returncode == 0 and "3 of 3 cases, 0 failed)" in r.stdout, (r.stdout, r.stderr)
    assert "3 finished, 0 failed; 1 runs lost (a runner or worker stopped) and run again" in r.stdout, r.stdout


def test_results_of_another_version_or_model_are_run_again_not_mixed(study, tmp_path, runner):
    # Issue 26 item 5: a resumed study reused results of another software version or GUID
    # without a word and mixed them into one table.
    import json
    s = load_study(study)
    out = tmp_path / "o"
    whole, _ = run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    lines = (out / "cases.jsonl").read_text().splitlines()
    rec = json.loads(lines[1])
    rec["result"]["guid"] = rec["identity"][1] = "{00000000-0000-0000-0000-000000000000}"
    rec["result"]["peak"]["left"] = 1.0
    lines[1] = json.dumps(rec)
    # The same version and GUID from an engine whose numbers differ (a change of the
    # numerics keeps both): its fingerprint tells it.
    rec = json.loads(lines[2])
    rec["identity"][2] = "000000000000"
    rec["result"]["peak"]["left"] = 2.0
    lines[2] = json.dumps(rec)
    (out / "cases.jsonl").write_text("\n".join(lines) + "\n")
    said = []
    again, n = run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False,
                         log=said.append)
    assert n == 2 and any("2 results of another software version, model GUID or engine" in x for x in said), said
    assert len(set(again["engine"])) == 1 and len(again["engine"][0]) == 12
    assert set(again["guid"]) == set(whole["guid"]) and len(set(again["guid"])) == 1
    assert comparable(again).equals(comparable(whole))


def test_two_runs_on_one_folder_at_once_are_refused(tmp_path, study, runner):
    # Issue 26 item 7: two runs on one folder each computed every case.
    import fcntl
    out = tmp_path / "o"
    out.mkdir()
    with open(out / ".lock", "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
        r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(study), "--serial", "--out", str(out),
                            "--runner", runner, "--no-progress"], env=env, capture_output=True, text=True,
                           timeout=60)
    assert r.returncode == 2 and "another run is writing into" in r.stderr, r.stderr
    assert not (out / "cases.jsonl").exists()


def test_a_runner_that_is_not_there_is_refused(tmp_path, study):
    # Issue 26 item 10: a missing --runner gave a traceback with exit status 1.
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(study), "--serial", "--out", str(tmp_path / "o"),
                        "--runner", str(tmp_path / "nowhere"), "--no-progress"], env=env, capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "not an executable file" in r.stderr, r.stderr


def test_a_chunk_or_worker_count_below_one_is_refused(tmp_path, study, runner):
    # Issue 26 item 4: `--chunk -5` printed "ran 3 cases" and ran none; a huge one was
    # a traceback after the cluster had started, a huge worker count hung.
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    for flag, v, said in (("--chunk", "-5", "--chunk -5: 1 to 1000000"),
                          ("--chunk", "99999999999999999999", "1 to 1000000"),
                          ("--workers", "-5", "--workers -5: 1 to 1024"),
                          ("--workers", "99999999999999999999", "1 to 1024"),
                          ("--case-time-limit", "1e10", "--case-time-limit 1e+10: 0 < S <= 1e+06 s"),
                          ("--case-time-limit", "nan", "0 < S"),
                          ("--scheduler", "foo", "--scheduler 'foo': an address such as tcp://HOST:8786"),
                          ("--runner", "/bin/echo", "does not answer as the case runner does"),
                          ("--runner", "/bin/false", "does not answer as the case runner does"),
                          ("--out", "/proc/nope", "--out /proc/nope: cannot write there")):
        args = [sys.executable, "-m", "wheelflat_study", str(study), flag, v, "--no-progress"]
        if flag != "--runner":
            args += ["--runner", runner]
        if flag != "--out":
            args += ["--out", str(tmp_path / "o")]
        r = subprocess.run(args, env=env, capture_output=True, text=True, timeout=60)
        assert r.returncode == 2 and said in r.stderr and "Traceback" not in r.stderr, (flag, v, r.stderr)


def test_the_tables_are_written_whole_or_not_at_all(tmp_path, monkeypatch):
    # Issue 26 item 6: a full disk left results.csv cut mid-number. A write that fails
    # leaves the previous table as it was and no temporary file.
    from wheelflat_study import tables
    path = tmp_path / "results.csv"
    path.write_text("old,table\n1,2\n")

    def failing(p):
        with open(p, "w") as fh:
            fh.write("new,tab")
        raise OSError(28, "No space left on device", p)
    with pytest.raises(OSError):
        tables._atomic(str(path), failing)
    assert path.read_text() == "old,table\n1,2\n"
    assert os.listdir(tmp_path) == ["results.csv"]


def test_the_runner_names_the_range_and_the_variable_a_user_sets(runner):
    # Issue 26 item 14: "`wheelsets` = 2147483648: a whole number is needed"; the
    # half-car's refusal named vehicle.wheelbase, which CoupledSystem does not have.
    import json
    r = subprocess.run([runner], input="wheelsets=2147483648 duration=0.01\n"
                       "vehicle.model=2 wheelsets=2 wheelset[2].offset=0.5 duration=0.01\n",
                       capture_output=True, text=True, timeout=60)
    big, short = [json.loads(x)["error"] for x in r.stdout.splitlines()]
    assert big == "`wheelsets` = 2147483648 is out of range: 1 <= wheelsets <= 4", big
    assert "`wheelset[2].offset` = 0.5 is out of range" in short and "vehicle.wheelbase" not in short, short


def test_a_duration_that_runs_no_step_is_refused_with_the_least_one(runner):
    # Issue 26 item 9: shorter than half a step, no step ran and the static state came
    # back as the result.
    import json
    r = subprocess.run([runner], input="speed=20 duration=5e-6\nspeed=20 duration=8e-6\n", capture_output=True,
                       text=True, timeout=60)
    short, enough = [json.loads(x) for x in r.stdout.splitlines()]
    assert "shorter than half the track's step" in short["error"] and "at least 7.2065" in short["error"], short
    assert enough["error"] is None and enough["steps"] == 1


def test_the_fmus_warnings_reach_the_tables_and_the_case_still_counts(tmp_path, runner):
    # Issue 26 item 8: a case within two spans of the fixed rail end reported 26 % above
    # the endless track's peak with an empty error column. Its warning is now a column
    # to filter on; the endless track's case has none.
    p = tmp_path / "end.toml"
    # 0.73 s at 25 m/s from 1.37 m: 19.6 m, short of the running length's end at 19.865 m
    # (the last span carries no wheel: past it the run ends with fmi2Discard).
    p.write_text('name = "end"\nduration = 0.73\n[fixed]\nspeed = 25.0\n[sweep]\n'
                 '"track.window.ahead" = [0.0, 20.0]\n')
    table, n = run_study(load_study(p), str(tmp_path / "end"), serial=True, runner_path=runner, progress=False,
                         plots=False, log=lambda *_: None)
    assert n == 2 and list(table["status"]) == ["ok", "ok"]
    assert "within 2 sleeper spans of the fixed rail end" in table["warnings"][0]
    assert table["warnings"][1] == ""


def vehicle_items():
    """`1 = roll_plane, 2 = half_car, ...`: the VehicleModel items of the variable table,
    as the refusal lists them."""
    import re
    text = open(os.path.join(ROOT, "modelDescription", "variables.xml")).read()
    vm = re.search(r'<SimpleType name="VehicleModel".*?</SimpleType>', text, re.S).group(0)
    return ", ".join(f"{v} = {n}" for n, v in re.findall(r'<Item name="(\w+)" value="(\d+)"', vm))


@pytest.mark.parametrize("text, said", [
    ('name = "s"\nduration = 0.1\n[fixd]\nspeed = 20.0\n', "unknown keys ['fixd']"),
    ('name = "s"\nduration = 0.1\n[fixed]\nspeed = 20.0\n[sweep]\nspeed = [10.0]\n', "`speed` is both fixed and swept"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { values = [40, 40], unit = "km/h" }\n', "the same case twice"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { values = [40], unit = "mph" }\n', "unit `mph`; known: MN/m, deg"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { range = [0, 1e9, 1e-3] }\n', "at most 1000000 cases"),
    ('name = "../out"\nduration = 0.1\n', "name = `../out`"),
    ('name = "s"\nduration = 0.1\ncombine = "zip"\n[sweep]\nspeed = [1.0, 2.0]\n"wheel.radius" = [0.4]\n',
     "speed: 2, wheel.radius: 1"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [20.0, 300.0]\n', "`speed` = 300 is out of range: 0 <= speed <= 200"),
    ('name = "s"\nduration = 0.1\n[sweep]\n"vehicle.mass" = [1.0]\n', "`vehicle.mass` is not a parameter"),
    # Issue 26 item 3: a kept name with a blank injected a parameter into every case; with
    # a newline it shifted the runner's answers by one case.
    ('name = "s"\nduration = 0.1\nkeep = ["primary.left.force flat.left[1].depth=0.004"]\n',
     "keep `primary.left.force flat.left[1].depth=0.004` is not a Real output of CoupledSystem"),
    ('name = "s"\nduration = 0.1\nkeep = ["primary.left.force\\nspeed=1"]\n', "is not a Real output of CoupledSystem"),
    ('name = "s"\nduration = 0.1\nkeep = ["speed"]\n', "keep `speed` is not a Real output"),
    # Issue 26 item 14: a half-integer random n was reported as n = 0.
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { random = { low = 1, high = 2, n = 0.5 } }\n',
     "random n = 0.5; allowed a whole number"),
    # Issue 26 item 10: these gave tracebacks with exit status 1.
    ('name = "s"\nduration = 0.1\nplot = [1]\n', "plot: tables, one [[plot]] each"),
    ('name = "s"\nduration = 0.1\nfixed = 5\n', "`fixed` = 5: a table"),
    ('name = "s"\nduration = 0.1\nsweep = [1, 2]\n', "`sweep` = [1, 2]: a table"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { range = 5 }\n', "range = [start, stop, step]"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { range = [0, 1e308, 1e-308] }\n', "range gives inf values"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [' + "9" * 300 + ']\n', "`speed` = 1e+300 is out of range"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { random = { low = 1, high = 2, n = 2, seed = [1] } }\n',
     "random seed = [1]; a whole number"),
    # Issue 26 items 4 and 11.
    ('name = "s"\nduration = 0.1\ncombine = "zip"\n', "combine = zip without a [sweep]"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [0.0, -0.0]\n', "the same case twice"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [1.0]\n[[plot]]\nname = "../../../x"\nkind = "lines"\nx = "speed"\n'
     'y = ["peak.left"]\n', "plot 1: name = `../../../x`"),
    # The review's: these ran every case and then failed, or gave tracebacks.
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [1.0]\n[[plot]]\nkind = "lines"\nx = "speed"\n'
     'y = ["peak.left"]\n', "plot 1: y = ['peak.left']: a column name or text"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [1.0]\n[[plot]]\nkind = ["lines"]\nx = "speed"\ny = "p"\n',
     "plot 1: kind one of"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { values = 5 }\n', "values = 5: a list of numbers"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { values = [1.0], unit = [1] }\n', "unit `[1]`"),
    ('name = "s"\nduration = 0.1\n[fixed]\nspeed = { value = 1.0, unit = { a = 1 } }\n', "unit `{'a': 1}`"),
    # Issue 38 (N9): an integer past a float's range gave a traceback with exit status 1.
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [' + "9" * 400 + ']\n',
     "sweep `speed`: an integer of 400 digits is not a finite number; allowed: -1.8e308 to 1.8e308"),
    ('name = "s"\nduration = 0.1\n[fixed]\nwheelsets = ' + "9" * 400 + '\n',
     "fixed `wheelsets`: an integer of 400 digits is not a finite number"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = { values = [1.0], unit = "km/h" }\n[[plot]]\nkind = "lines"\n'
     'x = "speed"\ny = "peak.left"\nscale = ' + "9" * 400 + '\n', "plot 1: scale = 9999"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [' + "9" * 5000 + ']\n', "not valid TOML: Exceeds the limit"),
    # Issue 38 (N10, N11): a word for a table was read as a path, /dev/zero said "no such file".
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "hertz"\n',
     "`rail.left.profile` = 'hertz': not a table: no file at "),
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "/dev/zero"\n',
     "`rail.left.profile` = '/dev/zero': /dev/zero is not a regular file (a device); allowed: a table's file"),
    ('name = "s"\nduration = 0.1\n[sweep]\n"wheel.left.out_of_roundness" = ["/tmp"]\n',
     "`wheel.left.out_of_roundness` = '/tmp': /tmp is not a regular file (a folder)"),
    # Issue 38 (item 3): a table parameter's value is always text, a path or a table, so
    # "20" is a file's path there (a file named 20 is read: the next test).
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "20"\n',
     "`rail.left.profile` = '20': not a table: no file at "),
    # Issue 38 (item 2): a number written as text gave a TypeError traceback, exit 1.
    ('name = "s"\nduration = 0.1\n[fixed]\nspeed = "20"\n',
     "`speed` = '20' is text (in quotes), but `speed` takes a number: 0 <= speed <= 200; write it without "
     "quotes: speed = 20"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = ["nan"]\n',
     "`speed` = 'nan' is text (in quotes), but `speed` takes a number: 0 <= speed <= 200"),
    ('name = "s"\nduration = 0.1\n[sweep]\nspeed = [10.0, "20"]\n',
     "`speed` = '20' is text (in quotes), but `speed` takes a number"),
    ('name = "s"\nduration = 0.1\n[fixed]\nwheelsets = "two"\n',
     "`wheelsets` = 'two' is text (in quotes), but `wheelsets` takes a number: a whole number, 1 <= wheelsets <= 4"),
    # Issue 38 (item 3): an enumeration's name was refused as "not a table: no file at";
    # issue 44: an item's name is its number (test_study_summary.py), another text is refused.
    ('name = "s"\nduration = 0.1\n[fixed]\n"vehicle.model" = "half_cart"\n',
     "`vehicle.model` = 'half_cart' is not one of its items; allowed: one of "
     f"{vehicle_items()} (an enumeration: its item's name, in quotes, or its number)"),
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = 20\n', "`rail.left.profile` = 20.0: a table"),
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "0 0; 1 x"\n',
     "`rail.left.profile` (the table written out): line 1, its point 2 after a `;`: not two numbers (2 fields)"),
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "0 0; 2 0; 1 0"\n',
     "`rail.left.profile` (the table written out), point 3: x = 1; allowed: above the point before's 2"),
    ('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "0 0;"\n', "1 points; allowed: 2 to 1,000,000"),
])
def test_bad_study_files_are_refused_before_anything_runs(tmp_path, runner, text, said):
    p = tmp_path / "s.toml"
    p.write_text(text)
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
                        "--runner", runner, "--no-progress"], env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and said in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not (tmp_path / "o" / "cases.jsonl").exists()


def test_a_table_file_named_like_a_number_is_a_table_and_text_for_a_number_is_refused_whatever_file_it_names(
        tmp_path, runner):
    # Issue 38 (item 3): files named `123` and `nan` given to a table parameter were
    # refused as numbers; a table parameter's value is always text (a path or a table).
    (tmp_path / "123").write_text("0 0\n10 0\n")
    (tmp_path / "nan").write_text("0 0\n10 1e-6\n")
    (tmp_path / "20").write_text("0 0\n10 0\n")
    p = tmp_path / "s.toml"
    p.write_text('name = "s"\nduration = 0.01\n[sweep]\n"rail.left.profile" = ["123", "nan"]\n')
    s = load_study(p)
    assert [t.name for t in s.sweep["rail.left.profile"]] == [str(tmp_path / "123"), str(tmp_path / "nan")]
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"), "--runner",
           runner, "--no-progress", "--no-plots"]
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "(2 of 2 cases, 0 failed)" in r.stdout, (r.stdout, r.stderr)
    # speed = "20" is text for a number even with a file named 20 beside the study.
    p.write_text('name = "s"\nduration = 0.01\n[fixed]\nspeed = "20"\n')
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "`speed` = '20' is text (in quotes), but `speed` takes a number" in r.stderr \
        and "Traceback" not in r.stderr, r.stderr


def test_damaged_results_and_passing_failures_run_again(study, tmp_path, runner):
    s = load_study(study)
    out = tmp_path / "damaged"
    whole, _ = run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    path = out / "cases.jsonl"
    lines = path.read_text().splitlines()
    # A stopped runner's failure, a record cut in half, garbage: those three run again.
    rec = __import__("json").loads(lines[0])
    rec["result"] = {"error": "the case runner stopped (no answer, exit status None)", "transient": True}
    path.write_text("\n".join([__import__("json").dumps(rec)] + lines[1:6] + ["[1, 2, 3]", lines[7][:40]]))
    again, n = run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    assert n == 3
    assert comparable(again).equals(comparable(whole))


def test_every_answer_names_its_case_and_a_shifted_answer_lands_on_no_case(tmp_path, runner):
    # Issue 26 item 3: a newline in `keep` desynchronised the runner's pipe, so each
    # case received the previous line's answer (the 30 m/s row showed the 20 m/s
    # result). Every request now carries its case's id, and the answer must carry it.
    r = subprocess.run([runner], input="case=abc-1.x speed=20 duration=0.001\ncase=a/b duration=1\n"
                                       "case=x case=y duration=1\n", capture_output=True, text=True, timeout=60)
    import json
    good, bad, twice = (json.loads(line) for line in r.stdout.splitlines())
    assert good["case"] == "abc-1.x" and good["error"] is None and good["steps"] > 0
    assert "case" not in bad and "case = `a/b`: a case id is 1 to 64 letters" in bad["error"]
    assert "`case` is given twice" in twice["error"]
    # A runner that answers each case with the previous case's answer (its first
    # answer for a case nobody asked): no answer lands on a case it is not for.
    shifted = tmp_path / "shifted_runner"
    fake_runner(shifted, runner, SHIFTED_RUNNER)
    p = tmp_path / "shift.toml"
    p.write_text('name = "shift"\nduration = 0.05\n[sweep]\nspeed = [20.0, 30.0, 40.0]\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
           "--no-progress", "--no-plots", "--runner"]
    r = subprocess.run(cmd + [str(shifted)], env=env, capture_output=True, text=True, timeout=120)
    # Each case is tried three times (a new runner each time, whose first answer is
    # for nobody), then fails by name: no answer is taken for another case's.
    assert r.returncode == 1 and "3 of 3 cases, 3 failed)" in r.stdout, (r.stdout, r.stderr)
    assert "0 finished, 3 failed (3 of them lost 3 times" in r.stdout, r.stdout
    records = [json.loads(line) for line in open(tmp_path / "o" / "cases.jsonl")]
    assert len(records) == 9
    for rec in records:
        assert "peak" not in rec["result"]
        if rec["result"].get("transient"):
            assert f"the case runner answered 'nobody' to case '{rec['id']}'" in rec["result"]["error"], rec
        else:
            assert rec["result"]["error"].startswith("lost 3 times in one run"), rec
            assert f"the case runner answered 'nobody' to case '{rec['id']}'" in rec["result"]["error"], rec
    import pandas as pd
    # The real runner runs all three again, each its own case.
    r = subprocess.run(cmd + [runner, "--retry-failed"], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and "3 to run" in r.stdout, (r.stdout, r.stderr)
    t = pd.read_parquet(tmp_path / "o" / "results.parquet")  # exact (pandas' CSV parser may miss an ulp)
    for speed, peak in zip(t["speed"], t["peak.left"]):
        alone = json.loads(subprocess.run([runner], input=f"speed={speed!r} duration=0.05\n", capture_output=True,
                                          text=True, timeout=60).stdout)
        assert alone["peak"]["left"] == peak


SHIFTED_RUNNER = """\
import json
before = None
for line in sys.stdin:
    child.stdin.write(line)
    child.stdin.flush()
    answer = child.stdout.readline()
    if line.startswith("case=warm-up"):
        sys.stdout.write(answer)
    else:
        sys.stdout.write(before or json.dumps(dict(json.loads(answer), case="nobody")) + "\\n")
        before = answer
    sys.stdout.flush()
"""


STALLING_RUNNER = """\
import time
for line in sys.stdin:
    if "speed=25.0" in line:
        time.sleep(3600)   # a case that stalls
    child.stdin.write(line)
    child.stdin.flush()
    sys.stdout.write(child.stdout.readline())
    sys.stdout.flush()
"""


def test_a_case_past_its_time_limit_fails_alone_and_the_study_goes_on(tmp_path, runner, monkeypatch):
    # Issue 26 item 13: one case could stall a study for hours.
    stalling = tmp_path / "stalling_runner"
    fake_runner(stalling, runner, STALLING_RUNNER)
    p = tmp_path / "stall.toml"
    p.write_text('name = "stall"\nduration = 0.02\n[sweep]\nspeed = [20.0, 25.0, 30.0]\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(p), "--out", str(tmp_path / "o"), "--no-progress",
           "--no-plots", "--runner", str(stalling)]
    t0 = time.perf_counter()
    r = subprocess.run(cmd + ["--serial", "--case-time-limit", "1.5"], env=env, capture_output=True, text=True,
                       timeout=120)
    assert time.perf_counter() - t0 < 30
    assert r.returncode == 1 and "3 of 3 cases, 1 failed" in r.stdout, (r.stdout, r.stderr)
    import pandas as pd
    t = pd.read_csv(tmp_path / "o" / "results.csv")
    assert list(t["status"]) == ["ok", "error", "ok"]
    assert "the case ran past its time limit of 1.5 s" in t["error"][1]
    # Not a passing failure: the next run keeps it; --retry-failed runs it again.
    r = subprocess.run(cmd + ["--serial", "--case-time-limit", "1.5"], env=env, capture_output=True, text=True,
                       timeout=120)
    assert "0 to run" in r.stdout, r.stdout
    r = subprocess.run(cmd[:-1] + [runner, "--serial", "--retry-failed"], env=env, capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and "1 to run" in r.stdout, (r.stdout, r.stderr)
    # On Dask too, and with the default limit: FACTOR times the duration at the cost
    # measured at the start, at least MIN_TIME_LIMIT (made small here).
    import wheelflat_study.run as run
    monkeypatch.setattr(run, "MIN_TIME_LIMIT", 2.0)
    table, _ = run_study(load_study(p), str(tmp_path / "d"), workers=1, runner_path=str(stalling), progress=False,
                         plots=False, log=lambda *_: None)
    assert list(table["status"]) == ["ok", "error", "ok"]
    assert "time limit of 2 s" in table["error"][1]


def test_the_fast_case_ids_are_the_cases_own():
    # Study.iter_cases builds each id from precomputed parts (about 2 us a case); it
    # must give Case.id's own hash, or a resumed study would run every case again.
    from wheelflat_study.spec import Case, Study
    studies = [Study("a", 0.5, {"speed": 27.0, "a.b": 1e-5},
                     {"flat.left[1].depth": [0.001, 0.0, 1e300], "start_position": [3.0, 4.5]},
                     keep=("primary.left.force", "rail.left.z")),
               Study("b", 0.12, {}, {"speed": [1.0, 2.0]}, combine="zip"),
               Study("c", 1e-3, {"speed": 3.0}, {}),
               Study("d", 0.5, {}, {}),
               # Tables: by their content's hash (issue 38).
               Study("e", 0.1, {"rail.left.profile": "0 0; 8 0; 8.5 -2e-3; 9 0; 30 0"},
                     {"wheel.left.out_of_roundness": ["", "0 0\n3 1e-4\n6 0"], "speed": [1.0, 2.0]})]
    for s in studies:
        cases = list(s.iter_cases())
        assert len(cases) == s.count()
        for c in cases:
            assert c.id == Case(c.params, c.duration, c.keep).id, (s.name, c.params)
    # The same table written otherwise (blanks, a comment, commas) is the same case; a
    # changed point is another.
    e = [c.id for c in studies[4].iter_cases()]
    other = Study("e", 0.1, {"rail.left.profile": "0,0;8,0;8.5,-2e-3;9,0;30,0"},
                  {"wheel.left.out_of_roundness": ["", "# angle deviation\n0 0\n3 1e-4\n6 0\n"], "speed": [1.0, 2.0]})
    assert [c.id for c in other.iter_cases()] == e
    changed = Study("e", 0.1, {"rail.left.profile": "0 0; 8 0; 8.5 -2e-3; 9 0; 30 0"},
                    {"wheel.left.out_of_roundness": ["", "0 0\n3 2e-4\n6 0"], "speed": [1.0, 2.0]})
    ids = [c.id for c in changed.iter_cases()]
    assert ids[:2] == e[:2] and not set(ids[2:]) & set(e)


def test_a_refused_table_file_is_named_but_its_content_never_quoted(tmp_path, runner):
    # Issue 38 (N15): a refusal quoted up to 40 characters of any readable file, such as
    # /proc/self/environ (another process's secrets, in a shared results folder's log).
    secret = "wheelflat-secret-4d1c"
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"), WHEELFLAT_TEST_TOKEN=secret)
    p = tmp_path / "s.toml"
    p.write_text('name = "s"\nduration = 0.1\n[fixed]\n"rail.left.profile" = "/proc/self/environ"\n')
    r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
                        "--runner", runner, "--no-progress"], env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2, r.stderr
    assert "`rail.left.profile` (/proc/self/environ): line 1: not two numbers" in r.stderr, r.stderr
    assert secret not in r.stderr + r.stdout and "WHEELFLAT_TEST_TOKEN" not in r.stderr + r.stdout
    # A file of words in two columns, and a one-line file with a `#`: named, not quoted.
    from wheelflat_study.spec import read_table
    (tmp_path / "words.txt").write_text("0 0\npassword hunter2\n")
    (tmp_path / "hash.txt").write_text("0 0; 1 0 # hunter2")
    for name, said in (("words.txt", "line 2: not two numbers (2 fields)"), ("hash.txt", "a `#` in a table on one")):
        with pytest.raises(ValueError) as e:
            read_table("rail.left.profile", name, str(tmp_path))
        assert said in str(e.value) and str(tmp_path / name) in str(e.value) and "hunter2" not in str(e.value)


def test_a_table_file_with_a_byte_order_mark_reads_as_the_same_table(tmp_path, runner):
    # Issue 38 (N15): a table file saved with a UTF-8 byte-order mark (as some editors
    # on Windows do) was refused. It is the same table, the same case id.
    (tmp_path / "plain.txt").write_text("# x (m)  height (m)\n0 0\n8 0\n8.5 -2e-3\n9 0\n30 0\n")
    (tmp_path / "bom.txt").write_bytes(b"\xef\xbb\xbf" + (tmp_path / "plain.txt").read_bytes().replace(b"\n", b"\r\n"))
    cases = {}
    for name in ("plain", "bom"):
        p = tmp_path / f"{name}.toml"
        p.write_text(f'name = "{name}"\nduration = 0.01\n[fixed]\n"rail.left.profile" = "{name}.txt"\n')
        [cases[name]] = load_study(p).cases()
    t = cases["bom"].params["rail.left.profile"]
    assert t.text == cases["plain"].params["rail.left.profile"].text == "0,0;8,0;8.5,-2e-3;9,0;30,0;"
    assert t.name == str(tmp_path / "bom.txt") and cases["bom"].id == cases["plain"].id
    # The runner takes what the study sends.
    import json
    out = json.loads(subprocess.run([runner], input=cases["bom"].line() + "\n", capture_output=True, text=True,
                                    timeout=60).stdout)
    assert out["error"] is None and out["steps"] > 0, out


def test_an_empty_table_can_be_swept_as_no_table(tmp_path, runner):
    # Issue 38 (N12): "" (no table) could not be swept beside a table.
    p = tmp_path / "e.toml"
    p.write_text('name = "e"\nduration = 0.06\n[fixed]\nstart_position = 7.8\nspeed = 20.0\n'
                 '"flat.left[1].depth" = 0.0\n"flat.left[1].length" = 0.0\n'
                 '[sweep]\n"rail.left.profile" = ["", "0 0; 8 0; 8.5 -2e-3; 9 0; 30 0"]\n')
    s = load_study(p)
    table, n = run_study(s, str(tmp_path / "o"), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    assert n == 2 and list(table["status"]) == ["ok", "ok"]
    assert list(table["rail.left.profile"]) == ["", "0,0;8,0;8.5,-2e-3;9,0;30,0;"]
    assert table["rail.left.profile.sha256"][0] == "" and len(table["rail.left.profile.sha256"][1]) == 64
    # "" is the ideal rail: the numbers of the same case without the parameter; the dip
    # is felt.
    import json
    alone = json.loads(subprocess.run([runner], input="start_position=7.8 speed=20.0 flat.left[1].depth=0.0 "
                                      "flat.left[1].length=0.0 duration=0.06\n", capture_output=True, text=True,
                                      timeout=60).stdout)
    assert table["peak.left"][0] == alone["peak"]["left"]
    assert table["peak.left"][1] > table["peak.left"][0] + 5e3


def test_no_part_file_is_left_after_a_full_disk(tmp_path, study, runner, monkeypatch):
    # Issue 38 (N15): after "disk full" the tables' .part files stayed: closing the CSV
    # failed too (its buffer could not be written) and stopped the cleanup.
    import errno

    import pyarrow.parquet as pq
    from wheelflat_study import tables
    s = load_study(study)
    out = tmp_path / "o"
    run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False, log=lambda *_: None)
    before = {n: (out / n).read_bytes() for n in ("results.csv", "results.parquet", "impacts.csv")}

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    class FullFile:
        """A CSV file on a full disk: a write fails, and so does the close."""
        def __init__(self, path, *args, **kwargs):
            self.f = open(path, *args, **kwargs)

        def write(self, text):
            self.f.write(text[:10])
            full()

        def close(self):
            self.f.close()
            full()

        def __getattr__(self, name):
            return getattr(self.f, name)

    def on_full_disk(path, mode="r", *args, **kwargs):
        return FullFile(path, mode, *args, **kwargs) if "w" in mode else open(path, mode, *args, **kwargs)
    monkeypatch.setattr(tables, "open", on_full_disk, raising=False)
    with pytest.raises(OSError) as e:
        run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False, log=lambda *_: None)
    assert e.value.errno == errno.ENOSPC
    assert not [n for n in os.listdir(out) if n.endswith(".part")], os.listdir(out)
    assert {n: (out / n).read_bytes() for n in before} == before
    # The Parquet writer on a full disk, the CSV's close failing after it.
    monkeypatch.setattr(pq.ParquetWriter, "write_table", lambda self, *a, **k: full())
    with pytest.raises(OSError):
        run_study(s, str(out), serial=True, runner_path=runner, progress=False, plots=False, log=lambda *_: None)
    assert not [n for n in os.listdir(out) if n.endswith(".part")], os.listdir(out)
    assert {n: (out / n).read_bytes() for n in before} == before


def test_a_run_of_hanging_sleepers_longer_than_the_track_is_refused_with_a_range_that_holds_values(runner):
    # Issue 38 (N15): "-0.3425 m <= track.void.position < -46.9225 m": a range nothing is in.
    import json
    import re
    r = subprocess.run([runner], input="track.window.ahead=0 track.void.sleepers=100 track.void.position=3 "
                                       "duration=0.01\n", capture_output=True, text=True, timeout=60)
    error = json.loads(r.stdout)["error"]
    assert "`track.void.sleepers` = 100 is out of range" in error and "track.void.sleepers <= 31" in error, error
    for lo, hi in re.findall(r"(-?\d[\d.e+-]*) m <= track\.void\.position < (-?\d[\d.e+-]*) m", error):
        assert float(lo) < float(hi), error


def test_a_dry_run_prints_the_case_table_and_runs_nothing(tmp_path, runner):
    # Issue 40 (item 4): --dry-run checks the study, prints every case (its id, the
    # swept values in their display units) and stops; no runner runs, no folder is made.
    p = tmp_path / "dry.toml"
    p.write_text('name = "dry"\nduration = 0.05\n[sweep]\nspeed = { values = [36.0, 72.0], unit = "km/h" }\n'
                 '"flat.left[1].length" = { values = [50.0, 100.0], unit = "mm" }\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    out = tmp_path / "never"
    r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(p), "--dry-run", "--out", str(out),
                        "--runner", runner], env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().split("\n")
    assert lines[0] == "id\tspeed [km/h]\tflat.left[1].length [mm]", lines[0]
    ids = [c.id for c in load_study(str(p)).cases()]
    rows = [ln.split("\t") for ln in lines[1:-1]]
    assert [row[0] for row in rows] == ids
    assert [row[1:] for row in rows] == [["36", "50"], ["36", "100"], ["72", "50"], ["72", "100"]]
    assert lines[-1].startswith("4 cases of 0.05 s") and "nothing was run" in lines[-1], lines[-1]
    assert not out.exists()


def test_a_limit_runs_the_first_cases_and_the_same_command_without_it_the_rest(tmp_path, runner):
    # Issue 40 (item 4): --limit N runs the study's first N cases, with the whole
    # study's ids, so a run without it goes on with the others.
    p = tmp_path / "lim.toml"
    p.write_text('name = "lim"\nduration = 0.01\n[sweep]\nspeed = [20.0, 30.0, 40.0]\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
           "--no-progress", "--no-plots", "--runner", runner]
    r = subprocess.run(cmd + ["--limit", "2"], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "(2 of 3 cases, 0 failed)" in r.stdout, (r.stdout, r.stderr)
    ids = [c.id for c in load_study(str(p)).cases()]
    done = [json.loads(line)["id"] for line in open(tmp_path / "o" / "cases.jsonl")]
    assert sorted(done) == sorted(ids[:2])
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "3 cases, 2 already done, 1 to run" in r.stdout + r.stderr, (r.stdout, r.stderr)
    assert "(3 of 3 cases, 0 failed)" in r.stdout, r.stdout
    # A later run of the first case only keeps the others in the tables (the breaker's
    # finding: they shrank to the limit's cases, cases.jsonl keeping them all).
    r = subprocess.run(cmd + ["--limit", "1"], env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0 and "(3 of 3 cases, 0 failed)" in r.stdout, (r.stdout, r.stderr)
    import pandas as pd
    assert len(pd.read_parquet(tmp_path / "o" / "results.parquet")) == 3
    r = subprocess.run(cmd + ["--limit", "0"], env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--limit 0: 1 to" in r.stderr, r.stderr


def test_every_csv_column_names_its_unit(tmp_path, runner):
    # Issue 40 (item 4): units in every CSV header ("peak.left [N]"); the Parquet tables
    # keep the plain names. A runner field or parameter without a known unit fails here.
    import pandas as pd
    from wheelflat_study.run import runner_units
    from wheelflat_study.tables import unit_of
    p = tmp_path / "units.toml"
    p.write_text('name = "units"\nduration = 0.3\nkeep = ["primary.left.force"]\n'
                 '[fixed]\n"track.window.ahead" = 8.0\n[sweep]\nspeed = { values = [70], unit = "km/h" }\n')
    out = tmp_path / "o"
    table, n = run_study(load_study(p), str(out), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    assert n == 1 and list(table["status"]) == ["ok"]
    declared = runner_units(runner)
    assert declared["speed"] == "m/s" and declared["primary.left.force"] == "N"
    for name in ("results", "impacts"):
        plain = list(pd.read_parquet(out / f"{name}.parquet").columns)
        assert [c for c in plain if unit_of(c, declared) is None] == [], name
        header = list(pd.read_csv(out / f"{name}.csv").columns)
        assert len(header) == len(plain)
    results = list(pd.read_csv(out / "results.csv").columns)
    for col in ("speed [m/s]", "track.window.ahead [m]", "peak.left [N]", "bearing.left.max [N]",
                "primary.left.force.max [N]", "contact_loss.left [s]", "duration [s]", "status", "impacts.left"):
        assert col in results, results
    impacts = list(pd.read_csv(out / "impacts.csv").columns)
    assert "peak [N]" in impacts and "time [s]" in impacts and "span_position" in impacts
    # The same numbers under both names.
    assert pd.read_csv(out / "results.csv")["peak.left [N]"][0] == table["peak.left"][0]
