"""The FMI 3.0 FMUs (fmu/fmi3/) in the Reference-FMUs' C fmusim (issue 43): fmusim v0.0.39,
vendored in tests/fmusim/ as released and built by scripts/build_fmusim.sh (without
CVODE: see tests/fmusim/README.md). ``FMUSIM=/path/to/fmusim`` runs these tests with another build.

- CoupledSystem to its DefaultExperiment's stop time (0.8 s), an output interval (and so
  communication step) of 1 ms: every output fmusim records (all of them) at every row
  is the FMI 2.0 fmu/CoupledSystem.fmu's in fmpy's simulate_fmu with the same stop time
  and output interval, to the 16 significant digits fmusim prints: fmpy's values printed
  as fmusim prints them (``%.16g`` for a Float64, an integer, Enumerations and Booleans
  as integers, an array's elements joined by spaces) are the same text.
- TrackContact alone, its inputs held at their start values (fmusim without an input
  file), 0.1 s at 1 ms: the contact forces, and every other output, equal the same FMI
  3.0 FMU's in fmpy, the same way.

Neither fmusim nor fmpy sets a stop time (fmusim without ``--set-stop-time``). Each
fmusim run exits 0 and prints nothing: fmusim prints every log message the FMU sends,
of any status, and stops at the first call that returns anything but OK.
"""

import csv
import os
import subprocess

import numpy as np
import pytest
from fmu_helpers import wf

import wheelflat_fmi3 as w3

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
STEP = 1e-3


@pytest.fixture(scope="module")
def fmusim():
    if os.environ.get("FMUSIM"):
        return os.environ["FMUSIM"]
    p = subprocess.run(["bash", os.path.join(ROOT, "scripts", "build_fmusim.sh")], cwd=ROOT,
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
    return os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR", "target"), "fmusim", "fmusim")


@pytest.fixture(scope="module")
def paths3(paths):
    return w3.paths3()


def run_fmusim(fmusim, fmu, csv_path, stop):
    """fmusim's CSV (header, rows of text) of a run of ``fmu`` to ``stop`` at STEP."""
    p = subprocess.run([fmusim, "--stop-time", repr(stop), "--output-interval", repr(STEP),
                        "--output-file", str(csv_path), fmu],
                       capture_output=True, text=True, timeout=300)
    log = (p.stdout + p.stderr).strip()
    assert p.returncode == 0 and log == "", (p.returncode, log[-3000:])
    with open(csv_path, newline="") as fh:
        rows = list(csv.reader(fh))
    assert rows[0][0] == "time" and len(rows) - 1 == round(stop / STEP) + 1, (rows[0][:3], len(rows))
    return rows[0], rows[1:]


def printed(value):
    """A value (a scalar, or an array's elements) as fmusim prints it."""
    return " ".join("%.16g" % x if isinstance(x, (float, np.floating)) else str(int(x))
                    for x in np.atleast_1d(value))


def outputs(path):
    from fmpy import read_model_description
    return {v.name for v in read_model_description(path).modelVariables if v.causality == "output"}


def assert_printed_alike(header, rows, result, what):
    assert len(rows) == len(result), (what, len(rows), len(result))
    for j, name in enumerate(header):
        for i, (row, value) in enumerate(zip(rows, result[name])):
            assert row[j] == printed(value), \
                f"{what}: {name} at t = {row[0]}: fmusim {row[j]}, fmpy {printed(value)}"


class Messages:
    """The FMU's log messages of a status other than OK, through fmpy's logger (FMI 2.0's
    and FMI 3.0's signatures)."""

    def __init__(self):
        self.records = []

    def fmi2(self, env, instance, status, category, message):
        if status:
            self.records.append(message.decode())

    def fmi3(self, env, status, category, message):
        if status:
            self.records.append(message.decode())


def test_coupled_system_in_fmusim_prints_the_fmi2_units_run_in_fmpy(fmusim, paths3, tmp_path):
    from fmpy import simulate_fmu
    fmu3, fmu2 = paths3["CoupledSystem"], os.path.join(wf.FMU_DIR, "CoupledSystem.fmu")
    header, rows = run_fmusim(fmusim, fmu3, tmp_path / "cs.csv", 0.8)
    # fmusim records every output; each is the FMI 2.0 unit's of the same name (one wheelset).
    assert set(header[1:]) == outputs(fmu3), set(header[1:]) ^ outputs(fmu3)
    assert set(header[1:]) <= outputs(fmu2), set(header[1:]) - outputs(fmu2)
    from wheelflat_kit import restore_fmpy_logger
    log = Messages()
    try:
        result = simulate_fmu(fmu2, stop_time=0.8, output_interval=STEP, set_stop_time=False,
                              output=header[1:], logger=log.fmi2)
    finally:
        # fmpy's logger proxy would call the dead callback at the next FMU's message.
        restore_fmpy_logger()
    assert log.records == [], log.records[:3]
    assert_printed_alike(header, rows, result, "CoupledSystem")


def test_track_contact_alone_in_fmusim_gives_fmpys_contact_forces(fmusim, paths3, tmp_path):
    from fmpy import simulate_fmu
    fmu3 = paths3["TrackContact"]
    header, rows = run_fmusim(fmusim, fmu3, tmp_path / "tc.csv", 0.1)
    assert set(header[1:]) == outputs(fmu3)
    log = Messages()
    result = simulate_fmu(fmu3, stop_time=0.1, output_interval=STEP, set_stop_time=False,
                          output=header[1:], logger=log.fmi3)
    assert log.records == [], log.records[:3]
    # The wheels held at their start values: the static wheel load, then the track's answer.
    forces = [header.index("contact.left.force"), header.index("contact.right.force")]
    assert all(float(rows[0][j]) > 1e5 for j in forces), [rows[0][j] for j in forces]
    assert_printed_alike(header, rows, result, "TrackContact")
