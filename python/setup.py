"""Builds the wheelflat wheel from this checkout (see pyproject.toml): the Python
package plus, under ``wheelflat_study/_data``, the case runner (``bin/wheelflat_case``),
the five FMUs (``fmu/``) and ``build.json``, the record of their versions and GUIDs and
the git commit. cargo builds the runner and the FMUs' library first (quick when they
are up to date); fmu/*.fmu are packed again when older than the library. The wheel is
tagged for this platform (py3-none-linux_x86_64): it holds a native program."""

import os
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.bdist_wheel import bdist_wheel
from setuptools.command.build_py import build_py

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
FMUS = ("TrackContact", "RollPlaneVehicle", "CoupledSystem", "HalfCarBogie", "Wagon")


def cargo_version():
    """The package's version: the crate's (Cargo.toml), so the wheel, the runner and
    the FMUs carry one version."""
    with open(os.path.join(ROOT, "Cargo.toml")) as fh:
        return re.search(r'^version\s*=\s*"([^"]+)"', fh.read(), re.M).group(1)


def built():
    """The case runner and the FMUs' folder, built with cargo when needed."""
    if not os.path.isfile(os.path.join(ROOT, "Cargo.toml")):
        sys.exit("the wheelflat wheel is built from a checkout of the repository (python/ inside it)")
    target = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR") or "target", "release")
    try:
        subprocess.check_call(["cargo", "build", "--release", "--quiet", "--lib", "--bin", "wheelflat_case",
                               "--bin", "build_fmus"], cwd=ROOT)
    except OSError:
        sys.exit("building the wheelflat wheel needs Rust's cargo on PATH (https://rustup.rs)")
    fmu_dir = os.path.join(ROOT, "fmu")
    library = os.path.join(target, "libwheelflat.so")
    fmus = [os.path.join(fmu_dir, n + ".fmu") for n in FMUS]
    if not all(os.path.isfile(f) and os.path.getmtime(f) >= os.path.getmtime(library) for f in fmus):
        subprocess.check_call([os.path.join(target, "build_fmus"), fmu_dir], cwd=ROOT, stdout=subprocess.DEVNULL)
    return os.path.join(target, "wheelflat_case"), fmu_dir


class build_with_runner(build_py):
    """build_py, then the runner, the FMUs and their record into the package."""

    def run(self):
        super().run()
        sys.path.insert(0, HERE)
        from wheelflat_study.buildinfo import collect
        runner, fmu_dir = built()
        data = os.path.join(self.build_lib, "wheelflat_study", "_data")
        os.makedirs(os.path.join(data, "bin"), exist_ok=True)
        os.makedirs(os.path.join(data, "fmu"), exist_ok=True)
        dest = os.path.join(data, "bin", "wheelflat_case")
        shutil.copyfile(runner, dest)
        os.chmod(dest, 0o755)
        for name in FMUS:
            shutil.copyfile(os.path.join(fmu_dir, name + ".fmu"), os.path.join(data, "fmu", name + ".fmu"))
        import json
        info = collect(dest, os.path.join(data, "fmu"), ROOT)
        with open(os.path.join(data, "build.json"), "w") as fh:
            json.dump(info, fh, indent=1)


class platform_wheel(bdist_wheel):
    """A wheel for this platform, any Python 3: it holds a native program, no extension."""

    def finalize_options(self):
        super().finalize_options()
        self.root_is_pure = False

    def get_tag(self):
        _, _, platform = super().get_tag()
        return "py3", "none", platform


setup(version=cargo_version(), cmdclass={"build_py": build_with_runner, "bdist_wheel": platform_wheel})
