"""The engine's discrete track against an independent NumPy implementation of the same
scheme (python/numpy_track.py, written from docs/MODEL.md and the thesis: the rail
stencil, pads and sleepers, fixed ends, the static start as the step's fixed point),
the thesis' table 4.1 case (two 100 kN loads at 50 km/h on 20 spans, n = 8).

Run by the README's test command (after the engine is built)."""

import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import numpy_track  # noqa: E402


def test_the_engine_track_is_the_numpy_track_to_the_csv_rounding():
    # The left rail's deflection under the load every 50 steps over 0.1 s (7,000
    # steps) agrees within half a unit of the CSV's seventh digit (measured: 0.84 of
    # it), from the static start (0.6117 mm) through the load's passage over seven
    # sleepers.
    worst, static = numpy_track.check(0.1, 50)
    assert abs(static + 6.1167e-4) < 1e-7, static
    assert worst <= 1.0, worst


def test_the_static_starts_agree_and_scale_with_the_load():
    # The NumPy static start (the fixed point of its own step) under 1 % more load sits
    # 1 % below the engine's banded static solve, to 1e-6: the two static states agree,
    # and a reference with another load would be told apart at once.
    rows = numpy_track.engine_run(0.02, 50)
    t = numpy_track.Track(spans=20, n=8)
    t.set_static(0.685, (101e3, 101e3))
    assert abs(t.rail_under(0.685)[0] / float(rows[0]["rail_z_left_m"]) - 1.01) < 1e-6
