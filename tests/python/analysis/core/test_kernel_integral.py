# The continuous integral int_0^tau H of a callback kernel (dmi.analysis.core.model.kernel_integral)
# against closed forms: a kernel with jumps at declared lags is integrated piecewise between them
# (to rounding), where one quadrature across a jump is off by at most the jump times the panel's
# width; without jumps the panels are uniform, min(tau / 8, 1 / reach) wide.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi.analysis.core.model import PANEL_NODES, equation_terms, kernel_integral, kernel_panels

TAU, LAG1, LAG2 = 1.0, 0.37, 0.8125


def H(s: float) -> np.ndarray:
    """exp(-s) before LAG1, 0.5 from LAG1 to LAG2, s^2 after; an off-diagonal 3 before LAG2."""
    a = math.exp(-s) if s < LAG1 else 0.5 if s < LAG2 else s * s
    return np.array([[a, 3.0 if s < LAG2 else 0.0], [0.0, -1.0]])


def exact() -> np.ndarray:
    a = (1 - math.exp(-LAG1)) + 0.5 * (LAG2 - LAG1) + (TAU ** 3 - LAG2 ** 3) / 3
    return np.array([[a, 3.0 * LAG2], [0.0, -TAU]])


def solver() -> dmi.Solver:
    s = dmi.Solver(2, TAU, 50)
    s.set_rhs(lambda t, u: np.array([u[0] - u[1], 0.5 * u[1]]))
    s.set_kernel(H)
    return s


def test_declared_jumps_are_integrated_piecewise():
    s = solver()
    K = kernel_integral(s, (LAG2, LAG1))
    assert np.max(np.abs(K - exact())) <= 1e-14
    # the same kernel with its jumps not declared: a panel straddles each jump, and Gauss's
    # positive weights bound a panel's error by its width times the entry's oscillation on it
    edges = np.linspace(0.0, TAU, 9)
    bound = np.zeros((2, 2))
    for a, b in zip(edges[:-1], edges[1:]):
        vals = np.array([H(t) for t in np.linspace(a, b, 2001)])
        bound += (b - a) * (vals.max(axis=0) - vals.min(axis=0))
    off = np.abs(kernel_integral(s) - exact())
    assert np.any(off > 1e-12)        # not exact: the declared jumps are what makes it exact
    assert np.all(off <= bound + 1e-14)
    # a lag outside (0, tau) cuts nothing
    assert np.array_equal(kernel_integral(s, (0.0, TAU, 2.0)), kernel_integral(s))
    s.close()


def test_equation_terms_take_the_jumps():
    s = solver()
    u = np.array([0.3, -0.2])
    X, G = equation_terms(s, (LAG1, LAG2))(u)
    f = np.array([u[0] - u[1], 0.5 * u[1]])
    want = u - s.h * f - s.h * (exact() @ u)
    assert np.max(np.abs(X - want)) <= 1e-15
    assert np.max(np.abs(G - (want - u))) <= 1e-15     # no resolvent: R(X) = X
    s.close()


def test_panels_without_jumps_are_uniform():
    x, w = np.polynomial.legendre.leggauss(PANEL_NODES)
    for tau, reach, panels in ((1.0, 1.0, 8), (2.0, 10.0, 20), (3.0, 2.9, 9)):
        s, wt, Hs = kernel_panels(lambda t: np.array([[t]]), tau, reach)
        edges = np.linspace(0.0, tau, panels + 1)
        half = 0.5 * np.diff(edges)
        assert np.array_equal(s, (edges[:-1, None] + half[:, None] * (x[None, :] + 1)).ravel())
        assert np.array_equal(wt, (half[:, None] * w[None, :]).ravel())
        assert np.sum(wt * Hs[:, 0, 0]) == pytest.approx(tau * tau / 2, rel=1e-14)
