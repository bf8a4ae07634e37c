"""Statistical studies over random tracks (issue 44): a seed swept as any Integer
parameter (one case per seed, stable ids), an enumeration swept by its items' names,
the ``[summary]`` of a case group's distribution held to numpy computed here from the
per-case results the study wrote, its refusals before anything runs, the distribution
plot, and studies/track_class_flat.toml (``rail.spectrum`` and its seed). In the
small studies an existing parameter stands in for the seed (a flat's angle, a void's
sleeper count). The helpers are in study_helpers.py, the ``runner`` fixture in
conftest.py."""

import hashlib
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from study_helpers import ROOT, load_study

ENV = dict(os.environ, PYTHONPATH=os.path.join(ROOT, "python"))


def command(args, timeout=120):
    return subprocess.run([sys.executable, "-m", "wheelflat_study"] + [str(a) for a in args], env=ENV,
                          capture_output=True, text=True, timeout=timeout)


# Two speeds (the groups), each over seven angles of the flat (the stand-in for a
# track's seed) and two shapes by name (the chord's cases refused by the engine: the
# haversine's 1.5 mm is not a 100 mm chord's depth), so each group has 14 cases of
# which 7 finish.
SMALL = """
name = "dist"
duration = 0.1
keep = ["primary.left.force"]

[fixed]
"track.window.ahead" = 8.0
"track.window.behind" = 8.0
"flat.left[1].depth" = 0.0015

[sweep]
speed = { values = [60, 100], unit = "km/h" }
"flat.left[1].angle" = { range = [0, 90, 15], unit = "deg" }
"flat.left[1].shape" = ["haversine", "chord"]

[summary]
over = ["flat.left[1].angle", "flat.left[1].shape"]
of = ["peak.left", "peak.right", "primary.left.force.max"]
percentile = 90

[[plot]]
kind = "distribution"
y = "peak.left"
by = "speed"
scale = 0.001
label = "peak contact force, left wheel (kN)"
name = "dist_peaks"
"""


def linear_percentile(x, q):
    """numpy's default percentile written out: the sorted values at the position
    (n - 1) q / 100, interpolated linearly between the two nearest."""
    x = np.sort(np.asarray(x, dtype=float))
    at = (len(x) - 1) * q / 100
    lo = int(np.floor(at))
    hi = min(lo + 1, len(x) - 1)
    return x[lo] + (at - lo) * (x[hi] - x[lo])


