"""Running a study: the cases in chunks on Dask (a local cluster by default, or an
existing scheduler), each worker with its own persistent case runner; results kept as
they come (``cases.jsonl``, so an interrupted study resumes), then the tables and plots.
"""

import hashlib
import itertools
import json
import os
import select
import subprocess
import sys
import threading
import time

from .done import read_done

HERE = os.path.dirname(os.path.abspath(__file__))
# The installed package's own case runner and FMUs (python/setup.py puts them there).
DATA = os.path.join(HERE, "_data")
INSTALLED_RUNNER = os.path.join(DATA, "bin", "wheelflat_case")
# In a checkout: the repository, and the case runner of the project's one build,
# scripts/build_fmus_glibc228.sh (python/wheelflat_fmus.py: BUILD_SCRIPT, RUNNER_228):
# cargo-zigbuild against the glibc 2.28 baseline, with the FMUs in fmu/. Never a plain
# `cargo build` of its own (target/release/, which needs the build machine's glibc).
ROOT = os.path.dirname(os.path.dirname(HERE))
TARGET_DIR = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR") or "target")
BUILD_SCRIPT = os.path.join(ROOT, "scripts", "build_fmus_glibc228.sh")
FMU_DIR = os.path.join(ROOT, "fmu")
RUNNER = os.path.join(TARGET_DIR, "x86_64-unknown-linux-gnu", "release", "wheelflat_case")

# The per-case time limit by default: this many times the case's simulated duration at
# the cost per simulated second measured when the study starts (CoupledSystem's
# defaults), and never below MIN_TIME_LIMIT. 200 covers a grid refined to n = 32 (16
# times the default's cost) on four wheelsets with the machine 1.7 times slower.
TIME_LIMIT_FACTOR = 200.0
MIN_TIME_LIMIT = 60.0
# A case whose runner stops, whose worker is lost or whose answer is for another case
# runs again within the same run, at most this many times in all; then it is recorded
# as failed, by name ("lost N times ..."; --retry-failed runs it again).
MAX_TRIES = 3


def installed():
    """Whether this is the installed package (with its own runner), not a checkout."""
    return os.path.isfile(INSTALLED_RUNNER)


def default_runner():
    """The case runner of this installation: the installed package's, else this
    checkout's portable one (RUNNER, from scripts/build_fmus_glibc228.sh; None when
    neither is there)."""
    for path in (INSTALLED_RUNNER, RUNNER):
        if os.path.isfile(path) and os.access(path, os.X_OK):
            return path
    return None


def runner_stale():
    """Whether the checkout's runner (RUNNER) is missing or older than a file it was
    built from: those cargo's dep-info beside it lists (RUNNER.d: the sources, the
    build script's inputs), Cargo.toml, Cargo.lock and the build script; no dep-info
    is stale too."""
    try:
        built = os.stat(RUNNER).st_mtime
        with open(RUNNER + ".d") as fh:
            deps = fh.read().split(": ", 1)[1]
    except (OSError, IndexError):
        return True
    import re
    paths = [p.replace("\\ ", " ") for p in re.split(r"(?<!\\)\s+", deps.strip()) if p]
    paths += [os.path.join(ROOT, "Cargo.toml"), os.path.join(ROOT, "Cargo.lock"), BUILD_SCRIPT]
    for path in paths:
        try:
            if os.stat(path).st_mtime > built:
                return True
        except OSError:
            return True
    return False


