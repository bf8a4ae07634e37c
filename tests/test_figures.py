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


@pytest.mark.parametrize("text,said", [
    ("a <!--fig pair.static-->107.66 kN and more", "is never closed"),
    ("a <!--fig pair.static-->107.66 kN<!--/generated--> b", "it takes <!--/fig-->"),
    ("<!--fig pair.static-->1 <!--fig pair.left-->2<!--/fig--> 3<!--/fig-->", "inside <!--fig pair.static-->"),
    ("x<!--/fig--> y", "closes no marker"),
    ("<!--fig pair.static -->107.66 kN<!--/fig-->", "is no marker"),
    ("<!--fig-->107.66 kN<!--/fig-->", "names no figure"),
])
def test_a_bad_marker_is_refused_with_its_line(text, said):
    # The breaker's findings: an unclosed, mismatched or nested marker made write mode
    # swallow prose and exit 0.
    with pytest.raises(figures.MarkerError) as e:
        figures.markers("first line\n" + text, "page.md")
    assert str(e.value).startswith("page.md:2: ") and said in str(e.value), str(e.value)


def test_rewrite_replaces_only_the_markers_content():
    text = "a <!--fig pair.left-->1 kN<!--/fig--> b\n<!--generated t-->\n| x |\n<!--/generated--> c"
    new = figures.rewrite(text, {"pair.left": "2 kN", "t": "\n| y |\n"}, "p")
    assert new == "a <!--fig pair.left-->2 kN<!--/fig--> b\n<!--generated t-->\n| y |\n<!--/generated--> c"


@pytest.mark.parametrize("committed,current,same", [
    ("255.8e3", "255.8e4", False),         # the exponent must agree
    ("1.5e-5", "1.6e-5", True),
    ("302.00 kN", "302 kN", False),        # the digits printed must agree, both ways
    ("302 kN", "302.00 kN", False),
])
def test_the_stated_rounding_of_exponents_and_digits(committed, current, same):
    assert figures.same_figure(committed, current) is same


def test_a_command_that_prints_nothing_shows_nothing_and_a_blank_line_is_named():
    assert figures.printed("") == [] and figures.same_transcript([], "") is None
    assert "reads" in figures.differs("\n| a |\n\n", "\n| a |\n")
    with pytest.raises(figures.MarkerError):
        figures.transcripts("```console\n$ true\n")
