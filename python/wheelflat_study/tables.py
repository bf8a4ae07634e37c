"""The study's tables: one row per case (``results``) and one per impact (``impacts``),
as Parquet (with the software version and FMU GUID in the file's metadata too) and
CSV, in the order of the study's cases."""

import json
import os

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


def write_tables(study, cases, done, out_dir):
    """Writes results.parquet/.csv and impacts.parquet/.csv; returns the results table
    (a pandas DataFrame, the cases in study order, those not run left out)."""
    import pandas as pd
    import pyarrow as pa
    import pyarrow.parquet as pq

    rows, impacts = [], []
    versions, guids = set(), set()
    for c in cases:
        rec = done.get(c.id)
        if rec is None:
            continue
        res = rec["result"]
        row = {"case_id": c.id}
        row.update(c.params)
        row["duration"] = c.duration
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
        versions.add(row["version"])
        guids.add(row["guid"])
        rows.append(row)
        for m in res.get("impacts") or []:
            imp = {"case_id": c.id}
            imp.update(c.params)
            imp.update(m)
            impacts.append(imp)
    table = pd.DataFrame(rows)
    meta = {b"wheelflat.study": study.name.encode(),
            b"wheelflat.version": json.dumps(sorted(v for v in versions if v)).encode(),
            b"wheelflat.guid.CoupledSystem": json.dumps(sorted(g for g in guids if g)).encode(),
            b"wheelflat.sweep": json.dumps(list(study.sweep)).encode()}
    for name, df in (("results", table), ("impacts", pd.DataFrame(impacts))):
        t = pa.Table.from_pandas(df, preserve_index=False)
        t = t.replace_schema_metadata({**(t.schema.metadata or {}), **meta})
        # Each table whole or not at all: written beside, then renamed over the old one
        # (a full disk left results.csv cut mid-number, which pandas read without a word).
        _atomic(os.path.join(out_dir, f"{name}.parquet"), lambda p: pq.write_table(t, p))
        _atomic(os.path.join(out_dir, f"{name}.csv"),
                lambda p: df.to_csv(p, index=False, float_format="%.17g"))
    return table


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