def test_the_summary_is_numpys_over_each_groups_finished_cases_and_the_plot_is_drawn(tmp_path, runner):
    import pandas as pd
    from wheelflat_study.tables import result_columns
    p = tmp_path / "dist.toml"
    p.write_text(SMALL)
    out = tmp_path / "o"
    r = command([p, "--serial", "--out", out, "--runner", runner, "--no-progress"])
    # The chord's cases fail (a case failed: exit status 1), the study goes on.
    assert r.returncode == 1 and "(28 of 28 cases, 14 failed)" in r.stdout, (r.stdout, r.stderr)
    results = pd.read_parquet(out / "results.parquet")
    assert list(results.loc[results["status"] == "error", "flat.left[1].shape"].unique()) == [2.0]
    # Every result column a [summary] may name, and only those, is in the table.
    params = {"speed", "flat.left[1].angle", "flat.left[1].shape", "track.window.ahead", "track.window.behind",
              "flat.left[1].depth"}
    meta = {"case_id", "duration", "status", "error", "warnings", "version", "guid", "engine", "runner_wall_s",
            "wall_s"}
    assert set(results.columns) - params - meta == set(result_columns(["primary.left.force"], 1))

    summary = pd.read_csv(out / "summary.csv", float_precision="round_trip")
    assert list(summary.columns) == ["speed [m/s]", "result", "unit", "cases", "count", "mean", "std", "p90",
                                     "min", "max"]
    # One row per group (the study's order: 60 then 100 km/h) and result (of's order).
    speeds = load_study(p).sweep["speed"]
    assert speeds == pytest.approx([60 / 3.6, 100 / 3.6])
    of = ["peak.left", "peak.right", "primary.left.force.max"]
    assert list(summary["speed [m/s]"]) == [s for s in speeds for _ in of]
    assert list(summary["result"]) == of * 2 and set(summary["unit"]) == {"N"}
    for speed in speeds:
        group = results[results["speed"] == speed]
        ok = group[group["status"] == "ok"]
        assert len(group) == 14 and len(ok) == 7
        for name in of:
            x = ok[name].to_numpy()
            row = summary[(summary["speed [m/s]"] == speed) & (summary["result"] == name)].iloc[0]
            assert row["cases"] == 14 and row["count"] == 7
            # CSV at 17 digits: numpy's numbers, to the last bit.
            assert row["mean"] == np.mean(x)
            assert row["std"] == np.std(x, ddof=1)
            assert row["p90"] == np.percentile(x, 90)
            assert row["min"] == x.min() and row["max"] == x.max()
            # The definition stated (linear interpolation), and a spread to summarise.
            assert row["p90"] == pytest.approx(linear_percentile(x, 90), rel=1e-14)
            assert row["std"] > 0 and row["min"] < row["p90"] <= row["max"]
            assert row["std"] == pytest.approx(np.sqrt(((x - x.mean()) ** 2).sum() / (len(x) - 1)), rel=1e-12)
    # The 100 km/h impacts are the harder: the groups are the speeds, not mixed.
    assert summary["mean"][3] > 1.1 * summary["mean"][0]

    # Printed at the end of the run: the groups in km/h, the statistics, the definitions.
    text = r.stdout
    assert "summary over flat.left[1].angle, flat.left[1].shape (the 90th percentile by numpy's linear " \
           "interpolation, std with ddof = 1" in text, text
    lines = text[text.index("speed [km/h]"):].split("\n")
    assert lines[0].split() == ["speed", "[km/h]", "result", "count", "mean", "std", "p90", "min", "max"]
    first = lines[1].split()
    assert first[:5] == ["60", "peak.left", "[N]", "7", "of"] and first[5] == "14"
    assert float(first[6]) == pytest.approx(summary["mean"][0], rel=1e-5)

    # The distribution plot, as the other plots: PNG and PDF in the results folder.
    for ext, magic in (("png", b"\x89PNG"), ("pdf", b"%PDF")):
        f = out / f"dist_peaks.{ext}"
        assert f.read_bytes()[:4] == magic and f.stat().st_size > 5000
        assert f"wrote {f}" in text


def test_a_summary_over_every_swept_variable_is_one_group_and_a_study_started_again_gives_it_again(tmp_path,
                                                                                                    runner):
    import pandas as pd
    from wheelflat_study import run_study
    p = tmp_path / "one.toml"
    p.write_text('name = "one"\nduration = 0.06\n[fixed]\n"track.window.ahead" = 8.0\n[sweep]\n'
                 '"flat.left[1].angle" = { range = [5, 45, 10], unit = "deg" }\n'
                 '[summary]\nover = ["flat.left[1].angle"]\nof = ["peak.left"]\n'
                 '[[plot]]\nkind = "distribution"\ny = "peak.left"\nname = "all"\n')
    s = load_study(p)
    assert s.summary.percentile == 95
    said = []
    table, n = run_study(s, str(tmp_path / "o"), serial=True, runner_path=runner, progress=False,
                         log=said.append)
    assert n == 5
    summary = pd.read_csv(tmp_path / "o" / "summary.csv", float_precision="round_trip")
    assert list(summary.columns) == ["result", "unit", "cases", "count", "mean", "std", "p95", "min", "max"]
    x = table["peak.left"].to_numpy()
    assert summary["count"][0] == 5 and summary["p95"][0] == np.percentile(x, 95)
    # Without `by`, one box of all the cases.
    assert (tmp_path / "o" / "all.png").read_bytes()[:4] == b"\x89PNG"
    before = (tmp_path / "o" / "summary.csv").read_bytes()
    run_study(load_study(p), str(tmp_path / "o"), serial=True, runner_path=runner, progress=False,
              log=said.append)
    assert (tmp_path / "o" / "summary.csv").read_bytes() == before


def case_id(params, duration, keep=()):
    """A case's id as Case.id documents it, computed here."""
    text = json.dumps([sorted((k, repr(float(v))) for k, v in params.items()), repr(float(duration)), list(keep)])
    return hashlib.sha1(text.encode()).hexdigest()[:16]


