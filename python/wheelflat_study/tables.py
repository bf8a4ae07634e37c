"""The study's tables: one row per case (``results``) and one per impact (``impacts``),
as Parquet (with the software version and FMU GUID in the file's metadata too) and
CSV, in the order of the study's cases."""

import json
import os

from .done import load_done
from .spec import Table

# Columns that describe how a case ran, not what it gave: left out of comparisons.
TIMING = ("wall_s", "runner_wall_s")


def _flatten(res):
    row = {}
    for wheel, p in (res.get("peak") or {}).items():
        row[f"peak.{wheel}"] = p
    lead = [row[k] for k in ("peak.left", "peak.right") if row.get(k) is not None]
    row["peak.max"] = max(lead) if lead else None
    for wheel in ("left", "right"):
        own = [m for m in res.get("impacts") or [] if m["wheel"] == wheel]
        row[f"impacts.{wheel}"] = len(own)
        row[f"impact_peak.{wheel}"] = max((m["peak"] for m in own), default=None)
        row[f"first_impact_peak.{wheel}"] = own[0]["peak"] if own else None
        row[f"first_impact_span_position.{wheel}"] = own[0]["span_position"] if own else None
    for side, r in (res.get("bearing") or {}).items():
        row[f"bearing.{side}.max"] = r["max"]
        row[f"bearing.{side}.min"] = r["min"]
    for side, x in (res.get("contact_loss") or {}).items():
        row[f"contact_loss.{side}"] = x
    for name, r in (res.get("extremes") or {}).items():
        row[f"{name}.max"] = r["max"]
        row[f"{name}.min"] = r["min"]
    return row


def result_columns(keep=(), wheelsets=1):
    """The results table's columns that a case's answer gives (:func:`_flatten`'s, in
    its order) for a study that keeps the outputs `keep` on at most `wheelsets`
    wheelsets: what a [summary]'s `of` and a distribution plot's `y` may name
    (tests/test_study_summary.py holds this list to a run's table)."""
    cols = ["peak.left", "peak.right"]
    for k in range(2, int(wheelsets) + 1):
        cols += [f"peak.wheelset[{k}].left", f"peak.wheelset[{k}].right"]
    cols.append("peak.max")
    for wheel in ("left", "right"):
        cols += [f"impacts.{wheel}", f"impact_peak.{wheel}", f"first_impact_peak.{wheel}",
                 f"first_impact_span_position.{wheel}"]
    for side in ("left", "right"):
        cols += [f"bearing.{side}.max", f"bearing.{side}.min"]
    cols += ["contact_loss.left", "contact_loss.right"]
    for name in keep:
        cols += [f"{name}.max", f"{name}.min"]
    return cols


# The unit of each column the case runner's result gives (src/bin/wheelflat_case.rs
# documents its fields), by the column's name with the wheel or side left out; a
# parameter's and a kept output's unit is the variable table's, as the runner lists it
# (`wheelflat_case --variables`, run.runner_units). Counts, fractions and text have none.
RESULT_UNITS = {"peak": "N", "impact_peak": "N", "first_impact_peak": "N", "bearing": "N", "contact_loss": "s",
                "duration": "s", "runner_wall_s": "s", "wall_s": "s", "time": "s", "passage": "s"}
NO_UNIT = {"impacts", "first_impact_span_position", "span_position", "k"}


def unit_of(name, declared):
    """The unit of a table's column `name` ("" for none): a parameter's or a kept
    output's (``NAME.max``, ``NAME.min``) as `declared` (name -> unit) says, else the
    runner's field's; None for a column no list knows (tests/test_study_cases.py holds
    every column of a study to a known unit)."""
    if name in TEXT or name.endswith(".sha256"):
        return ""
    base = name[:-4] if name.endswith((".max", ".min")) and name[:-4] in declared else name
    if base in declared:
        return declared[base]
    head = name.split(".")[0]
    if head in RESULT_UNITS:
        return RESULT_UNITS[head]
    return "" if head in NO_UNIT else None


def csv_header(names, declared):
    """The CSV header: each column with its unit, ``peak.left [N]`` (Parquet keeps the names)."""
    out = []
    for n in names:
        u = unit_of(n, declared)
        out.append(f"{n} [{u}]" if u else n)
    return out


# Columns that hold text; every other column is a float64 (an impact's `k` an int64).
TEXT = ("case_id", "status", "error", "warnings", "version", "guid", "engine", "wheel")
# Rows a batch of the tables holds: the tables are written a batch at a time, so the
# memory they take does not grow with the study.
BATCH = 20_000


def _params(case):
    """A case's parameters as columns: a table by its name (its file's path, or the table
    written out; "" for none) and, in the column beside it, `NAME.sha256`, the hash of
    the content the case ran with ("" for none)."""
    row = {}
    for k, v in case.params.items():
        if isinstance(v, Table):
            row[k] = v.name
            row[k + ".sha256"] = v.sha256
        else:
            row[k] = v
    return row


