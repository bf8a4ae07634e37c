"""python -m wheelflat_study STUDY.toml [--scheduler ADDRESS] [--workers N] [--serial]
[--out DIR] [--chunk N] [--no-plots]

Runs the study's cases on Dask (a local cluster of one process per core by default,
or the dask.distributed scheduler at ADDRESS, whose workers must reach this checkout's
case runner at the same path), writes results/<name>/results.parquet, .csv,
impacts.parquet, .csv and the plots; started again, it runs only the missing cases.
"""

import argparse
import os
import sys

from .run import ROOT, build_runner, run_study
from .spec import load_study


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m wheelflat_study", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("study", help="the study file (TOML), e.g. studies/speed_flat.toml")
    ap.add_argument("--scheduler", help="address of a running dask.distributed scheduler")
    ap.add_argument("--workers", type=int, help="local worker processes (default: one per core)")
    ap.add_argument("--serial", action="store_true", help="no Dask: every case in this process, in order")
    ap.add_argument("--out", help="output folder (default results/<study name>)")
    ap.add_argument("--chunk", type=int, help="cases per Dask task (default: a few per worker)")
    ap.add_argument("--no-plots", action="store_true")
    ap.add_argument("--no-progress", action="store_true")
    ap.add_argument("--runner", help="the case runner (default: built here with cargo)")
    args = ap.parse_args(argv)
    try:
        study = load_study(args.study)
    except (OSError, ValueError) as e:
        print(f"{args.study}: {e}", file=sys.stderr)
        return 2
    runner = args.runner or build_runner()
    out = args.out or os.path.join(ROOT, "results", study.name)
    table, _ = run_study(study, out, scheduler=args.scheduler, workers=args.workers,
                         serial=args.serial, chunk=args.chunk, runner_path=runner,
                         progress=not args.no_progress, plots=not args.no_plots)
    failed = int((table["status"] == "error").sum()) if len(table) else 0
    print(f"results: {os.path.join(out, 'results.parquet')} and .csv ({len(table)} cases, {failed} failed)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
