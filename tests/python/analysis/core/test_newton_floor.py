# A Newton solve at its residual's rounding floor: newton_loop's floor rule on a nearly singular
# linear system whose residual carries rounding-sized noise (the exact solution by hand: the
# matrix is diagonal), and the merged mesh's solve of a belt's orbit at its Hopf point, where the
# linear slip makes every amplitude an orbit at one p (a vertical branch): the orbit's error
# estimate is given, and it covers the period's and multipliers' errors against the closed form
# (lambda^2 - p lambda + 1 + g K(lambda) = 0 at lambda = i omega, both multipliers at 1; the
# belt and its Hopf point from models/truncated_belt.py).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

from dmi import analysis as da
from dmi.analysis.core.newton import ShootingError, newton_loop
from models.truncated_belt import V, belt, hopf

DIAG = np.array([2.0, 1.0, 0.5, 1e-7])     # a nearly singular direction: the last
RHS = np.array([1.0, -2.0, 0.25, 3e-7])
EXACT = RHS / DIAG                          # (0.5, -2, 0.5, 3), exact in binary


def noisy_linear(floor: int, accuracy: list[float] | None):
    """newton_loop on DIAG z = RHS with noise of 1e-15 in each residual (rounding's size)."""
    rng = np.random.default_rng(7)

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, None]:
        return DIAG * z - RHS + 1e-15 * rng.standard_normal(z.size), None

    def factor(z: np.ndarray, r: np.ndarray, state: None):
        return lambda r: -r / DIAG

    return newton_loop(evaluate, factor, np.zeros(4), tol=1e-12, max_iter=25, what="test",
                       converge="correction", stall=False, floor=floor, accuracy=accuracy)


def test_floor_rule_stops_with_the_accuracy_reached():
    with pytest.raises(ShootingError, match="no convergence"):
        noisy_linear(0, None)                      # the corrections never fall below 1e-12
    got: list[float] = []
    z, res = noisy_linear(3, got)
    assert len(got) == 1
    err = float(np.max(np.abs(z - EXACT)))
    assert err > 1e-12                             # not converged by the correction test
    assert got[0] >= err                           # the accuracy reported covers the error
    assert got[0] < 1e-6                           # and is the noise amplified, 1e-15 / 1e-7
    assert len(res) < 10 and res[-1] < 1e-13


def test_floor_rule_leaves_a_well_conditioned_solve_alone():
    """A well-conditioned solve converges on its correction, the accuracy its last one."""
    got: list[float] = []

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, None]:
        return np.array([z[0] ** 2 - 2.0]), None

    def factor(z: np.ndarray, r: np.ndarray, state: None):
        return lambda r: -r / (2 * z[0])

    z, _ = newton_loop(evaluate, factor, np.array([1.0]), tol=1e-12, max_iter=25, what="test",
                       converge="correction", stall=False, floor=3, accuracy=got)
    assert abs(z[0] - math.sqrt(2.0)) <= 4.5e-16 and got[0] <= 1e-12 * math.sqrt(2.0)


def test_vertical_branch_orbit_has_its_estimate():
    om, pH, xe = hopf()
    for a in (0.1, 0.3):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            e = da.equation_hopf_orbit(belt, da.HopfPoint(p=pH, omega=om, root=1j * om),
                                       [xe, -V], a)
        assert not [w for w in caught if "merged mesh" in str(w.message)], \
            [str(w.message) for w in caught]
        assert e.errors, "no error estimate"
        assert e.errors["period"] >= abs(e.period - 2 * math.pi / om)
        assert e.errors["period"] < 1e-3                 # the rounding floor's, not a failure
        at1 = np.argsort(np.abs(e.multipliers - 1))[:2]                 # the two at 1
        assert np.all(e.errors["multipliers"][at1] >= np.abs(e.multipliers[at1] - 1))
        # every amplitude is an orbit at p_H: the estimate says it is not determined there
        assert e.errors["amplitude"][1] >= 0.5 * a
        assert e.stable is None
