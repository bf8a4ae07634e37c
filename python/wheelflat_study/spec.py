"""Study files: what is fixed, what is swept, and the cases that makes."""

import hashlib
import itertools
import json
import math
import random
import tomllib
from dataclasses import dataclass, field

# Units a study may give values in, to SI.
UNITS = {None: 1.0, "": 1.0, "km/h": 1 / 3.6, "mm": 1e-3, "deg": math.pi / 180, "kN": 1e3,
         "MN/m": 1e6, "kN.s/m": 1e3}


@dataclass
class Case:
    """One run: the variables set (name -> SI value), in the study's order."""
    params: dict
    duration: float
    keep: tuple

    @property
    def id(self):
        """A stable identity of the case: what it sets, for how long, what it keeps."""
        text = json.dumps([sorted((k, repr(float(v))) for k, v in self.params.items()),
                           repr(float(self.duration)), list(self.keep)])
        return hashlib.sha1(text.encode()).hexdigest()[:16]

    def line(self):
        """The case as the runner reads it."""
        toks = [f"{k}={float(v)!r}" for k, v in self.params.items()]
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

    def cases(self):
        names = list(self.sweep)
        lists = [self.sweep[n] for n in names]
        if self.combine == "zip":
            n = {len(v) for v in lists}
            if len(n) > 1:
                raise ValueError(f"combine = zip needs lists of one length; got {sorted(n)}")
            rows = zip(*lists)
        else:
            rows = itertools.product(*lists)
        out = []
        for row in rows:
            params = dict(self.fixed)
            params.update(zip(names, row))
            out.append(Case(params, self.duration, tuple(self.keep)))
        return out


def _values(name, entry):
    """The SI values of one swept variable's entry, and its display unit."""
    unit = None
    if isinstance(entry, list):
        values = entry
    elif isinstance(entry, dict):
        unit = entry.get("unit")
        if unit not in UNITS:
            raise ValueError(f"sweep `{name}`: unit `{unit}`; known: {sorted(u for u in UNITS if u)}")
        if "values" in entry:
            values = entry["values"]
        elif "range" in entry:
            r = entry["range"]
            if len(r) != 3 or not r[2] > 0:
                raise ValueError(f"sweep `{name}`: range = [start, stop, step] with step > 0")
            start, stop, step = r
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            values = [start + i * step for i in range(n)]
        elif "random" in entry:
            r = entry["random"]
            rng = random.Random(r.get("seed", 0))
            values = [rng.uniform(r["low"], r["high"]) for _ in range(int(r["n"]))]
        else:
            raise ValueError(f"sweep `{name}`: give values, range or random")
    else:
        raise ValueError(f"sweep `{name}`: a list or a table (values, range or random)")
    if not values:
        raise ValueError(f"sweep `{name}`: no values")
    f = UNITS[unit]
    return [float(v) * f for v in values], unit


def load_study(path):
    """Reads a study file (TOML)."""
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    for key in ("name", "duration"):
        if key not in d:
            raise ValueError(f"{path}: `{key}` is missing")
    fixed = {}
    display = {}
    for name, entry in d.get("fixed", {}).items():
        if isinstance(entry, dict):
            unit = entry.get("unit")
            if unit not in UNITS:
                raise ValueError(f"fixed `{name}`: unit `{unit}`")
            fixed[name] = float(entry["value"]) * UNITS[unit]
        else:
            fixed[name] = float(entry)
    sweep = {}
    for name, entry in d.get("sweep", {}).items():
        sweep[name], unit = _values(name, entry)
        if unit:
            display[name] = (unit, 1 / UNITS[unit])
    combine = d.get("combine", "product")
    if combine not in ("product", "zip"):
        raise ValueError(f"combine = `{combine}`: product or zip")
    return Study(name=d["name"], duration=float(d["duration"]), fixed=fixed, sweep=sweep,
                 combine=combine, keep=tuple(d.get("keep", ())), plots=d.get("plot", []),
                 display=display)
