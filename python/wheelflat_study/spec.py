"""Study files: what is fixed, what is swept, and the cases that makes."""

import dataclasses
import hashlib
import itertools
import json
import math
import os
import random
import re
import stat
import sys
import tomllib
from dataclasses import dataclass, field

# The most cases one study may have.
MAX_CASES = 1_000_000
# The keys a study file may have, and those of a sweep entry.
TOP_KEYS = {"name", "duration", "keep", "combine", "fixed", "sweep", "plot", "summary"}
SWEEP_KEYS = {"values", "range", "random", "unit"}
RANDOM_KEYS = {"low", "high", "n", "seed"}
PLOT_KEYS = {"kind", "x", "y", "z", "by", "scale", "label", "title", "name"}
PLOT_KINDS = {"lines": ("x", "y"), "heatmap": ("x", "y", "z"), "phase": ("x", "y", "z"), "distribution": ("y",)}
# The keys of a study's [summary], and the percentile it gives by default.
SUMMARY_KEYS = {"over", "of", "percentile"}
DEFAULT_PERCENTILE = 95.0

# Units a study may give values in, to SI.
UNITS = {None: 1.0, "": 1.0, "km/h": 1 / 3.6, "mm": 1e-3, "deg": math.pi / 180, "kN": 1e3,
         "MN/m": 1e6, "kN.s/m": 1e3}


# The ready roughness spectrum a `roughness.*` String parameter names (the engine's
# ISO_3095_NAME): passed on as it is, not read as a file.
ISO_3095 = "iso3095"

# A table's file: at most this many bytes (the engine's MAX_TABLE_FILE) and points
# (its MAX_TABLE_POINTS).
MAX_TABLE_FILE = 100_000_000
MAX_TABLE_POINTS = 1_000_000
# A number as the engine reads it (Rust's f64 from text): a table's point is two.
_NUMBER = re.compile(r"[+-]?(?:(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?|inf|infinity|nan)",
                     re.IGNORECASE)
_BLANKS = re.compile(r"[\s,]+")


@dataclass(frozen=True)
class Table:
    """A String parameter's table as this process read it, once, when the study was
    loaded: ``name`` (the file's path, or the table as written out; "" for no table),
    ``text`` (the points as the engine takes a table written out, ``x,y;x,y;...;``,
    without blanks or comments; "" for no table) and ``sha256`` (of ``text``, in hex;
    "" for no table). The workers get ``text``, never the path: a worker never reads
    a file, and a case's id holds the hash, so an edited file is a new case."""
    name: str
    text: str
    sha256: str
    # The value as the study wrote it (a relative path as given), for refusals only.
    given: str = field(default="", compare=False, repr=False)

    def __repr__(self):
        # Never the content of a file (a refusal may quote a value).
        return repr(self.name) if self.name else "'' (no table)"

    @property
    def key(self):
        """The table in a case's id: its content's hash."""
        return "sha256:" + self.sha256 if self.text else "no table"


NO_TABLE = Table("", "", "")


@dataclass(frozen=True)
class Unread:
    """A study's text value that is not a table (no file at its path, a file refused,
    a table written out wrongly): kept as the text with ``why``, the table's refusal,
    until the variable's type is known. A String parameter's value is always text (a
    path or a table), so a text that looks like a number ("20", "nan") is a path there,
    and a file of that name is read; given to a parameter that takes a number, the text
    is refused as text, whatever file it names (the study command's check_variables,
    or :meth:`Study.check`)."""
    text: str
    why: str

    def __repr__(self):
        return repr(self.text)


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
        repr(duration), keep])``; a table's value is ``"sha256:"`` and its content's
        hash, so an edited file makes another case, a renamed one the same)."""
        if self._id is None:
            text = json.dumps([sorted((k, _repr(v)) for k, v in self.params.items()),
                               repr(float(self.duration)), list(self.keep)])
            self._id = hashlib.sha1(text.encode()).hexdigest()[:16]
        return self._id

    def line(self):
        """The case as the runner reads it."""
        return "".join(self.parts())

    def parts(self):
        """The case's line in pieces whose concatenation is :meth:`line`: a table's
        content (never its path) is a piece of its own, the study's own string, so the
        cases of a Dask chunk that share a table carry it once (pickle keeps one copy
        of an object within a message)."""
        parts = []
        text = []
        for k, v in self.params.items():
            if isinstance(v, Table):
                text.append(f"{k}=")
                parts += [" ".join(text), v.text]
                text = [""]
            else:
                text.append(f"{k}={v}" if isinstance(v, str) else f"{k}={float(v)!r}")
        text.append(f"duration={float(self.duration)!r}")
        if self.keep:
            text.append("keep=" + ",".join(self.keep))
        parts.append(" ".join(text))
        return parts

    def record_params(self):
        """The parameters as a record of cases.jsonl keeps them: a table by its name
        (its hash is in ``tables``)."""
        return {k: v.name if isinstance(v, Table) else v for k, v in self.params.items()}

    def table_hashes(self):
        """The tables' hashes by parameter (sha256 of the content the case ran)."""
        return {k: v.sha256 for k, v in self.params.items() if isinstance(v, Table)}


