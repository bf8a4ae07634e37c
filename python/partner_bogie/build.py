"""Builds the stand-in third-party bogie (standin_half_car.py) into an FMI 2.0
co-simulation FMU with pythonfmu (python/requirements.txt pins it).

    .venv/bin/python python/partner_bogie/build.py [DEST_DIR]

prints the FMU's path. By default it goes to target/partner_bogie/StandinHalfCar.fmu
(target/ is ignored by git; $CARGO_TARGET_DIR moves it, as wheelflat_fmus.TARGET_DIR).
The build is skipped when the FMU there was built from the same source with the same
pythonfmu (a stamp beside it holds their hash); builds by two processes at once each
write a temporary file and rename it into place.

A pythonfmu FMU embeds no interpreter: its binary (pythonfmu's libpythonfmu-export.so)
leaves every CPython symbol undefined and needs no libpython of its own, so it runs
in a process that already is Python with the libpython symbols global (fmpy,
libcosimpy, ecospy here, in .venv's interpreter, pyenv's shared libpython3.11) and
imports the model and numpy from that interpreter's sys.path.
"""

import hashlib
import os
import shutil
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
import wheelflat_fmus as wf  # noqa: E402

SOURCE = os.path.join(HERE, "standin_half_car.py")
MODEL = "StandinHalfCar"
DEFAULT_DIR = os.path.join(wf.TARGET_DIR, "partner_bogie")


def _stamp():
    import pythonfmu
    h = hashlib.sha256(open(SOURCE, "rb").read())
    h.update(f"pythonfmu {pythonfmu.__version__}".encode())
    return h.hexdigest()


def build(dest_dir=None, force=False):
    """Builds StandinHalfCar.fmu into `dest_dir` (default target/partner_bogie/) unless
    the one there is up to date; returns its path."""
    from pythonfmu.builder import FmuBuilder

    dest_dir = os.path.abspath(dest_dir or DEFAULT_DIR)
    os.makedirs(dest_dir, exist_ok=True)
    fmu = os.path.join(dest_dir, MODEL + ".fmu")
    stamp_file = fmu + ".stamp"
    stamp = _stamp()
    if not force and os.path.exists(fmu) and os.path.exists(stamp_file) and open(stamp_file).read() == stamp:
        return fmu
    tmp = tempfile.mkdtemp(prefix="standin_build_", dir=dest_dir)
    try:
        built = FmuBuilder.build_FMU(SOURCE, dest=tmp)
        os.replace(built, fmu)
        with open(stamp_file + ".tmp%d" % os.getpid(), "w") as f:
            f.write(stamp)
        os.replace(stamp_file + ".tmp%d" % os.getpid(), stamp_file)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
        # pythonfmu imports the model to write its description: forget it, so that an
        # FMU loaded in this process imports its own copy.
        sys.modules.pop("standin_half_car", None)
    return fmu


if __name__ == "__main__":
    import argparse
    wf.ensure_venv()
    ap = argparse.ArgumentParser(description="Builds the stand-in third-party half-car bogie FMU with pythonfmu; "
                                             "prints its path.")
    ap.add_argument("dest", nargs="?", default=None, help=f"folder (default {os.path.relpath(DEFAULT_DIR)})")
    ap.add_argument("--force", action="store_true", help="build even when up to date")
    a = ap.parse_args()
    print(build(a.dest, a.force))
