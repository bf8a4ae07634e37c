#!/usr/bin/env python3
"""An independent reference for the track's receptance (issue 44): Timoshenko rails on
discrete supports, in the frequency domain, by the exact dynamic stiffness of each
rail element. It shares nothing with the Rust engine's discretisation (no grid, no time
stepping): it is the check of `wheelflat receptance`.

The model (docs/MODEL.md, "Receptance (issue 44)"):

* the rail: a Timoshenko beam (EI, kAG, m, m r^2), each piece between two nodes (the
  sleepers, and the load and response points) by its exact harmonic solution: the four
  exponential waves ``exp(lambda x)`` of the first-order system in ``(w, w', theta,
  theta')``, each referred to the end it decays from (no overflow), give the 4 x 4
  dynamic stiffness ``K = F D^-1`` (``D`` the end displacements and rotations of the
  waves, ``F`` the end forces ``(-Q(0), -M(0), Q(a), M(a))``, ``Q = kAG (w' - theta)``,
  ``M = EI theta'``);
* each sleeper: the pad ``k_p + i w c_p`` in series with the sleeper (mass) on the
  ballast ``k_b + i w c_b`` of its seat. Two rails decompose exactly into the
  symmetric case (equal forces on both rails: the sleeper bounces, half its mass
  ``m_s / 2`` per rail) and the antisymmetric one (opposite forces: it rolls about its
  centre, the seats at ``+-L_s / 2``; per rail the mass ``J_s / (2 (L_s / 2)^2) =
  2 J_s / L_s^2``); one rail loaded is half their sum, the other rail half their
  difference;
* a finite track of ``spans`` spans with free ends, the load at the middle sleeper or
  mid-span: its global matrix is block tridiagonal (two unknowns a node), solved for
  every frequency at once by block elimination.

    python3 python/receptance_reference.py --at midspan --rails one --output ref.csv

writes the same columns as ``wheelflat receptance``: frequency_Hz,
magnitude_m_per_N, phase_deg, real, imag (m/N, displacement in the direction of the
force, ``exp(i w t)``).
"""

import argparse
import os
import sys

import numpy as np

# The FMUs' default track: table 4.4 (src/sim/presets.rs), EI, kAG and m r^2 as the
# engine derives them from E, G, A, I, kappa, m.
TABLE_4_4 = {
    "ei": 2.07e11 * 2.94e-5,
    "kag": 0.34 * 7.77e-3 * 81e9,
    "mass": 60.0,
    "rotary_inertia": 60.0 * 2.94e-5 / 7.77e-3,
    "sleeper_spacing": 0.685,
    "rail_seat_distance": 1.505,
    "kp": 140e6,
    "cp": 45e3,
    "kb": 40e6,
    "cb": 50e3,
    "ms": 270.0,
    "js": 90.0,
}


def element_stiffness(p, length, omega):
    """The exact dynamic stiffness (nf, 4, 4) of a Timoshenko rail piece of `length`
    (m) at each angular frequency of `omega` (nf,): unknowns (w0, theta0, w1, theta1),
    forces and moments on the piece at its ends."""
    ei, kag, m, mr2 = p["ei"], p["kag"], p["mass"], p["rotary_inertia"]
    nf = len(omega)
    a = np.zeros((nf, 4, 4))
    a[:, 0, 1] = 1.0
    a[:, 1, 0] = -m * omega ** 2 / kag
    a[:, 1, 3] = 1.0
    a[:, 2, 3] = 1.0
    a[:, 3, 1] = -kag / ei
    a[:, 3, 2] = (kag - mr2 * omega ** 2) / ei
    lam, vec = np.linalg.eig(a)                       # (nf, 4), (nf, 4, 4): columns
    # Each wave referred to the end it decays from: exp(lam (x - x0)), |.| <= 1 inside.
    x0 = np.where(lam.real > 0, length, 0.0)
    e0 = np.exp(lam * (0.0 - x0))
    e1 = np.exp(lam * (length - x0))
    w, dw, th, dth = vec[:, 0, :], vec[:, 1, :], vec[:, 2, :], vec[:, 3, :]
    d = np.stack([w * e0, th * e0, w * e1, th * e1], axis=1)
    q, mom = kag * (dw - th), ei * dth
    f = np.stack([-q * e0, -mom * e0, q * e1, mom * e1], axis=1)
    # K = F D^-1, i.e. K^T = D^-T F^T.
    return np.swapaxes(np.linalg.solve(np.swapaxes(d, 1, 2), np.swapaxes(f, 1, 2)), 1, 2)


def support_stiffness(p, omega, mass):
    """The dynamic stiffness (N/m) the rail feels at a sleeper: the pad in series with
    the sleeper's `mass` (kg, per rail) on the ballast."""
    kp = p["kp"] + 1j * omega * p["cp"]
    below = p["kb"] + 1j * omega * p["cb"] - omega ** 2 * mass
    return kp * below / (kp + below)