@dataclass(frozen=True)
class Summary:
    """A study's ``[summary]``: the cases that differ only in the swept variables
    ``over`` (every other swept variable equal) form one case group, a distribution;
    for each group and each result of ``of`` (a column of the results table, as a
    plot's y names it) the summary gives the count, mean, sample standard deviation
    (ddof = 1), the ``percentile`` (0 to 100, numpy's default linear interpolation),
    min and max (summary.py)."""
    over: tuple
    of: tuple
    percentile: float = DEFAULT_PERCENTILE


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
    # The first `limit` cases only (the command's --limit; None: all): their ids are
    # the whole study's, so a run without it goes on with the rest.
    limit: int = None
    # The [summary] (a Summary), or None.
    summary: Summary = None
    # The enumerations' items by variable: name -> {value: item}, for the variables the
    # study sets whose items CoupledSystem's model description lists (the command's
    # check_variables fills it; an item given by name is its number from there on).
    items: dict = field(default_factory=dict)

    def __post_init__(self):
        # A study made in code, with a table's path or the table as text: read here,
        # once (a relative path from the working folder), as load_study does.
        base, cache = os.getcwd(), {}
        self.fixed = {k: _tables(k, [v], base, cache)[0] if isinstance(v, str) else v for k, v in self.fixed.items()}
        self.sweep = {k: _tables(k, v, base, cache) if any(isinstance(x, str) for x in v) else v
                      for k, v in self.sweep.items()}

    def name_items(self, name, items):
        """Takes the enumeration `name`'s items [(value, item), ...]: keeps them for
        the case table, the summary and the plots, and makes each value given by an
        item's name (text, in quotes) that item's number (so `"hertz"` and `2` are the
        same case, with the same id). Other text is left for the refusal."""
        by_name = {item: float(k) for k, item in items}
        self.items[name] = {float(k): item for k, item in items}

        def number(v):
            text = v.text if isinstance(v, Unread) else (v.given or v.name) if isinstance(v, Table) else v
            return by_name.get(text.strip(), v) if isinstance(text, str) else v

        if name in self.fixed:
            self.fixed[name] = number(self.fixed[name])
        if name in self.sweep:
            self.sweep[name] = [number(v) for v in self.sweep[name]]

    def shown(self, name, v):
        """A variable's value as a person reads it: an enumeration's item by name, a
        number in the study's display unit (``36``, for 10 m/s given in km/h), a table
        by its name (its file's path, or the points written out; "no table")."""
        if isinstance(v, (Table, Unread)):
            v = v.name if isinstance(v, Table) else v.text
        if isinstance(v, str):
            return v or "no table"
        items = self.items.get(name)
        if items and float(v) in items:
            return items[float(v)]
        return f"{v * self.display.get(name, (None, 1.0))[1]:g}"

    def count(self):
        """The number of cases (at most :attr:`limit`)."""
        lens = [len(v) for v in self.sweep.values()]
        n = (lens[0] if lens else 1) if self.combine == "zip" else math.prod(lens)
        return n if self.limit is None else min(n, self.limit)

    def _rows(self):
        lists = list(self.sweep.values())
        if self.combine == "zip":
            return zip(*lists)
        return itertools.product(*lists)

    def check(self):
        """Refuses a text that is not a table (:class:`Unread`), a study whose cases
        are not all different, or a zip of lists of different lengths, without making
        the cases (a million-case study is checked in well under a second)."""
        for name, vs in itertools.chain(((k, [v]) for k, v in self.fixed.items()), self.sweep.items()):
            for v in vs:
                if isinstance(v, Unread):
                    hint = (f" (if `{name}` takes a number, write it without quotes: {name} = {v.text.strip()})"
                            if _finite_text(v.text) else "")
                    raise ValueError(v.why + hint)
        names = list(self.sweep)
        lists = [self.sweep[n] for n in names]
        if self.combine == "zip":
            if len({len(v) for v in lists}) > 1:
                lens = ", ".join(f"{k}: {len(v)}" for k, v in self.sweep.items())
                raise ValueError(f"combine = zip needs every swept variable to have as many values ({lens})")
            # Rows differ when one variable's values all differ; else compare the rows.
            if lists and not any(len(set(map(_repr, v))) == len(v) for v in lists):
                seen = set()
                for row in zip(*lists):
                    key = tuple(map(_repr, row))
                    if key in seen:
                        raise ValueError(f"the study has the same case twice: {dict(zip(names, row))} "
                                         f"(repeated values in the sweep)")
                    seen.add(key)
            return
        # A product's cases differ exactly when each variable's values do.
        for i, v in enumerate(lists):
            seen = set()
            for x in v:
                if _repr(x) in seen:
                    row = dict(zip(names, (w[0] for w in lists)))
                    row[names[i]] = x
                    raise ValueError(f"the study has the same case twice: {row} (repeated values in the sweep)")
                seen.add(_repr(x))

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
        # A float's text is its repr; a table's, its content's hash (_repr).
        text_of = _repr if any(isinstance(x, Table) for v in self.sweep.values() for x in v) else repr
        rows = self._rows() if self.limit is None else itertools.islice(self._rows(), self.limit)
        for row in rows:
            params = dict(self.fixed)
            params.update(zip(names, row))
            text = dict(fixed)
            text.update(zip(names, map(text_of, row)))
            pairs = '"], '.join(head[k] + text[k] for k in order) + '"]' if order else ""
            idtext = "[[" + pairs + rest
            yield Case(params, self.duration, keep, sha1(idtext.encode()).hexdigest()[:16])

    def cases(self):
        """All the cases, as a list (a small study's; a large one goes through
        :meth:`iter_cases`)."""
        self.check()
        return list(self.iter_cases())


