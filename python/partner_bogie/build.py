"""Builds the stand-in third-party bogie into co-simulation FMUs: FMI 2.0 with pythonfmu
(standin_half_car.py, StandinHalfCar.fmu) and FMI 3.0 with pythonfmu3
(standin_half_car3.py, StandinHalfCar3.fmu); python/requirements.txt pins both. Each FMU
carries its script and the model both step, standin_bogie.py.

    .venv/bin/python python/partner_bogie/build.py [DEST_DIR] [--fmi 2|3] [--force]

prints the FMU's path. By default it goes to target/partner_bogie/<model>.fmu
(target/ is ignored by git; $CARGO_TARGET_DIR moves it, as wheelflat_fmus.TARGET_DIR).
The build is skipped when the FMU there was built from the same sources with the same
exporter (a stamp beside it holds their hash); builds by two processes at once each
write a temporary file and rename it into place.

A pythonfmu (pythonfmu3) FMU embeds no interpreter: its binary (the exporter's
libpythonfmu-export.so) leaves every CPython symbol undefined and needs no libpython of
its own, so it runs in a process that already is Python with the libpython symbols
global (fmpy, libcosimpy, ecospy here, in .venv's interpreter, pyenv's shared
libpython3.11) and imports the model and numpy from that interpreter's sys.path.
"""

import hashlib
import importlib
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import wheelflat_fmus as wf  # noqa: E402

# The model both exports step (numpy only), carried in each FMU beside its script.
MODEL_SOURCE = os.path.join(HERE, "standin_bogie.py")
# Per FMI version: the script, the model identifier, the exporter's package, options of
# its builder.
EXPORTS = {
    2: dict(source=os.path.join(HERE, "standin_half_car.py"), model="StandinHalfCar", exporter="pythonfmu",
            options={}),
    # pythonfmu3 0.3.4 writes canHandleVariableCommunicationStepSize as the last of its
    # common options (canSerializeFMUState, false): set it, the bogie takes any step.
    3: dict(source=os.path.join(HERE, "standin_half_car3.py"), model="StandinHalfCar3", exporter="pythonfmu3",
            options={"canHandleVariableCommunicationStepSize": True}),
}
# The FMI 2.0 export's, as before the FMI 3.0 one came.
SOURCE = EXPORTS[2]["source"]
MODEL = EXPORTS[2]["model"]
DEFAULT_DIR = os.path.join(wf.TARGET_DIR, "partner_bogie")


def _stamp(fmi=2):
    e = EXPORTS[fmi]
    exporter = importlib.import_module(e["exporter"])
    h = hashlib.sha256()
    for path in (e["source"], MODEL_SOURCE):
        h.update(open(path, "rb").read())
    h.update(f"{e['exporter']} {exporter.__version__}".encode())
    return h.hexdigest()


def build(dest_dir=None, force=False, fmi=2):
    """Builds the FMI `fmi` (2 or 3) export into `dest_dir` (default
    target/partner_bogie/) unless the one there is up to date; returns its path."""
    e = EXPORTS[fmi]
    builder = importlib.import_module(e["exporter"] + ".builder").FmuBuilder

    dest_dir = os.path.abspath(dest_dir or DEFAULT_DIR)
    os.makedirs(dest_dir, exist_ok=True)
    fmu = os.path.join(dest_dir, e["model"] + ".fmu")
    stamp_file = fmu + ".stamp"
    stamp = _stamp(fmi)
    if not force and os.path.exists(fmu) and os.path.exists(stamp_file) and open(stamp_file).read() == stamp:
        return fmu
    tmp = tempfile.mkdtemp(prefix="standin_build_", dir=dest_dir)
    try:
        built = builder.build_FMU(e["source"], dest=tmp, project_files=[MODEL_SOURCE], **e["options"])
        os.replace(built, fmu)
        with open(stamp_file + ".tmp%d" % os.getpid(), "w") as f:
            f.write(stamp)
        os.replace(stamp_file + ".tmp%d" % os.getpid(), stamp_file)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        # The exporter imports the model to write its description: forget it, so that an
        # FMU loaded in this process imports its own copy.
        for name in ("standin_half_car", "standin_half_car3", "standin_bogie"):
            sys.modules.pop(name, None)
    return fmu


def build3(dest_dir=None, force=False):
    """:func:`build` of the FMI 3.0 export (pythonfmu3): StandinHalfCar3.fmu."""
    return build(dest_dir, force, fmi=3)


if __name__ == "__main__":
    import argparse
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description="Builds the stand-in third-party half-car bogie FMU with pythonfmu "
                                             "(FMI 2.0) or pythonfmu3 (FMI 3.0); prints its path.")
    ap.add_argument("dest", nargs="?", default=None, help=f"folder (default {os.path.relpath(DEFAULT_DIR)})")
    ap.add_argument("--fmi", type=int, choices=(2, 3), default=2, help="FMI version (default 2)")
    ap.add_argument("--force", action="store_true", help="build even when up to date")
    a = ap.parse_args()
    print(build(a.dest, a.force, a.fmi))