def one_rail(p, omega, mass, spans, load_x, resp_x):
    """Receptance (nf,) of one rail on supports of sleeper `mass` per rail: the rail's
    deflection at `resp_x` per unit force at `load_x` (m, from the first sleeper)."""
    a = p["sleeper_spacing"]
    sleepers = np.arange(spans + 1) * a
    nodes = np.unique(np.round(np.concatenate([sleepers, [load_x, resp_x]]), 12))
    is_sleeper = np.isin(nodes, np.round(sleepers, 12))
    nf, nn = len(omega), len(nodes)
    ks = support_stiffness(p, omega, mass)
    cache = {}
    blocks = []
    for e in range(nn - 1):
        length = round(nodes[e + 1] - nodes[e], 12)
        if length not in cache:
            cache[length] = element_stiffness(p, length, omega)
        blocks.append(cache[length])
    diag = np.zeros((nn, nf, 2, 2), complex)
    for e, k in enumerate(blocks):
        diag[e] += k[:, :2, :2]
        diag[e + 1] += k[:, 2:, 2:]
    diag[is_sleeper, :, 0, 0] += ks
    rhs = np.zeros((nn, nf, 2), complex)
    rhs[np.argmin(abs(nodes - load_x)), :, 0] = 1.0
    # Block elimination (Thomas) over the nodes, every frequency at once.
    cp, dp = [], []
    for i in range(nn):
        mi, bi = diag[i], rhs[i]
        if i > 0:
            low = blocks[i - 1][:, 2:, :2]
            mi = mi - low @ cp[-1]
            bi = bi - (low @ dp[-1][..., None])[..., 0]
        up = blocks[i][:, :2, 2:] if i < nn - 1 else np.zeros((nf, 2, 2))
        cp.append(np.linalg.solve(mi, up))
        dp.append(np.linalg.solve(mi, bi[..., None])[..., 0])
    x = dp[-1]
    r = np.argmin(abs(nodes - resp_x))
    for i in range(nn - 2, r - 1, -1):
        x = dp[i] - (cp[i] @ x[..., None])[..., 0]
    return x[:, 0]


def receptance(freqs, at="sleeper", rails="one", response="point", p=None, spans=400):
    """The reference receptance (m/N, complex, nf) at `freqs` (Hz): load at the middle
    sleeper or mid-span (`at`), on one rail or both (`rails`, equal forces), response
    `point`, `other-rail` or a distance (m, float) along the loaded rail."""
    p = dict(TABLE_4_4, **(p or {}))
    omega = 2 * np.pi * np.asarray(freqs, float)
    a = p["sleeper_spacing"]
    load_x = (spans // 2) * a + (0.5 * a if at == "midspan" else 0.0)
    resp_x = load_x + (float(response) if response not in ("point", "other-rail") else 0.0)
    sym = one_rail(p, omega, 0.5 * p["ms"], spans, load_x, resp_x)
    if rails == "both":
        return sym
    anti = one_rail(p, omega, 2 * p["js"] / p["rail_seat_distance"] ** 2, spans, load_x, resp_x)
    return 0.5 * (sym - anti) if response == "other-rail" else 0.5 * (sym + anti)


def write_csv(path, freqs, alpha):
    with open(path, "w") as fh:
        fh.write("frequency_Hz,magnitude_m_per_N,phase_deg,real,imag\n")
        for f, a in zip(freqs, alpha):
            fh.write(f"{f:.6f},{abs(a):.9e},{np.degrees(np.angle(a)):.6f},{a.real:.9e},{a.imag:.9e}\n")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--at", choices=["sleeper", "midspan"], default="sleeper")
    ap.add_argument("--rails", choices=["one", "both"], default="one")
    ap.add_argument("--response", default="point", help="point, other-rail or a distance (m)")
    ap.add_argument("--from", dest="f0", type=float, default=20.0)
    ap.add_argument("--to", dest="f1", type=float, default=3000.0)
    ap.add_argument("--points", type=int, default=200)
    ap.add_argument("--spans", type=int, default=400)
    ap.add_argument("--output", required=True)
    args = ap.parse_args(argv)
    if not (0 < args.f0 < args.f1) or args.points < 2:
        ap.error(f"--from {args.f0} --to {args.f1} --points {args.points}: need 0 < from < to, points >= 2")
    freqs = np.geomspace(args.f0, args.f1, args.points)
    alpha = receptance(freqs, args.at, args.rails, args.response, spans=args.spans)
    write_csv(args.output, freqs, alpha)
    print(f"wrote {os.path.relpath(args.output)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
