"""Issue 43: the stand-in third-party bogie exported with pythonfmu3 (FMI 3.0,
standin_half_car3.py) coupled with the FMI 3.0 TrackContact (fmu/fmi3/TrackContact.fmu)
at the axle boxes in an fmpy master loop, and the same master over the FMI 2.0 pair
(the pythonfmu stand-in, fmu/TrackContact.fmu) for comparison.

    .venv/bin/python python/partner_bogie/couple3.py [--jacobi] [--step S] [--stop S]

prints every wheel's peak of both runs against CoupledSystem's (the FMI 2.0
fmu/CoupledSystem.fmu, vehicle.model = half_car) and how far the two runs' histories
are apart.

The case is issue 41's (python/partner_bogie/matrix.py): the endless track of the
shipped axle-box system (20 m ahead and behind), 70 km/h, TrackContact's default
(reference) flat, TrackContact's parameters the shipped system's (interface = axle_box,
vehicle.model = half_car, two wheelsets) with the stand-in's wheelbase and static wheel
load. TrackContact on two wheelsets is set in Configuration Mode
(wheelflat_fmi3.Unit3.configure).

The master maps names, element by element: the stand-in's arrays are its own, 2 x 2
``[wheelset][side]`` (``z_frame``, ``v_frame`` out, ``F_box`` in), TrackContact's one
array per side sized by its wheelsets, the leading wheelset first
(``sideframe.left.z``, ..., ``primary.left.mean_force``, ...):
``z_frame[k][0] -> sideframe.left.z[k]``, ``z_frame[k][1] -> sideframe.right.z[k]``,
the same for ``v_frame`` and ``.v``, and ``primary.left.<output>[k] -> F_box[k][0]``,
``primary.right.<output>[k] -> F_box[k][1]`` (:func:`connections`).

Two masters, as issue 41's fmpy loops: sequential (TrackContact first, the stand-in
handed ``primary.*.mean_force``, the mean over the step just taken) or Jacobi (both step
from the same point, every output read before any input is set; the stand-in handed
``primary.*.force``). Every FMI call's status is counted, every logged message kept,
per instance (each instance has its own logger).
"""

import argparse
import ctypes
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_DIR = os.path.dirname(HERE)
sys.path.insert(0, PYTHON_DIR)
import wheelflat_fmi3 as w3  # noqa: E402
import wheelflat_fmus as wf  # noqa: E402
from partner_bogie import build, matrix  # noqa: E402

STOP = matrix.STOP
STEP = 1e-3
STATUS_NAMES = ("ok", "warning", "discard", "error", "fatal", "pending")
SIDES = ("left", "right")
# The order of every per-box list here: wheelset 1 left, right, wheelset 2 left, right
# (the stand-in's own order, and matrix.reference's).
BOXES = ("1L", "1R", "2L", "2R")


def connections(n=2, output="mean_force"):
    """The FMI 3.0 master's connections, element by element: ``(from unit, variable,
    element, to unit, variable, element)``, elements counted flat (row-major) from 0:
    the stand-in's side frames to TrackContact, TrackContact's primary forces
    (``primary.*.<output>``) to the stand-in, on `n` wheelsets."""
    out = []
    for q in ("z", "v"):
        for k in range(n):
            for s, side in enumerate(SIDES):
                out.append(("partner", f"{q}_frame", 2 * k + s, "track", f"sideframe.{side}.{q}", k))
    for k in range(n):
        for s, side in enumerate(SIDES):
            out.append(("track", f"primary.{side}.{output}", k, "partner", "F_box", 2 * k + s))
    return out


def case(output="mean_force"):
    """TrackContact's parameters of issue 41's case (matrix.system_of, scale 1):
    {name: value}, wheelsets among them."""
    system = matrix.system_of(matrix.cell("fmpy_seq", STEP, output, 1.0))
    return {name: value for name, (_, value) in system["track"].items()}


class _Watch:
    """Counts the status of every FMI call of an fmpy FMU (fmpy raises above Warning)
    and keeps the messages its logger receives."""

    def __init__(self):
        self.statuses = {}
        self.messages = []

    def wrap(self, fmu):
        from fmpy.fmi1 import FMICallException

        def call(fname, *args):
            fn = fmu._functions[fname]
            res = fn(*args)
            if fn.restype == ctypes.c_int:
                name = STATUS_NAMES[res] if 0 <= res < len(STATUS_NAMES) else str(res)
                self.statuses[name] = self.statuses.get(name, 0) + 1
                if res > 1:
                    raise FMICallException(function=fname, status=res)
            return res
        fmu._call = call

    def log3(self, env, status, category, message):
        self.messages.append((STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status),
                              message.decode(errors="replace") if isinstance(message, bytes) else str(message)))


