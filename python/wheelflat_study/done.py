"""The results a study's folder already holds (`cases.jsonl`), by case id: what a
resumed study skips and what its tables are written from. Read by the runners
(`run.py`) and the tables (`tables.py`)."""

import json
import os


def read_done(out_dir, retry_failed=False, ident=None, ids_only=False, offsets=False):
    """The results already in the study's folder, by case id. Lines that are not a
    whole record (cut by an interruption, or damaged) are skipped, so their cases run
    again; so do cases that failed for a passing reason (a stopped runner, a lost
    worker), with `retry_failed` every failed case, and, given `ident` (version, GUID,
    engine fingerprint), results of another software version, GUID or engine (one
    table holds one model's results): returns `(done, other)`, `other` the count of those. ids_only: the
    records' ids only (what a start needs; a million records' parameters would not fit
    in the memory a start has); offsets: where each record starts in cases.jsonl
    (bytes), for reading them one at a time."""
    path = os.path.join(out_dir, "cases.jsonl")
    done = {}
    # Ids whose latest record is another model's (a newer record of the id replaces it).
    other = set()
    if os.path.exists(path):
        with open(path, "rb") as fh:
            at = 0
            for line in fh:
                start, at = at, at + len(line)
                try:
                    rec = json.loads(line.decode("utf-8", errors="replace"))
                except json.JSONDecodeError:
                    continue
                if not (isinstance(rec, dict) and isinstance(rec.get("id"), str)
                        and isinstance(rec.get("result"), dict)):
                    continue
                cid, res = rec["id"], rec["result"]
                if res.get("error") and (res.get("transient") or retry_failed):
                    done.pop(cid, None)
                    other.discard(cid)
                    continue
                # Every record names the model that made it (failures too); one without
                # (written before the identities were kept) counts as another's.
                if ident is not None and tuple(rec.get("identity") or ()) != tuple(ident):
                    done.pop(cid, None)
                    other.add(cid)
                    continue
                done[cid] = start if offsets else True if ids_only else rec
                other.discard(cid)
    return done, len(other)


def load_done(out_dir, retry_failed=False, ident=None, ids_only=False, offsets=False):
    """:func:`read_done`'s results alone."""
    return read_done(out_dir, retry_failed, ident, ids_only, offsets)[0]
