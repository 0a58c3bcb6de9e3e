# Two stick-slip oscillators with an exponential memory g e^{-s} on [0, tau], tau = 30 (dry friction
# and set_kernel_exp): an autonomous belt, x' = y + V, y' in -x + k (y + V) - g I - alpha Sign(y),
# and a forced oscillator x'' + c x' + x + alpha Sign(x') + g I = F cos(w t).  Shared by the
# collocation tests of their multipliers (against an integration) and of the Jacobian's columns
# of their switching times.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

import dmi

TAU = 30.0                                  # e^{-tau} = 9.4e-14
V, ALPHA, G, K = 0.5, 0.4, 0.3, 0.05       # the belt (k: its negative damping, the parameter)
W, FF, ALPHA_F, C, G_F = 0.5, 1.5, 0.5, 0.05, 0.5   # the forced one (FF: the forcing, p)
PF = 2 * math.pi / W


def belt(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.05 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + V), u[0] - p * (u[1] + V)]))
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [G, 0.0]]])
    return s


def forced_for(M: int):
    """make(p), p the forcing's amplitude, h = PF / M."""
    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(2, TAU, h=PF / M)
        s.set_rhs(lambda t, u: np.array([-u[1], u[0] + C * u[1] - p * np.cos(W * t)]))
        s.set_friction([0.0, ALPHA_F])
        s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [G_F, 0.0]]])
        return s
    return make
