"""The stand-in third-party half-car bogie (issue 41's, standin_half_car.py) exported
as an FMI 3.0 co-simulation FMU with pythonfmu3 (python/partner_bogie/build.py --fmi 3
builds it, StandinHalfCar3.fmu).

The bogie above its primary suspension (the bolster with the car-body share, two side
frames, the secondary suspension, gravity), its own RK4: standin_bogie.py's
``StandinBogie``, the very class the FMI 2.0 export steps, which this FMU carries beside
this file. Only its face differs: FMI 3.0 arrays, as a partner exporting with pythonfmu3
would lay them out, its own names and its own layout (not TrackContact's):

* ``F_box`` (input, N, 2 x 2: ``[wheelset][side]``, wheelset 1 the leading one, left
  then right; row-major, so flat ``1L, 1R, 2L, 2R``): the primary force at each axle
  box, pressing the axle box down, so pushing the side frame up there; starts at the
  static forces (a quarter of the weight above the primary suspension each); a master
  that never sets it leaves those;
* ``z_frame``, ``v_frame`` (outputs, m and m/s, up, 2 x 2 as ``F_box``): each side
  frame's displacement (from ``z_frame_rest`` on) and velocity above each axle box;
* the parameters of standin_half_car.py, Float64 scalars of the same names.

A master coupling it to TrackContact's FMI 3.0 arrays (``sideframe.left.z``: one value
per wheelset, the leading first) maps ``z_frame[k][0]`` to ``sideframe.left.z[k]``, and
so on (python/partner_bogie/couple3.py).
"""

import numpy as np
from pythonfmu3 import Dimension, Fmi3Causality, Fmi3Slave, Fmi3Status, Fmi3StepResult, Fmi3Variability, Float64

try:  # imported as partner_bogie.standin_half_car3 (the tests)
    from .standin_bogie import PARAMETERS, StandinBogie, statics
except ImportError:  # in the FMU: resources/ holds standin_bogie.py beside this file
    from standin_bogie import PARAMETERS, StandinBogie, statics

# The arrays' shape: [wheelset][side].
SHAPE = (2, 2)


class StandinHalfCar3(Fmi3Slave):
    author = "wheelflat issue 43 (a stand-in for a third party)"
    description = ("A third party's half-car freight bogie above its primary suspension, FMI 3.0 (pythonfmu3): "
                   "bolster with the car-body share (bounce, roll), two side frames (bounce, pitch), secondary "
                   "suspension, gravity; the primary (axle-box) forces in and the side frames' motion above the "
                   "axle boxes out as 2 x 2 arrays [wheelset][side]. Own RK4 on substeps of at most h_max.")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.author = StandinHalfCar3.author
        self.description = StandinHalfCar3.description
        self.time = 0.0
        self.register_variable(Float64("time", causality=Fmi3Causality.independent,
                                       variability=Fmi3Variability.continuous, description="Simulation time (s)"))
        for name, value, unit, text in PARAMETERS:
            setattr(self, name, value)
            self.register_variable(Float64(name, causality=Fmi3Causality.parameter,
                                           variability=Fmi3Variability.fixed, description=f"{text} ({unit})"))
        start, _ = statics(self._parameters())
        self.F_box = np.array(start, dtype=float).reshape(SHAPE)
        self._forces_set = False
        dims = [Dimension(start=str(n)) for n in SHAPE]
        # Its own getter and setter: pythonfmu3 0.3.4's default array setter calls
        # np.reshape(v, newshape=...), a keyword NumPy 2.4 (pinned) no longer takes.
        self.register_variable(Float64(
            "F_box", causality=Fmi3Causality.input, variability=Fmi3Variability.continuous, dimensions=dims,
            description="Primary force at each axle box [wheelset][side] (wheelset 1 leading; left, right) pressing "
                        "the axle box down, so pushing the side frame up there (N); starts at the static forces",
            getter=lambda: self.F_box.flatten().tolist(), setter=self._set_forces))
        self.z_frame = np.full(SHAPE, float(self.z_frame_rest))
        self.v_frame = np.zeros(SHAPE)
        for what, unit in (("z", "m"), ("v", "m/s")):
            self.register_variable(Float64(
                f"{what}_frame", causality=Fmi3Causality.output, variability=Fmi3Variability.continuous,
                dimensions=dims,
                description=f"Side frame {'displacement' if what == 'z' else 'velocity'} above each axle box "
                            f"[wheelset][side], up ({unit})",
                getter=lambda what=what: getattr(self, f"{what}_frame").flatten().tolist()))
        self._bogie = None

    def _parameters(self):
        return {name: float(getattr(self, name)) for name, *_ in PARAMETERS}

    def _set_forces(self, values):
        self.F_box = np.array([float(x) for x in values]).reshape(SHAPE)
        self._forces_set = True

    def _prepare(self):
        self._bogie = StandinBogie(self._parameters())
        # Forces the master has not set hold the static forces of these parameters.
        if not self._forces_set:
            self.F_box = np.array(self._bogie.static_forces, dtype=float).reshape(SHAPE)
        self._publish()

    def _publish(self):
        z, v = self._bogie.side_frames()
        self.z_frame = np.array(z, dtype=float).reshape(SHAPE)
        self.v_frame = np.array(v, dtype=float).reshape(SHAPE)

    def exit_initialization_mode(self):
        self._prepare()

    def do_step(self, current_time, step_size):
        if self._bogie is None:
            self._prepare()
        if not step_size > 0.0:
            return True
        # The arrays' row-major order is BOXES' (1L, 1R, 2L, 2R), the model's.
        ok = self._bogie.step(self.F_box.flatten().tolist(), step_size)
        self.time = current_time + step_size
        self._publish()
        if not ok:
            self.log(f"at t = {current_time + step_size} s the bogie's displacements left 1 m "
                     f"(the exchange diverged)", Fmi3Status.error)
            return Fmi3StepResult(status=Fmi3Status.discard, terminateSimulation=True)
        return True
