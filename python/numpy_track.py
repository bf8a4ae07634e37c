"""A plain NumPy implementation of the discrete track (issue 29's reference): two
Timoshenko rails on discrete sleepers (thesis 3.4-3.23: the central-difference rail
stencil, the pads (3.9) and the sleepers' bounce and roll (3.18) with the implicit
damping of (3.25)), fixed rail ends, on the engine's grid, under a pair of constant
loads moving along it (the thesis' table 4.1 case, `VehicleSpec::ConstantLoad`), started
in its static equilibrium. Written from docs/MODEL.md and the thesis, one array
operation per term, without the engine's phase-blocked storage or SIMD.

It is an independent check of the engine's track (the rail deflection under the loads
against `target/release/wheelflat --preset table4.1 --between-nodes linear`, to the
CSV's seven digits) and the reference of docs/PERFORMANCE.md's speed ratio:

    .venv/bin/python python/numpy_track.py              # check, then time 0.1 s
    .venv/bin/python python/numpy_track.py --time 0.9   # time 0.9 simulated seconds
"""

import argparse
import csv
import os
import subprocess
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


# The engine's step on this grid: 0.9 of the critical step with the contact spring
# (TrackContact's solver.step with the defaults).
DEFAULT_DT = 1.4413057013760613e-5


