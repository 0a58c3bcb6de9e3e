# The predictor of the orbit born at a Hopf point (normal_form.predicted_parameter): the
# parameter p_H + side (A / kappa)^2 of a wanted amplitude A, against the closed forms of a
# rotationally symmetric oscillator with a distributed memory, whose circles are exact and are
# solved here (its Hopf point, crossing speed, first Lyapunov coefficient and the parameter of
# each circle); its refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.equilibria.normal_form import predicted_parameter

# z' = (mu + i W0) z + c1 |z|^2 z - int_0^TAU G e^-s z(t - s) ds, z = x + i y.  Its circles
# z = r e^(i Om t) solve d(i Om) = c1 r^2, d(lam) = lam + g(lam) - mu - i W0,
# g(lam) = G (1 - e^-(1 + lam) TAU) / (1 + lam); the Hopf point is d(i Om) = 0 at r = 0.
W0, G, TAU = 1.0, 0.5, 2.0


def g(lam: complex) -> complex:
    return G * (1 - np.exp(-(1 + lam) * TAU)) / (1 + lam)


def dg(lam: complex) -> complex:
    e = np.exp(-(1 + lam) * TAU)
    return G * (TAU * e * (1 + lam) - (1 - e)) / (1 + lam) ** 2


def circle(c1: complex, r: float) -> tuple[float, float]:
    """(Om, mu) of the exact circle of radius r: Im d(i Om) = Im c1 r^2 fixes Om, the real part
    mu."""
    om = so.brentq(lambda w: w + g(1j * w).imag - W0 - c1.imag * r * r, 0.1, 3.0,
                   xtol=1e-15, rtol=1e-15)
    return om, g(1j * om).real - c1.real * r * r


def model(c1: complex):
    """make(mu) with the exact derivative hook (f = -(the right-hand side) in (x, y))."""
    def make(mu: float) -> dmi.Solver:
        a = complex(mu, W0)

        def rhs(t, u):
            z = complex(*u)
            w = a * z + c1 * abs(z) ** 2 * z
            return -np.array([w.real, w.imag])

        def fu(t, u):
            z = complex(*u)
            dz, dzb = a + 2 * c1 * abs(z) ** 2, c1 * z * z       # dg/dz, dg/dzb
            cols = [dz + dzb, 1j * dz - 1j * dzb]
            return -np.array([[c.real for c in cols], [c.imag for c in cols]])

        def d2(t, u, v, w):
            z, A, B = complex(*u), complex(*v), complex(*w)
            r = c1 * (2 * A * B * z.conjugate() + 2 * z * (A * B.conjugate() + B * A.conjugate()))
            return -np.array([r.real, r.imag])

        def d3(t, u, v, w, x):
            A = [complex(*v), complex(*w), complex(*x)]
            r = 2 * c1 * sum(A[i] * A[j] * A[k].conjugate()
                             for i, j, k in ((0, 1, 2), (0, 2, 1), (1, 2, 0)))
            return -np.array([r.real, r.imag])

        s = dmi.Solver(2, TAU, 100)
        s.set_rhs(rhs)
        s.set_kernel_exp([-1.0], [0.0], [G * np.eye(2)])
        s.set_rhs_derivatives(fu, d2, d3)
        return s
    return make


SUPER, SUB = -1.0 + 0.5j, 0.7 - 0.3j


@pytest.fixture(scope="module", params=[SUPER, SUB], ids=["supercritical", "subcritical"])
def case(request):
    c1 = request.param
    om, mu_h = circle(c1, 0.0)
    hp = da.hopf(model(c1), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")
    return c1, om, mu_h, hp


def test_predicted_parameter_is_the_closed_form(case):
    c1, om, mu_h, hp = case
    d1 = 1 + dg(1j * om)
    # Re lambda' = Re 1 / d', and mu - mu_H = -r^2 Re(c1 / d') / Re(1 / d') to leading order
    slope = -(c1 / d1).real / (1 / d1).real
    for A in (0.05, 0.01):
        want = mu_h + slope * A * A
        got = predicted_parameter(hp, A)
        assert abs(got - want) <= 1e-9 * A * A * abs(slope) + 1e-11, (A, got, want)
        # each component's (max - min) / 2 is r: component 1 predicts the same
        assert abs(predicted_parameter(hp, A, component=1) - want) <= 1e-9 * A * A * abs(slope) \
            + 1e-11


def test_predicted_parameter_against_the_exact_circles(case):
    c1, om, mu_h, hp = case
    miss = {}
    for r in (0.04, 0.02):
        _, mu = circle(c1, r)
        got = predicted_parameter(hp, r)
        assert np.sign(got - hp.p) == np.sign(mu - mu_h) == hp.side
        miss[r] = abs(got - mu)
        assert miss[r] <= 0.05 * abs(mu - mu_h), (r, got, mu)   # a predictor, off by O(r^4)
    # the miss is O(r^4): a quarter of r, a sixteenth of the miss
    assert 12 < miss[0.04] / miss[0.02] < 20, miss


def test_refusals(case):
    c1, om, mu_h, hp = case
    scheme = da.hopf(model(c1), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0])   # no kappa
    with pytest.raises(ValueError, match="no kappa"):                 # bad-inputs PP01
        predicted_parameter(scheme, 0.01)
    for bad in (0.0, -0.01, math.nan, math.inf):
        with pytest.raises(ValueError, match="amplitude"):            # bad-inputs PP02
            predicted_parameter(hp, bad)
    for bad in (2, -1, 0.5):
        with pytest.raises(ValueError, match="component"):            # bad-inputs PP03
            predicted_parameter(hp, 0.01, component=bad)
    with pytest.raises(ValueError, match="HopfPoint"):                # bad-inputs PP04
        predicted_parameter((hp.p, hp.omega), 0.01)
