"""Issue 40, item 1: every figure README.md, docs/guide and docs/STUDIES.md quote is what
the current build prints (python/wheelflat_figures.py, which regenerates them).

Run by the README's test command after the FMUs are packed; the transcripts of the
pages' console blocks are checked by tests/test_docs.py, which runs their commands.
"""

import os
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import wheelflat_figures as figures  # noqa: E402
import wheelflat_fmus as wf  # noqa: E402


def test_every_committed_figure_is_what_the_build_gives():
    stale = figures.check(log=lambda *a: None, transcripts_too=False)
    assert not stale, "\n".join(stale) + "\nrun python3 python/wheelflat_figures.py and commit the diff"


def test_a_changed_result_is_caught_and_named(monkeypatch):
    # A scratch change of a default: the pair's case at 71 km/h instead of 70.
    run_pair = wf.run_pair

    def faster(paths, stop, *a, **kw):
        return run_pair(paths, stop, track_params={"speed": 71 / 3.6}, vehicle_params={"speed": 71 / 3.6})
    monkeypatch.setattr(wf, "run_pair", faster)
    stale = figures.check(only={"pair"}, log=lambda *a: None)
    readme = [s for s in stale if s.startswith("README.md: pair.left ")]
    assert readme and "reads '301.92 kN'; the current build gives '3" in readme[0], stale


def test_every_figure_names_its_source_and_every_page_quotes_some():
    texts = {p: open(os.path.join(ROOT, p)).read() for p in figures.pages()}
    assert set(figures.figures_wanted(texts)) == set(figures.SOURCES)
    for page in ("README.md", "docs/STUDIES.md", "python/quickstart/test_regression.py"):
        assert figures.markers(texts[page]), page


@pytest.mark.parametrize("committed,current,same", [
    ("301.92 kN", "301.92 kN", True),
    ("301.92 kN", "301.93 kN", True),      # a rounding boundary crossed: one unit in the last digit
    ("301.92 kN", "301.94 kN", False),
    ("301.9 kN", "301.92 kN", False),      # printed with other digits
    ("17 to 24 %", "17 to 25 %", True),
    ("17 to 24 %", "16 to 26 %", False),
    ("| 10 | 109.9 |", "| 10 | 110.1 |", False),
    ("279.0 kN", "279.0 MN", False),       # the words must agree
])
def test_the_stated_rounding(committed, current, same):
    assert figures.same_figure(committed, current) is same


def test_a_transcript_compares_figures_not_times():
    shown = ["peak 301.92 kN", "4 passed in 0.53s", "wall time: build 0.7 s"]
    assert figures.same_transcript(shown, "peak 301.92 kN\n4 passed in 1.20s\nwall time: build 12 s\n") is None
    assert "301.95" in figures.same_transcript(shown, "peak 301.95 kN\n4 passed in 0.5s\nwall time: 1 s\n")
    assert "lines shown" in figures.same_transcript(shown, "peak 301.92 kN\n")
    # cargo's status lines are not part of a transcript
    assert figures.same_transcript(["x"], "   Compiling wheelflat v0.1.0\n    Finished `release`\nx\n") is None