class Track:
    """The table 4.4 track of `spans` sleeper spans, `n` nodes per span, step `dt` (s)."""

    def __init__(self, spans=20, n=8, dt=None):
        e, g, area, inertia, kappa, mass = 2.07e11, 81e9, 7.77e-3, 2.94e-5, 0.34, 60.0
        self.a, ls = 0.685, 0.5 * 1.505
        kp, cp, kb, cb, ms, js = 140e6, 45e3, 40e6, 50e3, 270.0, 90.0
        ei, kag, rho_i = e * inertia, kappa * area * g, mass * inertia / area
        self.n, self.spans = n, spans
        self.nk = spans * n + 1
        self.ns = spans + 1
        dx = self.a / n
        self.dx = dx
        self.dt = dt = DEFAULT_DT if dt is None else dt
        dt2 = dt * dt
        # The rail stencil's weights (3.4-3.8 in central differences).
        self.zz = kag * dt2 / (mass * dx * dx)
        self.zc = 2.0 - 2.0 * self.zz
        self.zt = kag * dt2 / (2.0 * mass * dx)
        self.tt = ei * dt2 / (rho_i * dx * dx)
        self.t0 = kag * dt2 / rho_i
        self.tc = 2.0 - 2.0 * self.tt - self.t0
        self.tz = kag * dt2 / (2.0 * rho_i * dx)
        self.force = dt2 / (mass * dx)
        # The pads (3.9) and the sleepers (3.18) with the damping implicit (3.25).
        kphi, cphi = 2.0 * ls * ls * kb, 2.0 * ls * ls * cb
        zden = 1.0 / (1.0 + cb * dt / ms)
        pden = 1.0 / (1.0 + 0.5 * cphi * dt / js)
        self.ls, self.kpc, self.cp = ls, kp + cp / dt, cp / dt
        self.szz = (2.0 - 2.0 * kb * dt2 / ms) * zden
        self.szp = (cb * dt / ms - 1.0) * zden
        self.szf = dt2 / ms * zden
        self.spp = (2.0 - kphi * dt2 / js) * pden
        self.spq = (0.5 * cphi * dt / js - 1.0) * pden
        self.spf = ls * dt2 / js * pden
        self.seat = np.arange(self.ns) * n
        shape = (2, self.nk)
        self.z, self.th = np.zeros(shape), np.zeros(shape)
        self.z_prev, self.th_prev = np.zeros(shape), np.zeros(shape)
        self.zs, self.ph = np.zeros(self.ns), np.zeros(self.ns)
        self.zs_prev, self.ph_prev = np.zeros(self.ns), np.zeros(self.ns)

    def place(self, x):
        """Node `k` left of position `x` (m) and the fraction `w` to node `k + 1`."""
        s = max(x / self.dx, 0.0)
        k = min(int(s), self.nk - 2)
        return k, s - k

    def step(self, x, loads):
        """One step from t_j with the loads `loads` `[left, right]` (N, down) at `x` (m)."""
        z, th, zp, tp = self.z, self.th, self.z_prev, self.th_prev
        zs, ph, zsp, php = self.zs, self.ph, self.zs_prev, self.ph_prev
        seat = self.seat
        # Pads (3.9): the rail over each seat less the seat's displacement, now and a
        # step back.
        ul = z[0, seat] - (zs - self.ls * ph)
        ur = z[1, seat] - (zs + self.ls * ph)
        upl = zp[0, seat] - (zsp - self.ls * php)
        upr = zp[1, seat] - (zsp + self.ls * php)
        fl = -self.kpc * ul + self.cp * upl
        fr = -self.kpc * ur + self.cp * upr
        # Sleepers (3.18).
        zs_new = self.szz * zs + self.szp * zsp - self.szf * (fl + fr)
        ph_new = self.spp * ph + self.spq * php + self.spf * (fl - fr)
        # Rails (3.4-3.8), interior nodes; the ends stay fixed at zero.
        zn = np.zeros_like(z)
        tn = np.zeros_like(th)
        zn[:, 1:-1] = (self.zc * z[:, 1:-1] + self.zz * (z[:, 2:] + z[:, :-2])
                       - self.zt * (th[:, 2:] - th[:, :-2]) - zp[:, 1:-1])
        tn[:, 1:-1] = (self.tc * th[:, 1:-1] + self.tt * (th[:, 2:] + th[:, :-2])
                       + self.tz * (z[:, 2:] - z[:, :-2]) - tp[:, 1:-1])
        inner = seat[1:-1]
        zn[0, inner] += self.force * fl[1:-1]
        zn[1, inner] += self.force * fr[1:-1]
        # The moving loads, shared by the two nodes around them.
        k, w = self.place(x)
        for rail in (0, 1):
            if k > 0:
                zn[rail, k] -= self.force * (1.0 - w) * loads[rail]
            if k + 2 < self.nk:
                zn[rail, k + 1] -= self.force * w * loads[rail]
        self.z_prev, self.z = z, zn
        self.th_prev, self.th = th, tn
        self.zs_prev, self.zs = zs, zs_new
        self.ph_prev, self.ph = ph, ph_new

    def rail_under(self, x):
        """The rails' deflection under `x` (m), (3.23): the two nodes around it."""
        k, w = self.place(x)
        return (1.0 - w) * self.z[:, k] + w * self.z[:, k + 1]

    def state(self):
        return np.concatenate([self.z.ravel(), self.th.ravel(), self.zs, self.ph])

    def set_state(self, u):
        m = 2 * self.nk
        self.z = u[:m].reshape(2, -1).copy()
        self.th = u[m:2 * m].reshape(2, -1).copy()
        self.zs = u[2 * m:2 * m + self.ns].copy()
        self.ph = u[2 * m + self.ns:].copy()
        self.z_prev, self.th_prev = self.z.copy(), self.th.copy()
        self.zs_prev, self.ph_prev = self.zs.copy(), self.ph.copy()

    def set_static(self, x, loads):
        """The static equilibrium under `loads` at `x`: the fixed point `u = S(u, u)` of
        the step with the state at rest, an affine map whose matrix is probed column by
        column and solved directly."""
        m = len(self.state())

        def at_rest(u):
            self.set_state(u)
            self.step(x, loads)
            return self.state()

        b = at_rest(np.zeros(m))
        a = np.empty((m, m))
        for j in range(m):
            e = np.zeros(m)
            e[j] = 1.0
            a[:, j] = at_rest(e) - b
        u = np.linalg.solve(a - np.eye(m), -b)
        self.set_state(u)


