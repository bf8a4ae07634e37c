"""The fixtures test files share: ``paths``, the packed FMUs (built first when one is
missing), for the FMU tests (tests/test_fmu_*.py, their helpers in fmu_helpers.py);
``runner``, the case runner, and ``study``, a small study file, for the study tests
(tests/test_study_*.py, their helpers in study_helpers.py). A test file's own fixture
of the same name comes first."""

import os

import pytest


@pytest.fixture(scope="session")
def paths():
    from fmu_helpers import wf
    p = {n: os.path.join(wf.FMU_DIR, n + ".fmu")
         for n in ("TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon")}
    if not all(os.path.exists(x) for x in p.values()):
        p = wf.build_fmus()
    return p


@pytest.fixture(scope="module")
def runner():
    from study_helpers import build_runner
    return build_runner()


@pytest.fixture
def study(tmp_path):
    from study_helpers import STUDY
    p = tmp_path / "small.toml"
    p.write_text(STUDY)
    return p
