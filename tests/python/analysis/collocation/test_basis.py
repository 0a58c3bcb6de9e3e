# The collocation's Lagrange basis to rounding: its values and derivatives against the exact ones
# (mpmath at 40 digits) at degrees 2 to 8, and a period of degree 8 that does not drift with the
# mesh (the monomial form's rounding, divided by the intervals' lengths in the derivatives, moved
# van der Pol's period by 2.7e-12 between 60 and 132 intervals).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import mpmath as mp
import numpy as np
import pytest

import dmi
from dmi import analysis as da
from dmi.analysis.collocation.mesh import Basis


def exact(m: int, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The Lagrange polynomials of the nodes k / m and their derivatives at z, to 40 digits."""
    with mp.workdps(40):
        x = [mp.mpf(k) / m for k in range(m + 1)]

        def ell(k: int, t, skip: int = -1):
            return mp.fprod((t - x[j]) / (x[k] - x[j]) for j in range(m + 1)
                            if j not in (k, skip))

        vals = [[ell(k, mp.mpf(t)) for k in range(m + 1)] for t in z]
        ders = [[mp.fsum(ell(k, mp.mpf(t), i) / (x[k] - x[i]) for i in range(m + 1) if i != k)
                 for k in range(m + 1)] for t in z]
        return (np.array(vals, dtype=float), np.array(ders, dtype=float))


@pytest.mark.parametrize("m", range(2, 9))
def test_values_and_derivatives_to_rounding(m):
    b = Basis(m, m + 1)
    z = np.concatenate([b.gauss()[0], b.nodes, np.random.default_rng(m).random(12)])
    V, D = exact(m, z)
    # the monomial form (Horner's scheme) was 2.4e-14 off in the values and 1.1e-12 in the
    # derivatives at degree 8 (2.4e-12 is 2e-15 max|D| m there); the Legendre form 1.3e-15 and
    # 5.7e-14
    assert np.max(np.abs(b.values(z) - V)) <= 4e-15
    assert np.max(np.abs(b.derivatives(z) - D)) <= 2e-16 * np.max(np.abs(D)) * m
    # a constant's derivative: the rows sum to zero (to rounding of their entries; the monomial
    # form's 3.7e-13 at degree 8)
    assert np.max(np.abs(b.derivatives(z).sum(axis=1))) <= 2e-16 * np.max(np.abs(D)) * m


def test_a_period_of_degree_8_does_not_drift_with_the_mesh():
    """van der Pol with a distributed delay (eps = 1, a = 0.5): its period at degree 8 on 60 and
    132 intervals and at degree 6 on 180 (meshes past truncation: h^(2 m) would fall with L and
    the degree) agree to rounding (5e-14 measured; 2.7e-12 and 4.8e-12 with the monomial form,
    falling with L)."""
    def make(p: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, 1.0, h=h or 0.01)
        s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
        s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
        return s
    s = make(0.5, h=0.01)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(24000)
    o = da.periodic_orbit(make, 0.5, None, s, guess_period=6.0, steps=600, multipliers=0)
    T = [da.collocate(o, intervals=L, degree=m, multipliers=0).period
         for L, m in ((30, 8), (66, 8), (90, 6))]
    assert max(T) - min(T) <= 3e-13, T