def _repr(v):
    """A value's text in a case's id: a number's float repr, a table's content's hash
    (a text left as it is, a number written as text that is refused before anything
    runs, its own repr)."""
    if isinstance(v, Table):
        return repr(v.key)
    if isinstance(v, Unread):
        return repr(v.text)
    return repr(v) if isinstance(v, str) else repr(float(v))


def inline(v):
    """Whether a String parameter's value is the table itself (it holds a `;` or a line
    break), not its file's path."""
    return ";" in v or "\n" in v


def _finite_text(v):
    """Whether the text `v` is a finite number written as text ("20", not "nan")."""
    try:
        return math.isfinite(float(v))
    except ValueError:
        return False


def read_table(name, v, base, cache=None):
    """The String parameter `name`'s value `v` as a :class:`Table`, read once, here:
    "" (or blanks) for no table; a value that holds a `;` or a line break is the table
    itself; any other is a table file's path (taken from the folder `base` when
    relative), which must be a regular file of at most MAX_TABLE_FILE bytes of UTF-8
    text (a byte-order mark is skipped). Either way the points are read as the engine
    reads a table (``Table::parse``: one point a line or between `;`, two numbers
    separated by blanks or a comma, text after `#` a comment) and written out as
    ``x,y;x,y;...;``. A refusal names the variable, the value and what is allowed, and
    never quotes the file's content. `cache`: a dict of the files read so far (by
    path), so a file named twice is read once."""
    where = f"`{name}` = {v!r}"
    if not v.strip():
        return NO_TABLE
    if name.startswith("roughness.") and v.strip() == ISO_3095:
        # The ready spectrum by its name, as the engine takes it (no file is read).
        return Table(ISO_3095, ISO_3095, hashlib.sha256(ISO_3095.encode()).hexdigest(), v)
    if inline(v):
        return _table(f"`{name}` (the table written out)", None, v)
    path = os.path.normpath(os.path.join(base, v.strip()))
    if cache is not None and path in cache:
        return cache[path]
    allowed = (f"a table's file (a regular file of at most {MAX_TABLE_FILE:,} bytes of UTF-8 text, two numbers "
               f"a line), its path absolute or relative to the study file's folder; or the table itself "
               f"(x y; x y; ...); or \"\" for no table")
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ValueError(f"{where}: not a table: no file at {path}, and not a table written out (it holds no "
                         f"`;` or line break); allowed: {allowed}") from None
    except OSError as e:
        raise ValueError(f"{where}: cannot read {path} ({e.strerror}); allowed: {allowed}") from None
    if not stat.S_ISREG(st.st_mode):
        kind = ("a folder" if stat.S_ISDIR(st.st_mode) else "a device" if stat.S_ISCHR(st.st_mode)
                or stat.S_ISBLK(st.st_mode) else "a pipe" if stat.S_ISFIFO(st.st_mode) else "a socket"
                if stat.S_ISSOCK(st.st_mode) else "not a file")
        raise ValueError(f"{where}: {path} is not a regular file ({kind}); allowed: {allowed}")
    try:
        # At most one byte past the limit: a file that grows (or gives no size, as
        # /proc's do) is never read whole into memory.
        with open(path, "rb") as fh:
            data = fh.read(MAX_TABLE_FILE + 1)
    except OSError as e:
        raise ValueError(f"{where}: cannot read {path} ({e.strerror}); allowed: {allowed}") from None
    if len(data) > MAX_TABLE_FILE:
        raise ValueError(f"{where}: {path} has more than {MAX_TABLE_FILE:,} bytes; allowed: {allowed}")
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as e:
        raise ValueError(f"{where}: {path} is not UTF-8 text (byte {e.start + 1}); allowed: {allowed}") from None
    table = _table(f"`{name}` ({path})", path, text)
    if cache is not None:
        cache[path] = table
    return table


