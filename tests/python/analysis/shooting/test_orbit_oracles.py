# dmi.analysis.periodic_orbit and its Floquet multipliers against exact periodic solutions
# (models/orbit_models.py): Den Hartog's non-stick orbit (amplitude, phase, order 1 in h,
# saltation multipliers) and the first-order stick-slip orbit (slip phases, stick fraction,
# the zero multiplier of the stick).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import pytest

from dmi.analysis import floquet_multipliers, periodic_orbit
from dmi.analysis.shooting.shoot import StepMap
from models.orbit_models import DenHartog, StickSlip1


@pytest.fixture(scope="module")
def dh():
    return DenHartog()


def dh_orbit(dh, M, multipliers=0):
    x, v = dh.exact(0.0)
    guess = np.array([x, v]) + 0.2  # off the orbit: Newton has work to do
    return periodic_orbit(dh.make_for(M), 1.0, dh.T, guess, multipliers=multipliers)


def test_den_hartog_orbit_amplitude_phase_order1(dh):
    errs, hs = [], []
    for M in (1000, 2000, 4000):
        o = dh_orbit(dh, M)
        assert o.residual <= 1e-10 * max(1, np.max(np.abs(o.state))) and o.iterations >= 1
        x, v = dh.exact(o.t)
        err = max(np.max(np.abs(o.u[:, 0] - x)), np.max(np.abs(o.u[:, 1] - v)))
        errs.append(err)
        hs.append(o.h)
        # amplitude and phase: the maximum of x is a, reached at t0 + T/2 (mod T)
        k = int(np.argmax(o.u[:, 0]))
        assert abs(o.u[k, 0] - dh.a) < 20 * o.h
        dt = (o.t[k] - dh.t0 - dh.T / 2 + dh.T / 2) % dh.T - dh.T / 2
        assert abs(dt) < 20 * o.h, (o.t[k], dh.t0)
        assert o.period == pytest.approx(dh.T, rel=1e-12) and o.steps == M
    slope = np.polyfit(np.log(hs), np.log(errs), 1)[0]
    assert 0.9 <= slope <= 1.1, (errs, slope)
    assert errs[-1] < 0.01


def test_den_hartog_multipliers_saltation(dh):
    """Within 2 % of the saltation analysis at 2e4 steps per period; the exact piecewise
    derivative (a difference step far below h) misses the saltation by O(1)."""
    M = 20000
    o = dh_orbit(dh, M, multipliers=2)
    ref = dh.multipliers
    assert np.abs(ref[0]) < 0.6 and abs(ref[0].imag) > 0.1  # a complex pair, |mu| = 0.51
    mu = np.sort_complex(o.multipliers)
    assert np.max(np.abs(mu - np.sort_complex(ref))) < 0.02 * np.abs(ref[0]), (mu, ref)
    assert o.stable and np.all(o.stick_fraction == 0)
    # the wrong linearisation: the exact step derivative (eps = 1e-8) is off by O(1)
    F = StepMap(dh.make_for(M), 1.0, M)
    wrong = floquet_multipliers(F, o.state, 2, eps=1e-8)
    assert np.max(np.abs(np.sort_complex(wrong) - np.sort_complex(ref))) > 0.2


@pytest.fixture(scope="module")
def ss():
    return StickSlip1()


def test_stick_slip_orbit_and_zero_multiplier(ss):
    errs, hs = [], []
    for M in (1000, 4000):
        o = periodic_orbit(ss.make_for(M), 0.0, ss.T, [0.3], multipliers=2)
        err = np.max(np.abs(o.u[:, 0] - ss.exact(o.t)))
        errs.append(err)
        hs.append(o.h)
        assert o.stick_fraction[0] == pytest.approx(ss.stick_fraction, abs=3 / M * 4)
        assert np.all(o.multipliers == 0)  # the stick forgets every perturbation
        assert o.stable
    slope = np.log(errs[0] / errs[1]) / np.log(hs[0] / hs[1])
    assert 0.8 <= slope <= 1.2, (errs, slope)
    assert errs[-1] < 10 * hs[-1]


def test_smooth_nonlinear_orbit_multipliers_are_the_schemes():
    """A forced pendulum x'' + 0.5 x' + sin x = 1.1 cos(0.7 t) (no friction: no switch, the
    difference step must be small, not 5 % of the amplitude): the orbit and multipliers of its
    explicit scheme (N = 1, no kernel: U+ = U - h f(t, U)) solved in numpy, the multipliers as the
    eigenvalues of the product of the steps' Jacobians I - h Df."""
    import math

    import dmi
    import scipy.optimize as so

    M, w = 200, 0.7
    h = 2 * math.pi / (w * M)

    def f(t, u):
        return np.array([-u[1], 0.5 * u[1] + np.sin(u[0]) - 1.1 * np.cos(w * t)])

    def period_map(u, jac=False):
        J = np.eye(2)
        for k in range(M):
            t = k * h
            J = (np.eye(2) - h * np.array([[0.0, -1.0], [np.cos(u[0]), 0.5]])) @ J
            u = u - h * f(t, u)
        return (u, J) if jac else u

    u0 = so.fsolve(lambda u: period_map(u) - u, [-0.59, 1.96], xtol=1e-12)
    exact = np.linalg.eigvals(period_map(u0, jac=True)[1])
    exact = exact[np.argsort(-np.abs(exact))]

    def make(p):
        s = dmi.Solver(2, h, h=h)
        s.set_rhs(f)
        return s
    o = periodic_orbit(make, 0.0, 2 * math.pi / w, [-0.59, 1.96], multipliers=2)
    assert o.u[0] == pytest.approx(u0, abs=1e-9)
    assert np.abs(exact[0]) > 0.4  # a multiplier far from 0, that a 5 % step got wrong (-1.16)
    assert o.multipliers == pytest.approx(exact, abs=1e-6)


def test_ritz_on_a_rank_deficient_map():
    """The Krylov blocks of a map of rank 3 (a stuck phase wipes the other directions out) in 100
    dimensions, eigenvalues 0.9, -0.6, 0.3 and 0: the Ritz values are those, the basis handed to
    the continuation orthonormal (a block orthogonalised by qr of its own columns alone was not:
    0.904 for 0.9, |Q'Q - I| = 0.14, found in review)."""
    from dmi.analysis.scheme.floquet import ritz
    dim = 100
    P = np.linalg.qr(np.random.default_rng(1).standard_normal((dim, dim)))[0]
    A = P @ np.diag(np.r_[0.9, -0.6, 0.3, np.zeros(dim - 3)]) @ P.T

    class Linear:
        M = 100

        def __call__(self, x):
            return A @ x
    mu, Q, Z = ritz(Linear(), np.zeros(dim), 6, eps=1e-3, central=False)
    assert mu[:3] == pytest.approx([0.9, -0.6, 0.3], abs=1e-10) and np.all(mu[3:] == 0)
    assert np.abs(Q.T @ Q - np.eye(Q.shape[1])).max() < 1e-12
    assert np.abs(Z - A @ Q).max() < 1e-10

