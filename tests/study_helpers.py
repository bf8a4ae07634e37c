"""What the study tests (tests/test_study_*.py) share: the wheelflat_study package of this
checkout, a small study file, its tables without the timings, an executable stand-in
for the case runner. The ``runner`` and ``study`` fixtures are in conftest.py."""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
from wheelflat_study import load_study, run_study  # noqa: E402, F401
from wheelflat_study.done import load_done  # noqa: E402, F401
from wheelflat_study.run import ROOT, build_runner  # noqa: E402, F401
from wheelflat_study.tables import TIMING  # noqa: E402

STUDY = """
name = "small"
duration = 0.12
keep = ["rail.left.z"]

[fixed]
"track.window.ahead" = 8.0
"track.window.behind" = 8.0

[sweep]
speed = { values = [60, 100], unit = "km/h" }
"flat.left[1].length" = { values = [50, 100], unit = "mm" }
"flat.left[1].angle" = { values = [10, 60], unit = "deg" }
"""


def comparable(table):
    return table.drop(columns=[c for c in TIMING if c in table.columns]).reset_index(drop=True)


# The start of every stand-in runner below: the real runner as a child, `--variables`
# passed through; each stand-in's own loop over the case lines follows.
FAKE_RUNNER_START = """#!{python}
import subprocess, sys
child = subprocess.Popen([{runner!r}] + sys.argv[1:], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                         bufsize=1)
if sys.argv[1:]:
    sys.stdout.write(child.communicate()[0])
    sys.exit(0)
"""


# A stand-in runner's loop that stops, without an answer, on the 30 m/s case.
LOSING_RUNNER = """\
for line in sys.stdin:
    if "speed=30" in line:
        sys.exit(9)   # a runner killed on this case: no answer
    child.stdin.write(line)
    child.stdin.flush()
    sys.stdout.write(child.stdout.readline())
    sys.stdout.flush()
"""


def fake_runner(path, runner, loop):
    """Writes an executable stand-in for the case runner at `path`: the real `runner`
    behind `loop` (Python, reading `sys.stdin` and writing to `child`); its path."""
    path.write_text(FAKE_RUNNER_START.format(python=sys.executable, runner=runner) + loop)
    path.chmod(0o755)
    return path