def test_a_seed_swept_as_an_integer_range_makes_one_case_per_seed_with_stable_ids(tmp_path, runner):
    # track.void.sleepers (Integer, 0 to 100) stands in for rail.spectrum.seed.
    p = tmp_path / "seeds.toml"
    p.write_text('name = "seeds"\nduration = 0.05\n[sweep]\n"track.void.sleepers" = { range = [1, 50, 1] }\n'
                 'speed = [10.0, 20.0]\n[summary]\nover = ["track.void.sleepers"]\nof = ["peak.left"]\n')
    r = command([p, "--dry-run", "--runner", runner])
    assert r.returncode == 0, r.stderr
    lines = r.stdout.strip().split("\n")
    rows = [ln.split("\t") for ln in lines[1:-1]]
    assert lines[0] == "id\ttrack.void.sleepers\tspeed" and lines[-1].startswith("100 cases of 0.05 s")
    expected = [(str(k), f"{v:g}", case_id({"track.void.sleepers": k, "speed": v}, 0.05))
                for k in range(1, 51) for v in (10.0, 20.0)]
    assert [(row[1], row[2], row[0]) for row in rows] == expected
    # The same seeds as a list of whole numbers: the same cases, the same ids.
    p.write_text(p.read_text().replace("{ range = [1, 50, 1] }", str(list(range(1, 51)))))
    r2 = command([p, "--dry-run", "--runner", runner])
    assert r2.returncode == 0 and r2.stdout == r.stdout, r2.stderr
    # A seed that is not a whole number is refused.
    p.write_text(p.read_text().replace("[1, 2, 3,", "[1, 2.5, 3,"))
    r3 = command([p, "--dry-run", "--runner", runner])
    assert r3.returncode == 2 and "`track.void.sleepers` = 2.5: a whole number is needed" in r3.stderr, r3.stderr


def test_an_enumeration_is_swept_by_its_items_names_as_by_their_numbers(tmp_path, runner):
    p = tmp_path / "enum.toml"
    body = ('name = "enum"\nduration = 0.05\n[fixed]\n"vehicle.model" = {fixed}\n[sweep]\n'
            '"contact.model" = {{ values = {values} }}\n"flat.left[1].shape" = {shapes}\n')
    p.write_text(body.format(fixed='"roll_plane"', values='["adaptive", "hertz"]', shapes='["chord", "haversine"]'))
    by_name = command([p, "--dry-run", "--runner", runner])
    assert by_name.returncode == 0, by_name.stderr
    rows = [ln.split("\t") for ln in by_name.stdout.strip().split("\n")[1:-1]]
    assert [row[1:] for row in rows] == [["adaptive", "chord"], ["adaptive", "haversine"], ["hertz", "chord"],
                                         ["hertz", "haversine"]]
    assert "fixed: vehicle.model = roll_plane" in by_name.stdout
    p.write_text(body.format(fixed="1", values="[1, 2]", shapes="[2, 1]"))
    by_number = command([p, "--dry-run", "--runner", runner])
    assert by_number.returncode == 0 and by_number.stdout == by_name.stdout, by_number.stderr
    # An item that is not one, and an item given twice (by name and by number).
    p.write_text(body.format(fixed="1", values='["adaptive", "hertzian"]', shapes="[1]"))
    r = command([p, "--dry-run", "--runner", runner])
    assert r.returncode == 2 and "`contact.model` = 'hertzian' is not one of its items; allowed: one of 1 = " \
        "adaptive, 2 = hertz (an enumeration: its item's name, in quotes, or its number)" in r.stderr, r.stderr
    p.write_text(body.format(fixed="1", values='["hertz", 2]', shapes="[1]"))
    r = command([p, "--dry-run", "--runner", runner])
    assert r.returncode == 2 and "the same case twice" in r.stderr, r.stderr


HEAD = 'name = "s"\nduration = 0.1\nkeep = ["primary.left.force"]\n[fixed]\n"wheel.radius" = 0.46\n[sweep]\n' \
       'speed = [10.0, 20.0]\n"flat.left[1].angle" = [0.1, 0.2]\n'
SUMMARY = '[summary]\nover = ["flat.left[1].angle"]\nof = ["peak.left"]\n'


