"""Study files: what is fixed, what is swept, and the cases that makes."""

import hashlib
import itertools
import json
import math
import os
import random
import re
import tomllib
from dataclasses import dataclass, field

# The most cases one study may have.
MAX_CASES = 1_000_000
# The keys a study file may have, and those of a sweep entry.
TOP_KEYS = {"name", "duration", "keep", "combine", "fixed", "sweep", "plot"}
SWEEP_KEYS = {"values", "range", "random", "unit"}
RANDOM_KEYS = {"low", "high", "n", "seed"}
PLOT_KEYS = {"kind", "x", "y", "z", "by", "scale", "label", "title", "name"}
PLOT_KINDS = {"lines": ("x", "y"), "heatmap": ("x", "y", "z"), "phase": ("x", "y", "z")}

# Units a study may give values in, to SI.
UNITS = {None: 1.0, "": 1.0, "km/h": 1 / 3.6, "mm": 1e-3, "deg": math.pi / 180, "kN": 1e3,
         "MN/m": 1e6, "kN.s/m": 1e3}


@dataclass
class Case:
    """One run: the variables set (name -> SI value), in the study's order."""
    params: dict
    duration: float
    keep: tuple
    _id: str = field(default=None, repr=False, compare=False)

    @property
    def id(self):
        """A stable identity of the case: what it sets, for how long, what it keeps
        (16 hex digits of the SHA-1 of ``json.dumps([sorted (name, repr(value)) pairs,
        repr(duration), keep])``)."""
        if self._id is None:
            text = json.dumps([sorted((k, _repr(v)) for k, v in self.params.items()),
                               repr(float(self.duration)), list(self.keep)])
            self._id = hashlib.sha1(text.encode()).hexdigest()[:16]
        return self._id

    def line(self):
        """The case as the runner reads it."""
        toks = [f"{k}={v}" if isinstance(v, str) else f"{k}={float(v)!r}" for k, v in self.params.items()]
        toks.append(f"duration={float(self.duration)!r}")
        if self.keep:
            toks.append("keep=" + ",".join(self.keep))
        return " ".join(toks)


@dataclass
class Study:
    name: str
    duration: float
    fixed: dict
    sweep: dict  # name -> list of SI values
    combine: str = "product"
    keep: tuple = ()
    plots: list = field(default_factory=list)
    display: dict = field(default_factory=dict)  # name -> (unit, factor to the unit)

    def count(self):
        """The number of cases."""
        lens = [len(v) for v in self.sweep.values()]
        if self.combine == "zip":
            return lens[0] if lens else 1
        return math.prod(lens)

    def _rows(self):
        lists = list(self.sweep.values())
        if self.combine == "zip":
            return zip(*lists)
        return itertools.product(*lists)

    def check(self):
        """Refuses a study whose cases are not all different, or a zip of lists of
        different lengths, without making the cases (a million-case study is checked
        in well under a second)."""
        names = list(self.sweep)
        lists = [self.sweep[n] for n in names]
        if self.combine == "zip":
            if len({len(v) for v in lists}) > 1:
                lens = ", ".join(f"{k}: {len(v)}" for k, v in self.sweep.items())
                raise ValueError(f"combine = zip needs every swept variable to have as many values ({lens})")
            # Rows differ when one variable's values all differ; else compare the rows.
            if lists and not any(len(set(map(repr, v))) == len(v) for v in lists):
                seen = set()
                for row in zip(*lists):
                    key = tuple(map(repr, row))
                    if key in seen:
                        raise ValueError(f"the study has the same case twice: {dict(zip(names, row))} "
                                         f"(repeated values in the sweep)")
                    seen.add(key)
            return
        # A product's cases differ exactly when each variable's values do.
        for i, v in enumerate(lists):
            seen = set()
            for x in v:
                if repr(x) in seen:
                    row = dict(zip(names, (w[0] for w in lists)))
                    row[names[i]] = x
                    raise ValueError(f"the study has the same case twice: {row} (repeated values in the sweep)")
                seen.add(repr(x))

    def iter_cases(self):
        """The cases one by one, in the study's order, each with its id (made here at
        about a microsecond a case: the id's text from the names' parts made once)."""
        names = list(self.sweep)
        order = sorted(set(self.fixed) | set(names))
        # json.dumps of the id's list, piece by piece: a float's repr needs no escaping.
        head = {k: "[" + json.dumps(k) + ', "' for k in order}
        rest = "], " + json.dumps(repr(float(self.duration))) + ", " + json.dumps(list(self.keep)) + "]"
        fixed = {k: _repr(v) for k, v in self.fixed.items()}
        keep = tuple(self.keep)
        sha1 = hashlib.sha1
        for row in self._rows():
            params = dict(self.fixed)
            params.update(zip(names, row))
            text = dict(fixed)
            text.update(zip(names, map(repr, row)))
            pairs = '"], '.join(head[k] + text[k] for k in order) + '"]' if order else ""
            idtext = "[[" + pairs + rest
            yield Case(params, self.duration, keep, sha1(idtext.encode()).hexdigest()[:16])

    def cases(self):
        """All the cases, as a list (a small study's; a large one goes through
        :meth:`iter_cases`)."""
        self.check()
        return list(self.iter_cases())


