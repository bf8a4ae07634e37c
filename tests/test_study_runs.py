"""The sweep command (wheelflat-study, or python -m wheelflat_study in a checkout) on
Dask: a local cluster against a serial run bit for bit, a scheduler and workers as
separate processes on loopback (sharing this checkout's runner, and from the installed
wheel alone), an interrupted study resumed, a worker that joins with another engine,
a million cases and the tables' memory (issue 26). The ways a study could lose, mix or
invent a case are in test_study_cases.py; the helpers in study_helpers.py, the
``runner`` and ``study`` fixtures in conftest.py."""

import os
import signal
import socket
import subprocess
import sys
import time

import pytest

from study_helpers import LOSING_RUNNER, ROOT, comparable, fake_runner, load_done, load_study, run_study


def test_a_local_cluster_gives_the_serial_runs_bit_for_bit(study, tmp_path, runner):
    s = load_study(study)
    assert len(s.cases()) == 8
    serial, n1 = run_study(s, str(tmp_path / "serial"), serial=True, runner_path=runner, progress=False,
                           plots=False, log=lambda *_: None)
    dask, n2 = run_study(s, str(tmp_path / "dask"), workers=2, chunk=1, runner_path=runner, progress=False,
                         plots=False, log=lambda *_: None)
    assert n1 == n2 == 8
    assert (serial["status"] == "ok").all()
    a, b = comparable(serial), comparable(dask)
    assert a.equals(b)
    # Real impacts: the 100 mm flat at 100 km/h peaks far above the static load.
    assert a["peak.left"].max() > 2.5 * 107.66e3
    assert a["impacts.left"].min() >= 1


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_a_scheduler_and_two_workers_on_loopback_give_the_same_table(study, tmp_path, runner):
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    dask = [sys.executable, "-m"]
    procs = [subprocess.Popen(dask + ["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                                      "--no-dashboard"], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        time.sleep(2.0)
        # The second worker has two threads (dask worker's default is one per core):
        # one runner per thread, so its cases do not race on one runner.
        for k in range(2):
            procs.append(subprocess.Popen(dask + ["distributed.cli.dask_worker", addr, "--nworkers", "1", "--nthreads",
                                                  str(k + 1), "--no-dashboard", "--name", f"w{k}"],
                                          env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from dask.distributed import Client
        with Client(addr, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
        out = tmp_path / "remote"
        r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(study), "--scheduler", addr, "--out", str(out),
                            "--runner", runner, "--no-progress", "--no-plots"], env=env, capture_output=True, text=True,
                           timeout=300)
        assert r.returncode == 0, r.stderr
        s = load_study(study)
        serial, _ = run_study(s, str(tmp_path / "serial"), serial=True, runner_path=runner, progress=False,
                              plots=False, log=lambda *_: None)
        import pandas as pd
        remote = pd.read_parquet(out / "results.parquet")
        assert comparable(remote).equals(comparable(serial))
        assert set(remote["guid"]) == set(serial["guid"]) and len(set(remote["guid"])) == 1
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()


def test_an_interrupted_study_resumes_with_the_cases_it_lacks(study, tmp_path, runner):
    out = tmp_path / "resumed"
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    cmd = [sys.executable, "-m", "wheelflat_study", str(study), "--serial", "--out", str(out), "--runner", runner,
           "--no-progress", "--no-plots"]
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # Interrupt it once some cases are in.
    deadline = time.time() + 120
    while time.time() < deadline and len(load_done(str(out))) < 3:
        time.sleep(0.01)
    p.send_signal(signal.SIGKILL)
    p.wait()
    have = len(load_done(str(out)))
    assert 3 <= have < 8, have
    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert f"{have} already done, {8 - have} to run" in r.stdout, r.stdout
    s = load_study(study)
    import pandas as pd
    resumed = pd.read_parquet(out / "results.parquet")
    whole, _ = run_study(s, str(tmp_path / "whole"), serial=True, runner_path=runner, progress=False, plots=False,
                         log=lambda *_: None)
    assert comparable(resumed).equals(comparable(whole))


# A perfect wheel at 15 or 20 m/s from 7.8 m: 0.06 s takes it into a dip between 8 and 9 m.
DIPPED = """
name = "{name}"
duration = 0.06
[fixed]
start_position = 7.8
"flat.left[1].depth" = 0.0
"flat.left[1].length" = 0.0
"rail.left.profile" = "{profile}"
[sweep]
speed = {speeds}
"""
# The client's table and the one a worker would find at the same path.
CLIENTS = "# position (m)  height (m)\n0 0\n8 0\n8.5 -2e-3\n9 0\n30 0\n"
WORKERS = "# position (m)  height (m)\n0 0\n8 0\n8.5 -0.5e-3\n9 0\n30 0\n"


def _inline(table):
    return "; ".join(line for line in table.splitlines() if not line.startswith("#"))


RECORDING_RUNNER = """\
import os
for line in sys.stdin:
    with open(os.path.join({folder!r}, str(os.getpid())), "a") as fh:
        fh.write(line)
    child.stdin.write(line)
    child.stdin.flush()
    sys.stdout.write(child.stdout.readline())
    sys.stdout.flush()
"""


def test_the_workers_run_the_table_the_client_read_never_a_file_at_its_path(tmp_path, runner):
    # Issue 38 (N1): a table named by its path was read by each worker from its own
    # file at that path; a cluster whose workers saw another file there gave "3 of 3
    # cases, 0 failed", exit 0, with the workers' numbers. Here the client reads its
    # file when it loads the study; then the file at that path is replaced before the
    # cluster starts, so every worker would find the other table there. The numbers
    # must be those of the client's table written out, never the other's.
    profile = tmp_path / "profile.txt"
    profile.write_text(CLIENTS)
    p = tmp_path / "dip.toml"
    p.write_text(DIPPED.format(name="dip", profile="profile.txt", speeds="[15.0, 20.0]"))
    s = load_study(p)
    profile.write_text(WORKERS)
    # The workers' runners write down the lines they get.
    seen = tmp_path / "lines"
    seen.mkdir()
    recording = fake_runner(tmp_path / "recording_runner", runner, RECORDING_RUNNER.format(folder=str(seen)))
    on_dask, n = run_study(s, str(tmp_path / "dask"), workers=2, chunk=1, runner_path=str(recording),
                           progress=False, plots=False, log=lambda *_: None)
    assert n == 2 and (on_dask["status"] == "ok").all()
    lines = [line for f in seen.iterdir() for line in f.read_text().splitlines() if "speed=" in line]
    assert len(lines) == 2 and len({f.name for f in seen.iterdir()}) >= 1
    for line in lines:
        assert "rail.left.profile=0,0;8,0;8.5,-2e-3;9,0;30,0; " in line and "profile.txt" not in line, line
    # The same cases with each table written out in the study file, run serially.
    runs = {}
    for name, table in (("clients", CLIENTS), ("workers", WORKERS)):
        q = tmp_path / f"{name}.toml"
        q.write_text(DIPPED.format(name=name, profile=_inline(table), speeds="[15.0, 20.0]"))
        runs[name], _ = run_study(load_study(q), str(tmp_path / name), serial=True, runner_path=runner,
                                  progress=False, plots=False, log=lambda *_: None)
    numbers = [c for c in comparable(on_dask).columns if c.startswith(("peak.", "impacts.", "bearing.", "contact_"))]
    assert numbers and comparable(on_dask)[numbers].equals(comparable(runs["clients"])[numbers])
    # Not vacuous: the workers' file gives other numbers (the shallower dip).
    assert (on_dask["peak.left"] > runs["workers"]["peak.left"] + 10e3).all()
    # The table's name beside the hash of its content: the same content, the same case.
    assert list(on_dask["rail.left.profile"]) == [str(profile)] * 2
    assert list(on_dask["rail.left.profile.sha256"]) == list(runs["clients"]["rail.left.profile.sha256"])
    assert list(on_dask["case_id"]) == list(runs["clients"]["case_id"])
    assert list(on_dask["rail.left.profile.sha256"]) != list(runs["workers"]["rail.left.profile.sha256"])
    import hashlib
    assert on_dask["rail.left.profile.sha256"][0] == hashlib.sha256(b"0,0;8,0;8.5,-2e-3;9,0;30,0;").hexdigest()


def test_a_resumed_study_runs_again_a_case_whose_table_file_was_edited(tmp_path, runner):
    # Issue 38 (N2): a case's id covered the table's path, not its content: a study
    # resumed after its file was edited reused the old results ("1 already done").
    profile = tmp_path / "profile.txt"
    profile.write_text(CLIENTS)
    p = tmp_path / "dip.toml"
    p.write_text(DIPPED.format(name="dip", profile="profile.txt", speeds="[20.0]"))
    out = str(tmp_path / "o")
    quiet = dict(serial=True, runner_path=runner, progress=False, plots=False)
    first, _ = run_study(load_study(p), out, log=lambda *_: None, **quiet)
    profile.write_text(WORKERS)
    said = []
    edited, n = run_study(load_study(p), out, log=said.append, **quiet)
    assert n == 1 and "dip: 1 cases, 0 already done, 1 to run" in said, said
    q = tmp_path / "inline.toml"
    q.write_text(DIPPED.format(name="inline", profile=_inline(WORKERS), speeds="[20.0]"))
    inline, _ = run_study(load_study(q), str(tmp_path / "inline"), log=lambda *_: None, **quiet)
    assert edited["peak.left"][0] == inline["peak.left"][0] != first["peak.left"][0]
    assert edited["rail.left.profile.sha256"][0] == inline["rail.left.profile.sha256"][0]
    # The file as it was: its results are still there.
    profile.write_text(CLIENTS)
    said = []
    again, n = run_study(load_study(p), out, log=said.append, **quiet)
    assert n == 0 and "dip: 1 cases, 1 already done, 0 to run" in said, said
    assert again["peak.left"][0] == first["peak.left"][0]


def test_on_dask_a_lost_case_runs_again_in_the_same_run_then_fails_by_name(tmp_path, runner):
    # Issue 38 (N14): on Dask as in one process (test_study_cases.py): a case whose
    # runner stops runs again at once, three times in all, then is failed by name.
    import json
    losing = tmp_path / "losing_runner"
    fake_runner(losing, runner, LOSING_RUNNER)
    p = tmp_path / "lost.toml"
    p.write_text('name = "lost"\nduration = 0.01\n[sweep]\nspeed = [20.0, 30.0, 40.0]\n')
    said = []
    table, n = run_study(load_study(p), str(tmp_path / "o"), workers=1, chunk=1, runner_path=str(losing),
                         progress=False, plots=False, log=said.append)
    assert n == 3 and list(table["status"]) == ["ok", "error", "ok"], table
    assert table["error"][1].startswith("lost 3 times in one run") and "exit status 9" in table["error"][1]
    # The counts, as the summary line gives them: 2 finished, 1 failed after 3 tries,
    # its 2 lost tries run again.
    assert any("ran 3 cases" in x and "2 finished, 1 failed (1 of them lost 3 times" in x
               and "; 2 runs lost (a runner or worker stopped) and run again" in x for x in said), said
    lost = [json.loads(line) for line in open(tmp_path / "o" / "cases.jsonl") if '"speed": 30.0' in line]
    assert [bool(rec["result"].get("transient")) for rec in lost] == [True, True, False]


MILLION = """
name = "million"
duration = 0.001
[fixed]
"track.window.ahead" = 8.0
"track.window.behind" = 8.0
[sweep]
speed = { range = [10.0, 19.99, 0.01] }
start_position = { range = [10.0, 10.999, 0.001] }
"""

@pytest.mark.parametrize("where", [["--serial"], ["--workers", "1"]])
def test_a_million_case_study_starts_within_seconds_in_little_memory(tmp_path, runner, where):
    # Issue 26 item 12: a 1e6-case study printed nothing for over 90 s and reached
    # 935 MB before any case ran. The cases are now made as they are sent.
    p = tmp_path / "million.toml"
    p.write_text(MILLION)
    out = tmp_path / "o"
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    t0 = time.perf_counter()
    proc = subprocess.Popen([sys.executable, "-m", "wheelflat_study", str(p), "--out", str(out), "--no-progress",
                             "--no-plots", "--runner", runner] + where, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    records = out / "cases.jsonl"
    while not (records.exists() and records.stat().st_size > 0) and time.perf_counter() - t0 < 60:
        time.sleep(0.05)
    first = time.perf_counter() - t0
    time.sleep(2.0)  # a few thousand cases in
    with open(f"/proc/{proc.pid}/status") as fh:
        peak_kb = int(next(line for line in fh if line.startswith("VmHWM")).split()[1])
    proc.send_signal(signal.SIGTERM)  # a batch system's stop: as Ctrl-C
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130 and "interrupted: the cases done so far are kept" in stderr, (stdout, stderr)
    assert "million: 1000000 cases, 0 already done, 1000000 to run" in stdout
    # Measured: the first record after 0.2 s (serial) and 1.0 s (Dask, one worker); 19 and
    # 81 MB at the peak.
    assert first < 15, first
    assert peak_kb < 250_000, peak_kb
    assert len(load_done(str(out))) > 100


def test_two_sigterms_10_ms_apart_stop_the_study_quietly_with_130(tmp_path, runner):
    # Issue 38 (item 4): the second of two SIGTERMs (GNU timeout, a double Ctrl-C) gave a
    # KeyboardInterrupt traceback from stop_runners.
    p = tmp_path / "long.toml"
    p.write_text('name = "long"\nduration = 0.5\n[sweep]\nspeed = { range = [10.0, 49.0, 1.0] }\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    for attempt in range(3):
        out = tmp_path / f"o{attempt}"
        proc = subprocess.Popen([sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(out),
                                 "--no-progress", "--no-plots", "--runner", runner], env=env,
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        records = out / "cases.jsonl"
        t0 = time.perf_counter()
        # Cases running: the first results written (a case takes about 0.1 s).
        while not (records.exists() and records.stat().st_size > 0) and time.perf_counter() - t0 < 60:
            time.sleep(0.01)
        time.sleep(0.05 * attempt)
        proc.send_signal(signal.SIGTERM)
        time.sleep(0.01)
        proc.send_signal(signal.SIGTERM)
        stdout, stderr = proc.communicate(timeout=60)
        assert proc.returncode == 130 and "Traceback" not in stderr and "KeyboardInterrupt" not in stderr, stderr
        assert "interrupted" in stderr, stderr
        assert not [f for f in os.listdir(out) if f.endswith(".part")]


def test_the_study_command_in_a_checkout_runs_the_portable_runner_of_the_one_build(tmp_path):
    # Issue 38 (item 1): the command built a runner of its own (cargo build --release, in
    # target/release/, needing glibc 2.34/2.35) beside the one build's portable runner.
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import wheelflat_fmus as wf
    from wheelflat_study import run
    assert os.path.realpath(run.BUILD_SCRIPT) == os.path.realpath(wf.BUILD_SCRIPT)
    assert os.path.realpath(run.RUNNER) == os.path.realpath(wf.RUNNER_228)
    t0 = time.perf_counter()
    path = run.build_runner()
    took = time.perf_counter() - t0
    assert os.path.realpath(path) == os.path.realpath(wf.RUNNER_228) == os.path.realpath(run.default_runner())
    needed = wf.glibc_versions(path)
    assert needed and max(needed) <= wf.GLIBC_BASELINE, sorted(needed)
    print(f"build_runner (the one build's runner, up to date): {took:.4f} s")
    # Built by the one build script only when missing or older than a source it was
    # built from (cargo's dep-info beside it): a stand-in runner and source here.
    fake, src = tmp_path / "wheelflat_case", tmp_path / "a b.rs"
    src.write_text("")
    fake.write_text("")
    (tmp_path / "wheelflat_case.d").write_text(f"{fake}: {str(src).replace(' ', chr(92) + ' ')}\n")
    old = run.RUNNER
    try:
        run.RUNNER = str(fake)
        os.utime(src, (1e9, 1e9))
        assert not run.runner_stale()
        os.utime(src, (time.time() + 10, time.time() + 10))
        assert run.runner_stale()
        os.utime(src, (1e9, 1e9))
        (tmp_path / "wheelflat_case.d").unlink()
        assert run.runner_stale()
        fake.unlink()
        assert run.runner_stale()
    finally:
        run.RUNNER = old
    # The command without --runner: no build of its own, that runner's answers.
    p = tmp_path / "one.toml"
    p.write_text('name = "one"\nduration = 0.01\n[fixed]\nspeed = 20.0\n')
    env = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    r = subprocess.run([sys.executable, "-m", "wheelflat_study", str(p), "--serial", "--out", str(tmp_path / "o"),
                        "--no-progress", "--no-plots"], env=env, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0 and "(1 of 1 cases, 0 failed)" in r.stdout, (r.stdout, r.stderr)
    assert "cargo build" not in r.stderr and "target/release/" not in r.stderr, r.stderr


def test_the_installed_package_runs_a_study_on_a_scheduler_and_two_workers_without_a_checkout(study, tmp_path,
                                                                                               runner):
    # Issue 26, "On a real cluster": the workers needed the checkout's runner at the
    # client's path. Here the scheduler, two workers and the study command run as
    # separate processes, each in its own empty folder, with only the installed
    # package: no checkout on the path, no PYTHONPATH, no --runner.
    # The wheel, built from this checkout, installed by pip into a new environment,
    # which reuses .venv's installed dependencies (dask, pandas, ...) through a .pth
    # file instead of downloading them again.
    import sysconfig
    wheels = tmp_path / "wheels"
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", "-w",
                    str(wheels), os.path.join(ROOT, "python")], check=True, timeout=600)
    [wheel] = list(wheels.glob("wheelflat-*-py3-none-linux_*.whl"))
    env = tmp_path / "env"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(env)], check=True)
    py = str(env / "bin" / "python")
    site = subprocess.run([py, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                          capture_output=True, text=True, check=True).stdout.strip()
    with open(os.path.join(site, "_venv_dependencies.pth"), "w") as fh:
        fh.write(sysconfig.get_paths()["purelib"] + "\n")
    subprocess.run([sys.executable, "-m", "pip", "--python", py, "install", "-q", "--no-deps", str(wheel)],
                   check=True, timeout=300)
    bin_dir = env / "bin"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "CARGO_TARGET_DIR")}
    py = str(bin_dir / "python")
    folders = {name: tmp_path / name for name in ("scheduler", "worker1", "worker2", "client")}
    for f in folders.values():
        f.mkdir()
    where = subprocess.run([py, "-c", "import wheelflat_study.run as r, wheelflat_fmus as f; "
                                      "print(r.default_runner()); print(f.FMU_DIR)"],
                           cwd=folders["client"], env=env, capture_output=True, text=True, check=True).stdout.split()
    assert all(w.startswith(str(tmp_path / "env")) for w in where), where
    import json
    info = json.loads(subprocess.run([str(bin_dir / "wheelflat-study"), "--version"], cwd=folders["client"], env=env,
                                     capture_output=True, text=True, check=True).stdout)
    import zipfile
    with zipfile.ZipFile(os.path.join(ROOT, "fmu", "CoupledSystem.fmu")) as z:
        md = z.read("modelDescription.xml").decode()
    assert f'guid="{info["fmus"]["CoupledSystem"]["guid"]}"' in md
    assert info["runner"]["guid"] == info["fmus"]["CoupledSystem"]["guid"]
    # Every FMU of the registry, as the packer listed them beside the FMUs.
    sys.path.insert(0, os.path.join(ROOT, "python"))
    import wheelflat_fmus as wf
    assert set(info["fmus"]) == set(wf.registry()["fmus"])
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    procs = [subprocess.Popen([py, "-m", "distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                               "--no-dashboard"], cwd=folders["scheduler"], env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)]
    try:
        time.sleep(2.0)
        for k in (1, 2):
            procs.append(subprocess.Popen([py, "-m", "distributed.cli.dask_worker", addr, "--nworkers", "1",
                                           "--nthreads", "1", "--no-dashboard", "--name", f"w{k}"],
                                          cwd=folders[f"worker{k}"], env=env, stdout=subprocess.DEVNULL,
                                          stderr=subprocess.DEVNULL))
        from dask.distributed import Client
        with Client(addr, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
        (folders["client"] / "small.toml").write_text(study.read_text())
        r = subprocess.run([str(bin_dir / "wheelflat-study"), "small.toml", "--scheduler", addr, "--no-progress",
                            "--no-plots", "--chunk", "1"], cwd=folders["client"], env=env, capture_output=True,
                           text=True, timeout=300)
        assert r.returncode == 0, (r.stdout, r.stderr)
        assert "results/small/results.parquet" in r.stdout
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(timeout=20)
            except subprocess.TimeoutExpired:
                p.kill()
    import pandas as pd
    remote = pd.read_parquet(folders["client"] / "results" / "small" / "results.parquet")
    serial, _ = run_study(load_study(study), str(tmp_path / "serial"), serial=True, runner_path=runner,
                          progress=False, plots=False, log=lambda *_: None)
    assert len(remote) == 8 and (remote["status"] == "ok").all()
    assert comparable(remote).equals(comparable(serial))


OTHER_ENGINE_RUNNER = """\
import json
for line in sys.stdin:
    child.stdin.write(line)
    child.stdin.flush()
    answer = json.loads(child.stdout.readline())
    for k in answer.get("peak") or {}:
        answer["peak"][k] *= 1.5      # another engine: same version and GUID, other numbers
    sys.stdout.write(json.dumps(answer) + "\\n")
    sys.stdout.flush()
"""


def test_a_worker_that_joins_later_with_another_engine_is_retired_and_its_cases_run_elsewhere(tmp_path, runner):
    # Issue 26 review: the model's identity was checked once, at the start; a worker
    # that joined later with another engine (same version and GUID, other numbers) had
    # its results kept, stamped with the study's engine.
    import shutil
    pkg_b = tmp_path / "pkg_b"
    shutil.copytree(os.path.join(ROOT, "python", "wheelflat_study"), pkg_b / "wheelflat_study",
                    ignore=shutil.ignore_patterns("__pycache__", "_data"))
    fake = pkg_b / "wheelflat_study" / "_data" / "bin" / "wheelflat_case"
    fake.parent.mkdir(parents=True)
    fake_runner(fake, runner, OTHER_ENGINE_RUNNER)
    p = tmp_path / "late.toml"
    p.write_text('name = "late"\nduration = 0.05\n[sweep]\nstart_position = { range = [3.0, 6.99, 0.01] }\n')
    port = _free_port()
    addr = f"tcp://127.0.0.1:{port}"
    env_a = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))
    env_b = dict(os.environ, PYTHONPATH=str(pkg_b))
    dask = [sys.executable, "-m"]
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    procs = [subprocess.Popen(dask + ["distributed.cli.dask_scheduler", "--host", "127.0.0.1", "--port", str(port),
                                      "--no-dashboard"], env=env_a, **quiet)]
    out = tmp_path / "o"
    try:
        time.sleep(2.0)
        procs.append(subprocess.Popen(dask + ["distributed.cli.dask_worker", addr, "--nthreads", "1",
                                              "--no-dashboard", "--name", "a"], env=env_a, **quiet))
        study = subprocess.Popen([sys.executable, "-m", "wheelflat_study", str(p), "--scheduler", addr, "--out",
                                  str(out), "--no-progress", "--no-plots", "--chunk", "2"], env=env_a,
                                 stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        records = out / "cases.jsonl"
        deadline = time.time() + 120
        while not (records.exists() and records.stat().st_size > 0) and time.time() < deadline:
            time.sleep(0.05)
        procs.append(subprocess.Popen(dask + ["distributed.cli.dask_worker", addr, "--nthreads", "1",
                                              "--no-dashboard", "--name", "b"], env=env_b, **quiet))
        stdout, stderr = study.communicate(timeout=300)
    finally:
        for proc in reversed(procs):
            proc.terminate()
        for proc in procs:
            try:
                proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                proc.kill()
    assert study.returncode == 0, (stdout, stderr)
    assert "runs another model" in stderr and "retired" in stderr, stderr
    import pandas as pd
    table = pd.read_parquet(out / "results.parquet")
    serial, _ = run_study(load_study(p), str(tmp_path / "serial"), serial=True, runner_path=runner, progress=False,
                          plots=False, log=lambda *_: None)
    assert len(table) == 400 and comparable(table).equals(comparable(serial))


TABLES_MEMORY = """
import json, os, sys, tempfile
sys.path.insert(0, {python!r})
from wheelflat_study.spec import Study
from wheelflat_study.tables import write_tables
n = int(sys.argv[1])
out = tempfile.mkdtemp()
study = Study(name="big", duration=0.5, fixed={{"speed": 20.0}},
              sweep={{"start_position": [3.0 + 1e-4 * k for k in range(n)]}})
res = {{"version": "0.1.0", "guid": "{{g}}", "steps": 1, "step": 1e-5, "wall_s": 0.01,
       "peak": {{"left": 3e5, "right": 1.4e5}},
       "impacts": [{{"wheel": "left", "k": 0, "time": 0.04, "peak": 3e5, "passage": 0.04, "span_position": 0.3}}],
       "bearing": {{"left": {{"max": 1, "min": 0}}, "right": {{"max": 1, "min": 0}}}},
       "contact_loss": {{"left": 0.001, "right": 0.0}}, "extremes": {{}}, "warnings": [], "error": None}}
ident = ["0.1.0", "{{g}}", "abc"]
with open(os.path.join(out, "cases.jsonl"), "w") as fh:
    for c in study.iter_cases():
        fh.write(json.dumps({{"id": c.id, "params": c.params, "duration": c.duration, "keep": [], "result": res,
                             "wall_s": 0.01, "identity": ident}}) + "\\n")
import gc; gc.collect()
before = int(next(l for l in open("/proc/self/status") if l.startswith("VmRSS")).split()[1])
t = write_tables(study, out, ident)
assert len(t) == n and len(__import__("pandas").read_csv(os.path.join(out, "impacts.csv"))) == n
hwm = int(next(l for l in open("/proc/self/status") if l.startswith("VmHWM")).split()[1])
print(hwm)
"""


def test_writing_the_tables_takes_memory_in_proportion_to_a_batch_not_to_the_records(tmp_path):
    # Issue 26 review: the tables were made from every record held whole, about 9 kB
    # each (947 MB for 100,000 cases, so several GB near the million-case maximum). Now
    # the records are read a batch of rows at a time; what grows with the study is
    # where each record starts and the returned table's columns, about 1 kB a case.
    # Measured at 100,000 cases: 303 MB at the peak against 1,019 MB before.
    script = tmp_path / "tables_memory.py"
    script.write_text(TABLES_MEMORY.format(python=os.path.join(ROOT, "python")))
    peak = {}
    for n in (10_000, 40_000):
        r = subprocess.run([sys.executable, str(script), str(n)], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        peak[n] = int(r.stdout.split()[-1])
    grown_per_case = (peak[40_000] - peak[10_000]) * 1024 / 30_000
    assert grown_per_case < 3_000, f"{grown_per_case:.0f} bytes a case"
