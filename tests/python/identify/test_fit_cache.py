# A fit's residuals and Jacobian at one point are computed once (the problem's cache, a
# dmi._cache.Cache): the Jacobian asked twice at the same parameters runs the sensitivities once,
# another point or another jumps setting runs them again, and the residuals kept with the
# Jacobian are those of plain runs; the Jacobian against central differences of the residuals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

import dmi
from dmi.identify import Record
from dmi.identify.fitting import _check_record, _Problem


def make(p: np.ndarray) -> dmi.Solver:
    """u' = -a u, u = 1 before t = 0 (h = 1/20)."""
    a = float(p[0])
    s = dmi.Solver(1, 1.0, 20)
    s.set_rhs(lambda t, u: np.array([a * u[0]]))
    s.set_history(lambda t: np.array([1.0]))
    return s


def problem() -> _Problem:
    t = np.linspace(0.1, 2.0, 12)
    d = _check_record(Record(t, np.exp(-0.8 * t)), 0, 1)
    return _Problem([make], np.array([1.0]), np.array([True]), [d], None)


def test_the_jacobian_at_one_point_is_computed_once():
    pr = problem()
    x = np.array([0.7])
    J = pr.jacobian(x)
    assert pr.jacobian(x.copy()) is J and pr.njev == 1
    r, J2 = pr.linearised(x)
    assert J2 is J and pr.njev == 1
    assert np.max(np.abs(r - pr.residuals(x))) <= 1e-12
    e = 1e-6
    fd = (pr.residuals(x + e) - pr.residuals(x - e)) / (2 * e)
    assert np.max(np.abs(J[:, 0] - fd)) <= 1e-6 * max(1.0, float(np.max(np.abs(fd))))
    pr.jacobian(np.array([0.9]))
    assert pr.njev == 2
    pr.jumps = False
    pr.jacobian(np.array([0.9]))
    assert pr.njev == 3
    pr.jacobian(np.array([0.7]))      # the cache keeps the last point only
    assert pr.njev == 4 and math.isfinite(float(J[0, 0]))
