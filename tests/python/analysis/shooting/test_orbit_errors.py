# dmi.analysis.periodic_orbit / continue_orbit on bad input: each gives a clear error with what
# was tried (a period <= 0 or not a whole number of steps, a parameter the model refuses, a
# singular Jacobian, a guess far from any orbit, a Newton cut short, a guess of the wrong shape).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import pytest

import dmi
from dmi.analysis import ShootingError, continue_orbit, periodic_orbit
from models.orbit_models import DenHartog


@pytest.fixture(scope="module")
def dh():
    return DenHartog()


def test_period_not_positive_or_not_a_multiple_of_h(dh):
    make = dh.make_for(400)
    for bad in (0.0, -1.0, float("nan")):
        with pytest.raises(ValueError, match=r"period = .*must be finite and > 0"):
            periodic_orbit(make, 1.0, bad, [1.0, 0.0])
    with pytest.raises(ValueError, match="not a whole number of steps"):
        periodic_orbit(make, 1.0, dh.T * 1.0001, [1.0, 0.0])


def test_parameter_out_of_range(dh):
    # the model's own exception, with a note naming the call
    with pytest.raises(ValueError, match=r"forcing scale must be in \[0, 10\]") as e:
        periodic_orbit(dh.make_for(400), 20.0, dh.T, [1.0, 0.0])
    assert any("make(p = 20.0)" in note for note in e.value.__notes__), e.value.__notes__
    o = periodic_orbit(dh.make_for(400), 1.0, dh.T, [1.0, 0.0], multipliers=0)
    for bad in (float("nan"), 1.0):   # (nan: it ran to max_points, never reaching p_end)
        with pytest.raises(ValueError, match="p_end = .*must be finite and differ"):
            continue_orbit(o, bad, step=0.5, multipliers=0)
    b = continue_orbit(o, 12.0, step=4.0, multipliers=0, max_step=8.0)  # make refuses p > 10
    assert all(q.p <= 10 for q in b.points) and "failed" in b.status, b.status


def test_continuation_into_a_failing_map_ends_the_branch():
    def make(p):  # u' + u = p cos t; beyond p = 5 the rhs overflows the scheme (a dmi.Error)
        s = dmi.Solver(1, 2 * np.pi / 200, 1)
        big = 1e300 if p > 5 else 1.0
        s.set_rhs(lambda t, u: np.array([big * big * u[0] - p * np.cos(t)]))
        return s
    o = periodic_orbit(make, 1.0, 2 * np.pi, [0.5], multipliers=0)
    b = continue_orbit(o, 8.0, step=1.0, multipliers=0, max_step=2.0)  # does not raise
    assert b.status.startswith("corrector failed") and "non-finite" in b.status, b.status
    assert 4.9 < b.p[-1] <= 5.0
    for q in b.points:   # u = p (cos t + sin t) / 2 sampled by the scheme: amplitude ~ p / sqrt 2
        assert q.amplitude[0] == pytest.approx(q.p / np.sqrt(2), rel=0.02)


def test_singular_jacobian():
    def make(p):  # u' = 1: no periodic orbit, F(x) = x + T, DF = I
        s = dmi.Solver(1, 0.01, 1)
        s.set_rhs(lambda t, u: np.array([-1.0]))
        return s
    with pytest.raises(ShootingError, match=r"singular.*residuals \[1") as e:
        periodic_orbit(make, 0.0, 1.0, [0.0])
    assert e.value.residuals[0] == pytest.approx(1.0)


def test_guess_far_from_any_orbit():
    def make(p):  # u' = u^2 + cos t: from u = 50 the scheme overflows within a period
        s = dmi.Solver(1, 0.01, 1)
        s.set_rhs(lambda t, u: np.array([-u[0] ** 2 - np.cos(t)]))
        return s
    with pytest.raises(ShootingError, match="too far from any orbit") as e:
        periodic_orbit(make, 0.0, 6.28, [50.0])
    assert isinstance(e.value.__cause__, dmi.Error)


def test_newton_cut_short_says_so(dh):
    with pytest.raises(ShootingError, match=r"no convergence in 1 Newton iterations \(residuals") \
            as e:
        periodic_orbit(dh.make_for(400), 1.0, dh.T, [30.0, -20.0], max_iter=1)
    assert e.value.iterations == 2 and e.value.residuals[0] > 1


def test_guess_of_the_wrong_shape(dh):
    with pytest.raises(ValueError, match=r"guess has 3 values .*n = 2: give n = 2 values"):
        periodic_orbit(dh.make_for(400), 1.0, dh.T, [1.0, 0.0, 0.0])
    s = dmi.Solver(2, 1.0, 3)
    with pytest.raises(ValueError, match="guess: a solver with n = 2, N = 3"):
        periodic_orbit(dh.make_for(400), 1.0, dh.T, s)
