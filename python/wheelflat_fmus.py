"""Helpers for the wheelflat FMUs: a local virtual environment with fmpy, building the
FMUs (through scripts/build_fmus_glibc228.sh, for the glibc 2.28 baseline), and the
coupling of TrackContact with RollPlaneVehicle through fmpy's FMU2Slave in the order of
MODEL.md.

The static-equilibrium handshake (in initialization mode):
  1. vehicle -> track: ``static_load.left``, ``static_load.right`` (N);
  2. track -> vehicle: ``static_wheel_z.left``, ``static_wheel_z.right`` (m).
Then each communication point: vehicle outputs -> track inputs -> track outputs ->
vehicle inputs -> both step.
"""

import json
import os
import re
import subprocess
import sys
import tempfile
import venv
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# In a checkout (python/ inside the repository) the FMUs are built into fmu/;
# installed from the wheelflat wheel (python/pyproject.toml) they come with it.
CHECKOUT = os.path.isfile(os.path.join(ROOT, "Cargo.toml"))
VENV = os.path.join(ROOT, ".venv")
REQUIREMENTS = os.path.join(ROOT, "python", "requirements.txt")
FMU_DIR = os.path.join(ROOT, "fmu") if CHECKOUT else \
    os.path.join(os.path.dirname(os.path.abspath(__file__)), "wheelflat_study", "_data", "fmu")


def registry(fmu_dir=None):
    """The FMUs and the vehicle registry (src/vehicle/registry.rs) as the packer wrote
    them beside the FMUs (``fmus.json``): ``{"fmus": [model identifiers], "vehicles":
    [{"fmu", "item", "value", "wheelsets", "offsets"}]}``, each offset of a wheelset
    behind the leading one the sum of those parameters of the vehicle's FMU."""
    with open(os.path.join(fmu_dir or FMU_DIR, "fmus.json")) as fh:
        return json.load(fh)


def vehicle_kind(fmu, fmu_dir=None):
    """The registry's entry of the vehicle FMU `fmu`."""
    return next(k for k in registry(fmu_dir)["vehicles"] if k["fmu"] == fmu)
# Cargo's build directory: $CARGO_TARGET_DIR when set (relative to the repository), else target/.
TARGET_DIR = os.path.join(ROOT, os.environ.get("CARGO_TARGET_DIR") or "target")
# The one build of the FMUs, shared by the README's main command (build_fmus below), the
# test command and the wheel (python/setup.py): cargo-zigbuild against this glibc
# baseline (docs/guide/fmus.md, "Where the FMUs run"). The case runner it builds beside
# the library is RUNNER_228.
BUILD_SCRIPT = os.path.join(ROOT, "scripts", "build_fmus_glibc228.sh")
GLIBC_BASELINE = (2, 28)
RUNNER_228 = os.path.join(TARGET_DIR, "x86_64-unknown-linux-gnu", "release", "wheelflat_case")


def venv_python():
    return os.path.join(VENV, "bin", "python")


