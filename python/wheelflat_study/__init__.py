"""Parametric studies of the wheelflat model, run as sweeps on Dask.

A study is a small TOML file (``studies/*.toml``): fixed CoupledSystem variables, swept
ones (lists, ranges or random samples, in SI or with a unit), the run's duration and
the outputs whose extremes to keep. Each case runs in the engine's study runner
(``wheelflat_case``, the CoupledSystem model in process, sampled at every internal
step), one persistent runner per Dask worker. Results go to ``results.parquet`` and
``results.csv`` (one row per case, with its parameters, the software version and the
FMU GUID), ``impacts.parquet``/``.csv`` (one row per impact), and the plots the study
asks for; a study started again skips the cases it already has.

    python -m wheelflat_study studies/speed_flat.toml [--scheduler ADDRESS] [--workers N]

See README.md ("Studies at scale") and docs/STUDIES.md.
"""

from .spec import Study, load_study  # noqa: F401
from .run import run_study  # noqa: F401