def build_runner():
    """The case runner: the installed package's, or in a checkout the portable one of
    the project's one build, ``bash scripts/build_fmus_glibc228.sh fmu`` (the runner
    and the FMUs against the glibc 2.28 baseline), run here when the runner is missing
    or older than a source (:func:`runner_stale`; the check takes milliseconds and
    builds nothing, so an up-to-date runner leaves fmu/ as it is). A first build takes
    minutes, a changed source rebuilds what it touches."""
    if installed():
        return INSTALLED_RUNNER
    if not (os.path.isfile(os.path.join(ROOT, "Cargo.toml")) and os.path.isfile(BUILD_SCRIPT)):
        raise RuntimeError("no case runner: install the package (docs/guide/studies.md) or give --runner")
    if not runner_stale():
        return RUNNER
    print("building the case runner and the FMUs (bash scripts/build_fmus_glibc228.sh fmu, the project's one "
          "build, against glibc 2.28; " + ("a source changed" if os.path.isfile(RUNNER) else
                                          "a few minutes the first time") + ") ...", file=sys.stderr, flush=True)
    try:
        # The packer's list of files is dropped; cargo's progress and errors go to stderr.
        subprocess.check_call(["bash", BUILD_SCRIPT, FMU_DIR], cwd=ROOT, stdout=subprocess.DEVNULL)
    except (OSError, subprocess.CalledProcessError) as e:
        raise RuntimeError(f"building the case runner failed ({e}): run bash scripts/build_fmus_glibc228.sh "
                           f"fmu in {ROOT} to see why, or give --runner") from None
    if not os.path.isfile(RUNNER):
        raise RuntimeError(f"bash scripts/build_fmus_glibc228.sh left no case runner at {RUNNER}: give --runner")
    return RUNNER


class CaseRunner:
    """One persistent ``wheelflat_case`` process: a case line in, a JSON line out.
    Each request carries its case's id and each answer must carry it back; an answer
    for another case, a runner that stops or a case past its time limit ends the
    runner (the next case starts a new one)."""

    def __init__(self, path):
        self.path = path
        self.proc = None
        self._buf = b""

    def _start(self):
        self.proc = subprocess.Popen([self.path], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                     stderr=subprocess.DEVNULL, bufsize=0)
        self._buf = b""

    def _stop(self):
        """Ends the runner; how it ended, in words."""
        proc, self.proc = self.proc, None
        try:
            code = proc.wait(timeout=5)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = proc.wait()
        return f"killed by signal {-code}" if code < 0 else f"exit status {code}"

    def _kill(self):
        if self.proc is not None:
            self.proc.kill()
            self._stop()

    def _readline(self, deadline):
        """The runner's next line (bytes, without the newline); b"" when it stopped;
        None at the deadline (time.monotonic(); None waits as long as it takes)."""
        fd = self.proc.stdout.fileno()
        while b"\n" not in self._buf:
            wait = None if deadline is None else max(0.0, deadline - time.monotonic())
            ready, _, _ = select.select([fd], [], [], wait)
            if not ready:
                return None
            more = os.read(fd, 1 << 16)
            if not more:
                return b""
            self._buf += more
        line, self._buf = self._buf.split(b"\n", 1)
        return line

    def run(self, line, case_id="case", limit=None):
        """Runs one case: `line` (the runner's tokens), `case_id` (carried to the runner
        and back), `limit` (s of wall time, None for none). The answer as a dict; a
        failure of the runner as ``{"error": ..., "transient": True}`` (the case runs
        again next time), a case past its limit as an error with ``time_limit``."""
        if self.proc is None or self.proc.poll() is not None:
            self._start()
        t0 = time.monotonic()
        try:
            self.proc.stdin.write(f"case={case_id} {line}\n".encode())
            self.proc.stdin.flush()
            out = self._readline(None if limit is None else t0 + min(limit, MAX_TIME_LIMIT))
        except (BrokenPipeError, OSError) as e:
            out, why = b"", str(e)
        else:
            why = "no answer"
        if out is None:
            self._kill()
            return {"error": f"the case ran past its time limit of {limit:.4g} s (the runner was stopped; "
                             f"--case-time-limit sets the limit, --retry-failed runs it again)",
                    "time_limit": limit}
        if not out:
            how = self._stop()
            return {"error": f"the case runner stopped ({why}, {how})", "transient": True}
        try:
            res = json.loads(out)
        except ValueError:
            res = None
        if not isinstance(res, dict) or res.get("case") != case_id:
            # Never take an answer for another case (or none) as this one's.
            got = res.get("case") if isinstance(res, dict) else out[:80].decode(errors="replace")
            self._kill()
            return {"error": f"the case runner answered {got!r} to case {case_id!r} (the runner was "
                             f"restarted)", "transient": True}
        del res["case"]
        if not (res.get("error") or (isinstance(res.get("version"), str) and isinstance(res.get("guid"), str)
                                     and isinstance(res.get("peak"), dict))):
            self._kill()
            return {"error": "the case runner's answer has no version, GUID or peaks: not the case runner "
                             "(the runner was restarted)", "transient": True}
        return res


