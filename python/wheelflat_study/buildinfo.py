"""What an installation of the wheelflat package holds: the software version, the git
commit it was built from, the case runner's version and CoupledSystem GUID, and each
FMU's version and GUID (from its modelDescription.xml). ``python/setup.py`` writes this
record into the wheel (``_data/build.json``) when it packs the runner and the FMUs;
``wheelflat-study --version`` prints it, and a checkout makes it from its build."""

import json
import os
import subprocess
import xml.etree.ElementTree as ET
import zipfile



def fmu_names(fmu_dir):
    """The FMUs' model identifiers the packer listed beside them (``fmus.json``)."""
    with open(os.path.join(fmu_dir, "fmus.json")) as fh:
        return json.load(fh)["fmus"]


def fmu_identity(path):
    """An FMU's {"version", "guid"}, from its modelDescription.xml."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    return {"version": root.get("version"), "guid": root.get("guid")}


def runner_identity(runner):
    """The case runner's {"version", "guid"} (CoupledSystem's), from its answer to a
    case it refuses."""
    r = subprocess.run([runner], input="duration=0\n", capture_output=True, text=True, timeout=60)
    rec = json.loads(r.stdout.splitlines()[0])
    return {"version": rec.get("version"), "guid": rec.get("guid")}


def collect(runner, fmu_dir, root=None):
    """The record for the runner at `runner` and the FMUs in `fmu_dir` (those there);
    `root`: the checkout, for the git commit."""
    info = {"runner": runner_identity(runner), "fmus": {}}
    info["version"] = info["runner"]["version"]
    for name in fmu_names(fmu_dir):
        path = os.path.join(fmu_dir, name + ".fmu")
        if os.path.isfile(path):
            info["fmus"][name] = fmu_identity(path)
    if root is not None:
        try:
            info["commit"] = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                                            text=True, check=True).stdout.strip()
            dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=root,
                                   capture_output=True, text=True, check=True).stdout.strip()
            info["commit_modified"] = bool(dirty)
        except (OSError, subprocess.CalledProcessError):
            pass
    return info
