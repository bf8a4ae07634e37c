"""wheelflat-study STUDY.toml [--scheduler ADDRESS] [--workers N] [--serial]
[--out DIR] [--chunk N] [--case-time-limit S] [--no-plots]
(in a checkout also: python -m wheelflat_study ...)

Runs the study's cases on Dask (a local cluster of one process per core by default,
or the dask.distributed scheduler at ADDRESS, whose workers run the case runner of
their own wheelflat install, which must be the same version), writes
<out>/results.parquet, .csv, impacts.parquet, .csv and the plots (out: results/<name>
in a checkout, else ./results/<name>); started again, it runs only the missing cases.
"""

import argparse
import json
import os
import sys

from .run import (MAX_TIME_LIMIT, MIN_TIME_LIMIT, ROOT, TIME_LIMIT_FACTOR, build_runner, installed, run_study,
                  stop_runners)
from .spec import MAX_CASES, Table, Unread, _finite_text, inline, load_study


def main(argv=None):
    """The study command; returns its exit status."""
    try:
        return _main(argv)
    except KeyboardInterrupt:
        # Ctrl-C or SIGTERM before the cases started (reading the study, checking it).
        stop_runners()
        print("\ninterrupted", file=sys.stderr)
        return 130
    finally:
        # Arrow's native threads (the tables' Parquet writers) joined while Arrow is
        # alive: left to the interpreter's teardown they can abort the process
        # (SIGABRT, "terminate called without an active exception", apache/arrow
        # #34314) after the study has finished.
        import gc
        gc.collect()


