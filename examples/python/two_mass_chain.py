#!/usr/bin/env python3
# Two masses on a line with dry friction and a viscoelastic (Prony-series)
# memory, integrated by libdmi through the Python binding with a numba cfunc
# right-hand side, and plotted with matplotlib.  See docs/python.md.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Two-mass chain with dry friction and a Prony-series memory.

    wall --k1-- m1 --k2-- m2 <- F cos(omega t)

x = (x1, x2) the displacements, v = x' the velocities.  Each mass rubs on the ground with dry
(Coulomb) friction mu_i, and the springs relax: besides K x, their force has a fading memory
of the past displacements, a Prony series G(s) = sum_k g_k exp(-s / theta_k) K, cut at
tau = 2 (exp(-2 / 0.5) < 2 %):

    m x'' + K x + int_0^tau G(s) x(t - s) ds + mu sigma(x') ∋ F(t).

In libdmi's first-order form u = (x1, x2, v1, v2):  u' + A(u) + f(t, u) + int H(s) u(t-s) ds ∋ 0,
f = (-v, M^-1 (K x - F(t))), A = the friction mu_i / m_i on v_i (built in), H(s) the block
M^-1 G(s) in rows v, columns x: two exponential terms (Solver.set_kernel_exp, computed by the
O(1) recursion).  f is a numba cfunc reading its parameters through the user pointer.
"""
from __future__ import annotations

import argparse
import time

import numpy as np

# The model (also read by the test, tests/python/binding/test_example.py).
K1, K2 = 1.0, 0.8          # spring stiffnesses
M1, M2 = 1.0, 0.5          # masses
MU = (0.12, 0.1)           # friction forces
FORCE, OMEGA = 0.3, 1.2    # the drive on m2
G = (0.4, 0.2)             # Prony weights g_k
THETA = (0.1, 0.5)         # relaxation times theta_k
TAU = 2.0                  # memory cut-off


def stiffness() -> np.ndarray:
    return np.array([[K1 + K2, -K2], [-K2, K2]])


def kernel_terms() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a, b, C) of H(s) = sum_k exp(a_k s) C_k for Solver.set_kernel_exp: C_k is g_k M^-1 K in
    the rows of v and the columns of x."""
    a = -1.0 / np.array(THETA)
    C = np.zeros((len(G), 4, 4))
    for k, g in enumerate(G):
        C[k, 2:, :2] = g * stiffness() / np.array([[M1], [M2]])
    return a, np.zeros(len(G)), C


def params() -> np.ndarray:
    """The right-hand side's parameters, passed to it through the user pointer."""
    return np.array([K1, K2, M1, M2, FORCE, OMEGA])


def numba_rhs():
    """f(t, u) as a numba cfunc; its user pointer is a double * to the values of params()."""
    import numba
    from numba import types

    sig = types.intc(types.float64, types.CPointer(types.float64), types.CPointer(types.float64),
                     types.CPointer(types.float64))

    @numba.cfunc(sig)
    def rhs(t, u, out, user):
        k1, k2, m1, m2, force, omega = user[0], user[1], user[2], user[3], user[4], user[5]
        out[0] = -u[2]
        out[1] = -u[3]
        out[2] = ((k1 + k2) * u[0] - k2 * u[1]) / m1
        out[3] = (-k2 * u[0] + k2 * u[1] - force * np.cos(omega * t)) / m2
        return 0
    return rhs


def simulate(T: float, N: int) -> tuple[np.ndarray, np.ndarray, float]:
    """(t, U, seconds): the states at every step from 0 to T with h = TAU / N, from rest."""
    import dmi

    p = params()
    s = dmi.Solver(4, TAU, N)
    s.set_rhs(numba_rhs(), p)  # the cfunc's user pointer: p's data (the solver keeps p alive)
    s.set_friction([0.0, 0.0, MU[0] / M1, MU[1] / M2])
    s.set_kernel_exp(*kernel_terms())
    s.init()
    start = time.perf_counter()
    t, U = s.run(round(T / s.h))
    return t, U, time.perf_counter() - start


def plot(t: np.ndarray, U: np.ndarray, path: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax_x, ax_v) = plt.subplots(2, 1, sharex=True, figsize=(9.5, 5.5))
    for i, c in enumerate(("tab:blue", "tab:red")):
        ax_x.plot(t, U[:, i], color=c, label=f"$x_{i + 1}$")
        ax_v.plot(t, U[:, 2 + i], color=c, label=f"$v_{i + 1}$")
        stuck = U[:, 2 + i] == 0
        ax_v.plot(t[stuck], np.zeros(stuck.sum()) - 0.02 * (i + 1), "|", color=c, ms=4,
                  label=f"mass {i + 1} sticks")
    ax_x.set_ylabel("displacement $x_i$")
    ax_v.set_ylabel("velocity $v_i = x_i'$")
    ax_v.set_xlabel("time $t$")
    # the legends beside the axes, not over the curves
    ax_x.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
    ax_v.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax_x.set_title("Two-mass chain, dry friction, Prony-series memory (libdmi from Python, numba)")
    fig.tight_layout()
    fig.savefig(path, dpi=120)


def main() -> None:
    ap = argparse.ArgumentParser(description="Integrates the two-mass chain with libdmi (numba "
                                 "callbacks), plots it and prints the time per step and the "
                                 "fractions of time each mass sticks.")
    ap.add_argument("--T", type=float, default=60.0, help="end time (default: 60)")
    ap.add_argument("--N", type=int, default=2000, help="steps per tau = 2, h = 2 / N (default: 2000)")
    ap.add_argument("--out", default="two_mass_chain.png", help="the plot (default: two_mass_chain.png)")
    ap.add_argument("--csv", help="also write t,x1,x2,v1,v2 of every step there (default: none)")
    args = ap.parse_args()
    if not (args.T > 0 and args.N >= 1):
        ap.error("--T must be > 0 and --N >= 1")
    t, U, secs = simulate(args.T, args.N)
    if args.csv:
        np.savetxt(args.csv, np.column_stack([t, U]), delimiter=",", header="t,x1,x2,v1,v2",
                   comments="", fmt="%.17g")
    plot(t, U, args.out)
    steps = len(t) - 1
    print(f"{steps} steps of h = {TAU / args.N:g} in {secs:.3f} s ({1e9 * secs / steps:.0f} ns per step)")
    for i in range(2):
        print(f"mass {i + 1} sticks {np.mean(U[1:, 2 + i] == 0):.1%} of the time")
    print(f"plot: {args.out}")


if __name__ == "__main__":
    main()