class Partner3:
    """The FMI 3.0 stand-in through fmpy's FMU3Slave, by name; an array's size from its
    model description's dimensions (fixed: ``Dimension start``)."""

    def __init__(self, path, instance_name, log_message):
        from fmpy import extract, read_model_description
        from fmpy.fmi3 import FMU3Slave
        self.md = read_model_description(path)
        self.dir = extract(path)
        self.vars = {v.name: v for v in self.md.modelVariables}
        self.fmu = FMU3Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=instance_name)
        self.fmu.instantiate(loggingOn=False, logMessage=log_message)

    def size(self, name):
        n = 1
        for d in self.vars[name].dimensions:
            n *= int(d.start)
        return n

    def get(self, name):
        return list(self.fmu.getFloat64([self.vars[name].valueReference], self.size(name)))

    def set(self, name, values):
        self.fmu.setFloat64([self.vars[name].valueReference], [float(x) for x in values])

    def close(self, terminate=True):
        import shutil
        from fmpy.fmi1 import FMICallException
        try:
            if terminate:
                self.fmu.terminate()
        except FMICallException:
            pass
        finally:
            self.fmu.freeInstance()
            shutil.rmtree(self.dir, ignore_errors=True)


class _Fmi3:
    """The FMI 3.0 pair: TrackContact (wheelflat_fmi3.Unit3, arrays by name) and the
    pythonfmu3 stand-in, joined by :func:`connections`. Values in and out in BOXES'
    order."""

    def __init__(self, track_fmu, standin_fmu, output, watch_track, watch_partner):
        self.track = w3.Unit3(track_fmu, "TrackContact", log_message=watch_track.log3)
        self.partner = Partner3(standin_fmu, "StandinHalfCar3", watch_partner.log3)
        watch_track.wrap(self.track.fmu)
        watch_partner.wrap(self.partner.fmu)
        self.output = output
        self.units = (self.track, self.partner)

    def initialise(self, params, standin_params):
        self.track.set_parameters(params)  # wheelsets first, in Configuration Mode
        for name, value in standin_params.items():
            self.partner.set(name, [value])
        n = self.track.wheelsets
        self.links = connections(n, self.output)
        for u in self.units:
            u.fmu.enterInitializationMode(startTime=0.0)
        for u in self.units:
            u.fmu.exitInitializationMode()

    def frames_to_track(self):
        """The stand-in's side frames into TrackContact's arrays (the values handed)."""
        z, v = self.partner.get("z_frame"), self.partner.get("v_frame")
        out = {"z_frame": z, "v_frame": v}
        arrays = {}
        for a, x, i, b, y, j in self.links:
            if a == "partner":
                arrays.setdefault(y, [None] * self.track.size(y))[j] = out[x][i]
        names = list(arrays)
        self.track.set(names, [e for y in names for e in arrays[y]])
        return z + v

    def primary(self):
        """TrackContact's primary forces as the stand-in's F_box (row-major)."""
        names = [f"primary.{side}.{self.output}" for side in SIDES]
        got = dict(zip(names, _split(self.track.get(*names), [self.track.size(x) for x in names])))
        f = [None] * self.partner.size("F_box")
        for a, x, i, b, y, j in self.links:
            if a == "track":
                f[j] = got[x][i]
        return f

    def forces_to_partner(self, f):
        self.partner.set("F_box", f)

    def step(self, unit, t, h):
        (self.track if unit == "track" else self.partner).fmu.doStep(t, h)

    def contact(self, what="force"):
        """TrackContact's contact.*.<what> in BOXES' order."""
        n = self.track.wheelsets
        left, right = _split(self.track.get(f"contact.left.{what}", f"contact.right.{what}"), [n, n])
        return [x for k in range(n) for x in (left[k], right[k])]

    def close(self):
        w3.close_all(*self.units)


def _split(values, sizes):
    out, i = [], 0
    for n in sizes:
        out.append(values[i:i + n])
        i += n
    return out


