"""The one build of the FMUs: what the README's main command (``python3 python/couple.py``)
leaves in fmu/ is the portable build, the shared library against the glibc 2.28
baseline (docs/guide/fmus.md, "Where the FMUs run"). Run by the README's test command."""

import os
import platform
import subprocess
import sys
import time
import zipfile

from fmu_helpers import wf

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def test_the_main_command_leaves_fmus_that_need_no_glibc_symbol_version_above_2_28(tmp_path):
    # The main command itself, on a short run: it builds (through
    # scripts/build_fmus_glibc228.sh) and packs fmu/ before it couples the pair.
    start = time.time()
    r = subprocess.run([sys.executable, os.path.join(ROOT, "python", "couple.py"), "--stop", "0.002",
                        "--out", str(tmp_path)], cwd=ROOT, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "peak contact force, left wheel" in r.stdout
    libraries = {}
    for name in wf.registry()["fmus"]:
        path = os.path.join(wf.FMU_DIR, name + ".fmu")
        # Packed by this run, not left from an earlier one (1 s for coarse timestamps).
        assert os.path.getmtime(path) >= start - 1, f"{path} was not packed by the main command"
        with zipfile.ZipFile(path) as z:
            [member] = [m for m in z.namelist() if m.startswith("binaries/")]
            assert member == f"binaries/linux64/{name}.so"
            libraries[name] = z.read(member)
    # Every FMU carries the same library.
    assert len(set(libraries.values())) == 1
    so = tmp_path / "TrackContact.so"
    so.write_bytes(libraries["TrackContact"])
    needed = wf.glibc_versions(str(so))
    assert needed, "objdump -T found no glibc symbol version: the check would pass anything"
    assert max(needed) <= (2, 28), "above GLIBC_2.28: " + ", ".join(
        f"GLIBC_{'.'.join(map(str, v))}" for v in sorted(needed) if v > (2, 28))

    # The same reading of objdump -T finds what a plain `cargo build` on this machine
    # needs (glibc 2.34's dladdr and pthread_key_*, 2.35's hypot): the check has teeth.
    host = os.path.join(wf.TARGET_DIR, "release", "libwheelflat.so")
    if os.path.exists(host) and tuple(map(int, platform.libc_ver()[1].split("."))) >= (2, 34):
        assert max(wf.glibc_versions(host)) >= (2, 34)