def engine_run(duration, every):
    """The engine's table 4.1 run (rail between nodes by (3.23)): rows of the CSV."""
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target"), "release", "wheelflat")
    out = os.path.join(ROOT, "out", "numpy_track_engine.csv")
    os.makedirs(os.path.dirname(out), exist_ok=True)
    subprocess.run([exe, "--preset", "table4.1", "--between-nodes", "linear", "--duration", str(duration),
                    "--every", str(every), "--output", out], check=True, capture_output=True)
    with open(out) as f:
        return list(csv.DictReader(f))


def check(duration=0.1, every=50):
    """The NumPy track against the engine: the left rail's deflection under the load at
    every `every`-th step. Returns the largest difference in units of the CSV's rounding
    (half a unit in the seventh significant digit of each value; 1: at the rounding)
    and the static deflection (m)."""
    rows = engine_run(duration, every)
    # The CSV's times carry eight decimals: the engine's step is this grid's default.
    dt = DEFAULT_DT
    assert abs(float(rows[1]["time_s"]) - every * dt) < 1e-8, rows[1]["time_s"]
    t = Track(spans=20, n=8, dt=dt)
    v, x0, loads = 50.0 / 3.6, 0.685, (100e3, 100e3)
    t.set_static(x0, loads)
    static = t.rail_under(x0)[0]
    worst = 0.0
    step = 0
    for r in rows:
        k = round(float(r["time_s"]) / dt)
        while step < k:
            t.step(x0 + v * step * dt, loads)
            step += 1
        mine = t.rail_under(x0 + v * step * dt)[0]
        theirs = float(r["rail_z_left_m"])
        worst = max(worst, abs(mine - theirs) / (5e-7 * abs(theirs)))
    return worst, static


def timed(duration, spans=30):
    """Wall time (s) per simulated second of the NumPy track on the table 4.4 grid (n =
    8, the engine's step), `spans` spans, loads moving at 70 km/h."""
    t = Track(spans=spans, n=8)
    v, x0, loads = 70.0 / 3.6, 2 * 0.685, (107664.75, 107664.75)
    steps = int(round(duration / t.dt))
    t0 = time.perf_counter()
    for j in range(steps):
        t.step(x0 + v * j * t.dt, loads)
    return (time.perf_counter() - t0) / (steps * t.dt), t.dt


def engine_timed(duration, spans=30, repeats=5):
    """Wall time (s) per simulated second of the engine on the same case (a run of
    `duration` less a run of none, the best of `repeats`): the command-line runner with
    the constant loads at 70 km/h, its CSV written once at the end."""
    exe = os.path.join(os.environ.get("CARGO_TARGET_DIR") or os.path.join(ROOT, "target"), "release", "wheelflat")
    out = os.path.join(ROOT, "out", "numpy_track_timing.csv")
    os.makedirs(os.path.dirname(out), exist_ok=True)

    def run(d):
        best = float("inf")
        for _ in range(repeats):
            t0 = time.perf_counter()
            subprocess.run([exe, "--preset", "table4.1", "--spans", str(spans), "--speed", "70", "--start", "1.37",
                            "--duration", str(d), "--every", "100000000", "--output", out],
                           check=True, capture_output=True)
            best = min(best, time.perf_counter() - t0)
        return best

    return (run(duration) - run(1e-3)) / (duration - 1e-3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--time", type=float, default=0.1,
                    help="simulated seconds to time, at most 0.9 (the 30-span track's length; default 0.1)")
    ap.add_argument("--no-check", action="store_true", help="skip the check against the engine")
    a = ap.parse_args()
    if not a.no_check:
        err, static = check()
        print(f"NumPy track against the engine (table 4.1, 0.1 s, static deflection {static * 1e3:.4f} mm): "
              f"largest difference {err:.2f} of the CSV's rounding")
        if err > 1.0:
            return 1
    per, dt = timed(a.time)
    print(f"NumPy track, 30 spans, n = 8, dt = {dt * 1e6:.2f} us: {per:.2f} s of wall per simulated second")
    eng = engine_timed(min(a.time, 0.9))
    print(f"the engine on the same case: {eng * 1e3:.1f} ms of wall per simulated second; NumPy / engine = "
          f"{per / eng:.0f}")


if __name__ == "__main__":
    sys.exit(main())