class _Fmi2:
    """The same master over the FMI 2.0 pair: TrackContact (fmu/TrackContact.fmu,
    ``wheelset[k].`` names) and the pythonfmu stand-in (its scalars ``z_frame_1L``, ...)."""

    def __init__(self, track_fmu, standin_fmu, output, watch_track, watch_partner):
        self.track = wf.Unit(track_fmu, "TrackContact", callbacks=_callbacks2(watch_track))
        self.partner = wf.Unit(standin_fmu, "StandinHalfCar", callbacks=_callbacks2(watch_partner))
        watch_track.wrap(self.track.fmu)
        watch_partner.wrap(self.partner.fmu)
        self.output = output
        self.units = (self.track, self.partner)

    def initialise(self, params, standin_params):
        n = int(params.get("wheelsets", 1))
        self.frames_from = [f"{q}_frame_{b}" for q in "zv" for b in BOXES[:2 * n]]
        frames = {(q, k, s): (f"sideframe.{side}.{q}" if k == 0 else f"wheelset[{k + 1}].sideframe.{side}.{q}")
                  for q in "zv" for k in range(n) for s, side in enumerate(SIDES)}
        self.frames_to = [frames[(q, k, s)] for q in "zv" for k in range(n) for s in range(2)]
        self.primary_from = wf.every_wheelset(n, tuple(f"primary.{side}.{self.output}" for side in SIDES))
        self.forces_to = [f"F_box_{b}" for b in BOXES[:2 * n]]
        self.max_from = wf.every_wheelset(n, ("contact.left.max_force", "contact.right.max_force"))
        self.force_from = wf.every_wheelset(n, wf.FORCES)
        for u in self.units:
            u.fmu.setupExperiment(startTime=0.0)
        self.track.set_parameters(params)
        self.partner.set_parameters(standin_params)
        for u in self.units:
            u.fmu.enterInitializationMode()
        for u in self.units:
            u.fmu.exitInitializationMode()

    def frames_to_track(self):
        z = self.partner.get(*self.frames_from)
        self.track.set(self.frames_to, z)
        return z

    def primary(self):
        return self.track.get(*self.primary_from)

    def forces_to_partner(self, f):
        self.partner.set(self.forces_to, f)

    def step(self, unit, t, h):
        (self.track if unit == "track" else self.partner).fmu.doStep(t, h)

    def contact(self, what="force"):
        return self.track.get(*(self.force_from if what == "force" else self.max_from))

    def close(self):
        wf.close_all(*self.units)


def _callbacks2(watch):
    from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    def logger(env, name, status, category, message):
        watch.messages.append((STATUS_NAMES[status] if 0 <= status < len(STATUS_NAMES) else str(status),
                               message.decode(errors="replace")))
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = ctypes.CFUNCTYPE(ctypes.c_void_p, ctypes.c_size_t, ctypes.c_size_t)(lambda n, s: None)
    cb.freeMemory = ctypes.CFUNCTYPE(None, ctypes.c_void_p)(lambda p: None)
    watch._keep = cb  # the callbacks must outlive the instance
    return cb


