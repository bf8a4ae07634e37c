"""Quick start (d): a regression test of the FMUs in pytest over fmpy.simulate_fmu.

    .venv/bin/python -m pytest -q python/quickstart/test_regression.py

Each case runs CoupledSystem (the whole model in one FMU) for 0.3 s, two impacts of the
flat on the left wheel, and asserts the peak contact force of each wheel against the
reference of this build (REFERENCE, in N). Assert TrackContact's running maxima
`contact.*.max_force` at the stop time, never the largest sample of `contact.*.force`:
an output interval coarser than the track's step misses the impact's top
(test_the_sampled_force_under_reads_the_peak shows by how much).
"""
import os

import pytest
from fmpy import simulate_fmu

# fmu/ of this repository (python3 python/couple.py builds it), wherever pytest runs.
FMU = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                   "fmu", "CoupledSystem.fmu")
STOP = 0.3
# A build's results agree with these to rounding; 0.1 % leaves room for another
# machine's vector width and catches any change of the model (one grid step more
# moves the peak by more).
RTOL = 1e-3
# (speed km/h, flat length mm, flat depth mm) -> (left, right) peak contact force (N)
REFERENCE = {
    # <!--generated regression.references-->
    (50, 100, 1.5): (255.8e3, 134.7e3),
    (70, 100, 1.5): (301.9e3, 141.3e3),
    (100, 100, 1.5): (343.0e3, 139.6e3),
    # <!--/generated-->
}
PEAKS = ["contact.left.max_force", "contact.right.max_force"]


def run(speed, length, depth, **options):
    assert os.path.exists(FMU), f"no {FMU}: build the FMUs first (python3 python/couple.py)"
    start = {"speed": speed / 3.6, "flat.left[1].length": length / 1e3, "flat.left[1].depth": depth / 1e3}
    return simulate_fmu(FMU, stop_time=STOP, start_values=start, output=PEAKS + ["contact.left.force"], **options)


@pytest.mark.parametrize("case", sorted(REFERENCE), ids=lambda c: "{} km/h, {} x {} mm".format(*c))
def test_peak_contact_forces(case):
    r = run(*case)
    got = (r["contact.left.max_force"][-1], r["contact.right.max_force"][-1])
    assert got == pytest.approx(REFERENCE[case], rel=RTOL)


def test_the_sampled_force_under_reads_the_peak():
    # fmpy's default output interval (here CoupledSystem's default step, 0.4 ms) samples
    # the force 28 times more coarsely than the track steps: the impact's top, which
    # lasts about a millisecond, falls between samples.
    r = run(100, 100, 1.5)
    sampled, peak = max(r["contact.left.force"]), r["contact.left.max_force"][-1]
    assert sampled < 0.95 * peak
