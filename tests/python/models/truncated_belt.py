# A belt with a truncated exponential memory, x' = y + V, y' ∈ -x + p (y + V) - g int_0^tau e^{-s}
# x(t - s) ds - alpha Sign(y) (y: the block's velocity relative to the belt), and its Hopf point
# and equilibrium in closed form: while y < 0 it is linear, every amplitude below grazing an orbit
# at p_H (a vertical branch).  Shared by the collocation tests (its branch, its refusals, the
# Newton solve at its floor).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import scipy.optimize as so

import dmi

V, ALPHA, GB, TAUB = 0.5, 0.4, 0.3, 2.0


def belt(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAUB, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + V), u[0] - p * (u[1] + V)]))
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [GB, 0.0]]])
    return s


def hopf() -> tuple[float, float, float]:
    """(omega, p_H, x_eq): lambda^2 - p lambda + 1 + g K(lambda) = 0 at lambda = i omega,
    K(lambda) = (1 - e^{-(1 + lambda) tau}) / (1 + lambda); x_eq (1 + g (1 - e^{-tau})) = alpha."""
    def K(lam: complex) -> complex:
        return (1 - np.exp(-(1 + lam) * TAUB)) / (1 + lam)
    om = so.brentq(lambda w: 1 - w * w + GB * K(1j * w).real, 0.3, 3.0, xtol=1e-15)
    return om, GB * K(1j * om).imag / om, ALPHA / (1 + GB * (1 - math.exp(-TAUB)))