def _rows(case, rec):
    """The results row and the impacts rows of `case` from its record `rec`."""
    res = rec["result"]
    row = {"case_id": case.id}
    params = _params(case)
    row.update(params)
    row["duration"] = case.duration
    row["status"] = "error" if res.get("error") else "ok"
    row["error"] = res.get("error") or ""
    # The FMU's warnings (the case ran, but read them: near a fixed rail end, say);
    # a column to filter on.
    row["warnings"] = " | ".join(res.get("warnings") or [])
    row.update(_flatten(res))
    row["version"] = res.get("version", "")
    row["guid"] = res.get("guid", "")
    # The engine's fingerprint: changes with the model's numbers (run.warm_up).
    row["engine"] = (rec.get("identity") or ["", "", ""])[2]
    row["runner_wall_s"] = res.get("wall_s")
    row["wall_s"] = rec.get("wall_s")
    impacts = []
    for m in res.get("impacts") or []:
        imp = {"case_id": case.id}
        imp.update(params)
        imp.update(m)
        impacts.append(imp)
    return row, impacts


def write_tables(study, out_dir, ident=None, units=None):
    """Writes results.parquet/.csv and impacts.parquet/.csv from the records in
    `out_dir`'s cases.jsonl of the study's cases (in the study's order; cases without a
    record are left out) and of the model `ident`; returns the results
    table (a pandas DataFrame read back from results.parquet). The records are read a
    batch of rows at a time, twice (the columns first, then the rows), so the memory
    this takes is that of a batch and of the returned table's columns, not of the
    records."""
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    offsets = load_done(out_dir, ident=ident, offsets=True)
    path = os.path.join(out_dir, "cases.jsonl")

    # Every case of the study with a result, whatever --limit ran now: a run of the
    # first cases does not drop the rest from the tables.
    import dataclasses
    whole = dataclasses.replace(study, limit=None)

    def records():
        with open(path, "rb") as fh:
            for c in whole.iter_cases():
                at = offsets.get(c.id)
                if at is not None:
                    fh.seek(at)
                    yield c, json.loads(fh.readline().decode("utf-8", errors="replace"))

    # First pass: the columns, in the order a table of every row would have them, and
    # the versions and GUIDs.
    columns, impact_columns, versions, guids = {}, {}, set(), set()
    for c, rec in records():
        row, impacts = _rows(c, rec)
        columns.update(dict.fromkeys(row))
        for imp in impacts:
            impact_columns.update(dict.fromkeys(imp))
        versions.add(row["version"])
        guids.add(row["guid"])
    meta = {b"wheelflat.study": study.name.encode(),
            b"wheelflat.version": json.dumps(sorted(v for v in versions if v)).encode(),
            b"wheelflat.guid.CoupledSystem": json.dumps(sorted(g for g in guids if g)).encode(),
            b"wheelflat.sweep": json.dumps(list(study.sweep)).encode()}

    # The String parameters (tables by name, and their hashes) are text too.
    strings = {n for n, v in study.fixed.items() if isinstance(v, (str, Table))} | {
        n for n, vs in study.sweep.items() if any(isinstance(x, (str, Table)) for x in vs)}
    text = set(TEXT) | strings | {n + ".sha256" for n in strings}

    def schema(names):
        fields = [pa.field(n, pa.string() if n in text else pa.int64() if n == "k" else pa.float64())
                  for n in names]
        return pa.schema(fields, metadata=meta)

    tables = {"results": (list(columns), schema(columns)), "impacts": (list(impact_columns), schema(impact_columns))}
    writers, parts = {}, []
    try:
        for name, (names, sch) in tables.items():
            for ext in ("parquet", "csv"):
                parts.append(os.path.join(out_dir, f"{name}.{ext}.part"))
            writers[name] = (pq.ParquetWriter(os.path.join(out_dir, f"{name}.parquet.part"), sch),
                             open(os.path.join(out_dir, f"{name}.csv.part"), "w", newline=""))
        batch = {"results": [], "impacts": []}
        header = {name: csv_header(names, units or {}) for name, (names, _) in tables.items()}

        def flush(name):
            names, sch = tables[name]
            df = pd.DataFrame(batch[name], columns=names)
            for n in names:
                if n not in text and n != "k":
                    df[n] = df[n].astype("float64")
            writers[name][0].write_table(pa.Table.from_pandas(df, schema=sch, preserve_index=False))
            df.to_csv(writers[name][1], index=False, header=header[name] or False, float_format="%.17g")
            header[name] = None
            batch[name] = []

        # Second pass: the rows, a batch at a time.
        for c, rec in records():
            row, impacts = _rows(c, rec)
            batch["results"].append(row)
            batch["impacts"].extend(impacts)
            for name in batch:
                if len(batch[name]) >= BATCH:
                    flush(name)
        for name in batch:
            if batch[name] or header[name]:
                flush(name)
        for pw, fh in writers.values():
            pw.close()
            fh.close()
        # Each table whole or not at all: written beside, then renamed over the old one
        # (a full disk left results.csv cut mid-number, which pandas read without a word).
        for part in parts:
            os.replace(part, part[:-len(".part")])
    except BaseException:
        # Every writer closed and every part removed, whatever fails on the way: on a
        # full disk closing the CSV fails too (its buffer cannot be written), which
        # stopped this cleanup and left the .part files.
        for w in (w for pair in writers.values() for w in pair):
            try:
                w.close()
            except Exception:
                pass
        for part in parts:
            try:
                os.remove(part)
            except OSError:
                pass
        raise
    return pd.read_parquet(os.path.join(out_dir, "results.parquet"))


def _atomic(path, write):
    """Calls ``write(tmp)`` for a temporary file beside ``path``, then renames it to
    ``path``; the temporary file is removed if the write fails."""
    tmp = path + ".part"
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
