# The equation's answers (of="equation") with a fitted singular kernel: the near cells run the exact
# kernel c s^-beta on [0, delta], so the equation's transform takes its own integral there (a lower
# incomplete gamma function), checked against mpmath; the equilibrium and the Hopf point then match
# the exact kernel's at every h.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math

import mpmath as mp
import numpy as np
import pytest

import dmi
from dmi import analysis, kernels
from dmi._transform import power_laplace

mp.mp.dps = 30


def lower_gamma_transform(lam, beta, c, delta):
    """int_0^delta c s^-beta e^{-lam s} ds by mpmath's quadrature after s = t^(1 / (1 - beta))
    (a smooth integrand), independent of the incomplete gamma's branch."""
    lam, q = mp.mpc(lam), 1 / (1 - mp.mpf(beta))
    top = mp.mpf(delta) ** (1 - mp.mpf(beta))
    return c * q * mp.quad(lambda t: mp.exp(-lam * t ** q), mp.linspace(0, top, 9))


@pytest.mark.parametrize("beta", [0.5, 0.9])
def test_power_laplace_against_mpmath(beta):
    delta = 0.05
    for lam in (0.0, 1.5, -2.0, 3j, 40 - 25j, 400 + 300j):
        ref = complex(lower_gamma_transform(lam, beta, 0.7, delta))
        # and the closed form c lam^(beta - 1) gamma(1 - beta, lam delta) where lam != 0
        z = mp.mpc(lam)
        closed = (0.7 * mp.mpf(delta) ** (1 - beta) / (1 - beta) if lam == 0 else
                  0.7 * z ** (beta - 1) * mp.gammainc(1 - beta, 0, z * delta))
        assert abs(complex(closed) - ref) <= 1e-14 * abs(ref), (lam, closed, ref)
        got = complex(power_laplace(np.array([lam]), beta, 0.7, delta)[0])
        assert abs(got - ref) <= 1e-11 * max(1.0, abs(ref)), (lam, got, ref)


TAU, BETA, CF = 10.0, 0.5, 0.3 / math.sqrt(math.pi)     # c s^-1/2 / Gamma(1/2), c = 0.3
DELTA = 0.05
FIT = kernels.fit(kernels.PowerKernel(BETA, CF), TAU, tol=1e-10, relative=True, delta=DELTA)
A_, B_ = 0.2, 1.0


def make_scalar(p, N):
    """u' + a u - b + int_0^tau c s^-beta u(t - s) ds = 0."""
    s = dmi.Solver(1, TAU, N)
    s.set_rhs(lambda t, u: np.array([A_ * u[0] - B_]))
    s.set_quadrature("cell")
    s.set_kernel_fit(FIT)
    return s


@pytest.mark.parametrize("N", [200, 400])
def test_equilibrium_with_a_fitted_singular_kernel(N):
    """u* = b / (a + int_0^tau c s^-beta ds) (the integral by mpmath), to 1e-9 at every h."""
    W = float(CF * mp.quad(lambda s: s ** (-BETA), [0, DELTA, TAU]))
    exact = B_ / (A_ + W)
    eq = analysis.equilibrium(lambda p: make_scalar(p, N), 0.0, [1.0], of="equation")
    assert eq.u[0] == pytest.approx(exact, rel=1e-9), (eq.u[0], exact)


K_ = 1.0


def make_osc(p, N):
    """x' = y, y' = -k x + p y - int_0^tau c s^-1/2 / Gamma(1/2) y(t - s) ds: negative damping p
    against the fractional damping, a Hopf point where they balance."""
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], K_ * u[0] - p * u[1]]))
    s.set_quadrature("cell")
    s.set_kernel_fit(FIT, entry=(1, 1))
    return s


@pytest.fixture(scope="module")
def hopf_exact():
    """lambda (lambda - p + Hhat(lambda)) + k = 0 at lambda = i omega, Hhat the exact kernel's
    truncated transform c lambda^(beta - 1) gamma(1 - beta, lambda tau): omega from the real part,
    p = Re Hhat(i omega)."""
    def hhat(lam):
        return CF * lam ** (BETA - 1) * mp.gammainc(1 - BETA, 0, lam * TAU)

    def g(w):
        return -w * w + K_ - w * mp.im(hhat(mp.mpc(0, w)))
    w = mp.findroot(g, 1.0)
    return float(mp.re(hhat(mp.mpc(0, w)))), float(w)


@pytest.mark.parametrize("N", [200, 400])
def test_hopf_point_with_a_fitted_singular_kernel(hopf_exact, N):
    """The equation's Hopf point with the near cells' exact transform: the mpmath value to 1e-7
    at every h (formerly off by about 1e-2 sqrt(h))."""
    p_h, w_h = hopf_exact
    hp = analysis.hopf(lambda p: make_osc(p, N), p_h - 0.05, p_h + 0.05, [0.0, 0.0], of="equation")
    assert hp.p == pytest.approx(p_h, abs=1e-7), (hp.p, p_h)
    assert hp.omega == pytest.approx(w_h, abs=1e-7), (hp.omega, w_h)


def test_near_cells_of_another_kernel_are_refused_for_the_equation():
    fit = kernels.fit(lambda s: np.exp(-s) / np.sqrt(s), 5.0, tol=1e-8, relative=True, delta=0.05)

    def make(p):
        s = dmi.Solver(1, 5.0, 100)
        s.set_rhs(lambda t, u: np.array([u[0] - 1.0]))
        s.set_quadrature("cell")
        s.set_kernel_fit(fit, near=lambda s: np.exp(-s) / np.sqrt(s))
        return s
    with pytest.raises(ValueError, match="PowerKernel"):
        analysis.equilibrium(make, 0.0, [0.5], of="equation")


def test_near_kernel_other_than_the_fits_power_kernel_is_refused_for_the_equation():
    """A PowerKernel fit whose near cells run another kernel (near=): its transform on
    [0, delta] is not the power kernel's, refused (before: the power kernel's would be taken)."""
    def make(p):
        s = make_scalar(p, 200)
        s.set_kernel_fit(FIT, near=lambda s: 2 * CF * s ** -BETA)
        return s
    with pytest.raises(ValueError, match="other than the fit's PowerKernel"):
        analysis.equilibrium(make, 0.0, [0.5], of="equation")
