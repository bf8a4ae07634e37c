"""Throughput of the sweep command on this machine: 40 cases of the 100 km/h
reference-flat case over 0.5 s (the start moved by 1 cm per case), run serially in this
process and on a LocalCluster of one worker per core; prints cases per minute and the
sweep machinery's overhead per case (wall time per case less the runner's own time for
the case, per worker).

    python -m wheelflat_study.throughput [--cases 40] [--workers N]
"""

import argparse
import os
import tempfile
import time

from .run import build_runner, run_study
from .spec import Study


def study(n):
    return Study(name="throughput", duration=0.5,
                 fixed={"speed": 100 / 3.6, "track.window.ahead": 20.0, "track.window.behind": 20.0},
                 sweep={"start_position": [10.0 + 0.01 * k for k in range(n)]})


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", type=int, default=40)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()
    runner = build_runner()
    s = study(args.cases)
    quiet = dict(progress=False, plots=False, log=lambda *_: None, runner_path=runner)
    for label, kw, workers in (("serial", dict(serial=True), 1),
                               (f"Dask, {args.workers} workers", dict(workers=args.workers), args.workers)):
        with tempfile.TemporaryDirectory() as out:
            t0 = time.perf_counter()
            table, n = run_study(s, out, **kw, **quiet)
            wall = time.perf_counter() - t0
        t = run_study.timing
        case = table["runner_wall_s"].mean()
        per_case = t["cases_s"] * workers / n
        print(f"{label:18s}: {n} cases in {wall:.2f} s ({t['startup_s']:.2f} s start-up, {t['cases_s']:.2f} s "
              f"the cases, {t['tables_s']:.2f} s the tables), {60 * n / t['cases_s']:.0f} cases per minute once "
              f"started; a case {1e3 * case:.1f} ms in the runner, {1e3 * per_case:.1f} ms of a worker's time: "
              f"overhead {1e3 * (per_case - case):.1f} ms per case ({100 * (per_case / case - 1):.1f} %)")

if __name__ == "__main__":
    main()