@pytest.mark.parametrize("tail, said", [
    ('[summary]\nover = ["wheel.radius"]\nof = ["peak.left"]\n',
     "[summary] over: 'wheel.radius' is fixed, not swept; allowed: the swept variables ([sweep]): speed, "
     "flat.left[1].angle"),
    ('[summary]\nover = ["rail.spectrum.seed"]\nof = ["peak.left"]\n',
     "[summary] over: 'rail.spectrum.seed' is not swept; allowed: the swept variables"),
    ('[summary]\nover = "flat.left[1].angle"\nof = ["peak.left"]\n',
     "[summary] over = 'flat.left[1].angle': a list of swept variables' names"),
    ('[summary]\nover = []\nof = ["peak.left"]\n', "[summary] over = []: a list of swept variables' names"),
    ('[summary]\nover = ["speed", "speed"]\nof = ["peak.left"]\n', "a variable named twice"),
    ('[summary]\nover = ["speed"]\n', "[summary]: `of` is missing"),
    ('[summary]\nof = ["peak.left"]\n', "[summary]: `over` is missing"),
    ('[summary]\nover = ["speed"]\nof = ["peak.left"]\nseed = 3\n',
     "[summary]: unknown keys ['seed']; allowed: ['of', 'over', 'percentile']"),
    ('[summary]\nover = ["speed"]\nof = ["peak.lft"]\n',
     "[summary] of: 'peak.lft' is not a result of the study's cases; allowed: peak.left, peak.right, "
     "peak.max, impacts.left"),
    ('[summary]\nover = ["speed"]\nof = ["speed"]\n', "(a parameter the study sets, not a result)"),
    ('[summary]\nover = ["speed"]\nof = ["rail.left.z.max"]\n',
     "(an output's extremes need it kept: keep = [\"rail.left.z\"])"),
    ('[summary]\nover = ["speed"]\nof = ["peak.wheelset[2].left"]\n', "(set wheelsets = 2 or more for it)"),
    ('[summary]\nover = ["speed"]\nof = []\n', "[summary] of = []: a list of results"),
    ('[summary]\nover = ["speed"]\nof = ["peak.left", "peak.left"]\n', "a result named twice"),
    (SUMMARY + 'percentile = 101\n', "[summary] percentile = 101: allowed a number from 0 to 100"),
    (SUMMARY + 'percentile = -0.5\n', "[summary] percentile = -0.5: allowed a number from 0 to 100"),
    (SUMMARY + 'percentile = nan\n', "[summary] percentile = nan: allowed a number from 0 to 100"),
    (SUMMARY + 'percentile = "95"\n', "[summary] percentile = '95': allowed a number from 0 to 100"),
    (SUMMARY + 'percentile = true\n', "[summary] percentile = True: allowed a number from 0 to 100"),
    ('summary = 5\n', "summary = 5: a table, [summary] with over, of and percentile"),
    ('[[plot]]\nkind = "distribution"\ny = "peak.left"\n', "plot 1 (distribution): needs a [summary]"),
    (SUMMARY + '[[plot]]\nkind = "distribution"\n', "plot 1 (distribution): needs ['y']"),
    (SUMMARY + '[[plot]]\nkind = "distribution"\ny = "peak.leftt"\n',
     "plot 1 (distribution): y = 'peak.leftt' is not a result of the study's cases"),
    (SUMMARY + '[[plot]]\nkind = "distribution"\ny = "peak.left"\nby = "flat.left[1].angle"\n',
     "plot 1 (distribution): by = 'flat.left[1].angle' is in the [summary]'s over (its values make one box); "
     "allowed: a swept variable outside the [summary]'s over: speed"),
    (SUMMARY + '[[plot]]\nkind = "distribution"\ny = "peak.left"\nby = "wheel.radius"\n',
     "by = 'wheel.radius' is not swept"),
    (SUMMARY + '[[plot]]\nkind = "distribution"\ny = "peak.left"\nx = "speed"\n',
     "plot 1 (distribution): ['x'] not allowed"),
])
def test_a_bad_summary_or_distribution_plot_is_refused_when_the_study_is_loaded(tmp_path, tail, said):
    p = tmp_path / "s.toml"
    # A top-level key goes before the tables.
    p.write_text(tail + HEAD if tail.startswith("summary =") else HEAD + tail)
    with pytest.raises(ValueError) as e:
        load_study(p)
    assert said in str(e.value)


