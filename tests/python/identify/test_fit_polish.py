# estimate's polish (Gauss-Newton steps with the scheme's own tangent) ends at the scheme's least
# squares: on a forced oscillator with dry friction (stick-slip in the data) its cost is that of
# SciPy's least_squares on plain runs with central differences at tight tolerances (an
# independent fit), to 1e-8; with the optimum on a bound, the polish's step leaves the bounds and
# least_squares polishes instead, ending on the bound.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import optimize

import dmi
from dmi.identify import Record, estimate

STEPS = 300
TRUTH = np.array([1.0, 0.4])            # k, mu


def make(p: np.ndarray) -> dmi.Solver:
    """x' = v, v' = -k x + 0.9 cos(1.1 t) - mu sign(v) (friction on v), h = 0.02."""
    k, mu = float(p[0]), float(p[1])
    s = dmi.Solver(2, 0.02, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] - 0.9 * math.cos(1.1 * t)]))
    s.set_friction([0.0, mu])
    s.set_history(lambda t: np.array([0.5, 0.0]))
    return s


def run(p: np.ndarray) -> np.ndarray:
    s = make(p)
    s.init()
    return s.run(STEPS)[1][2::2, 0]


def data() -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(2, STEPS + 1, 2) * 0.02
    rng = np.random.default_rng(3)
    return t, run(TRUTH) + 1e-3 * rng.standard_normal(len(t))


def test_the_polish_ends_at_the_schemes_least_squares():
    t, y = data()
    start = TRUTH * np.array([1.1, 0.9])
    ref = optimize.least_squares(lambda p: run(p) - y, start, jac="3-point", ftol=1e-14,
                                 xtol=1e-14, gtol=1e-14)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = estimate(make, start, Record(t, y))
        rough = estimate(make, start, Record(t, y), polish=False)
    v = np.sign(np.diff(run(TRUTH)))
    assert np.any(v[1:] != v[:-1])                       # the data reverse
    assert est.success
    assert abs(est.cost - ref.cost) <= 1e-8 * ref.cost
    assert np.max(np.abs(est.p - ref.x) / ref.x) <= 1e-5
    assert est.cost <= rough.cost


def test_a_polish_step_beyond_a_bound_falls_back_to_least_squares():
    t, y = data()
    start = np.array([0.9, 0.36])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = estimate(make, start, Record(t, y), bounds=([0.5, 0.1], [0.97, 1.0]))
    assert np.all(est.p <= [0.97, 1.0]) and np.all(est.p >= [0.5, 0.1])
    assert abs(est.p[0] - 0.97) <= 1e-6                   # the optimum k = 1 lies beyond the bound
