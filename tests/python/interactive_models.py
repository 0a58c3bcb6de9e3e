# Small, fast branches and a chart for the interactive figures' tests (test_analysis_interactive.py
# and tests/docs/browser_check.py figures): a Stuart-Landau oscillator with a distributed delay
# whose frequency grows with the amplitude, so that the period changes along its orbit branch.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

import dmi
from dmi import analysis as da

# z' = (mu - |z|^2) z + i (w0 + b |z|^2) z - int_0^tau k e^(-a s) z(t - s) ds, z = u_1 + i u_2;
# in dmi's form u' + f + int H u = 0: f = -(mu - r^2) u - (w0 + b r^2) J u, H = k e^(-a s) I.
W0, B, KG, AG, TAU, N = 1.0, 1.5, 0.5, 1.0, 1.0, 40


def landau(mu: float, h: float | None = None, q: float = KG) -> dmi.Solver:
    """The oscillator at mu (kernel gain q), step tau / N (or h)."""
    s = dmi.Solver(2, TAU, N) if h is None else dmi.Solver(2, TAU, h=h)

    def f(t, u):
        r2 = u[0] ** 2 + u[1] ** 2
        g, w = mu - r2, W0 + B * r2
        return np.array([-g * u[0] + w * u[1], -g * u[1] - w * u[0]])
    s.set_rhs(f)
    s.set_kernel_exp([-AG], [0.0], [q * np.eye(2)])
    return s


def landau2(mu: float, q: float) -> dmi.Solver:
    """The two-parameter model of the chart: mu and the kernel gain q."""
    return landau(mu, q=q)


def branches(points: int = 5) -> tuple[da.Branch, da.Branch]:
    """The branch of equilibria u = 0 over mu in [0, 0.6] (a Hopf point near mu = 0.25) and the
    branch of orbits born there (``points`` points, their period shrinking as they grow)."""
    eq = da.equilibrium(landau, 0.0, [0.02, -0.01])
    equilibria = da.continue_equilibrium(eq, 0.6, step=0.1)
    hopf = next(e for e in equilibria.events if e.kind == "hopf")
    M = round(2 * math.pi / hopf.hopf.omega / (TAU / N))
    o = da.hopf_orbit(landau, hopf.hopf, hopf.u, amplitude=0.1, steps=M, component=0)
    orbits = da.continue_orbit(o, 1.0, step=0.1, max_points=points, multipliers=3)
    return equilibria, orbits


def chart() -> da.StabilityChart:
    """The rightmost root of u = 0 on a 4 x 3 grid of (mu, q), without traced curves."""
    return da.stability_chart(landau2, [0.0, 0.2, 0.4, 0.6], [0.2, 0.5, 0.8], [0.0, 0.0],
                              workers=1, trace=False)
