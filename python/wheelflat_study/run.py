"""Running a study: the cases in chunks on Dask (a local cluster by default, or an
existing scheduler), each worker with its own persistent case runner; results kept as
they come (``cases.jsonl``, so an interrupted study resumes), then the tables and plots.
"""

import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
TARGET_DIR = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR") or "target")
RUNNER = os.path.join(TARGET_DIR, "release", "wheelflat_case")


def build_runner():
    """Builds the case runner (cargo, release profile); its path."""
    subprocess.check_call(["cargo", "build", "--release", "--quiet", "--bin", "wheelflat_case"], cwd=ROOT)
    return RUNNER


class CaseRunner:
    """One persistent ``wheelflat_case`` process: a case line in, a JSON line out."""

    def __init__(self, path):
        self.path = path
        self.proc = None

    def _start(self):
        self.proc = subprocess.Popen([self.path], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, text=True, bufsize=1)

    def run(self, line):
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        try:
            self.proc.stdin.write(line + "\n")
            self.proc.stdin.flush()
            out = self.proc.stdout.readline()
        except (BrokenPipeError, OSError) as e:
            out = ""
            why = str(e)
        else:
            why = "no answer"
        if not out:
            try:
                code = self.proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                code = self.proc.wait()
            self.proc = None
            how = f"killed by signal {-code}" if code < 0 else f"exit status {code}"
            return {"error": f"the case runner stopped ({why}, {how})", "transient": True}
        return json.loads(out)


_RUNNERS = {}


def _runner(path):
    """The case runner of this process (one per Dask worker process)."""
    r = _RUNNERS.get(path)
    if r is None:
        r = _RUNNERS[path] = CaseRunner(path)
    return r


def run_chunk(chunk, runner_path):
    """Runs the cases of `chunk` (a list of (case id, runner line)); a list of
    (case id, result dict, wall seconds in this function)."""
    out = []
    r = _runner(runner_path)
    for cid, line in chunk:
        t0 = time.perf_counter()
        try:
            res = r.run(line)
        except Exception as e:  # a failing case is recorded, the study goes on
            res = {"error": f"{type(e).__name__}: {e}", "transient": True}
        out.append((cid, res, time.perf_counter() - t0))
    return out


def _chunks(items, size):
    return [items[i:i + size] for i in range(0, len(items), size)]


def identity(runner_path):
    """The software version and CoupledSystem's GUID of the case runner at
    `runner_path` (from its answer to a case it refuses)."""
    r = subprocess.run([runner_path], input="duration=0\n", capture_output=True, text=True, timeout=60)
    rec = json.loads(r.stdout.splitlines()[0])
    return rec.get("version"), rec.get("guid")


def load_done(out_dir, retry_failed=False, ident=None):
    """The results already in the study's folder, by case id. Lines that are not a
    whole record (cut by an interruption, or damaged) are skipped, so their cases run
    again; so do cases that failed for a passing reason (a stopped runner, a lost
    worker), with `retry_failed` every failed case, and, given `ident` (version, GUID),
    results of another software version or GUID (one table holds one model's
    results); `load_done.other` counts those."""
    load_done.other = 0
    path = os.path.join(out_dir, "cases.jsonl")
    done = {}
    if os.path.exists(path):
        with open(path, encoding="utf-8", errors="replace") as fh:
            for line in fh:
                try:
                    rec = json.loads(line)
                except json.JSONDecodeError:
                    continue
                if not (isinstance(rec, dict) and isinstance(rec.get("id"), str)
                        and isinstance(rec.get("result"), dict)):
                    continue
                res = rec["result"]
                if res.get("error") and (res.get("transient") or retry_failed):
                    done.pop(rec["id"], None)
                    continue
                if ident is not None and res.get("version") is not None \
                        and (res.get("version"), res.get("guid")) != tuple(ident):
                    done.pop(rec["id"], None)
                    load_done.other += 1
                    continue
                done[rec["id"]] = rec
    return done


def _append(out_dir, records):
    path = os.path.join(out_dir, "cases.jsonl")
    # A line cut by an interruption is closed first, so the next record starts a line.
    cut = False
    if os.path.exists(path) and os.path.getsize(path) > 0:
        with open(path, "rb") as fh:
            fh.seek(-1, os.SEEK_END)
            cut = fh.read(1) != b"\n"
    with open(path, "a") as fh:
        if cut:
            fh.write("\n")
        for rec in records:
            fh.write(json.dumps(rec) + "\n")
        # Flushed, not synced: a killed study keeps what it wrote (the operating
        # system has it); a line cut by a crash only runs its case again.