# The most wall time a case may be given (s): select() takes no more.
MAX_TIME_LIMIT = 1e6

# One runner per (path, thread): a Dask worker with several threads runs a case in each.
_RUNNERS = {}
_IDENTITIES = {}
_LOCK = threading.Lock()


def _runner(path):
    """The case runner of this thread (one per Dask worker thread); `path` None: this
    installation's own (on a cluster's worker: the worker's install)."""
    path = path or default_runner()
    if path is None:
        raise RuntimeError("no case runner on this worker: install the wheelflat package there "
                           "(docs/guide/studies.md)")
    key = (path, threading.get_ident())
    with _LOCK:
        r = _RUNNERS.get(key)
        if r is None:
            r = _RUNNERS[key] = CaseRunner(path)
    return r


def stop_runners():
    """Ends every case runner of this process (at an interruption: a runner left alone
    would finish its case for nobody)."""
    with _LOCK:
        runners = list(_RUNNERS.values())
        _RUNNERS.clear()
    for r in runners:
        r._kill()


def identity(runner_path=None):
    """(version, GUID, engine) of this process's runner at `runner_path` (None: its own
    install's), measured once per process ([`warm_up`])."""
    path = runner_path or default_runner()
    with _LOCK:
        known = _IDENTITIES.get(path)
    if known is None:
        known = warm_up(path)[0]
    return known


def runner_units(runner_path):
    """Every variable's unit by name, as the case runner lists them (`--variables`: the
    variable table's, the same as the FMUs' model descriptions)."""
    import subprocess
    listing = subprocess.run([runner_path, "--variables"], capture_output=True, text=True, check=True,
                             timeout=60).stdout
    return {f[0]: f[4] for f in (line.split("\t") for line in listing.splitlines()) if len(f) == 5}


def run_chunk(chunk, runner_path=None):
    """Runs the cases of `chunk` (a list of (case id, runner line, time limit s); a line
    may be a list of pieces to join, Case.parts, which shares a table's content between
    the cases of a chunk) in this thread's runner; (the runner's identity (version,
    GUID, engine), where it ran (the Dask worker's address, or None), a list of (case
    id, result dict, wall seconds in this function)). The identity lets the study keep only results of its own model,
    also from workers that joined after it started."""
    out = []
    ident = identity(runner_path)
    r = _runner(runner_path)
    for cid, line, limit in chunk:
        if not isinstance(line, str):
            line = "".join(line)
        t0 = time.perf_counter()
        try:
            res = r.run(line, cid, limit)
        except Exception as e:  # a failing case is recorded, the study goes on
            res = {"error": f"{type(e).__name__}: {e}", "transient": True}
        out.append((cid, res, time.perf_counter() - t0))
    try:
        from distributed import get_worker
        where = get_worker().address
    except (ImportError, ValueError):
        where = None
    return ident, where, out