def _main(argv=None):
    ap = argparse.ArgumentParser(prog="wheelflat-study", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", nargs="?", help="the study file (TOML), e.g. studies/speed_flat.toml")
    ap.add_argument("--scheduler", help="address of a running dask.distributed scheduler")
    ap.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    ap.add_argument("--serial", action="store_true", help="no Dask: every case in this process, in order")
    ap.add_argument("--out", help="output folder (default results/<study name>)")
    ap.add_argument("--chunk", type=int, help="cases per Dask task (default: a few per worker)")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--runner", help="the case runner, at this path for this process and every worker "
                                     "(default: the installed package's, or in a checkout the portable one that "
                                     "bash scripts/build_fmus_glibc228.sh fmu builds, run first)")
    ap.add_argument("--case-time-limit", type=float, metavar="S",
                    help=f"wall time one case may take (s); a case past it is stopped and recorded as "
                         f"failed (default: {TIME_LIMIT_FACTOR:g} times its duration at the cost measured "
                         f"at the start, at least {MIN_TIME_LIMIT:g} s)")
    ap.add_argument("--limit", type=int, metavar="N",
                    help="run the study's first N cases only (their ids are the whole study's: the same command "
                         "without --limit goes on with the rest)")
    ap.add_argument("--dry-run", action="store_true",
                    help="check the study, print its case table (each case's id and the values it sweeps, in "
                         "their display units) and stop, running nothing")
    ap.add_argument("--version", action="store_true", help="print the installed versions and GUIDs, then stop")
    ap.add_argument("--retry-failed", action="store_true",
                    help="run again the cases that failed (those that failed for a passing reason, "
                         "a stopped runner or a lost worker, always run again)")
    args = ap.parse_args(argv)
    # A batch system's SIGTERM stops the study as Ctrl-C does: the cases done are kept.
    # Only the first signal stops it; those that follow (GNU timeout's second SIGTERM, a
    # double Ctrl-C) are ignored while it stops its runners and keeps what it has, so
    # they give no traceback (SIGKILL still ends it at once).
    import signal

    def stop(signum, frame):
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        raise KeyboardInterrupt
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    if args.version:
        from . import build_info
        try:
            print(json.dumps(build_info(), indent=1))
        except RuntimeError as e:
            print(f"wheelflat-study --version: {e}", file=sys.stderr)
            return 2
        return 0
    if args.study is None:
        ap.print_usage(sys.stderr)
        print("wheelflat-study: the study file is needed", file=sys.stderr)
        return 2
    limit = args.case_time_limit
    if limit is not None and not 0 < limit <= MAX_TIME_LIMIT:
        print(f"--case-time-limit {limit:g}: 0 < S <= {MAX_TIME_LIMIT:g} s", file=sys.stderr)
        return 2
    for flag, v, most in (("--chunk", args.chunk, MAX_CASES), ("--workers", args.workers, 1024),
                          ("--limit", args.limit, MAX_CASES)):
        if v is not None and not 1 <= v <= most:
            print(f"{flag} {v}: 1 to {most}", file=sys.stderr)
            return 2
    if args.scheduler is not None and not (args.scheduler.startswith(("tcp://", "tls://", "inproc://",
                                                                         "ucx://", "ws://", "wss://"))
                                           or ":" in args.scheduler):
        print(f"--scheduler {args.scheduler!r}: an address such as tcp://HOST:8786", file=sys.stderr)
        return 2
    try:
        study = load_study(args.study)
    except (OSError, ValueError) as e:
        print(f"{args.study}: {e}", file=sys.stderr)
        return 2
    if args.runner is not None:
        # A bare name would be looked up on PATH by the processes that start it.
        args.runner = os.path.abspath(args.runner)
    try:
        runner = args.runner or build_runner()
    except RuntimeError as e:
        print(str(e), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("interrupted while building the case runner", file=sys.stderr)
        return 130
    if not (os.path.isfile(runner) and os.access(runner, os.X_OK)):
        print(f"--runner {runner}: not an executable file (the case runner: target/x86_64-unknown-linux-gnu/release/wheelflat_case in a checkout)",
              file=sys.stderr)
        return 2
    try:
        check_variables(study, runner)
        study.check()
    except ValueError as e:
        print(f"{args.study}: {e}", file=sys.stderr)
        return 2
    except RuntimeError as e:
        print(str(e), file=sys.stderr)
        return 2
    study.limit = args.limit
    if args.dry_run:
        print_cases(study)
        return 0
    out = args.out or os.path.join("results" if installed() else os.path.join(ROOT, "results"), study.name)
    try:
        os.makedirs(out, exist_ok=True)
        with open(os.path.join(out, ".lock"), "a"):
            pass
    except OSError as e:
        print(f"--out {out}: cannot write there ({e.strerror or e})", file=sys.stderr)
        return 2
    try:
        # Without --runner each worker runs its own install's runner (checked to be
        # this one's version and GUID), so a cluster's hosts need no shared path.
        table, _ = run_study(study, out, scheduler=args.scheduler, workers=args.workers,
                             serial=args.serial, chunk=args.chunk, runner_path=args.runner,
                             progress=not args.no_progress, plots=not args.no_plots,
                             retry_failed=args.retry_failed, time_limit=limit)
    except KeyboardInterrupt:
        stop_runners()
        print("\ninterrupted: the cases done so far are kept; run the same command to go on", file=sys.stderr)
        return 130
    except RuntimeError as e:
        print(f"{args.study}: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        import errno
        if e.errno == errno.ENOSPC:
            print(f"{args.study}: disk full while writing into {out} ({e.filename or 'a results file'}): "
                  f"free some space and run the same command again; the cases done so far are kept",
                  file=sys.stderr)
            return 1
        raise
    failed = int((table["status"] == "error").sum()) if len(table) else 0
    # A case with no result (its runner or worker lost) is a failure too: it runs the
    # next time the same command runs.
    # (The tables hold every case of the study with a result; those --limit asked for
    # and have none are the missing.)
    import dataclasses
    have = set(table["case_id"]) if len(table) else set()
    missing = sum(1 for c in study.iter_cases() if c.id not in have)
    whole = dataclasses.replace(study, limit=None).count()
    print(f"results: {os.path.join(out, 'results.parquet')} and .csv ({len(table)} of {whole} cases, "
          f"{failed} failed" + (f", {missing} without a result: run the same command again to run them"
                                if missing else "") + ")")
    failed += missing
    return 1 if failed else 0


def print_cases(study):
    """The case table of `study` on standard output, tab-separated: `id` and each swept
    variable, with its display unit (`speed [km/h]`), then the count and what every case
    fixes; a table by its file's name (or `table`, written out) and content's hash."""
    names = list(study.sweep)
    head = ["id"] + [f"{n} [{study.display[n][0]}]" if n in study.display else n for n in names]
    print("\t".join(head))

    def text(name, v):
        if hasattr(v, "sha256"):
            return f"{v.name if not inline(v.name) else 'table'} ({v.key})" if v.text else "no table"
        # An enumeration by its item's name, a number in its display unit.
        return study.shown(name, v)

    for case in study.iter_cases():
        print("\t".join([case.id] + [text(n, case.params[n]) for n in names]))
    fixed = ", ".join(f"{k} = {text(k, v)}" for k, v in study.fixed.items()) or "nothing"
    print(f"{study.count()} cases of {study.duration:g} s; fixed: {fixed}; nothing was run (--dry-run)")


def check_variables(study, runner):
    """Refuses, before anything runs, a variable CoupledSystem does not have and a value
    outside its range (as fmi2SetReal would), naming both."""
    import subprocess
    try:
        listing = subprocess.run([runner, "--variables"], capture_output=True, text=True, check=True,
                                 timeout=60).stdout
        known, outputs, units = {}, set(), {}
        for line in listing.splitlines():
            name, ty, lo, hi, unit = line.split("\t")
            units[name] = unit
            if ty == "output":
                outputs.add(name)
            else:
                known[name] = (ty, float(lo), float(hi))
        if not known or not outputs:
            raise ValueError("no variables listed")
    except (OSError, ValueError, subprocess.SubprocessError) as e:
        raise RuntimeError(f"--runner {runner}: does not answer as the case runner does ({type(e).__name__}: "
                           f"{str(e)[:200]}); give target/x86_64-unknown-linux-gnu/release/wheelflat_case or the installed "
                           f"wheelflat-case's program") from None
    # A kept name goes into the runner's line as it is: one that is not an output (a
    # blank in it, another token, a newline) would set a parameter or shift the answers.
    for name in study.keep:
        if name not in outputs:
            raise ValueError(f"keep `{name}` is not a Real output of CoupledSystem (docs/VARIABLES.md)")
    # An enumeration's item given by name is its number from here on (the same case, and
    # case id, as the number); the items are kept for the case table, summary and plots.
    for name in list(study.fixed) + list(study.sweep):
        if name in known and known[name][0] == "Integer":
            items = enumeration_items(name, known[name][1], known[name][2])
            if items:
                study.name_items(name, items)
    values = dict((k, [v]) for k, v in study.fixed.items())
    values.update(study.sweep)
    for name, vs in values.items():
        if name not in known:
            raise ValueError(f"`{name}` is not a parameter or input of CoupledSystem (docs/VARIABLES.md)")
        ty, lo, hi = known[name]
        for v in vs:
            # A text was read as a table when the study was loaded (spec.read_table);
            # one that is not a table is kept with the table's refusal (spec.Unread).
            if ty == "String":
                if isinstance(v, Unread):
                    raise ValueError(v.why)
                if not isinstance(v, Table):
                    raise ValueError(f"`{name}` = {v!r}: a table: its file's path, the table itself (x y; x y; "
                                     f"...), or \"\" for no table (a String parameter's value is always text, in "
                                     f"quotes)")
                continue
            if isinstance(v, (Table, Unread)):
                raise ValueError(takes_a_number(name, v, ty, lo, hi))
            if not lo <= v <= hi:
                raise ValueError(f"`{name}` = {v:g} is out of range: {lo:g} <= {name} <= {hi:g}")
            if ty == "Integer" and v != int(v):
                raise ValueError(f"`{name}` = {v:g}: a whole number is needed")


def takes_a_number(name, v, ty, lo, hi):
    """The refusal of text `v` (a :class:`Table` or :class:`Unread`) given to `name`,
    which takes a number of type `ty` ("Real", "Integer") from `lo` to `hi`; an
    enumeration's items with their values when CoupledSystem's model description
    beside the runner lists them."""
    text = v.text if isinstance(v, Unread) else v.given or v.name
    items = enumeration_items(name, lo, hi) if ty == "Integer" else None
    if items:
        allowed = ("one of " + ", ".join(f"{k} = {item}" for k, item in items)
                   + " (an enumeration: its item's name, in quotes, or its number)")
    elif ty == "Integer":
        allowed = f"a whole number, {lo:g} <= {name} <= {hi:g}"
    else:
        allowed = f"{lo:g} <= {name} <= {hi:g}"
    said = f"`{name}` = {text!r} is text (in quotes), but `{name}` takes a number: {allowed}"
    if items:
        said = f"`{name}` = {text!r} is not one of its items; allowed: {allowed}"
    if _finite_text(text):
        said += f"; write it without quotes: {name} = {text.strip()}"
    elif ty == "Integer" and not items and _descriptions() is not None and name not in _descriptions():
        # The runner knows the variable, the FMUs beside it do not: another build's.
        said += (f"; CoupledSystem.fmu beside the runner lacks `{name}` (another build's), so an enumeration's "
                 f"items are unknown: pack the runner's build's FMUs (bash scripts/build_fmus_glibc228.sh fmu)")
    return said


def enumeration_items(name, lo, hi):
    """The items [(value, name), ...] of CoupledSystem's enumeration `name`, read from
    the description of the variable in this installation's CoupledSystem.fmu (its
    model description ends it with "(1 = roll_plane, 2 = half_car, 3 = wagon)"); None
    when there is no such FMU or list, or the list does not cover lo to hi (another
    build than the runner's)."""
    import re
    descriptions = _descriptions()
    if descriptions is None or name not in descriptions:
        return None
    m = re.search(r"\(((?:[0-9]+ = [A-Za-z_][A-Za-z0-9_]*(?:, )?)+)\)\s*$", descriptions[name])
    if not m:
        return None
    items = [(int(k), item) for k, item in re.findall(r"([0-9]+) = ([A-Za-z_][A-Za-z0-9_]*)", m.group(1))]
    if [k for k, _ in items] != list(range(int(lo), int(hi) + 1)):
        return None
    return items


_DESCRIPTIONS = []


def _descriptions():
    """The description of every variable of this installation's CoupledSystem.fmu, by
    name (read once); None when there is no such FMU."""
    if not _DESCRIPTIONS:
        import zipfile
        import xml.etree.ElementTree as ET
        from . import fmu_paths
        try:
            with zipfile.ZipFile(fmu_paths()["CoupledSystem"]) as z:
                root = ET.fromstring(z.read("modelDescription.xml"))
        except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError):
            _DESCRIPTIONS.append(None)
        else:
            _DESCRIPTIONS.append({v.get("name"): v.get("description") or "" for v in root.iter("ScalarVariable")})
    return _DESCRIPTIONS[0]


if __name__ == "__main__":
    sys.exit(main())
