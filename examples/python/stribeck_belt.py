# A mass on a moving belt with velocity-weakening (Stribeck) friction and fractional (Caputo 1/2)
# damping of a long memory: the model of plot_stribeck_belt.py (and of its checks in
# tests/python/analysis/scheme/test_verified.py).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""x'' + c D^(1/2) x + k x + F(x' - v_b) ∋ 0 with the Stribeck law

    F(v) = sign(v) (mu_d + (mu_s - mu_d) e^(-|v| / v_s)),   F(0) = [-mu_s, mu_s],

split into the maximal monotone sign graph at the *static* level, mu_s sigma(v), which goes to A
(the resolvent's dead zone holds the stick), and the continuous remainder

    g(v) = F(v) - mu_s sign(v) = -sign(v) (mu_s - mu_d) (1 - e^(-|v| / v_s)),   g(0) = 0,

which goes to f: it is Lipschitz with the constant L = (mu_s - mu_d) / v_s (its slope at 0+, the
largest), and it is *not* monotone (velocity weakening: g decreases), which f may be while A may
not.  In the relative velocity y = x' - v_b, u = (x, y):
f = (-(y + v_b), k x + g(y) + c v_b W), A = {0} x mu_s sigma, and the kernel c s^(-1/2) / Gamma(1/2)
in row y, column y (fitted by dmi.kernels.fit on [h, tau], the first cell exact), W =
int_0^tau s^(-1/2) / Gamma(1/2) ds = 2 sqrt(tau / pi) the belt's constant part of D^(1/2) x.
The memory tau is 8 periods of the free oscillation: a long memory, whose Floquet multipliers
form a ring of nearly equal modulus."""
from __future__ import annotations

import math
from collections.abc import Callable

import numba
import numpy as np

import dmi
from dmi import kernels

K, C = 1.0, 0.1                     # stiffness, fractional damping
MU_S, MU_D, V_S = 0.5, 0.3, 0.3     # static and dynamic friction levels, Stribeck velocity
LIPSCHITZ = (MU_S - MU_D) / V_S     # of the continuous part g
P0 = 2 * math.pi                    # the free period
TAU = 8 * P0                        # the memory: 8 periods
M = 200                             # steps a period
W = 2 * math.sqrt(TAU / math.pi)    # int_0^tau s^-1/2 / Gamma(1/2) ds
def stribeck(v: float) -> float:
    """F(v) for v != 0 (at v = 0 the interval [-mu_s, mu_s])."""
    return math.copysign(MU_D + (MU_S - MU_D) * math.exp(-abs(v) / V_S), v)


@numba.njit
def weakening(v: float) -> float:
    """g(v) = F(v) - mu_s sign(v): continuous, g(0) = 0, Lipschitz with (mu_s - mu_d) / v_s."""
    return -math.copysign((MU_S - MU_D) * -math.expm1(-abs(v) / V_S), v)


def model(steps: int = M) -> Callable[..., dmi.Solver]:
    """The model make(vb, h=...) at ``steps`` steps a free period: the fractional kernel fitted
    on [h, tau] (relative error 1e-8) with its first cell exact."""
    h0 = P0 / steps
    fit = kernels.fit(kernels.PowerKernel(0.5, C / math.sqrt(math.pi)), TAU, tol=1e-8,
                      relative=True, delta=h0)

    def make(vb: float, h: float = h0) -> dmi.Solver:
        """The belt at the speed vb with the step h (an autonomous orbit's period sets h): the
        right-hand side compiled by numba (jit=True), the sign graph at mu_s in A, the fitted
        fractional kernel with its first cell exact (the cell rule)."""
        s = dmi.Solver(2, TAU, h=h)
        s.set_rhs(lambda t, u: np.array([-(u[1] + vb), K * u[0] + weakening(u[1]) + C * W * vb]),
                  jit=True)
        s.set_friction([0.0, MU_S])
        s.set_quadrature("cell")
        s.set_kernel_fit(fit, entry=(1, 1))
        return s
    return make


make = model(M)


def period_changes(make_p, p: float, state: np.ndarray, steps: int, periods: int,
                   kick: float) -> np.ndarray:
    """e_k = max |U over period k - U over period k - 1|, k = 1 .. periods - 1, of a plain run
    from the orbit's state with its last row's y scaled by 1 + kick: the growth (or decay) of a
    perturbation a period, the shift along the orbit cancelled."""
    s = make_p(p)
    X = np.array(np.asarray(state).reshape(-1, 2)[-(s.N + 1):])
    X[-1, 1] *= 1 + kick
    s.init()
    s.set_window(X)
    U = s.run(periods * steps)[1]
    s.close()
    return np.array([np.max(np.abs(U[k * steps + 1:(k + 1) * steps + 1]
                                   - U[(k - 1) * steps + 1:k * steps + 1]))
                     for k in range(1, periods)])


def amplitude_deviation(make_p, p: float, state: np.ndarray, steps: int, periods: int,
                        kick: float, amplitude: np.ndarray) -> np.ndarray:
    """max_i |A_i(k) - amplitude_i| for each period k of a plain run from the orbit's state with
    kick added to its last row's y, A_i(k) the half range of u_i over period k: how far the run
    is from the orbit across it (a shift along the orbit leaves the amplitude alone)."""
    s = make_p(p)
    X = np.array(np.asarray(state).reshape(-1, 2)[-(s.N + 1):])
    X[-1, 1] += kick
    s.init()
    s.set_window(X)
    U = s.run(periods * steps)[1]
    s.close()
    B = U[1:].reshape(periods, steps, 2)
    return np.max(np.abs(0.5 * (B.max(axis=1) - B.min(axis=1)) - amplitude), axis=1)