def warm_up(runner_path=None):
    """Starts this process's runner; its identity (version, GUID, engine) and cost per
    simulated second of CoupledSystem's default case (s/s, measured on 0.2 s). The
    engine is a fingerprint of that case's numbers (12 hex digits of the SHA-1 of its
    answer less the wall time): it changes whenever the model's numbers do, which the
    version and GUID need not (a change of the numerics keeps the variables)."""
    r = _runner(runner_path).run("duration=0.2", "warm-up", limit=120.0)
    if r.get("error"):
        raise RuntimeError(f"the case runner {runner_path or default_runner()} fails: {r['error']}")
    numbers = {k: v for k, v in r.items() if k not in ("wall_s", "warnings")}
    engine = hashlib.sha1(json.dumps(numbers, sort_keys=True).encode()).hexdigest()[:12]
    ident = (r.get("version"), r.get("guid"), engine)
    with _LOCK:
        _IDENTITIES[runner_path or default_runner()] = ident
    return ident, r["wall_s"] / 0.2


def described(ident):
    """A runner's identity in words: "version V, GUID G, engine E"."""
    return f"version {ident[0]}, GUID {ident[1]}, engine {ident[2]}"


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
              runner_path=None, progress=True, plots=True, log=print, retry_failed=False, time_limit=None):
    """Runs the cases of `study` not yet in `out_dir` and writes the tables (and plots).

    scheduler: the address of a running dask.distributed scheduler; None starts a
    LocalCluster of `workers` processes (default: one per core). serial: no Dask, in
    this process. runner_path: the case runner for this process and every worker
    (None: each uses its own installation's, which must be the same version and GUID).
    time_limit: the wall time a case may take (s); None: TIME_LIMIT_FACTOR times its
    duration at the measured cost, at least MIN_TIME_LIMIT. Returns (the results table,
    the number of cases run now); the times of the last run (start-up, the cases, the
    tables) are in `run_study.timing`."""
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
                           log, retry_failed, time_limit)


def _run_locked(study, out_dir, scheduler, workers, serial, chunk, runner_path, progress, plots, log,
                retry_failed, time_limit):
    """:func:`run_study` with the folder's lock held. The cases are made as they are
    sent, so memory stays in proportion to the chunks in flight, not to the study."""
    started = time.perf_counter()
    study.check()
    # The command built the runner already (build_runner); a library call without one
    # takes this installation's, built only if there is none.
    ident, cost = warm_up(runner_path or default_runner() or build_runner())
    done, other = read_done(out_dir, retry_failed, ident, ids_only=True)
    done = set(done)
    if other:
        log(f"{study.name}: {other} results of another software version, model GUID or engine in "
            f"{out_dir} are set aside and run again (this runner: {described(ident)})")
    total = study.count()
    have = sum(1 for c in study.iter_cases() if c.id in done) if done else 0
    log(f"{study.name}: {total} cases, {have} already done, {total - have} to run")
    todo = (c for c in study.iter_cases() if c.id not in done)
    if time_limit is None:
        def limit(case):
            return max(MIN_TIME_LIMIT, TIME_LIMIT_FACTOR * cost * case.duration)
    else:
        def limit(case):
            return time_limit
    ready = time.perf_counter()
    counts = {"ok": 0, "failed": 0, "lost": 0, "again": 0}
    if total > have:
        if serial:
            _serial(todo, total - have, out_dir, runner_path, progress, limit, counts)
        else:
            ready = _dask(todo, total - have, out_dir, runner_path, scheduler, workers, chunk, progress, limit,
                          ident, counts)
    finished = time.perf_counter()
    elapsed = finished - ready
    if total > have:
        log(_ran(counts, total - have, elapsed))
    from .tables import write_tables
    units = runner_units(runner_path or default_runner())
    table = write_tables(study, out_dir, ident, units=units)
    run_study.timing = {"startup_s": ready - started, "cases_s": finished - ready,
                        "tables_s": time.perf_counter() - finished}
    if plots and study.plots:
        from .plots import make_plots
        for p in make_plots(study, table, out_dir, log):
            log(f"wrote {p}")
    if study.summary is not None:
        from .summary import format_summary, write_summary
        path, rows = write_summary(study, table, out_dir, units)
        s = study.summary
        log(f"summary over {', '.join(s.over)} ({percentile_words(s.percentile)} by numpy's linear "
            f"interpolation, std with ddof = 1; count: the cases that finished with the result): {path}")
        log(format_summary(study, rows, units))
    return table, counts["ok"] + counts["failed"]


