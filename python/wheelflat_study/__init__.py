"""Parametric studies of the wheelflat model, run as sweeps on Dask.

A study is a small TOML file (``studies/*.toml``): fixed CoupledSystem variables, swept
ones (lists, ranges or random samples, in SI or with a unit), the run's duration and
the outputs whose extremes to keep. Each case runs in the engine's study runner
(``wheelflat_case``, the CoupledSystem model in process, sampled at every internal
step), one persistent runner per Dask worker. Results go to ``results.parquet`` and
``results.csv`` (one row per case, with its parameters, the software version and the
FMU GUID), ``impacts.parquet``/``.csv`` (one row per impact), ``summary.csv`` (the
distribution of results over each case group of its ``[summary]``, summary.py) and the
plots the study asks for; a study started again skips the cases it already has.

    wheelflat-study studies/speed_flat.toml [--scheduler ADDRESS] [--workers N]

Installed from its wheel (``python/pyproject.toml``), the package carries its own case
runner and the FMUs (``fmu_paths()``), so a cluster's worker needs only the
install. See docs/guide/studies.md and docs/STUDIES.md.
"""

import json
import os

from .spec import Study, load_study  # noqa: F401
from .run import run_study  # noqa: F401
from .run import DATA, ROOT, default_runner, installed


def fmu_paths():
    """The FMUs by name (those the packer listed in ``fmus.json``): the installed
    package's, or in a checkout those in fmu/ (built by ``bash
    scripts/build_fmus_glibc228.sh fmu``, the portable build the main command makes)."""
    from .buildinfo import fmu_names
    where = os.path.join(DATA, "fmu") if installed() else os.path.join(ROOT, "fmu")
    return {name: os.path.join(where, name + ".fmu") for name in fmu_names(where)}


def build_info():
    """The versions and GUIDs of this installation's case runner and FMUs, and the git
    commit it was built from (a dict; see :mod:`wheelflat_study.buildinfo`)."""
    if installed():
        with open(os.path.join(DATA, "build.json")) as fh:
            return json.load(fh)
    from .buildinfo import collect
    runner = default_runner()
    if runner is None:
        raise RuntimeError("no case runner built in this checkout: bash scripts/build_fmus_glibc228.sh fmu")
    return collect(runner, os.path.join(ROOT, "fmu"), ROOT)