def _table(where, name, text):
    """The :class:`Table` named `name` (None: the content, for a table written out) of
    the text `text` (the engine's table format; `where` names it in a refusal, which
    quotes no content)."""
    import numpy as np
    if "\n" not in text and "#" in text:
        raise ValueError(f"{where}: a `#` in a table on one line would make the rest of the line, points and "
                         f"all, a comment: take the comment out, or give the table a line a point")
    points = []
    for n, line in enumerate(text.split("\n")):
        line = line.split("#", 1)[0]
        for k, point in enumerate(line.split(";")):
            fields = [f for f in _BLANKS.split(point) if f]
            if not fields:
                continue
            if len(fields) != 2 or not (_NUMBER.fullmatch(fields[0]) and _NUMBER.fullmatch(fields[1])):
                part = f", its point {k + 1} after a `;`" if k else ""
                raise ValueError(f"{where}: line {n + 1}{part}: not two numbers ({len(fields)} fields); allowed: "
                                 f"x y, two numbers separated by blanks or a comma, a `;` or a line break "
                                 f"between points, text after `#` a comment")
            points.append(fields)
            if len(points) > MAX_TABLE_POINTS:
                raise ValueError(f"{where}: more than {MAX_TABLE_POINTS:,} points; allowed: 2 to "
                                 f"{MAX_TABLE_POINTS:,}")
    if len(points) < 2:
        raise ValueError(f"{where}: {len(points)} points; allowed: 2 to {MAX_TABLE_POINTS:,} points, two numbers "
                         f"each (\"\" for no table)")
    xy = np.array(points, dtype=float)
    bad = ~np.isfinite(xy).all(axis=1)
    if bad.any():
        i = int(np.argmax(bad))
        raise ValueError(f"{where}, point {i + 1}: not finite; allowed: finite numbers")
    steps = np.diff(xy[:, 0])
    if (steps <= 0).any():
        i = int(np.argmax(steps <= 0)) + 1
        raise ValueError(f"{where}, point {i + 1}: x = {xy[i, 0]:.17g}; allowed: above the point before's "
                         f"{xy[i - 1, 0]:.17g} (x strictly increasing)")
    content = ";".join(a + "," + b for a, b in points) + ";"
    return Table(content if name is None else name, content, hashlib.sha256(content.encode()).hexdigest())