def run(fmi=3, stop=STOP, step=STEP, jacobi=False, output=None, params=None, standin_params=None,
        standin_fmu=None, track_fmu=None, record=False):
    """Couples the stand-in and TrackContact at the axle boxes, FMI `fmi` (3: the
    pythonfmu3 stand-in and fmu/fmi3/TrackContact.fmu; 2: the pythonfmu stand-in and
    fmu/TrackContact.fmu), every `step` s to `stop` s, sequential (TrackContact first)
    or `jacobi`. `output`: TrackContact's primary output handed on (default
    ``mean_force`` sequential, ``force`` Jacobi); `params`: TrackContact's parameters
    set apart from the case's ({name: value}); `standin_params`: the stand-in's
    ({name: value}, Float64 scalars: ``sideframe_scale``, ...).

    Returns a dict: ``peaks`` (N, every wheel's largest contact force, BOXES' order),
    ``failure`` (None, or the call refused and the first message at Discard or above),
    ``time`` (s reached), ``statuses`` and ``messages`` of ``track`` and ``partner``
    (every call's status counted; every message logged, ``(status, text)``),
    ``history`` (with `record`: per communication point after both steps ``[t, the
    contact forces (4), the primary forces handed (4), the side frames handed (8: z
    then v)]``), ``wall`` (s)."""
    from fmpy.fmi1 import FMICallException

    output = output or ("force" if jacobi else "mean_force")
    if standin_fmu is None:
        standin_fmu = build.build(fmi=fmi)
    if track_fmu is None:
        track_fmu = os.path.join(w3.FMU3_DIR if fmi == 3 else wf.FMU_DIR, "TrackContact.fmu")
    watch = {"track": _Watch(), "partner": _Watch()}
    pair = (_Fmi3 if fmi == 3 else _Fmi2)(track_fmu, standin_fmu, output, watch["track"], watch["partner"])
    history = [] if record else None
    failure, reached, peaks, t = None, 0.0, None, 0.0
    t0 = time.perf_counter()
    try:
        pair.initialise(dict(case(output), **(params or {})), standin_params or {})
        steps = int(round(stop / step))
        for k in range(steps):
            t = k * step
            if jacobi:  # every output of this point before any input is set
                f = pair.primary()
                z = pair.frames_to_track()
                pair.forces_to_partner(f)
                pair.step("track", t, step)
                pair.step("partner", t, step)
            else:
                z = pair.frames_to_track()
                pair.step("track", t, step)
                f = pair.primary()
                pair.forces_to_partner(f)
                pair.step("partner", t, step)
            reached = (k + 1) * step
            if record:
                history.append([reached] + pair.contact("force") + list(f) + list(z))
        peaks = pair.contact("max_force")
    except FMICallException as e:
        failure = f"{e} at t = {t:g} s"
        msgs = [m for w in watch.values() for s, m in w.messages if s not in ("ok", "warning")]
        if msgs:
            failure += ": " + msgs[0][:300]
        try:
            peaks = pair.contact("max_force")
        except Exception:  # noqa: BLE001 - an instance that failed may refuse to answer
            pass
    finally:
        try:
            pair.close()
        except Exception:  # noqa: BLE001 - a unit that failed may refuse to terminate
            if failure is None:
                raise
    return dict(peaks=peaks, failure=failure, time=reached, history=history,
                statuses={k: w.statuses for k, w in watch.items()},
                messages={k: w.messages for k, w in watch.items()}, wall=time.perf_counter() - t0)


def errors(peaks, stop=STOP):
    """Every wheel's peak error against CoupledSystem's (matrix.reference: FMI 2.0
    CoupledSystem.fmu, vehicle.model = half_car, the same track), relative."""
    ref = matrix.reference("standin", 1.0, stop)
    return [p / r - 1 for p, r in zip(peaks, ref)]


def main():
    ap = argparse.ArgumentParser(description="The pythonfmu3 stand-in bogie with the FMI 3.0 TrackContact at the "
                                             "axle boxes, and the same master over the FMI 2.0 pair, against "
                                             "CoupledSystem.")
    ap.add_argument("--jacobi", action="store_true", help="Jacobi master (primary.*.force) instead of sequential")
    ap.add_argument("--step", type=float, default=STEP, help=f"communication step (s, default {STEP:g})")
    ap.add_argument("--stop", type=float, default=STOP, help=f"stop time (s, default {STOP:g})")
    a = ap.parse_args()
    wf.ensure_venv()
    runs = {fmi: run(fmi, a.stop, a.step, a.jacobi, record=True) for fmi in (3, 2)}
    ref = matrix.reference("standin", 1.0, a.stop)
    print(f"case: 70 km/h, reference flat, endless track (20 m a side), {a.stop:g} s, "
          f"{'Jacobi' if a.jacobi else 'sequential'} at {a.step * 1e3:g} ms")
    print("CoupledSystem: " + ", ".join(f"{b} {x / 1e3:.3f}" for b, x in zip(BOXES, ref)) + " kN")
    for fmi, r in runs.items():
        if r["failure"]:
            print(f"FMI {fmi}.0: failed: {r['failure']}")
            continue
        e = errors(r["peaks"], a.stop)
        print(f"FMI {fmi}.0: " + ", ".join(f"{b} {x / 1e3:.3f} ({100 * d:+.3f} %)"
                                           for b, x, d in zip(BOXES, r["peaks"], e))
              + f" kN; {r['wall']:.2f} s; TrackContact's statuses {r['statuses']['track']}, "
              + f"messages {r['messages']['track'][:3]}")
    h3, h2 = runs[3]["history"], runs[2]["history"]
    if h3 and h2 and len(h3) == len(h2):
        diff = max(abs(x - y) for a3, a2 in zip(h3, h2) for x, y in zip(a3, a2))
        same = sum(a3 == a2 for a3, a2 in zip(h3, h2))
        print(f"FMI 3.0 against FMI 2.0: {same} of {len(h3)} points bit for bit, largest difference {diff:g}")


if __name__ == "__main__":
    main()
