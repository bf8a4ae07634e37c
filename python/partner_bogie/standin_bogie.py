"""The stand-in third-party half-car bogie's model, numpy only: the one model class both
of its exports step, the FMI 2.0 one (standin_half_car.py, pythonfmu) and the FMI 3.0
one (standin_half_car3.py, pythonfmu3), so that they cannot drift apart. Each FMU carries
this file beside its script (build.py, build3.py) and imports it from there.

Written apart from this project's code, as a partner would write it: its own names, its
own matrices, its own integrator. It is the bogie ABOVE its primary suspension, the part
a partner couples to TrackContact at the axle boxes:

* the bolster carrying its share of the car body, in bounce ``z_b`` (m, up) and roll
  ``phi_b`` (rad, positive raising the right side);
* two side frames, left and right, in bounce ``z_s`` (m, up) and pitch ``theta_s``
  (rad, positive raising the front, wheelset 1's end);
* one secondary spring ``k_sec`` and damper ``c_sec`` per side between the bolster at
  ``y = -+ b_sec / 2`` (left at minus) and the side frame's centre;
* gravity on the bolster with the car body and on the side frames (inertias none);
* the four primary forces (inputs, N), each pushing its side frame up at its axle box,
  ``x = +wheelbase / 2`` for wheelset 1 (leading), ``-wheelbase / 2`` for wheelset 2.

Integration: classical fourth-order Runge-Kutta on fixed substeps of at most ``h_max``
(s), the input forces held over each communication step. The system is linear and
time-invariant, so the RK4 step is taken as the matrices of its stages
(``x <- P x + R f``, P and R the RK4 polynomials of ``h A``): the same arithmetic as four
stage evaluations, a fraction of the cost.
"""

import math

import numpy as np

# The four axle boxes, in the order of the inputs and outputs: wheelset 1 left, right,
# wheelset 2 left, right.
BOXES = ("1L", "1R", "2L", "2R")

# Parameters: name, default, unit, description.
PARAMETERS = (
    ("m_body", 40300.0, "kg", "Car-body mass carried by the bolster (the bogie's share: half the car body)"),
    ("m_bolster", 465.0, "kg", "Bolster mass"),
    ("J_bolster", 175.0, "kg.m2", "Roll inertia of the bolster with its car-body share"),
    ("m_sideframe", 447.5, "kg", "Mass of ONE WHOLE side frame (it spans both wheelsets)"),
    ("J_sideframe", 180.0, "kg.m2", "Pitch inertia of one side frame about its centre"),
    ("sideframe_scale", 1.0, "1", "Factor on both m_sideframe and J_sideframe"),
    ("k_sec", 5.1e6, "N/m", "Secondary stiffness per side"),
    ("c_sec", 88480.0, "N.s/m", "Secondary damping per side"),
    ("b_sec", 1.6002, "m", "Lateral distance between the two secondary suspensions"),
    ("wheelbase", 1.8, "m", "Distance between the two wheelsets (axle boxes at +- wheelbase / 2)"),
    ("g", 9.81, "m/s2", "Gravitational acceleration"),
    ("z_frame_rest", -0.01725226666550715, "m",
     "Side-frame height above each axle box at rest (the outputs' value at the start)"),
    ("h_max", 1e-4, "s", "Largest integrator substep"),
)

# Degrees of freedom: bolster bounce, roll; left side frame bounce, pitch; right side
# frame bounce, pitch.
N_DOF = 6


def bogie_matrices(p):
    """M (diagonal, as a vector), K, C, the gravity load f_g and the map G of the four
    box forces onto the degrees of freedom, for the parameters `p` (a dict)."""
    s = p["sideframe_scale"]
    msf, jsf = s * p["m_sideframe"], s * p["J_sideframe"]
    mass = np.array([p["m_body"] + p["m_bolster"], p["J_bolster"], msf, jsf, msf, jsf])
    k = np.zeros((N_DOF, N_DOF))
    c = np.zeros((N_DOF, N_DOF))
    for side, y in ((0, -0.5 * p["b_sec"]), (1, 0.5 * p["b_sec"])):
        # Compression of the secondary suspension: bolster at y above the side frame.
        a = np.zeros(N_DOF)
        a[0], a[1], a[2 + 2 * side] = 1.0, y, -1.0
        k += p["k_sec"] * np.outer(a, a)
        c += p["c_sec"] * np.outer(a, a)
    f_g = -p["g"] * np.array([mass[0], 0.0, msf, 0.0, msf, 0.0])
    g_map = np.zeros((N_DOF, 4))
    for col, box in enumerate(BOXES):
        x = 0.5 * p["wheelbase"] * (1.0 if box[0] == "1" else -1.0)
        side = 0 if box[1] == "L" else 1
        g_map[2 + 2 * side, col] = 1.0
        g_map[3 + 2 * side, col] = x
    return mass, k, c, f_g, g_map