def _tables(name, values, base, cache):
    """`values` with each text read as a table (a path or the table written out, a
    text that looks like a number too: a file may be named `20`); a text that is not
    one is kept as :class:`Unread`, refused once the variable's type is known (as a
    table's text for a String parameter, as text for one that takes a number)."""
    out = []
    for v in values:
        if isinstance(v, str):
            try:
                v = dataclasses.replace(read_table(name, v, base, cache), given=v)
            except ValueError as e:
                v = Unread(v, str(e))
        out.append(v)
    return out


def _number(where, v):
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ValueError(f"{where}: `{v}` is not a finite number")
    try:
        x = float(v)
    except OverflowError:
        # An integer of more than 308 digits (TOML has no limit).
        raise ValueError(f"{where}: an integer of {len(str(abs(v)))} digits is not a finite number; allowed: "
                         f"-1.8e308 to 1.8e308 (and the variable's own range)") from None
    if not math.isfinite(x):
        raise ValueError(f"{where}: `{v}` is not a finite number")
    return x


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
    return [v if isinstance(v, str) else _number(where, v) * f + 0.0 for v in values], unit


def load_study(path):
    """Reads a study file (TOML)."""
    with open(path, "rb") as fh:
        try:
            d = tomllib.load(fh)
        except ValueError as e:  # TOMLDecodeError, an integer over Python's 4300 digits
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
            fixed[var] = entry
        else:
            fixed[var] = _number(f"fixed `{var}`", entry) + 0.0
    # Every table is read here, once (a relative path from the study file's folder):
    # the workers get the content.
    base = os.path.dirname(os.path.abspath(path))
    cache = {}
    for var, v in fixed.items():
        [fixed[var]] = _tables(var, [v], base, cache)
    sweep = {}
    for var, entry in d.get("sweep", {}).items():
        if var in fixed:
            raise ValueError(f"`{var}` is both fixed and swept")
        sweep[var], unit = _values(var, entry)
        sweep[var] = _tables(var, sweep[var], base, cache)
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
                                 and abs(p["scale"]) <= sys.float_info.max and p["scale"] != 0):
            raise ValueError(f"plot {i + 1}: scale = {p['scale']!r}: a finite number other than 0")
    summary = _summary(d["summary"], fixed, sweep, keep) if "summary" in d else None
    for i, p in enumerate(plots):
        if p.get("kind") == "distribution":
            _distribution(i, p, summary, fixed, sweep, keep)
    study = Study(name=name, duration=duration, fixed=fixed, sweep=sweep, combine=combine,
                  keep=tuple(keep), plots=plots, display=display, summary=summary)
    if study.count() > MAX_CASES:
        raise ValueError(f"{study.count()} cases; at most {MAX_CASES} a study")
    return study


def _results(fixed, sweep, keep):
    """The results a [summary] or a distribution plot may name: the results table's
    columns a case's answer gives (tables.result_columns), for the most wheelsets the
    study sets."""
    from .tables import result_columns
    given = [fixed["wheelsets"]] if "wheelsets" in fixed else sweep.get("wheelsets", [1.0])
    most = max((v for v in given if isinstance(v, (int, float))), default=1.0)
    return result_columns(keep, int(min(max(most, 1.0), 4.0)))


def _result(where, name, allowed, fixed, sweep):
    """Refuses `name` at `where` unless it is one of the results `allowed`."""
    if isinstance(name, str) and name in allowed:
        return name
    hint = ""
    if isinstance(name, str):
        m = re.fullmatch(r"peak\.wheelset\[([0-9]+)\]\.(left|right)", name)
        if name in sweep or name in fixed:
            hint = " (a parameter the study sets, not a result)"
        elif m and 2 <= int(m.group(1)) <= 4:
            hint = f" (set wheelsets = {m.group(1)} or more for it)"
        elif name.endswith((".max", ".min")):
            hint = f" (an output's extremes need it kept: keep = [\"{name[:-4]}\"])"
    raise ValueError(f"{where} {name!r} is not a result of the study's cases{hint}; allowed: "
                     f"{', '.join(allowed)}")