def run_study(study, out_dir, scheduler=None, workers=None, serial=False, chunk=None,
              runner_path=None, progress=True, plots=True, log=print, retry_failed=False):
    """Runs the cases of `study` not yet in `out_dir` and writes the tables (and plots).

    scheduler: the address of a running dask.distributed scheduler; None starts a
    LocalCluster of `workers` processes (default: one per core). serial: no Dask, in
    this process. Returns (the results table, the number of cases run now); the
    times of the last run (start-up, the cases, the tables) are in `run_study.timing`."""
    os.makedirs(out_dir, exist_ok=True)
    # One run per folder: a second one at the same time would compute every case again
    # and interleave the records.
    import fcntl
    with open(os.path.join(out_dir, ".lock"), "w") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise RuntimeError(f"another run is writing into {out_dir}: wait for it to end, or give "
                               f"another --out") from None
        return _run_locked(study, out_dir, scheduler, workers, serial, chunk, runner_path, progress, plots,
                           log, retry_failed)


def _run_locked(study, out_dir, scheduler, workers, serial, chunk, runner_path, progress, plots, log,
                retry_failed):
    """:func:`run_study` with the folder's lock held."""
    runner_path = runner_path or RUNNER
    cases = study.cases()
    ids = [c.id for c in cases]
    if len(set(ids)) != len(ids):
        raise ValueError("the study has duplicate cases")
    ident = identity(runner_path)
    done = load_done(out_dir, retry_failed, ident)
    if load_done.other:
        log(f"{study.name}: {load_done.other} results of another software version or model GUID in "
            f"{out_dir} are set aside and run again (this runner: version {ident[0]}, GUID {ident[1]})")
    todo = [(c.id, c.line()) for c in cases if c.id not in done]
    by_id = {c.id: c for c in cases}
    log(f"{study.name}: {len(cases)} cases, {len(cases) - len(todo)} already done, {len(todo)} to run")
    started = time.perf_counter()
    ready = started
    if todo:
        if serial:
            ready = _serial(todo, by_id, out_dir, runner_path, progress)
        else:
            ready = _dask(todo, by_id, out_dir, runner_path, scheduler, workers, chunk, progress)
    finished = time.perf_counter()
    elapsed = finished - started
    if todo:
        log(f"ran {len(todo)} cases in {elapsed:.2f} s ({60 * len(todo) / elapsed:.0f} cases per minute)")
    from .tables import write_tables
    table = write_tables(study, cases, load_done(out_dir, ident=ident), out_dir)
    run_study.timing = {"startup_s": ready - started, "cases_s": finished - ready,
                        "tables_s": time.perf_counter() - finished}
    if plots and study.plots:
        from .plots import make_plots
        for p in make_plots(study, table, out_dir, log):
            log(f"wrote {p}")
    return table, len(todo)


def _record(cid, res, wall, case):
    return {"id": cid, "params": case.params, "duration": case.duration, "keep": list(case.keep),
            "result": res, "wall_s": wall}


def _bar(total, progress):
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=total, unit="case", file=sys.stderr)


def _serial(todo, by_id, out_dir, runner_path, progress):
    """Runs the cases here; returns when the runner was ready (perf_counter)."""
    _runner(runner_path).run("duration=1e-9")  # starts the runner
    ready = time.perf_counter()
    bar = _bar(len(todo), progress)
    for cid, line in todo:
        [(cid, res, wall)] = run_chunk([(cid, line)], runner_path)
        _append(out_dir, [_record(cid, res, wall, by_id[cid])])
        if bar:
            bar.update(1)
    if bar:
        bar.close()
    return ready


def _dask(todo, by_id, out_dir, runner_path, scheduler, workers, chunk, progress):
    from dask.distributed import Client, LocalCluster, as_completed
    if scheduler:
        try:
            client = Client(scheduler, timeout=60)
        except OSError as e:
            raise RuntimeError(f"cannot reach the scheduler {scheduler}: {e}") from None
        cluster = None
        try:
            client.wait_for_workers(1, timeout=120)
        except Exception:
            client.close()
            raise RuntimeError(f"the scheduler {scheduler} has no workers after 120 s: start some "
                               f"(dask worker {scheduler}) with PYTHONPATH={os.path.join(ROOT, 'python')}")
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        client = Client(cluster)
    try:
        # Every worker's runner started: the cluster is ready.
        client.run(lambda: _runner(runner_path).run("duration=1e-9") and None)
        ready = time.perf_counter()
        nworkers = max(1, len(client.scheduler_info().get("workers", {})) or (workers or 1))
        # Chunks of a few cases: the scheduler's cost per task is shared, and every
        # worker still gets several chunks to balance the load.
        size = chunk or max(1, min(8, len(todo) // (8 * nworkers)))
        chunks = _chunks(todo, size)
        futures = client.map(run_chunk, chunks, runner_path=runner_path, pure=False)
        meta = {f.key: c for f, c in zip(futures, chunks)}
        bar = _bar(len(todo), progress)
        for fut in as_completed(futures):
            try:
                results = fut.result()
            except Exception as e:  # a lost worker or task: its cases run again next time
                results = [(cid, {"error": f"{type(e).__name__}: {e}", "transient": True}, 0.0)
                           for cid, _ in meta[fut.key]]
            _append(out_dir, [_record(cid, res, wall, by_id[cid]) for cid, res, wall in results])
            if bar:
                bar.update(len(results))
        if bar:
            bar.close()
        return ready
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
