# A Stuart-Landau oscillator with a distributed memory whose frequency grows with the amplitude:
# the model of plot_interactive_branch.py (and of the interactive figures' tests).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""z' = (mu - |z|^2) z + i (w0 + b |z|^2) z - int_0^tau k e^(-a s) z(t - s) ds, z = u_1 + i u_2;
in dmi's form u' + f(u) + int_0^tau H(s) u(t - s) ds = 0 with f = -(mu - r^2) u - (w0 + b r^2) J u
(J the rotation by pi/2) and H = k e^(-a s) I.  The rest u = 0 loses its stability at a Hopf
point as mu grows (near mu = 0.26 for the constants below); the orbits born there are circles
whose period shrinks as they grow."""
from __future__ import annotations

import numpy as np

import dmi

W0, B, K, A, TAU, N = 1.0, 1.5, 0.5, 1.0, 1.0, 40


def make(mu: float, h: float | None = None, k: float = K) -> dmi.Solver:
    """The oscillator at mu with the memory gain k, step tau / N (or h: an autonomous orbit's
    period sets it)."""
    s = dmi.Solver(2, TAU, N) if h is None else dmi.Solver(2, TAU, h=h)

    def f(t, u):
        r2 = u[0] ** 2 + u[1] ** 2
        g, w = mu - r2, W0 + B * r2
        return np.array([-g * u[0] + w * u[1], -g * u[1] - w * u[0]])
    s.set_rhs(f)
    s.set_kernel_exp([-A], [0.0], [k * np.eye(2)])
    return s