def _repr(v):
    """A value's text in a case's id: a number's float repr, a table's own repr."""
    return repr(v) if isinstance(v, str) else repr(float(v))


def inline(v):
    """Whether a String parameter's value is the table itself (it holds a `;` or a line
    break), not its file's path."""
    return ";" in v or "\n" in v


def _is_number(v):
    try:
        float(v)
        return True
    except ValueError:
        return False


def _path_from(base, v):
    """A table's path `v` taken from the folder `base` when relative; other values (and
    text that reads as a number, which is refused later as a String for a number) as
    they are."""
    if isinstance(v, str) and not inline(v) and not os.path.isabs(v) and not _is_number(v):
        return os.path.normpath(os.path.join(base, v))
    return v


def _text(where, v):
    """A String parameter's value: a table's path, or the table as x,y;x,y;... (the
    runner's case line splits at blanks, so the value holds none)."""
    if not v or any(c.isspace() for c in v):
        raise ValueError(f"{where}: `{v}`: give a table's path without blanks, or the table "
                         f"itself as x,y;x,y;... without blanks")
    return v


def _number(where, v):
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ValueError(f"{where}: `{v}` is not a finite number")
    return float(v)


def _unit(where, unit):
    if not (unit is None or isinstance(unit, str)) or unit not in UNITS:
        raise ValueError(f"{where}: unit `{unit}`; known: {', '.join(sorted(u for u in UNITS if u))}")
    return unit


def _values(name, entry):
    """The SI values of one swept variable's entry, and its display unit."""
    unit = None
    where = f"sweep `{name}`"
    if isinstance(entry, list):
        values = entry
    elif isinstance(entry, dict):
        extra = set(entry) - SWEEP_KEYS
        if extra or len(set(entry) & {"values", "range", "random"}) != 1:
            raise ValueError(f"{where}: give exactly one of values, range or random (and unit); "
                             f"got {sorted(entry)}")
        unit = _unit(where, entry.get("unit"))
        if "values" in entry:
            values = entry["values"]
            if not isinstance(values, list):
                raise ValueError(f"{where}: values = {values!r}: a list of numbers")
        elif "range" in entry:
            r = entry["range"]
            if not isinstance(r, list) or len(r) != 3:
                raise ValueError(f"sweep `{name}`: range = [start, stop, step] with step > 0")
            start, stop, step = (_number(where, x) for x in r)
            if not step > 0:
                raise ValueError(f"sweep `{name}`: range = [start, stop, step] with step > 0")
            count = math.floor((stop - start) / step + 1e-9) + 1 if math.isfinite((stop - start) / step) \
                else math.inf
            if not count <= MAX_CASES:
                raise ValueError(f"{where}: range gives {count:g} values; at most {MAX_CASES} cases a study")
            n = int(count)
            if n > MAX_CASES:
                raise ValueError(f"{where}: range gives {n} values; at most {MAX_CASES} cases a study")
            values = [start + i * step for i in range(n)]
        elif "random" in entry:
            r = entry["random"]
            if not isinstance(r, dict) or set(r) - RANDOM_KEYS or not {"low", "high", "n"} <= set(r):
                raise ValueError(f"{where}: random = {{ low, high, n, seed }} (seed optional)")
            n = _number(where, r["n"])
            if n != int(n) or not 1 <= n <= MAX_CASES:
                raise ValueError(f"{where}: random n = {r['n']}; allowed a whole number, 1 to {MAX_CASES}")
            n = int(n)
            seed = r.get("seed", 0)
            if isinstance(seed, bool) or not isinstance(seed, int):
                raise ValueError(f"{where}: random seed = {seed!r}; a whole number")
            rng = random.Random(seed)
            low, high = _number(where, r["low"]), _number(where, r["high"])
            values = [rng.uniform(low, high) for _ in range(n)]
        else:
            raise ValueError(f"sweep `{name}`: give values, range or random")
    else:
        raise ValueError(f"sweep `{name}`: a list or a table (values, range or random)")
    if not values:
        raise ValueError(f"sweep `{name}`: no values")
    f = UNITS[unit]
    if unit and any(isinstance(v, str) for v in values):
        raise ValueError(f"{where}: unit = {unit!r} with text values (tables): a unit is for numbers")
    # + 0.0 makes -0.0 the 0.0 it is (else the same physics ran as two cases).
    return [_text(where, v) if isinstance(v, str) else _number(where, v) * f + 0.0 for v in values], unit