def install_venv():
    """Creates .venv with the pinned packages of python/requirements.txt, or brings it
    up to date when the requirements changed."""
    stamp = os.path.join(VENV, ".requirements")
    wanted = open(REQUIREMENTS).read()
    if not (os.path.exists(stamp) and open(stamp).read() == wanted):
        import time
        t0 = time.perf_counter()
        print("setting up .venv (python/requirements.txt: fmpy, numpy, matplotlib, pytest, dask, "
              "libcosimpy, ecospy, ...; pip's progress follows) ...", file=sys.stderr, flush=True)
        if not os.path.exists(venv_python()):
            venv.create(VENV, with_pip=True)
        # pip's lines (one per package) on stderr: this command's output stays its own.
        subprocess.check_call([venv_python(), "-m", "pip", "install", "--progress-bar", "off",
                               "--disable-pip-version-check", "-r", REQUIREMENTS], stdout=sys.stderr)
        with open(stamp, "w") as f:
            f.write(wanted)
        print(f".venv ready in {time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)


def ensure_venv():
    """Re-runs the current script inside .venv (installed when needed); installed from
    the wheel, the environment is the one it was installed into."""
    if not CHECKOUT or os.path.realpath(sys.prefix) == os.path.realpath(VENV):
        return
    install_venv()
    os.execv(venv_python(), [venv_python()] + sys.argv)


def build_fmus():
    """Builds the shared library against the glibc 2.28 baseline and packs fmu/*.fmu
    through scripts/build_fmus_glibc228.sh (cargo-zigbuild, release profile; cargo's
    progress on stderr, the packer's list dropped); the FMUs by name. Installed from the
    wheel: the FMUs that came with it, built the same way."""
    if CHECKOUT:
        import time
        t0 = time.perf_counter()
        subprocess.check_call(["bash", BUILD_SCRIPT, FMU_DIR], cwd=ROOT, stdout=subprocess.DEVNULL)
        if time.perf_counter() - t0 > 10:  # a build that did work: its stage and time
            print(f"built and packed the FMUs into {os.path.relpath(FMU_DIR)} in "
                  f"{time.perf_counter() - t0:.0f} s", file=sys.stderr, flush=True)
    return {name: os.path.join(FMU_DIR, name + ".fmu") for name in registry()["fmus"]}


def glibc_versions(path):
    """The glibc symbol versions, as tuples such as (2, 28), that the ELF file at `path`
    needs (objdump -T); for an .fmu, those of every library under its binaries/."""
    if path.endswith(".fmu"):
        found = set()
        with zipfile.ZipFile(path) as z, tempfile.TemporaryDirectory() as tmp:
            for member in z.namelist():
                if member.startswith("binaries/") and not member.endswith("/"):
                    found |= glibc_versions(z.extract(member, tmp))
        return found
    dump = subprocess.run(["objdump", "-T", path], capture_output=True, text=True, check=True).stdout
    return {tuple(int(x) for x in v.split(".")) for v in re.findall(r"\bGLIBC_([0-9]+(?:\.[0-9]+)*)", dump)}


def value_references(model_description):
    return {v.name: v.valueReference for v in model_description.modelVariables}


class Unit:
    """One FMU instance through fmpy's FMU2Slave."""

    def __init__(self, path, instance_name, callbacks=None, logging_on=False, unzip_dir=None):
        """unzip_dir: an already extracted FMU to share (its shared library is then
        loaded once for all units that share it); by default each unit extracts its own."""
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave

        self.path = path
        self.md = read_model_description(path)
        self.owns_dir = unzip_dir is None
        self.dir = extract(path) if unzip_dir is None else unzip_dir
        self.vr = value_references(self.md)
        self.types = {v.name: v.type for v in self.md.modelVariables}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.fmu.instantiate(callbacks=callbacks, loggingOn=logging_on)

    def get(self, *names):
        return list(self.fmu.getReal([self.vr[n] for n in names]))

    def set(self, names, values):
        self.fmu.setReal([self.vr[n] for n in names], list(values))

    def set_parameters(self, params):
        """Sets parameters by name (Real, Integer/Enumeration, or String: a table's text
        or path, by their declared type)."""
        for name, value in (params or {}).items():
            if self.types[name] == "String":
                self.fmu.setString([self.vr[name]], [str(value)])
            elif self.types[name] in ("Integer", "Enumeration"):
                self.fmu.setInteger([self.vr[name]], [int(value)])
            else:
                self.fmu.setReal([self.vr[name]], [float(value)])

    def close(self, terminate=True):
        """Terminates (FMI 2.0 allows it after stepping only: pass terminate=False in
        the other states) and frees the instance. A refused fmi2Terminate (a run that
        failed before it stepped) is passed over: the failure that stopped the run is
        the one to report, and the instance is freed all the same."""
        import shutil
        from fmpy.fmi1 import FMICallException
        try:
            if terminate:
                self.fmu.terminate()
        except FMICallException:
            pass
        finally:
            self.fmu.freeInstance()
            if self.owns_dir:
                shutil.rmtree(self.dir, ignore_errors=True)


WHEELS = ("wheel.left.z", "wheel.right.z", "wheel.rotation")
FORCES = ("contact.left.force", "contact.right.force")
TRACK_RECORD = ("contact.left.force", "contact.right.force", "contact.left.max_force", "contact.right.max_force",
                "rail.left.z", "rail.right.z", "position")


def close_all(*units):
    """Closes every unit, each even when closing another fails; the first failure is
    raised after every unit is freed and its folder removed. Called from a `finally`
    while a failure unwinds (a parameter refused in initialization, say), it frees
    without fmi2Terminate, which FMI 2.0 allows only after stepping."""
    first = None
    failing = sys.exc_info()[0] is not None
    for u in units:
        try:
            u.close(terminate=not failing)
        except Exception as e:  # noqa: BLE001 - raised below, once every unit is closed
            first = first or e
    if first is not None:
        raise first


def track_step(paths, track_params=None):
    """The track's internal step ``solver.step`` (s) for these parameters."""
    u = Unit(paths["TrackContact"], "probe")
    try:
        u.fmu.setupExperiment(startTime=0.0)
        u.set_parameters(track_params)
        u.fmu.enterInitializationMode()
        return u.get("solver.step")[0]
    finally:
        # Still in initialization mode, where fmi2Terminate is not allowed.
        u.close(terminate=False)


def static_handshake(track, vehicle, track_params=None, vehicle_params=None):
    """Parameters and the static-equilibrium handshake, leaving both in initialization
    mode: the vehicle's static wheel loads to the track, the track's static wheel
    heights back (:func:`carrier_handshake` of one wheelset)."""
    carrier_handshake(track, vehicle, 1, track_params, vehicle_params)


def initialise_pair(track, vehicle, track_params=None, vehicle_params=None):
    """Parameters, static-equilibrium handshake and the first exchange."""
    static_handshake(track, vehicle, track_params, vehicle_params)
    track.set(WHEELS, vehicle.get(*WHEELS))
    vehicle.set(FORCES, track.get(*FORCES))
    vehicle.fmu.exitInitializationMode()
    track.fmu.exitInitializationMode()


def units_of(fmus):
    """Every variable's unit ("N", "m", "rad"; "" where it has none) in the model
    descriptions of the FMUs at the paths `fmus`, by name."""
    from fmpy import read_model_description
    units = {}
    for path in fmus:
        for v in read_model_description(path).modelVariables:
            units.setdefault(v.name, v.unit or (v.declaredType.unit if v.declaredType else None) or "")
    return units


def case_of(track_fmu, params=None):
    """The case in words, "70 km/h, 100 mm x 1.5 mm flat": TrackContact's speed and
    its left wheel's first flat, its start values with `params` (SI units) set."""
    from fmpy import read_model_description
    start = {v.name: float(v.start) for v in read_model_description(track_fmu).modelVariables
             if v.start is not None and v.type in ("Real", "Integer", "Enumeration")}
    start.update(params or {})
    speed = start["speed"] * 3.6
    length, depth = start["flat.left[1].length"] * 1e3, start["flat.left[1].depth"] * 1e3
    flat = "no flat" if length == 0 else (f"{length:g} mm x {depth:g} mm flat" if depth
                                         else f"{length:g} mm flat, its depth from its length")
    return f"{speed:g} km/h, {flat}"


def run_pair(paths, stop_time, comm_step=None, track_params=None, vehicle_params=None,
             input_derivatives=False):
    """Couples TrackContact and RollPlaneVehicle; comm_step None takes the track's
    internal step (``solver.step``), which reproduces CoupledSystem exactly. With
    ``input_derivatives`` the vehicle's wheel velocities and axle rate
    (``fmi2GetRealOutputDerivatives``) go to the track with the wheel inputs
    (``fmi2SetRealInputDerivatives``), which then moves the wheels linearly over each
    step instead of holding them. Returns a dict of lists: time, the TRACK_RECORD
    outputs and the wheel outputs."""
    track = Unit(paths["TrackContact"], "track")
    vehicle = Unit(paths["RollPlaneVehicle"], "vehicle")
    try:
        initialise_pair(track, vehicle, track_params, vehicle_params)
        h = comm_step if comm_step is not None else track.get("solver.step")[0]
        n = int(round(stop_time / h))
        out = {k: [] for k in ("time",) + TRACK_RECORD + WHEELS}
        t = 0.0
        wheel_vrs = ([vehicle.vr[w] for w in WHEELS], [track.vr[w] for w in WHEELS])
        for k in range(n + 1):
            z = vehicle.get(*WHEELS)
            track.set(WHEELS, z)
            if input_derivatives:
                rates = vehicle.fmu.getRealOutputDerivatives(wheel_vrs[0], [1, 1, 1])
                track.fmu.setRealInputDerivatives(wheel_vrs[1], [1, 1, 1], list(rates))
            rec = track.get(*TRACK_RECORD)
            vehicle.set(FORCES, rec[:2])
            out["time"].append(t)
            for name, x in zip(TRACK_RECORD + WHEELS, rec + z):
                out[name].append(x)
            if k == n:
                break
            track.fmu.doStep(t, h)
            vehicle.fmu.doStep(t, h)
            t = (k + 1) * h
        return out
    finally:
        close_all(track, vehicle)


def trailing(k, names):
    """The names of wheelset k (2, 3, ..) for the leading wheelset's `names`."""
    return tuple(f"wheelset[{k}].{n}" for n in names)


def run_bogie(paths, stop_time, wheelsets=2, track_params=None, vehicle_params=None):
    """Couples one TrackContact carrying `wheelsets` wheelsets with one vehicle model per
    wheelset (here RollPlaneVehicle instances, where a third-party bogie model would
    give each wheelset's wheel heights and axle rotation and take its contact forces),
    at the track's internal step. The handshake is the pair's, per wheelset: the
    static loads of the (identical) vehicles to the track, each wheelset's static
    wheel heights (``static_wheel_z.*``, ``wheelset[k].static_wheel_z.*``) back to its
    vehicle. Returns a dict of lists: time, and per wheelset k (1 the leading one) its
    left and right contact force as ``force[k].left``/``.right``."""
    params = dict(track_params or {})
    params["wheelsets"] = wheelsets
    track = Unit(paths["TrackContact"], "track")
    vehicles = [Unit(paths["RollPlaneVehicle"], f"vehicle{k}") for k in range(1, wheelsets + 1)]
    names = [(WHEELS, FORCES, ("static_wheel_z.left", "static_wheel_z.right"))] + [
        (trailing(k, WHEELS), trailing(k, FORCES), trailing(k, ("static_wheel_z.left", "static_wheel_z.right")))
        for k in range(2, wheelsets + 1)]
    try:
        for u in [track] + vehicles:
            u.fmu.setupExperiment(startTime=0.0)
        track.set_parameters(params)
        for v in vehicles:
            v.set_parameters(vehicle_params)
            v.fmu.enterInitializationMode()
        track.fmu.enterInitializationMode()
        loads = ("static_load.left", "static_load.right")
        track.set(loads, vehicles[0].get(*loads))
        for v, (wheels, forces, heights) in zip(vehicles, names):
            v.set(("static_wheel_z.left", "static_wheel_z.right"), track.get(*heights))
            track.set(wheels, v.get(*WHEELS))
        for v, (wheels, forces, heights) in zip(vehicles, names):
            v.set(FORCES, track.get(*forces))
            v.fmu.exitInitializationMode()
        track.fmu.exitInitializationMode()
        h = track.get("solver.step")[0]
        n = int(round(stop_time / h))
        out = {"time": []}
        for k in range(1, wheelsets + 1):
            out[f"force[{k}].left"], out[f"force[{k}].right"] = [], []
        t = 0.0
        for step in range(n + 1):
            for v, (wheels, _, _) in zip(vehicles, names):
                track.set(wheels, v.get(*WHEELS))
            out["time"].append(t)
            for k, (v, (_, forces, _)) in enumerate(zip(vehicles, names), 1):
                p = track.get(*forces)
                v.set(FORCES, p)
                out[f"force[{k}].left"].append(p[0])
                out[f"force[{k}].right"].append(p[1])
            if step == n:
                break
            track.fmu.doStep(t, h)
            for v in vehicles:
                v.fmu.doStep(t, h)
            t = (step + 1) * h
        return out
    finally:
        close_all(track, *vehicles)


FRAMES = ("sideframe.left.z", "sideframe.right.z", "sideframe.left.v", "sideframe.right.v")
# The mean primary forces over the track's step just taken: what a sequential master
# (track first) hands the vehicle. A Jacobi master (libcosim, ecos) hands it
# primary.*.force, the force at the communication point.
PRIMARY = ("primary.left.mean_force", "primary.right.mean_force")
AXLE_BOX = ("axle_box.left.force", "axle_box.right.force")


def run_axle_box_pair(paths, stop_time, comm_step=1e-3, track_params=None, vehicle_params=None, record=None):
    """Couples TrackContact and RollPlaneVehicle at the axle boxes (``interface`` =
    axle_box): TrackContact carries the wheelset and its primary suspension,
    RollPlaneVehicle the bodies above. Per communication step: the side frames' motion
    (``sideframe.*.z``, ``.v``) to the track, the track steps, its mean primary forces
    over that step (``primary.*.mean_force``) to the vehicle (``axle_box.*.force``), the
    vehicle steps (track first: a Gauss-Seidel exchange). Returns the track's largest
    contact forces ``[left, right]`` (N) over the run; ``record``, a list, receives
    ``[time, contact forces, mean primary forces]`` at every communication point."""
    tp = dict(track_params or {}, interface=2)
    vp = dict(vehicle_params or {}, interface=2)
    track = Unit(paths["TrackContact"], "track")
    vehicle = Unit(paths["RollPlaneVehicle"], "vehicle")
    try:
        static_handshake(track, vehicle, tp, vp)
        vehicle.fmu.exitInitializationMode()
        track.fmu.exitInitializationMode()
        n = int(round(stop_time / comm_step))
        for k in range(n):
            t = k * comm_step
            track.set(FRAMES, vehicle.get(*FRAMES))
            track.fmu.doStep(t, comm_step)
            vehicle.set(AXLE_BOX, track.get(*PRIMARY))
            vehicle.fmu.doStep(t, comm_step)
            if record is not None:
                record.append([t + comm_step] + track.get(*FORCES, *PRIMARY))
        return track.get("contact.left.max_force", "contact.right.max_force")
    finally:
        close_all(track, vehicle)


HEIGHTS = ("static_wheel_z.left", "static_wheel_z.right")


def carrier_handshake(track, vehicle, n, track_params, vehicle_params):
    """Parameters and the static handshake of TrackContact carrying the `n` wheelsets of
    a vehicle (its registry entry's, :func:`vehicle_kind`): its static loads to the
    track, every wheelset's static wheel heights back; both left in initialization
    mode. With several wheelsets TrackContact's offsets are the vehicle's (each the sum
    of the parameters its registry entry names: the HalfCarBogie's
    ``vehicle.wheelbase``; the Wagon's, its ``vehicle.bogie_distance`` and their sum;
    the TwoAxleWagon's ``wheelset[2].offset``)."""
    vp = dict(vehicle_params or {})
    tp = dict(track_params or {})
    for u in (track, vehicle):
        u.fmu.setupExperiment(startTime=0.0)
    vehicle.set_parameters(vp)
    if n > 1:
        start = {v.name: v.start for v in vehicle.md.modelVariables}
        kind = vehicle_kind(vehicle.md.coSimulation.modelIdentifier, os.path.dirname(vehicle.path))
        tp["wheelsets"] = n
        for k, names in enumerate(kind["offsets"], start=2):
            tp[f"wheelset[{k}].offset"] = sum(float(vp.get(x, start[x])) for x in names)
    track.set_parameters(tp)
    vehicle.fmu.enterInitializationMode()
    track.fmu.enterInitializationMode()
    loads = ("static_load.left", "static_load.right")
    track.set(loads, vehicle.get(*loads))
    vehicle.set(HEIGHTS, track.get(*HEIGHTS))
    for k in range(2, n + 1):
        names = trailing(k, HEIGHTS)
        vehicle.set(names, track.get(*names))


def every_wheelset(n, names):
    """`names` of the leading wheelset, then of wheelsets 2 to `n`."""
    out = list(names)
    for k in range(2, n + 1):
        out += trailing(k, names)
    return out


def run_carrier(paths, model, n, stop_time, track_params=None, vehicle_params=None, record=None):
    """Couples TrackContact (`n` wheelsets) and the vehicle FMU `model` on them
    (HalfCarBogie: 2, Wagon: 4) at the contact, at the track's internal step: per
    communication point every wheelset's wheel heights and axle rotation to the track,
    its contact forces back, both step. This is CoupledSystem with ``vehicle.model`` =
    half_car or wagon, exchanged at every step. Returns the largest contact forces
    ``[[left, right] of each wheelset]`` (N); ``record``, a list, receives ``[time, the
    contact forces]`` at every point."""
    track = Unit(paths["TrackContact"], "track")
    vehicle = Unit(paths[model], "vehicle")
    wheels = every_wheelset(n, WHEELS)
    forces = every_wheelset(n, FORCES)
    try:
        carrier_handshake(track, vehicle, n, track_params, vehicle_params)
        track.set(wheels, vehicle.get(*wheels))
        vehicle.set(forces, track.get(*forces))
        vehicle.fmu.exitInitializationMode()
        track.fmu.exitInitializationMode()
        h = track.get("solver.step")[0]
        steps = int(round(stop_time / h))
        peak = [[-1e300] * 2 for _ in range(n)]
        t = 0.0
        for k in range(steps + 1):
            track.set(wheels, vehicle.get(*wheels))
            p = track.get(*forces)
            vehicle.set(forces, p)
            for i in range(2 * n):
                peak[i // 2][i % 2] = max(peak[i // 2][i % 2], p[i])
            if record is not None:
                record.append([t] + p)
            if k == steps:
                break
            track.fmu.doStep(t, h)
            vehicle.fmu.doStep(t, h)
            t = (k + 1) * h
        return peak
    finally:
        close_all(track, vehicle)


def run_half_car(paths, stop_time, track_params=None, bogie_params=None, record=None):
    """:func:`run_carrier` of the HalfCarBogie: CoupledSystem with ``vehicle.model`` =
    half_car, exchanged at every step."""
    return run_carrier(paths, "HalfCarBogie", 2, stop_time, track_params, bogie_params, record)


def run_wagon(paths, stop_time, track_params=None, wagon_params=None, record=None):
    """:func:`run_carrier` of the Wagon (four wheelsets): CoupledSystem with
    ``vehicle.model`` = wagon, exchanged at every step."""
    return run_carrier(paths, "Wagon", 4, stop_time, track_params, wagon_params, record)


def run_carrier_axle_box(paths, model, n, stop_time, comm_step=1e-3, track_params=None, vehicle_params=None,
                         record=None, jacobi=False, primary_output="mean_force", steps=None, velocities=True):
    """Couples TrackContact (`n` wheelsets) and the vehicle FMU `model` at the axle
    boxes (``interface`` = axle_box): the track carries every wheelset with its primary
    suspension, the vehicle the bodies above. Per communication step the side frames'
    motion above each axle box to the track, the track steps, its mean primary forces
    back, the vehicle steps (track first). With ``jacobi`` both step from the same
    communication point, as OSP libcosim and ecos do, the vehicle given the forces of
    the point before the track steps. ``primary_output``: the track's output handed to
    the vehicle, ``mean_force`` (for a sequential master) or ``force`` (for a Jacobi
    one). ``steps``: the communication steps (s) one by one instead of ``comm_step`` to
    ``stop_time``; ``velocities`` False hands the track the side frames' displacements
    only (a partner that leaves ``sideframe.*.v`` unset). Returns the largest contact
    forces ``[[left, right] of each wheelset]`` (N) over the run; ``record``, a list,
    receives ``[time, the contact forces]`` at every communication point."""
    track = Unit(paths["TrackContact"], "track")
    vehicle = Unit(paths[model], "vehicle")
    frames = every_wheelset(n, FRAMES)
    primary = every_wheelset(n, tuple(f"primary.{s}.{primary_output}" for s in ("left", "right")))
    axle_box = every_wheelset(n, AXLE_BOX)
    forces = every_wheelset(n, FORCES)
    try:
        # vehicle.model of the vehicle's kind: what the track carries above the axle boxes
        # (the bogies' pitching side frames, or nothing for the two-axle wagon).
        value = vehicle_kind(model, os.path.dirname(paths[model]))["value"]
        carrier_handshake(track, vehicle, n, dict(track_params or {}, interface=2, **{"vehicle.model": value}),
                          dict(vehicle_params or {}, interface=2))
        vehicle.fmu.exitInitializationMode()
        track.fmu.exitInitializationMode()
        if steps is None:
            steps = [comm_step] * int(round(stop_time / comm_step))
        if not velocities:
            frames = [f for f in frames if f.endswith(".z")]
        t = 0.0
        for h in steps:
            if jacobi:  # both units' outputs of this point, before either gets an input
                vehicle.set(axle_box, track.get(*primary))
            track.set(frames, vehicle.get(*frames))
            track.fmu.doStep(t, h)
            if not jacobi:
                vehicle.set(axle_box, track.get(*primary))
            vehicle.fmu.doStep(t, h)
            t += h
            if record is not None:
                record.append([t] + track.get(*forces))
        m = track.get(*every_wheelset(n, ("contact.left.max_force", "contact.right.max_force")))
        return [m[2 * i:2 * i + 2] for i in range(n)]
    finally:
        close_all(track, vehicle)


def run_half_car_axle_box(paths, stop_time, comm_step=1e-3, track_params=None, bogie_params=None, record=None):
    """:func:`run_carrier_axle_box` of the HalfCarBogie."""
    return run_carrier_axle_box(paths, "HalfCarBogie", 2, stop_time, comm_step, track_params, bogie_params, record)


def run_wagon_axle_box(paths, stop_time, comm_step=1e-3, track_params=None, wagon_params=None, record=None):
    """:func:`run_carrier_axle_box` of the Wagon (four wheelsets)."""
    return run_carrier_axle_box(paths, "Wagon", 4, stop_time, comm_step, track_params, wagon_params, record)



def run_two_axle(paths, stop_time, track_params=None, wagon_params=None, record=None):
    """:func:`run_carrier` of the TwoAxleWagon: CoupledSystem with ``vehicle.model`` =
    two_axle, exchanged at every step."""
    return run_carrier(paths, "TwoAxleWagon", 2, stop_time, track_params, wagon_params, record)


def run_two_axle_axle_box(paths, stop_time, comm_step=1e-3, track_params=None, wagon_params=None, record=None):
    """:func:`run_carrier_axle_box` of the TwoAxleWagon."""
    return run_carrier_axle_box(paths, "TwoAxleWagon", 2, stop_time, comm_step, track_params, wagon_params, record)


if __name__ == "__main__":
    import argparse
    argparse.ArgumentParser(
        description="Sets up .venv at the repository's root with the packages of python/requirements.txt "
                    "(fmpy, dask, pandas, pyarrow, libcosimpy, ecospy), which the other commands run in; "
                    "imported, the coupling helpers (run_pair, run_carrier, run_carrier_axle_box, ...).").parse_args()
    install_venv()


def axle_box_against_coupled_system(paths, run_axle_box, start, stop_time=0.3, comm_step=1e-3):
    """A vehicle FMU coupled at the axle boxes by `run_axle_box` (:func:`run_wagon_axle_box`,
    :func:`run_two_axle_axle_box`, ...: fmpy's sequential loop every `comm_step` s on the
    track window of `start`) and CoupledSystem with `start` (its vehicle.model, wheelsets
    and offsets): every wheel's largest contact force over `stop_time` in both, wheelset
    by wheelset, left then right, as two lists (N)."""
    from fmpy import simulate_fmu
    window = {k: v for k, v in start.items() if k.startswith("track.window.")}
    got = [x for w in run_axle_box(paths, stop_time, comm_step, track_params=window) for x in w]
    maxima = every_wheelset(len(got) // 2, ("contact.left.max_force", "contact.right.max_force"))
    r = simulate_fmu(paths["CoupledSystem"], stop_time=stop_time, start_values=start, output=maxima)
    return got, [r[n][-1] for n in maxima]
