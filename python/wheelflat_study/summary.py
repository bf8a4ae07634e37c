"""A study's distribution summary (its ``[summary]``): the cases that differ only in the
swept variables ``over`` (a random track's seed, say; every other swept variable
equal) form one case group, and for each group and each result of ``of`` the summary
gives, over the group's cases that finished with a value of that result:

* ``count``: how many (``cases``: the group's cases in the results table, failed
  ones too; a failed case, or one without the result, is left out of the rest);
* ``mean``; ``std``, the sample standard deviation (numpy's ``std`` with ddof = 1;
  NaN for fewer than two values);
* ``pQ`` (``p95`` for percentile = 95): the Q-th percentile by numpy's default,
  linear interpolation (``numpy.percentile(x, Q)``, method "linear": the sorted
  values x[0] .. x[n-1] at the positions (n - 1) Q / 100, interpolated between the
  two nearest);
* ``min``, ``max``.

Written to ``summary.csv`` beside the study's tables (one row per group and result, in
the study's order; each group's swept variables by value, an enumeration by its item's
name; the result's unit in ``unit``) and printed as a table at the end of a run.
"""

import math
import os

import numpy as np

from .tables import _atomic, unit_of


def group_names(study):
    """The swept variables that tell the case groups apart: those outside `over`."""
    return [n for n in study.sweep if n not in study.summary.over]


def groups(study, table):
    """The case groups of `table` (rows of the results table), in the study's order:
    a list of (the group's values of :func:`group_names`, its rows). A table
    parameter's cases group by its content's hash too."""
    names = group_names(study)
    if table.empty:
        return []
    cols = []
    for n in names:
        cols.append(n)
        if n + ".sha256" in table.columns:
            cols.append(n + ".sha256")
    if not cols:
        return [({}, table)]
    out = []
    for key, rows in table.groupby(cols, sort=False, dropna=False):
        key = key if isinstance(key, tuple) else (key,)
        values = dict(zip(cols, key))
        out.append(({n: values[n] for n in names}, rows))
    return out


def statistics(values, percentile):
    """count, mean, std (ddof = 1), the percentile (numpy's linear interpolation), min
    and max of the finite numbers among `values` (a dict; NaN where there are too
    few: none, or one for std)."""
    x = np.asarray(values, dtype=float)
    x = x[np.isfinite(x)]
    n = len(x)
    nan = float("nan")
    return {"count": n,
            "mean": float(np.mean(x)) if n else nan,
            "std": float(np.std(x, ddof=1)) if n > 1 else nan,
            "percentile": float(np.percentile(x, percentile)) if n else nan,
            "min": float(np.min(x)) if n else nan,
            "max": float(np.max(x)) if n else nan}


def percentile_column(study):
    """The percentile's column: ``p95`` (``p97.5``, ...)."""
    # + 0.0: -0 reads as 0.
    return f"p{study.summary.percentile + 0.0:g}"


def summarise(study, table):
    """The summary's rows (dicts), one per case group and result, in the study's order
    and `of`'s: the group's swept variables (SI values, a table by its name), then
    ``result``, ``cases``, ``count``, ``mean``, ``std``, ``pQ``, ``min``, ``max``."""
    s = study.summary
    pcol = percentile_column(study)
    rows = []
    for key, g in groups(study, table):
        ok = g[g["status"] == "ok"] if "status" in g else g
        for result in s.of:
            values = ok[result] if result in ok.columns else []
            st = statistics(values, s.percentile)
            row = dict(key)
            row.update({"result": result, "cases": len(g), "count": st["count"], "mean": st["mean"],
                        "std": st["std"], pcol: st["percentile"], "min": st["min"], "max": st["max"]})
            rows.append(row)
    return rows


def write_summary(study, table, out_dir, units=None):
    """Writes ``summary.csv`` into `out_dir` (whole or not at all) from the results
    table `table`; returns (its path, the rows). `units`: every variable's unit by
    name (the runner's list), for the header (``speed [m/s]``) and the results' unit
    column."""
    import pandas as pd
    rows = summarise(study, table)
    names = group_names(study)
    declared = units or {}
    pcol = percentile_column(study)
    out = []
    for r in rows:
        row = {n: _value(study, n, r[n]) for n in names}
        row.update({"result": r["result"], "unit": unit_of(r["result"], declared) or "", "cases": r["cases"],
                    "count": r["count"]})
        row.update({k: r[k] for k in ("mean", "std", pcol, "min", "max")})
        out.append(row)
    columns = names + ["result", "unit", "cases", "count", "mean", "std", pcol, "min", "max"]
    header = []
    for n in columns:
        u = unit_of(n, declared) if n in names and n not in study.items else ""
        header.append(f"{n} [{u}]" if u else n)
    df = pd.DataFrame(out, columns=columns)
    path = os.path.join(out_dir, "summary.csv")
    _atomic(path, lambda tmp: df.to_csv(tmp, index=False, header=header, float_format="%.17g"))
    return path, rows


def _value(study, name, v):
    """A group's value of `name` in summary.csv: an enumeration's item by name, else
    as the results table has it (SI, a table by its name)."""
    items = study.items.get(name)
    if items and not isinstance(v, str) and float(v) in items:
        return items[float(v)]
    return v


def format_summary(study, rows, units=None):
    """The summary as a table to print: the groups' values in their display units (an
    enumeration by its item), the statistics to 6 digits, in each result's unit."""
    declared = units or {}
    names = group_names(study)
    pcol = percentile_column(study)
    head = [f"{n} [{study.display[n][0]}]" if n in study.display else n for n in names]
    head += ["result", "count", "mean", "std", pcol, "min", "max"]
    lines = [head]
    for r in rows:
        unit = unit_of(r["result"], declared) or ""
        line = [study.shown(n, r[n]) for n in names]
        line += [f"{r['result']} [{unit}]" if unit else r["result"],
                 f"{r['count']}" + (f" of {r['cases']}" if r["cases"] != r["count"] else "")]
        # A statistic there are too few values for (std of one) is blank, as in the CSV.
        line += ["" if math.isnan(r[k]) else f"{r[k]:.6g}" for k in ("mean", "std", pcol, "min", "max")]
        lines.append(line)
    widths = [max(len(str(line[i])) for line in lines) for i in range(len(head))]
    return "\n".join("  ".join(str(c).ljust(w) if i < len(names) + 1 else str(c).rjust(w)
                               for i, (c, w) in enumerate(zip(line, widths))).rstrip() for line in lines)
