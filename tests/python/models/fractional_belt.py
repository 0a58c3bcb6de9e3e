# The fractional belt: a mass on a belt with velocity-weakening (Stribeck) friction and a Caputo
# damping of order 1/2,
#     x'' + c_f D^(1/2) x + k x + F(x' - v_b) = 0,   m = k = 1, c_f = 0.1,
# F(y) = mu(y) sign y, mu(y) = 0.5 + 0.3 e^(-|y| / 0.5), split as the docs' Stribeck section does
# (the sign graph at the static level 0.8 in A, the continuous rest g in f); in u = (x, y), y = x' -
# v_b: f = (-(y + v_b), x + g(y) + c_f W v_b), W = 2 sqrt(tau / pi), and the kernel c_f s^-1/2 /
# Gamma(1/2) on y, fitted by dmi.kernels.fit(PowerKernel(...), tau, tol=1e-8, relative=True, delta=0.002)
# (exponential terms plus exact near cells).  Stick-slip at v_b = 0.6 (period about 6.30), a Hopf
# point of the sliding equilibrium at v_b ~ 1.025.  Shared by bench/bench_longmem.py (tau = 50,
# about eight periods) and the collocation tests of graded switches (a shorter memory).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
from typing import Callable

import numba
import numpy as np

import dmi
from dmi import analysis as da
from dmi import kernels

CF, H, DELTA = 0.1, 0.005, 0.002              # damping, the scheme's step, the near cells
MU_S, MU_D, V_S = 0.8, 0.5, 0.5               # static, dynamic friction, Stribeck velocity
VB_SLIP, PERIOD_SLIP = 0.6, 6.315             # the stick-slip orbit's belt speed and period


@numba.njit
def weakening(v: float) -> float:
    """g(v) = F(v) - mu_s sign(v): continuous, g(0) = 0."""
    return -math.copysign((MU_S - MU_D) * -math.expm1(-abs(v) / V_S), v)


def model(tau: float) -> tuple[Callable[..., dmi.Solver], kernels.KernelFit]:
    """(make(v_b, h=H), the kernel's fit): the fractional belt with the memory tau."""
    fit = kernels.fit(kernels.PowerKernel(0.5, CF / math.sqrt(math.pi)), tau, tol=1e-8,
                      relative=True, delta=DELTA)
    w = 2 * math.sqrt(tau / math.pi)

    def make(vb: float, h: float = H) -> dmi.Solver:
        s = dmi.Solver(2, tau, h=h)
        s.set_rhs(lambda t, u: np.array([-(u[1] + vb), u[0] + weakening(u[1]) + CF * w * vb]),
                  jit=True)
        s.set_friction([0.0, MU_S])
        s.set_quadrature("cell")
        s.set_kernel_fit(fit, entry=(1, 1))
        return s
    return make, fit


def stick_slip_orbit(make: Callable[..., dmi.Solver], periods: int = 40) -> da.Orbit:
    """The scheme's stick-slip orbit at v_b = 0.6 (steps of about H), reached from (0.5, 0)
    after ``periods`` periods."""
    M = round(PERIOD_SLIP / H)
    s = make(VB_SLIP, h=PERIOD_SLIP / M)
    s.set_history(lambda t: np.array([0.5, 0.0]))
    s.init()
    s.advance(periods * M)
    return da.periodic_orbit(make, VB_SLIP, None, s, guess_period=PERIOD_SLIP, steps=M,
                             multipliers=0)