def test_a_by_that_leaves_a_swept_variable_to_mix_in_a_box_is_refused_and_nothing_runs(tmp_path, runner):
    p = tmp_path / "s.toml"
    p.write_text(HEAD + '"flat.left[1].length" = [0.05, 0.1]\n' + SUMMARY
                 + '[[plot]]\nkind = "distribution"\ny = "peak.left"\nby = "speed"\n')
    out = tmp_path / "o"
    r = command([p, "--serial", "--out", out, "--runner", runner, "--no-progress"], timeout=60)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "plot 1 (distribution): by = 'speed', but the swept flat.left[1].length is neither by nor in the " \
           "[summary]'s over: each box would mix its values" in r.stderr, r.stderr
    assert not (out / "cases.jsonl").exists()


def test_the_track_class_study_makes_a_case_per_class_and_seed_and_summarises_each_class(tmp_path, runner):
    path = os.path.join(ROOT, "studies", "track_class_flat.toml")
    s = load_study(path)
    assert s.count() == 100 and list(s.sweep) == ["rail.spectrum", "rail.spectrum.seed"]
    assert s.sweep["rail.spectrum.seed"] == [float(k) for k in range(1, 51)]
    assert s.summary.over == ("rail.spectrum.seed",) and s.summary.percentile == 95
    assert [p["kind"] for p in s.plots] == ["distribution"] and s.plots[0]["by"] == "rail.spectrum"
    # The reference flat (the FMUs' defaults, 100 x 1.5 mm at 90 deg) at 70 km/h, over
    # two of its impacts (the second at 0.19 s), on the converged endless track.
    assert s.fixed["speed"] == pytest.approx(70 / 3.6) and s.duration >= 0.25
    # The track classes by name, the seeds as numbers: one case per class and seed.
    r = command([path, "--dry-run", "--runner", runner])
    assert r.returncode == 0, r.stderr
    rows = [ln.split("\t") for ln in r.stdout.strip().split("\n")[1:-1]]
    assert len(rows) == 100 and len({row[0] for row in rows}) == 100
    assert [row[1:] for row in rows] == [[c, str(k)] for c in ("fra_class_4", "fra_class_6") for k in range(1, 51)]
    # The study itself, cut to three seeds over the first impact: each class a group of
    # three cases whose peaks the seeds spread.
    import pandas as pd
    small = tmp_path / "tc.toml"
    text = open(path).read()
    small.write_text(text.replace("range = [1, 50, 1]", "range = [1, 3, 1]").replace("duration = 0.3",
                                                                                     "duration = 0.06"))
    r = command([small, "--serial", "--out", tmp_path / "o", "--runner", runner, "--no-progress"])
    assert r.returncode == 0, r.stderr
    summary = pd.read_csv(tmp_path / "o" / "summary.csv", float_precision="round_trip")
    assert list(summary["rail.spectrum"]) == ["fra_class_4"] * 3 + ["fra_class_6"] * 3
    assert list(summary["count"]) == [3] * 6 and (summary["std"] > 0).all()
    results = pd.read_parquet(tmp_path / "o" / "results.parquet")
    x = results.loc[results["rail.spectrum"] == results["rail.spectrum"].min(), "peak.left"].to_numpy()
    assert summary["p95"][0] == np.percentile(x, 95) and summary["std"][0] == np.std(x, ddof=1)
    assert (tmp_path / "o" / "track_class_flat_peaks.png").exists()


def test_a_group_of_one_case_has_no_standard_deviation_and_prints_it_blank(tmp_path):
    # One value: its mean, percentile, least and largest are itself; a sample standard
    # deviation needs two (NaN in the rows, blank in the CSV and the printed table).
    from wheelflat_study.summary import format_summary, group_names, percentile_column, statistics
    st = statistics([301.5e3, float("nan")], 90)
    assert st["count"] == 1 and np.isnan(st["std"])
    assert st["mean"] == st["percentile"] == st["min"] == st["max"] == 301.5e3
    path = tmp_path / "dist.toml"
    path.write_text(SMALL)
    study = load_study(str(path))
    row = {n: 100 / 3.6 for n in group_names(study)}
    row.update({"result": "peak.left", "cases": 2, "count": 1, "mean": st["mean"], "std": st["std"],
                percentile_column(study): st["percentile"], "min": st["min"], "max": st["max"]})
    text = format_summary(study, [row])
    assert "nan" not in text and "1 of 2" in text and "301500" in text, text