def percentile_words(q):
    """`q` (0 to 100) as words: "the 95th percentile"."""
    text = f"{q:g}"
    last = text[-1]
    suffix = "th" if text.endswith(("11", "12", "13")) or "." in text else {"1": "st", "2": "nd", "3": "rd"}.get(
        last, "th")
    return f"the {text}{suffix} percentile"


def _ran(counts, count, elapsed):
    """What ran, in words: the cases that finished (a result, or a failure of the case
    itself), those that failed, those lost MAX_TRIES times (failed by name), the runs
    lost and run again, and any case left without a result."""
    ran = counts["ok"] + counts["failed"]
    text = f"ran {ran} cases in {elapsed:.2f} s ({60 * ran / max(elapsed, 1e-9):.0f} cases per minute): " \
           f"{counts['ok']} finished, {counts['failed']} failed"
    if counts["lost"]:
        text += f" ({counts['lost']} of them lost {MAX_TRIES} times: a runner or worker stopped on each try)"
    if counts["again"]:
        text += f"; {counts['again']} runs lost (a runner or worker stopped) and run again"
    if count > ran:
        text += f"; {count - ran} without a result"
    return text


def _final(res, tries, counts):
    """The result to record of a case's try number `tries` (from 1), or None when it
    was lost (a stopped runner or worker, an answer for another case) and runs again;
    counts it."""
    if res.get("transient"):
        if tries < MAX_TRIES:
            counts["again"] += 1
            return None
        # Lost on every try: a failure by name, not a case left without a result.
        res = {"error": f"lost {tries} times in one run (each try's runner or worker stopped; the last: "
                        f"{res.get('error')}): the case may stop its runner; --retry-failed runs it again",
               "lost": tries}
        counts["lost"] += 1
    counts["failed" if res.get("error") else "ok"] += 1
    return res


def _record(cid, res, wall, case, ident):
    """A line of cases.jsonl; `ident`: the (version, GUID, engine) of the runner that
    answered. A table parameter is kept by its name, and in `tables` the hash of the
    content the case ran with."""
    rec = {"id": cid, "params": case.record_params(), "duration": case.duration, "keep": list(case.keep),
           "result": res, "wall_s": wall, "identity": list(ident)}
    tables = case.table_hashes()
    if tables:
        rec["tables"] = tables
    return rec


def _bar(total, progress):
    if not progress:
        return None
    from tqdm import tqdm
    return tqdm(total=total, unit="case", file=sys.stderr)


def _serial(todo, count, out_dir, runner_path, progress, limit, counts):
    """Runs the `count` cases of the iterator `todo` here, in order (a lost case again
    at once, up to MAX_TRIES times)."""
    bar = _bar(count, progress)
    for case in todo:
        for tries in range(1, MAX_TRIES + 1):
            ident, _, [(cid, res, wall)] = run_chunk([(case.id, case.parts(), limit(case))], runner_path)
            final = _final(res, tries, counts)
            # A lost try is recorded too (an interruption now runs it next time).
            _append(out_dir, [_record(cid, final or res, wall, case, ident)])
            if final is not None:
                break
        if bar:
            bar.update(1)
    if bar:
        bar.close()


