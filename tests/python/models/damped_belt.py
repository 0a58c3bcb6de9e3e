# A belt with a memory that destabilises sliding (the self-excited oscillations' tests and the
# landing test's orbit on a vertical branch):
# x' = v + v_b, v' + k x + c (v + v_b) + alpha sigma(v) + (g / tau) int_0^tau x(t - s) ds ∋ 0,
# v = x' - v_b; sliding equilibrium x = alpha / (k + g), v = -v_b; the memory makes it lose
# stability as the damping c falls.  While the orbit slips the system is linear: the branch leaves
# the Hopf point vertically up to grazing (v reaches 0), then sticks.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np

import dmi

TAU = 1.0
KB, GB, ALPHA, VB = 1.0, 0.8, 0.5, 0.3


def belt(c: float, h: float | None = None, N: int = 50) -> dmi.Solver:
    s = dmi.Solver(2, TAU, N) if h is None else dmi.Solver(2, TAU, h=h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + VB), KB * u[0] + c * (u[1] + VB)]))
    s.set_kernel_exp([0.0], [0.0], [np.array([[0.0, 0.0], [GB / TAU, 0.0]])])
    s.set_friction([0.0, ALPHA])
    return s
