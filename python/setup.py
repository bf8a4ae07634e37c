"""Builds the wheelflat wheel from this checkout (see pyproject.toml): the Python
package plus, under ``wheelflat_study/_data``, the case runner (``bin/wheelflat_case``),
the FMUs (``fmu/``) and ``build.json``, the record of their versions and GUIDs, the
newest glibc symbol version they need and the git commit. Both come from the one build
of the FMUs, scripts/build_fmus_glibc228.sh (the README's main command's), against the
glibc 2.28 baseline (quick when up to date; it packs fmu/ again); the wheel is refused
when anything in it needs a newer glibc. The wheel is tagged for this platform
(py3-none-linux_x86_64): it holds a native program."""

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


def cargo_version():
    """The package's version: the crate's (Cargo.toml), so the wheel, the runner and
    the FMUs carry one version."""
    with open(os.path.join(ROOT, "Cargo.toml")) as fh:
        return re.search(r'^version\s*=\s*"([^"]+)"', fh.read(), re.M).group(1)


def built():
    """The case runner, the FMUs' folder and the newest glibc symbol version they need
    (e.g. "2.28"), built through scripts/build_fmus_glibc228.sh."""
    if not os.path.isfile(os.path.join(ROOT, "Cargo.toml")):
        sys.exit("the wheelflat wheel is built from a checkout of the repository (python/ inside it)")
    sys.path.insert(0, HERE)
    import wheelflat_fmus as wf
    try:
        paths = wf.build_fmus()
    except (OSError, subprocess.CalledProcessError) as e:
        sys.exit(f"building the wheelflat wheel: {wf.BUILD_SCRIPT} failed ({e}); it needs bash, Rust's cargo "
                 "(https://rustup.rs), pip and binutils")
    needed = set()
    for path in [wf.RUNNER_228] + list(paths.values()):
        needed |= wf.glibc_versions(path)
    newest = max(needed)
    if newest > wf.GLIBC_BASELINE:
        sys.exit(f"the wheel's runner or FMUs need glibc {'.'.join(map(str, newest))}, above the baseline "
                 f"{'.'.join(map(str, wf.GLIBC_BASELINE))}")
    return wf.RUNNER_228, wf.FMU_DIR, ".".join(map(str, newest))


def wf_registry(fmu_dir):
    """The packer's list of the FMUs and the vehicle registry beside them."""
    import json
    with open(os.path.join(fmu_dir, "fmus.json")) as fh:
        return json.load(fh)


class build_with_runner(build_py):
    """build_py, then the runner, the FMUs and their record into the package."""

    def run(self):
        super().run()
        sys.path.insert(0, HERE)
        from wheelflat_study.buildinfo import collect
        runner, fmu_dir, glibc = built()
        data = os.path.join(self.build_lib, "wheelflat_study", "_data")
        os.makedirs(os.path.join(data, "bin"), exist_ok=True)
        os.makedirs(os.path.join(data, "fmu"), exist_ok=True)
        dest = os.path.join(data, "bin", "wheelflat_case")
        shutil.copyfile(runner, dest)
        os.chmod(dest, 0o755)
        # The FMUs and the vehicle registry (fmus.json) the packer wrote.
        shutil.copyfile(os.path.join(fmu_dir, "fmus.json"), os.path.join(data, "fmu", "fmus.json"))
        for name in wf_registry(fmu_dir)["fmus"]:
            shutil.copyfile(os.path.join(fmu_dir, name + ".fmu"), os.path.join(data, "fmu", name + ".fmu"))
        import json
        info = collect(dest, os.path.join(data, "fmu"), ROOT)
        info["glibc_needed"] = glibc
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