def _dask(todo, count, out_dir, runner_path, scheduler, workers, chunk, progress, limit, ident, counts):
    """Runs the `count` cases of the iterator `todo` on Dask, a few chunks per worker in
    flight (a lost case again, up to MAX_TRIES times in all); returns when every
    worker's runner was ready (perf_counter)."""
    from dask.distributed import Client, LocalCluster, as_completed
    if scheduler:
        try:
            client = Client(scheduler, timeout=60)
        except (OSError, ValueError, TypeError) as e:
            raise RuntimeError(f"cannot reach the scheduler {scheduler}: {type(e).__name__}: {e}") from None
        cluster = None
        try:
            client.wait_for_workers(1, timeout=120)
        except Exception:
            client.close()
            raise RuntimeError(f"the scheduler {scheduler} has no workers after 120 s: start some "
                               f"(dask worker {scheduler}, where the wheelflat package is installed)")
    else:
        n = workers or os.cpu_count() or 1
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=":0")
        client = Client(cluster)
    try:
        # Every worker's runner started, and the same model as this process's: one
        # table holds one model's results.
        try:
            answers = client.run(warm_up, runner_path)
        except Exception as e:
            raise RuntimeError(f"a worker cannot start its case runner: {type(e).__name__}: {e}") from None
        # A worker with several threads runs a case in each, one runner per thread.
        other = {w: tuple(i) for w, (i, _) in answers.items() if tuple(i) != tuple(ident)}
        if other:
            raise RuntimeError(f"workers with another version, model GUID or engine than this one's "
                               f"({described(ident)}): "
                               + ", ".join(f"{w}: {described(i)}" for w, i in other.items()))
        ready = time.perf_counter()
        nworkers = max(1, len(answers))
        # Chunks of a few cases: the scheduler's cost per task is shared, and every
        # worker still gets several chunks to balance the load. Four chunks a worker in
        # flight keep it busy; the rest are made when these come back.
        size = chunk or max(1, min(8, count // (8 * nworkers)))
        pending = as_completed()
        flying = {}

        requeued = []
        # The tries of the cases lost so far (only those: the dict stays small).
        tries = {}

        def send():
            cases = [requeued.pop() for _ in range(min(size, len(requeued)))]
            cases += list(itertools.islice(todo, size - len(cases)))
            if cases:
                fut = client.submit(run_chunk, [(c.id, c.parts(), limit(c)) for c in cases], runner_path,
                                    pure=False)
                flying[fut.key] = cases
                pending.add(fut)
            return bool(cases)

        def fill():
            # Four chunks a worker in flight, and every case sent again (several may
            # come back from one chunk) on its way.
            while (len(flying) < 4 * nworkers or requeued) and send():
                pass

        fill()
        bar = _bar(count, progress)
        retired, succeeded, failures = set(), False, []
        for fut in pending:
            cases = {c.id: c for c in flying.pop(fut.key)}
            try:
                wid, where, results = fut.result()
            except Exception as e:  # a lost worker or task: its cases run again next time
                wid, where = ident, None
                results = [(cid, {"error": f"{type(e).__name__}: {e}", "transient": True}, 0.0)
                           for cid in cases]
                failures.append(f"{type(e).__name__}: {e}")
                # Tasks that fail before any succeeds (a scheduler or workers that cannot
                # load them): stop, rather than record the whole study as lost.
                if not succeeded and len(failures) >= 3:
                    raise RuntimeError(f"the cluster fails every task ({failures[0][:300]}): is the wheelflat "
                                       f"package installed where the scheduler and the workers run?")
            else:
                succeeded = True
            if tuple(wid) != tuple(ident):
                # A worker that joined after the start with another model: its answers
                # are not kept, it is sent away and its cases run again on the others.
                requeued.extend(cases.values())
                results = []
                if where is not None and where not in retired:
                    retired.add(where)
                    print(f"worker {where} runs another model ({described(wid)}; this study's: "
                          f"{described(ident)}): retired, its cases run elsewhere", file=sys.stderr)
                    try:
                        client.retire_workers(workers=[where], close_workers=True)
                    except Exception:
                        pass
                wid = ident
            fut.release()
            records, finished = [], 0
            for cid, res, wall in results:
                tries[cid] = tries.get(cid, 0) + 1
                final = _final(res, tries[cid], counts)
                if final is None:
                    requeued.append(cases[cid])
                else:
                    tries.pop(cid)
                    finished += 1
                records.append(_record(cid, final or res, wall, cases[cid], wid))
            if records:
                _append(out_dir, records)
            fill()
            if bar:
                bar.update(finished)
        if bar:
            bar.close()
        return ready
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
