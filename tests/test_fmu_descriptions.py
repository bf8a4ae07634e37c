"""FMU tests with fmpy: the model descriptions (fmpy's validation, units, license), the C
header and the exported functions, the documentation pages and icons, each binary and
its GUIDs, the libraries loaded with RTLD_GLOBAL. Run by the README's test command (after
the FMUs are built); the helpers are in fmu_helpers.py, the ``paths`` fixture in
conftest.py."""

import ctypes
import glob
import html.parser
import os
import re
import subprocess
import sys
import zipfile

import pytest

from fmpy.fmi2 import fmi2CallbackFunctions
from fmpy.validation import validate_fmu

from fmu_helpers import FMI2_CS_FUNCTIONS, Log, wf



# ------------------------------------------------------------------ model descriptions and header

@pytest.mark.parametrize("name", ["TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon"])
def test_fmpy_validate_reports_nothing(paths, name):
    assert validate_fmu(paths[name]) == []


def test_header_compiles_against_official_fmi2Functions_h(tmp_path):
    import fmpy
    official = os.path.join(os.path.dirname(fmpy.__file__), "c-code")
    assert os.path.exists(os.path.join(official, "fmi2Functions.h"))
    header = os.path.join(wf.FMU_DIR, "include", "wheelflat_fmi2.h")
    text = open(header).read()
    for f in FMI2_CS_FUNCTIONS:
        assert f" {f}(" in text or f"*{f}(" in text, f"{f} missing from the generated header"
    src = tmp_path / "check.c"
    # Each declaration of our header must agree with the official one, or the C compiler
    # reports conflicting types.
    src.write_text('#include "fmi2Functions.h"\n#include "wheelflat_fmi2.h"\nint main(void) { return 0; }\n')
    r = subprocess.run(["cc", "-std=c99", "-Wall", "-Werror", "-pedantic", "-fsyntax-only",
                        "-I", official, "-I", os.path.dirname(header), str(src)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # A deliberately wrong declaration is caught, so the check has teeth.
    bad = tmp_path / "bad.c"
    bad.write_text('#include "fmi2Functions.h"\nfmi2Status fmi2DoStep(fmi2Component c, fmi2Real t);\n')
    r = subprocess.run(["cc", "-fsyntax-only", "-I", official, str(bad)], capture_output=True, text=True)
    assert r.returncode != 0


def test_shared_library_exports_every_fmi2_cs_function(paths):
    lib = glob.glob(os.path.join(wf.TARGET_DIR, "release", "libwheelflat.so"))[0]
    out = subprocess.run(["nm", "-D", "--defined-only", lib], capture_output=True, text=True, check=True).stdout
    names = {line.split()[-1] for line in out.splitlines() if line.strip()}
    assert set(FMI2_CS_FUNCTIONS) <= names


def official_fmi3_functions():
    """The functions the official fmi3Functions.h (shipped with fmpy) declares: its
    ``FMI3_Export fmi3XTYPE fmi3X;`` lines (75 of them), and the headers' folder."""
    import fmpy
    official = os.path.join(os.path.dirname(fmpy.__file__), "c-code")
    text = open(os.path.join(official, "fmi3Functions.h")).read()
    names = re.findall(r"^FMI3_Export\s+(fmi3\w+)TYPE\s+\1;", text, re.M)
    assert len(names) == 75, names
    return official, names


def test_fmi3_header_compiles_against_official_fmi3Functions_h(tmp_path):
    official, names = official_fmi3_functions()
    header = os.path.join(wf.FMU_DIR, "include", "wheelflat_fmi3.h")
    text = open(header).read()
    # Every function of the standard is declared (the refused ones too), so the compiler
    # checks each one's prototype below.
    for f in names:
        assert f" {f}(" in text or f"*{f}(" in text, f"{f} missing from the generated header"
    # The header names the standard's types; the Rust types behind those names
    # (src/fmu/ffi3/types.rs) must have their sizes (an enum's is C int's).
    c_of = {"f32": "float", "f64": "double", "i8": "int8_t", "u8": "uint8_t", "i16": "int16_t",
            "u16": "uint16_t", "i32": "int32_t", "u32": "uint32_t", "i64": "int64_t", "u64": "uint64_t",
            "bool": "bool", "c_int": "int", "usize": "size_t"}
    aliases = re.findall(r"^pub type (fmi3\w+) =\s*([^;]+);", open(os.path.join(wf.ROOT, "src/fmu/ffi3/types.rs")).read(), re.M)
    assert len(aliases) >= 25, aliases
    asserts = "".join(f'_Static_assert(sizeof({name}) == sizeof({c_of.get(rust, "void *")}), "{name}");\n'
                      for name, rust in aliases)
    src = tmp_path / "check.c"
    src.write_text('#include "fmi3Functions.h"\n#include "wheelflat_fmi3.h"\n' + asserts + 'int main(void) { return 0; }\n')
    r = subprocess.run(["cc", "-std=c11", "-Wall", "-Werror", "-pedantic", "-fsyntax-only",
                        "-I", official, "-I", os.path.dirname(header), str(src)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    # A deliberately wrong declaration is caught, so the check has teeth: an enum's array
    # as int32_t (fmi3IntervalQualifier is an enum), and a missing argument.
    for wrong in ["fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference v[],"
                  " size_t n, fmi3Float64 intervals[], int32_t qualifiers[]);",
                  "fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 t, fmi3Float64 h);"]:
        bad = tmp_path / "bad.c"
        bad.write_text(f'#include "fmi3Functions.h"\n{wrong}\n')
        r = subprocess.run(["cc", "-fsyntax-only", "-I", official, str(bad)], capture_output=True, text=True)
        assert r.returncode != 0 and "conflicting types" in r.stderr, wrong


def test_shared_library_exports_every_fmi3_function(paths):
    _, names = official_fmi3_functions()
    lib = glob.glob(os.path.join(wf.TARGET_DIR, "release", "libwheelflat.so"))[0]
    out = subprocess.run(["nm", "-D", "--defined-only", lib], capture_output=True, text=True, check=True).stdout
    exported = {line.split()[-1] for line in out.splitlines() if line.split()[1:2] == ["T"]}
    assert set(names) - exported == set()
    # And nothing beyond the standard under its prefix.
    assert {n for n in exported if n.startswith("fmi3")} == set(names)


class HtmlTables(html.parser.HTMLParser):
    """The rows of a page's tables as lists of cell texts; fails on an element closed
    out of order (void elements excepted)."""

    VOID = {"area", "base", "br", "col", "embed", "hr", "img", "input", "link", "meta", "source", "track", "wbr"}

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.rows, self.open, self.cell = [], [], None
        self.feed(text)
        self.close()
        assert self.open == [], f"unclosed elements: {self.open}"

    def handle_starttag(self, tag, attrs):
        if tag not in self.VOID:
            self.open.append(tag)
        if tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self.cell = ""

    def handle_endtag(self, tag):
        assert self.open and self.open[-1] == tag, f"</{tag}> closes {self.open[-1:]}"
        self.open.pop()
        if tag in ("td", "th"):
            self.rows[-1].append(self.cell)
            self.cell = None

    def handle_data(self, data):
        if self.cell is not None:
            self.cell += data


@pytest.mark.parametrize("name", ["TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon"])
def test_documentation_lists_every_variable_with_its_unit(paths, name):
    from fmpy import read_model_description
    with zipfile.ZipFile(paths[name]) as z:
        page = z.read("documentation/index.html").decode("utf-8")
    assert page.startswith("<!DOCTYPE html>")
    md = read_model_description(paths[name])
    assert md.guid in page
    header = ["name", "causality", "variability", "type", "unit", "start", "min/max", "description"]
    tables = HtmlTables(page).rows
    assert header in tables
    rows = {r[0]: r for r in tables if len(r) == len(header) and r != header}
    assert sorted(rows) == sorted(v.name for v in md.modelVariables)
    for v in md.modelVariables:
        row = dict(zip(header, rows[v.name]))
        unit = f"{v.unit} ({v.displayUnit})" if v.unit and v.displayUnit else (v.unit or "")
        assert row["unit"] == unit, v.name
        assert (row["causality"], row["variability"]) == (v.causality, v.variability), v.name
        assert row["description"] == (v.description or ""), v.name


@pytest.mark.parametrize("name", ["TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon"])
def test_model_descriptions_declare_the_units_they_use_and_a_license(paths, name):
    import xml.etree.ElementTree as ET
    with zipfile.ZipFile(paths[name]) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    assert root.get("license") == "MIT" and "Copyright" in root.get("copyright")
    declared = {u.get("name") for u in root.iter("Unit")}
    used = {r.get("unit") for r in root.iter("Real") if r.get("unit")}
    assert declared == used, (declared - used, used - declared)


@pytest.mark.parametrize("name", ["TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon"])
def test_each_fmu_carries_its_icon(paths, name):
    import io
    import matplotlib.image as mpimg
    with zipfile.ZipFile(paths[name]) as z:
        img = mpimg.imread(io.BytesIO(z.read("model.png")), format="png")
    assert img.shape == (128, 128, 4)
    assert (img[:, :, 3] > 0).mean() > 0.15  # a drawing, not an empty picture

# ------------------------------------------------------------------ binaries and GUIDs

def test_wrong_guid_is_refused(paths):
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(paths["TrackContact"])
    d = extract(paths["TrackContact"])
    fmu = FMU2Slave(guid="{00000000-0000-0000-0000-000000000000}", unzipDirectory=d,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="x")
    log = Log()
    with pytest.raises(Exception):
        fmu.instantiate(callbacks=log.callbacks)
    assert "matches none of" in log.text()


@pytest.mark.parametrize("name", ["TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon"])
def test_each_fmu_binary_instantiates_only_its_own_guid(paths, name):
    """The three FMUs carry the same library; inside an FMU it is named after the model
    identifier, and takes only that FMU's GUID."""
    import shutil
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    guids = {n: read_model_description(p).guid for n, p in paths.items()}
    d = extract(paths[name])
    try:
        for other, guid in guids.items():
            log = Log()
            fmu = FMU2Slave(guid=guid, unzipDirectory=d, modelIdentifier=name, instanceName="x")
            if other == name:
                fmu.instantiate(callbacks=log.callbacks)
                fmu.freeInstance()
                continue
            with pytest.raises(Exception):
                fmu.instantiate(callbacks=log.callbacks)
            assert log.records[-1][0] == 3
            assert log.text() == (f'fmi2Instantiate: GUID "{guid}" belongs to {other}, but this binary '
                                  f'is {name} (GUID {guids[name]}): instantiate {other} from its own FMU')
            fmu.freeLibrary()
    finally:
        shutil.rmtree(d, ignore_errors=True)


def test_development_library_instantiates_every_guid(paths):
    from fmpy import read_model_description
    lib = ctypes.CDLL(os.path.join(wf.TARGET_DIR, "release", "libwheelflat.so"))
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_char_p,
                                    ctypes.POINTER(fmi2CallbackFunctions), ctypes.c_int, ctypes.c_int]
    lib.fmi2FreeInstance.argtypes = [ctypes.c_void_p]
    log = Log()
    for p in paths.values():
        guid = read_model_description(p).guid.encode()
        c = lib.fmi2Instantiate(b"dev", 1, guid, b"", ctypes.byref(log.callbacks), 0, 0)
        assert c, log.text()
        lib.fmi2FreeInstance(c)
    assert not lib.fmi2Instantiate(b"dev", 1, b"{0}", b"", ctypes.byref(log.callbacks), 0, 0)
    assert "matches none of TrackContact" in log.text()


# ------------------------------------------------------------------ issue 25

RTLD_GLOBAL_SCRIPT = r'''
import ctypes, math, os, random, sys, tempfile, zipfile
from fmpy import read_model_description
from fmpy.fmi2 import (fmi2CallbackFunctions, fmi2CallbackLoggerTYPE,
                       fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE)
seed = int(sys.argv[1])
paths = dict(arg.split("=", 1) for arg in sys.argv[2:])
msgs = []
cb = fmi2CallbackFunctions()
cb.logger = fmi2CallbackLoggerTYPE(lambda c, i, s, cat, m: msgs.append((s, m.decode(errors="replace"))))
cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(lambda n, s: None)
cb.freeMemory = fmi2CallbackFreeMemoryTYPE(lambda p: None)
libs = []
for name, path in paths.items():
    d = tempfile.mkdtemp()
    with zipfile.ZipFile(path) as z:
        z.extractall(d)
    lib = ctypes.CDLL(os.path.join(d, "binaries", "linux64", name + ".so"), mode=ctypes.RTLD_GLOBAL)
    lib.fmi2Instantiate.restype = ctypes.c_void_p
    libs.append((name, lib, read_model_description(path), d))
D, U, I = ctypes.c_double, ctypes.c_uint, ctypes.c_int
rng = random.Random(seed)
bad = []
units = []
for name, lib, md, d in libs:
    c = lib.fmi2Instantiate(b"x", 1, md.guid.encode(), ("file://" + d + "/resources").encode(),
                            ctypes.byref(cb), 0, 0)
    if not c:
        print(name, "refused:", msgs[-1:])
        continue
    c = ctypes.c_void_p(c)
    init = [lib.fmi2SetupExperiment(c, 0, D(0.0), D(0.0), 0),
            lib.fmi2EnterInitializationMode(c), lib.fmi2ExitInitializationMode(c),
            lib.fmi2DoStep(c, D(0.0), D(1e-4), 1)]
    print(name, "statuses", init)
    inputs = [v for v in md.modelVariables if v.causality == "input" and v.type == "Real"]
    outputs = [v for v in md.modelVariables if v.causality == "output" and v.type == "Real"]
    units.append([name, lib, md, c, inputs, outputs, 1e-4])
# Random calls, the derivative functions late and in any order among them, on all four
# libraries interleaved: statuses are FMI statuses, every non-OK one is logged, and no
# output read with fmi2OK is NaN or infinite.
for n in range(400):
    u = rng.choice(units)
    name, lib, md, c, inputs, outputs, t = u
    call = rng.choice(["set", "get", "step", "inder", "outder", "dirder"])
    before = len(msgs)
    if call == "set" and inputs:
        v = rng.choice(inputs)
        x = float(v.start) * (1 + rng.uniform(-1e-3, 1e-3)) if v.start else rng.uniform(-1e-3, 1e-3)
        s = lib.fmi2SetReal(c, (U * 1)(v.valueReference), 1, (D * 1)(x))
    elif call == "get":
        vrs = rng.sample(outputs, min(8, len(outputs)))
        out = (D * len(vrs))()
        s = lib.fmi2GetReal(c, (U * len(vrs))(*[v.valueReference for v in vrs]), len(vrs), out)
        if s == 0 and not all(math.isfinite(x) for x in out):
            bad.append((name, n, "non-finite output with fmi2OK"))
    elif call == "step":
        h = rng.choice([1e-5, 1.4413057013760613e-5, 1e-4, 1e-3])
        s = lib.fmi2DoStep(c, D(t), D(h), 1)
        if s in (0, 1):
            u[6] = t + h
    elif call == "inder" and inputs:
        v = rng.choice(inputs)
        s = lib.fmi2SetRealInputDerivatives(c, (U * 1)(v.valueReference), 1, (I * 1)(rng.choice([1, 2])),
                                            (D * 1)(rng.uniform(-1e-2, 1e-2)))
    elif call == "outder":
        v = rng.choice(outputs)
        out = (D * 1)()
        s = lib.fmi2GetRealOutputDerivatives(c, (U * 1)(v.valueReference), 1, (I * 1)(1), out)
        if s == 0 and not math.isfinite(out[0]):
            bad.append((name, n, "non-finite output derivative with fmi2OK"))
    elif call == "dirder" and inputs:
        v, w = rng.choice(outputs), rng.choice(inputs)
        out = (D * 1)()
        s = lib.fmi2GetDirectionalDerivative(c, (U * 1)(v.valueReference), 1, (U * 1)(w.valueReference), 1,
                                             (D * 1)(1.0), out)
        if s == 0 and not math.isfinite(out[0]):
            bad.append((name, n, "non-finite directional derivative with fmi2OK"))
    else:
        continue
    if s not in (0, 1, 2, 3):
        bad.append((name, n, call, "status", s))
    if s != 0 and len(msgs) == before:
        bad.append((name, n, call, "status", s, "without a message"))
for name, lib, md, c, *_ in units:
    lib.fmi2FreeInstance(c)
print("bad", bad)
'''


def test_every_fmu_instantiates_with_the_libraries_loaded_rtld_global(paths):
    # Issue 25: with RTLD_GLOBAL, dladdr on an exported function named the first library
    # loaded, so the others refused their own GUIDs. All five in one process. Then 400
    # random calls over the five, the derivative functions among them late and in any
    # order.
    r = subprocess.run([sys.executable, "-c", RTLD_GLOBAL_SCRIPT, "25"] + [f"{n}={p}" for n, p in paths.items()],
                       capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(paths) == 5 and len(lines) == len(paths) + 1, r.stdout
    for line in lines[:-1]:
        assert line.endswith("statuses [0, 0, 0, 0]"), r.stdout
    assert lines[-1] == "bad []", r.stdout