def load_study(path):
    """Reads a study file (TOML)."""
    with open(path, "rb") as fh:
        try:
            d = tomllib.load(fh)
        except tomllib.TOMLDecodeError as e:
            raise ValueError(f"not valid TOML: {e}") from None
    extra = set(d) - TOP_KEYS
    if extra:
        raise ValueError(f"unknown keys {sorted(extra)}; a study has {sorted(TOP_KEYS)}")
    for key in ("name", "duration"):
        if key not in d:
            raise ValueError(f"`{key}` is missing")
    name = d["name"]
    if not isinstance(name, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", name) or name.startswith("."):
        raise ValueError(f"name = `{name}`: letters, digits, '_', '.', '-' (it names the results folder)")
    duration = _number("duration", d["duration"])
    if not 0 < duration <= 1e4:
        raise ValueError(f"duration = {duration}: 0 < duration <= 1e4 s")
    for key in ("fixed", "sweep"):
        if not isinstance(d.get(key, {}), dict):
            raise ValueError(f"`{key}` = {d[key]!r}: a table, [{key}] with one variable a line")
    fixed = {}
    display = {}
    for var, entry in d.get("fixed", {}).items():
        if isinstance(entry, dict):
            if set(entry) - {"value", "unit"} or "value" not in entry:
                raise ValueError(f"fixed `{var}`: a number or {{ value, unit }}")
            unit = _unit(f"fixed `{var}`", entry.get("unit"))
            fixed[var] = _number(f"fixed `{var}`", entry["value"]) * UNITS[unit]
        elif isinstance(entry, str):
            fixed[var] = _text(f"fixed `{var}`", entry)
        else:
            fixed[var] = _number(f"fixed `{var}`", entry) + 0.0
    # A table's relative path is the study file's: the runners may run elsewhere.
    base = os.path.dirname(os.path.abspath(path))
    for var, v in fixed.items():
        fixed[var] = _path_from(base, v)
    sweep = {}
    for var, entry in d.get("sweep", {}).items():
        if var in fixed:
            raise ValueError(f"`{var}` is both fixed and swept")
        sweep[var], unit = _values(var, entry)
        sweep[var] = [_path_from(base, v) for v in sweep[var]]
        if unit:
            display[var] = (unit, 1 / UNITS[unit])
    combine = d.get("combine", "product")
    if combine not in ("product", "zip"):
        raise ValueError(f"combine = `{combine}`: product or zip")
    if combine == "zip" and not sweep:
        raise ValueError("combine = zip without a [sweep]: there is nothing to zip")
    keep = d.get("keep", [])
    if not isinstance(keep, list) or not all(isinstance(k, str) and k for k in keep):
        raise ValueError("keep: a list of output names")
    plots = d.get("plot", [])
    if not isinstance(plots, list) or not all(isinstance(p, dict) for p in plots):
        raise ValueError("plot: tables, one [[plot]] each")
    for i, p in enumerate(plots):
        pname = p.get("name")
        if pname is not None and (not isinstance(pname, str) or not re.fullmatch(r"[A-Za-z0-9_.-]+", pname)
                                  or pname.startswith(".")):
            raise ValueError(f"plot {i + 1}: name = `{pname}`: letters, digits, '_', '.', '-' (it names a file "
                             f"in the results folder)")
        kind = p.get("kind", "lines")
        if not isinstance(kind, str) or kind not in PLOT_KINDS or set(p) - PLOT_KEYS:
            raise ValueError(f"plot {i + 1}: kind one of {sorted(PLOT_KINDS)}, keys {sorted(PLOT_KEYS)}")
        missing = [k for k in PLOT_KINDS[kind] if k not in p]
        if missing:
            raise ValueError(f"plot {i + 1} ({kind}): needs {missing}")
        for key in ("x", "y", "z", "by", "label", "title"):
            if key in p and not isinstance(p[key], str):
                raise ValueError(f"plot {i + 1}: {key} = {p[key]!r}: a column name or text, in quotes")
        if "scale" in p and not (isinstance(p["scale"], (int, float)) and not isinstance(p["scale"], bool)
                                 and math.isfinite(p["scale"]) and p["scale"] != 0):
            raise ValueError(f"plot {i + 1}: scale = {p['scale']!r}: a finite number other than 0")
    study = Study(name=name, duration=duration, fixed=fixed, sweep=sweep, combine=combine,
                  keep=tuple(keep), plots=plots, display=display)
    if study.count() > MAX_CASES:
        raise ValueError(f"{study.count()} cases; at most {MAX_CASES} a study")
    return study
