# Zero-Hopf and Hopf-Hopf points detected and located on Hopf curves (dmi.analysis.continue_curve)
# against closed forms written here: rotationally symmetric oscillators with a distributed memory,
# whose characteristic equation splits into scalar ones solved here, one with a second
# oscillator whose pair crosses on the curve (Hopf-Hopf), one with a scalar component whose
# equilibrium folds on the curve (zero-Hopf); a few seconds each.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.equilibria.normal_form import CriticalityWarning

# Every component has the memory int_0^TAU G e^-s u(t - s) ds, whose transform is
# g(lam) = G (1 - e^-(1 + lam) TAU) / (1 + lam).  An oscillator z' = (mu + i W) z + C1 |z|^2 z -
# memory (z = x + i y) linearised at 0 has the roots of lam + g(lam) = mu + i W and their
# conjugates: a pair +-i Om on the axis where Om + Im g(i Om) = W and mu = Re g(i Om).  A scalar
# x' = -x^2 + q - memory has the equilibria x^2 + g(0) x = q and the root lam of
# lam + 2 x + g(lam) = 0: a root 0 where x = -g(0) / 2, at the fold q = -g(0)^2 / 4.
G, TAU = 0.5, 2.0
W1, W2 = 1.0, 2.0
A, B, C = 0.5, 0.5, -0.35
C1 = -1.0 + 0.5j
#: The located point's (p, q) to this (the curve is corrected to 1e-10, each event located by
#: Brent's method along the arclength; measured about 1e-11).
TOL = 1e-8


def g(lam: complex) -> complex:
    return G * (1 - np.exp(-(1 + lam) * TAU)) / (1 + lam)


def pair(W: float) -> tuple[float, float]:
    """(Om, mu) of the oscillator's pair on the axis."""
    om = so.brentq(lambda w: w + g(1j * w).imag - W, 0.1, 5.0, xtol=1e-15, rtol=1e-15)
    return om, g(1j * om).real


def oscillator(mu: float, W: float, x: float, y: float) -> tuple[float, float]:
    """The right-hand side of z' = (mu + i W) z + C1 |z|^2 z at z = x + i y."""
    z = complex(x, y)
    w = (mu + 1j * W) * z + C1 * abs(z) ** 2 * z
    return w.real, w.imag


def two_oscillators(p: float, q: float) -> dmi.Solver:
    """z1 with mu = p + A q and z2 with mu = q + C p: the Hopf curve of z1 is p = mu1 - A q,
    and z2's pair crosses on it where q + C p = mu2."""
    s = dmi.Solver(4, TAU, 20)
    s.set_rhs(lambda t, u: -np.array([*oscillator(p + A * q, W1, u[0], u[1]),
                                      *oscillator(q + C * p, W2, u[2], u[3])]))
    s.set_kernel_exp([-1.0], [0.0], [G * np.eye(4)])
    return s


def oscillator_and_fold(p: float, q: float) -> dmi.Solver:
    """z1 with mu = p + A q + B x, and x' = -x^2 + q: the Hopf curve of z1 is
    p = mu1 - A q - B x(q), x(q) on a branch of x^2 + g(0) x = q; at the fold x = -g(0) / 2 a
    real root crosses 0 (and the curve turns back in q)."""
    s = dmi.Solver(3, TAU, 20)
    s.set_rhs(lambda t, u: -np.array([*oscillator(p + A * q + B * u[2], W1, u[0], u[1]),
                                      -u[2] ** 2 + q]))
    s.set_kernel_exp([-1.0], [0.0], [G * np.eye(3)])
    return s


def curve(make2, p0: float, q0: float, q_end: float, u0: np.ndarray, **kw) -> da.Curve:
    om1, _ = pair(W1)
    with warnings.catch_warnings():   # the criticality's, near the zero-Hopf point
        warnings.simplefilter("ignore", CriticalityWarning)
        return da.continue_curve(da.HopfPoint(p=p0, omega=om1, root=1j * om1), make2, q0, q_end,
                                 u_eq=u0, **kw)


def test_hopf_hopf_point_on_the_hopf_curve():
    _, mu1 = pair(W1)
    om2, mu2 = pair(W2)
    # p = mu1 - A q and q + C p = mu2
    q_hh = (mu2 - C * mu1) / (1 - C * A)
    p_hh = mu1 - A * q_hh
    q0 = q_hh + 0.04
    cv = curve(two_oscillators, mu1 - A * q0, q0, q_hh - 0.04, np.zeros(4))
    assert cv.status.startswith("reached"), cv.status
    # every point on the closed-form curve
    assert np.max(np.abs(cv.p - (mu1 - A * cv.q))) <= 1e-9
    hh = [e for e in cv.events if e.kind == "hopf-hopf"]
    assert len(hh) == 1 and not [e for e in cv.events if e.kind == "zero-hopf"], cv.events
    e = hh[0]
    assert abs(e.p - p_hh) <= TOL and abs(e.q - q_hh) <= TOL, (e.p - p_hh, e.q - q_hh)
    # the second pair crosses at z2's frequency
    om = float(e.detail.split("omega = ")[1].split()[0])
    assert abs(om - om2) <= 1e-6, (om, om2)
    assert np.max(np.abs(e.u)) <= 1e-9
    # the event lies between the points around it
    assert cv.points[e.index - 1].q > q_hh > cv.points[e.index].q


def test_zero_hopf_point_on_the_hopf_curve():
    _, mu1 = pair(W1)
    g0 = g(0.0).real
    x_zh, q_zh = -g0 / 2, -g0 * g0 / 4
    p_zh = mu1 - A * q_zh - B * x_zh
    q0 = q_zh + 0.03
    x0 = (-g0 + math.sqrt(g0 * g0 + 4 * q0)) / 2          # the branch of the stable root
    cv = curve(oscillator_and_fold, mu1 - A * q0 - B * x0, q0, q_zh - 0.02,
               np.array([0.0, 0.0, x0]), step=0.01, max_points=30)
    # the curve turns back in q at the fold (it cannot pass below q_zh) and leaves its range
    assert cv.status.startswith("left the range"), cv.status
    assert np.min(cv.q) >= q_zh - 1e-12
    x = np.array([pt.u[2] for pt in cv.points])
    assert np.max(np.abs(x * x + g0 * x - cv.q)) <= 1e-9
    assert np.max(np.abs(cv.p - (mu1 - A * cv.q - B * x))) <= 1e-9
    zh = [e for e in cv.events if e.kind == "zero-hopf"]
    assert len(zh) == 1 and not [e for e in cv.events if e.kind == "hopf-hopf"], cv.events
    e = zh[0]
    assert abs(e.p - p_zh) <= TOL and abs(e.q - q_zh) <= TOL, (e.p - p_zh, e.q - q_zh)
    assert abs(e.u[2] - x_zh) <= 1e-6, (e.u, x_zh)
    assert "real root crosses 0" in e.detail
