"""A stand-in for a third party's half-car freight bogie, exported as an FMI 2.0
co-simulation FMU with pythonfmu (python/partner_bogie/build.py builds it).

Written apart from this project's code, as a partner would write it: its own names, its
own matrices (numpy only), its own integrator. It is the bogie ABOVE its primary
suspension, the part a partner couples to TrackContact at the axle boxes:

* the bolster carrying its share of the car body, in bounce ``z_b`` (m, up) and roll
  ``phi_b`` (rad, positive raising the right side);
* two side frames, left and right, in bounce ``z_s`` (m, up) and pitch ``theta_s``
  (rad, positive raising the front, wheelset 1's end);
* one secondary spring ``k_sec`` and damper ``c_sec`` per side between the bolster at
  ``y = -+ b_sec / 2`` (left at minus) and the side frame's centre;
* gravity on the bolster with the car body and on the side frames (inertias none);
* the four primary forces (inputs, N), each pushing its side frame up at its axle box,
  ``x = +wheelbase / 2`` for wheelset 1 (leading), ``-wheelbase / 2`` for wheelset 2.

With its defaults it is the thesis' half-car bogie as this project's HalfCarBogie and
CoupledSystem (``vehicle.model = half_car``) carry it above the primary suspension
(table 4.4: a car-body share of 40,300 kg, a 465 kg bolster, side frames of 447.5 kg and
180 kg m^2, 5.1 MN/m and 88.48 kN s/m a side).

Outputs: each side frame's displacement and velocity above each axle box,
``z_s + x theta_s`` (m, m/s, up), the displacement measured from ``z_frame_rest``, the
height at rest (by default the datum of this project's half-car bogie at its axle boxes:
where the wheels touch the undeformed rails, the static sag included).

Integration: classical fourth-order Runge-Kutta on fixed substeps of at most ``h_max``
(s), the input forces held over each communication step. The system is linear and
time-invariant, so the RK4 step is taken as the matrices of its stages
(``x <- P x + R f``, P and R the RK4 polynomials of ``h A``): the same arithmetic as four
stage evaluations, a fraction of the cost.

Start: at static equilibrium under the primary forces that hold it, computed from the
parameters (the inputs' start values are those forces, a quarter of the weight above
the primary suspension each; inputs a master does not set keep them).

The model itself (matrices, statics, RK4) is standin_bogie.py's ``StandinBogie``,
numpy only, which this FMU carries beside this file; the FMI 3.0 export of the same
bogie (standin_half_car3.py, pythonfmu3) steps the same class, so the two cannot drift.
This file is its FMI 2.0 face: the scalar names below and pythonfmu's slave.
"""

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real
from pythonfmu.enums import Fmi2Status

try:  # imported as partner_bogie.standin_half_car (matrix.py, the tests)
    from .standin_bogie import BOXES, N_DOF, PARAMETERS, StandinBogie, bogie_matrices, rk4_matrices, statics
except ImportError:  # in the FMU: resources/ holds standin_bogie.py beside this file
    from standin_bogie import BOXES, N_DOF, PARAMETERS, StandinBogie, bogie_matrices, rk4_matrices, statics

__all__ = ["BOXES", "N_DOF", "PARAMETERS", "StandinBogie", "StandinHalfCar", "bogie_matrices", "rk4_matrices",
           "statics"]


class StandinHalfCar(Fmi2Slave):
    author = "wheelflat issue 41 (a stand-in for a third party)"
    description = ("A third party's half-car freight bogie above its primary suspension: bolster with the "
                   "car-body share (bounce, roll), two side frames (bounce, pitch), secondary suspension, "
                   "gravity; the four primary (axle-box) forces in, the side frames' motion above the four "
                   "axle boxes out. Own RK4 on substeps of at most h_max.")

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        for name, value, unit, text in PARAMETERS:
            setattr(self, name, value)
            self.register_variable(Real(name, causality=Fmi2Causality.parameter,
                                        variability=Fmi2Variability.fixed, description=f"{text} ({unit})"))
        start, _ = statics(self._parameters())
        self._set_by_master = set()
        for i, box in enumerate(BOXES):
            setattr(self, f"F_box_{box}", float(start[i]))
            side = "left" if box[1] == "L" else "right"
            self.register_variable(Real(
                f"F_box_{box}", causality=Fmi2Causality.input, variability=Fmi2Variability.continuous,
                description=f"Primary force at axle box {box} (wheelset {box[0]}, {side}) pressing the axle box "
                            "down, so pushing the side frame up there (N); starts at the static force",
                setter=lambda v, box=box: self._set_force(box, v)))
        for what, unit in (("z", "m"), ("v", "m/s")):
            for box in BOXES:
                setattr(self, f"{what}_frame_{box}", self.z_frame_rest if what == "z" else 0.0)
                self.register_variable(Real(
                    f"{what}_frame_{box}", causality=Fmi2Causality.output, variability=Fmi2Variability.continuous,
                    description=f"Side frame {'displacement' if what == 'z' else 'velocity'} above axle box {box}, "
                                f"up ({unit})"))
        self._bogie = None

    def _parameters(self):
        return {name: float(getattr(self, name)) for name, *_ in PARAMETERS}

    def _set_force(self, box, value):
        setattr(self, f"F_box_{box}", float(value))
        self._set_by_master.add(box)

    def _prepare(self):
        self._bogie = StandinBogie(self._parameters())
        # Inputs the master has not set hold the static forces of these parameters.
        for i, box in enumerate(BOXES):
            if box not in self._set_by_master:
                setattr(self, f"F_box_{box}", float(self._bogie.static_forces[i]))
        self._publish()

    def _publish(self):
        z, v = self._bogie.side_frames()
        for i, box in enumerate(BOXES):
            setattr(self, f"z_frame_{box}", float(z[i]))
            setattr(self, f"v_frame_{box}", float(v[i]))

    def exit_initialization_mode(self):
        self._prepare()

    def do_step(self, current_time, step_size):
        if self._bogie is None:
            self._prepare()
        if not step_size > 0.0:
            return True
        ok = self._bogie.step([getattr(self, f"F_box_{box}") for box in BOXES], step_size)
        self._publish()
        if not ok:
            self.log(f"at t = {current_time + step_size} s the bogie's displacements left 1 m "
                     f"(the exchange diverged)", Fmi2Status.error)
            return False
        return True