def _summary(entry, fixed, sweep, keep):
    """The study's [summary] (a :class:`Summary`), refused naming the key, the value
    and what is allowed."""
    if not isinstance(entry, dict):
        raise ValueError(f"summary = {entry!r}: a table, [summary] with over, of and percentile")
    extra = set(entry) - SUMMARY_KEYS
    if extra:
        raise ValueError(f"[summary]: unknown keys {sorted(extra)}; allowed: {sorted(SUMMARY_KEYS)}")
    for key in ("over", "of"):
        if key not in entry:
            raise ValueError(f"[summary]: `{key}` is missing; it needs over (the swept variables whose cases form "
                             f"one distribution) and of (the results summarised)")
    swept = ", ".join(sweep) or "nothing (the study has no [sweep])"
    over = entry["over"]
    if not isinstance(over, list) or not over:
        raise ValueError(f"[summary] over = {over!r}: a list of swept variables' names, such as over = "
                         f"[\"{next(iter(sweep), 'rail.spectrum.seed')}\"]; swept: {swept}")
    for name in over:
        if not isinstance(name, str) or name not in sweep:
            why = "is fixed, not swept" if isinstance(name, str) and name in fixed else "is not swept"
            raise ValueError(f"[summary] over: {name!r} {why}; allowed: the swept variables ([sweep]): {swept}")
    if len(set(over)) != len(over):
        raise ValueError(f"[summary] over = {over!r}: a variable named twice")
    of = entry["of"]
    allowed = _results(fixed, sweep, keep)
    if not isinstance(of, list) or not of:
        raise ValueError(f"[summary] of = {of!r}: a list of results, such as of = [\"peak.left\"]; allowed: "
                         f"{', '.join(allowed)}")
    for name in of:
        _result("[summary] of:", name, allowed, fixed, sweep)
    if len(set(of)) != len(of):
        raise ValueError(f"[summary] of = {of!r}: a result named twice")
    q = entry.get("percentile", DEFAULT_PERCENTILE)
    if isinstance(q, bool) or not isinstance(q, (int, float)) or not (math.isfinite(q) and 0 <= q <= 100):
        raise ValueError(f"[summary] percentile = {q!r}: allowed a number from 0 to 100 (95: the 95th "
                         f"percentile, numpy's linear interpolation)")
    return Summary(over=tuple(over), of=tuple(of), percentile=float(q))


def _distribution(i, p, summary, fixed, sweep, keep):
    """Refuses a distribution plot the study cannot draw: one without a [summary], a
    y that is not a result, a `by` that is not a swept variable outside the summary's
    `over`, or one that leaves another swept variable to mix in a box."""
    where = f"plot {i + 1} (distribution)"
    if summary is None:
        raise ValueError(f"{where}: needs a [summary] (its over: the swept variables whose cases make one box; its "
                         f"percentile is marked)")
    extra = set(p) & {"x", "z"}
    if extra:
        raise ValueError(f"{where}: {sorted(extra)} not allowed; a distribution plot has y (a result), by (the "
                         f"swept variable of its boxes; optional), scale, label, title, name")
    _result(f"{where}: y =", p["y"], _results(fixed, sweep, keep), fixed, sweep)
    groups = [n for n in sweep if n not in summary.over]
    if "by" in p:
        by = p["by"]
        if by not in groups:
            why = ("is in the [summary]'s over (its values make one box)" if by in summary.over
                   else "is not swept")
            raise ValueError(f"{where}: by = {by!r} {why}; allowed: a swept variable outside the [summary]'s over: "
                             f"{', '.join(groups) or 'none (every swept variable is in over: leave by out)'}")
        other = [n for n in groups if n != by]
        if other:
            raise ValueError(f"{where}: by = {by!r}, but the swept {', '.join(other)} is neither by nor in the "
                             f"[summary]'s over: each box would mix its values; leave by out (a box per case group) "
                             f"or add it to over")