def statics(p):
    """The primary forces (N, the four boxes) that hold the bogie at rest and its
    displacements there, with the side frames at 0 above every axle box.

    The bogie above its primary suspension has four rigid modes (bounce, roll and each
    side frame's pitch), which the secondary suspension does not hold: the forces are
    those whose load is orthogonal to them (the weight shared equally), the state the
    one that springs carry that load with the side frames level at 0 at the boxes."""
    mass, k, c, f_g, g_map = bogie_matrices(p)
    _, sv, vt = np.linalg.svd(k)
    rank = int(np.sum(sv > sv[0] * 1e-12))
    null = vt[rank:].T                        # the rigid modes, 6 x 4
    # N^T (f_g + G F) = 0: four conditions on the four forces.
    forces = np.linalg.solve(null.T @ g_map, -null.T @ f_g)
    load = f_g + g_map @ forces
    # K q = load with G^T q = 0 (the rigid modes fixed by the boxes' heights).
    q, *_ = np.linalg.lstsq(np.vstack([k, g_map.T]), np.concatenate([load, np.zeros(4)]), rcond=None)
    return forces, q


def rk4_matrices(a, b, h):
    """One classical RK4 step of ``x' = A x + B f`` with f held: ``x <- P x + R f``."""
    n = a.shape[0]
    ha = h * a
    eye = np.eye(n)
    ha2 = ha @ ha
    ha3 = ha2 @ ha
    p = eye + ha + ha2 / 2.0 + ha3 / 6.0 + ha3 @ ha / 24.0
    r = h * (eye + ha / 2.0 + ha2 / 6.0 + ha3 / 24.0) @ b
    return p, r


class StandinBogie:
    """The bogie above its primary suspension for the parameters `p` (a dict of
    PARAMETERS' names), started at rest: ``static_forces`` (N, the four boxes, BOXES'
    order) hold it there; :meth:`side_frames` gives the side frames' motion above the
    boxes, :meth:`step` moves it on under the four primary forces held."""

    def __init__(self, p):
        mass, k, c, f_g, g_map = bogie_matrices(p)
        forces, q = statics(p)
        self.static_forces = forces
        inv_m = 1.0 / mass
        self._a = np.block([[np.zeros((N_DOF, N_DOF)), np.eye(N_DOF)],
                            [-inv_m[:, None] * k, -inv_m[:, None] * c]])
        self._b = np.vstack([np.zeros((N_DOF, N_DOF)), np.diag(inv_m)])
        self._f_g, self._g = f_g, g_map
        self._x = np.concatenate([q, np.zeros(N_DOF)])
        self._steps = {}
        self._h_max = p["h_max"]
        self._rest = p["z_frame_rest"]

    def side_frames(self):
        """The side frames' displacement (m, from ``z_frame_rest`` on) and velocity (m/s)
        above the four boxes, up: two arrays in BOXES' order."""
        z = self._rest + self._g.T @ self._x[:N_DOF]
        v = self._g.T @ self._x[N_DOF:]
        return z, v

    def step(self, forces, step_size):
        """Moves on by `step_size` (s) under the primary forces `forces` (N, the four
        boxes, up on the side frames) held, in RK4 substeps of at most ``h_max``; False
        when the displacements left 1 m or are not finite (the exchange diverged)."""
        if not step_size > 0.0:
            return True
        n = max(1, math.ceil(step_size / self._h_max - 1e-9))
        h = step_size / n
        if h not in self._steps:
            self._steps[h] = rk4_matrices(self._a, self._b, h)
        p, r = self._steps[h]
        u = np.array([float(f) for f in forces])
        drive = r @ (self._f_g + self._g @ u)
        x = self._x
        for _ in range(n):
            x = p @ x + drive
        self._x = x
        return bool(np.all(np.isfinite(x)) and np.max(np.abs(x[:N_DOF])) < 1.0)
