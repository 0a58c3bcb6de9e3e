# dmi.analysis.collocate on kernels beyond smooth exponential sums, against references computed
# here, not by the code under test: a fitted PowerKernel (its near part c s^-beta exact on
# [0, delta], the fit's exponential sum on [delta, tau]) in a linear forced model, whose periodic
# solution is Re(c e^{i w t} / (i w + k + Hhat(i w))) and whose multipliers are e^{lambda T},
# lambda the roots of lambda + k + Hhat(lambda) = 0, Hhat by mpmath's quadrature of the near part
# and of the fit's terms (evaluated here, in mpmath); a nonlinear model with the same kernel, its
# order under mesh refinement; a piecewise-constant kernel with a jump inside (0, tau), Hhat in
# closed form: the order with the jump given, the warning without it; the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import mpmath as mp
import numpy as np
import pytest

import dmi
from dmi import analysis as da
from dmi import kernels as dk
from dmi.analysis.collocation.system import CollocationWarning

BETA, CK, TAU, DELTA = 0.4, 0.3, 1.0, 0.05
K, C, OM = 0.1, 1.0, 2.0
T = 2 * math.pi / OM


@pytest.fixture(scope="module")
def power_fit() -> dk.KernelFit:
    return dk.fit(dk.PowerKernel(BETA, CK), TAU, delta=DELTA, tol=1e-6)


def fitted_model(fit: dk.KernelFit, M: int, cubic: float = 0.0):
    """u' + k u + cubic u^3 + int_0^tau H u = p c cos(w t) with the fitted kernel, h = T / M."""
    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(1, TAU, h=T / M)
        s.set_rhs(lambda t, u: np.array([K * u[0] + cubic * u[0] ** 3
                                         - p * C * np.cos(OM * t)]))
        s.set_quadrature("cell")
        s.set_kernel_fit(fit)
        return s
    return make


def scheme_orbit(make, M: int = 400, periods: int = 10) -> da.Orbit:
    s = make(1.0)
    s.init()
    s.advance(periods * M)
    return da.periodic_orbit(make, 1.0, T, s, multipliers=0)


def hhat_fitted(fit: dk.KernelFit, lam) -> mp.mpc:
    """int_0^delta c s^-beta e^{-lam s} ds + int_delta^tau H~(s) e^{-lam s} ds, the fit's sum
    H~ = sum e^{a s} (C cos b s + D sin b s) written here in mpmath."""
    lam = mp.mpc(lam)
    near = mp.quad(lambda s: CK * s ** (-BETA) * mp.exp(-lam * s), [0, DELTA])
    terms = [tuple(mp.mpf(float(v)) for v in t) for t in zip(fit.a, fit.b, fit.C, fit.D)]

    def H(s):
        return sum(mp.exp(a * s) * (c * mp.cos(b * s) + d * mp.sin(b * s))
                   for a, b, c, d in terms)
    return near + mp.quad(lambda s: H(s) * mp.exp(-lam * s), [DELTA, TAU])


def test_fitted_power_kernel_forced_orbit_and_multipliers(power_fit):
    o = scheme_orbit(fitted_model(power_fit, 400))
    e = da.collocate(o, intervals=48)
    mp.mp.dps = 20
    Z = complex(C / (1j * OM + K + hhat_fitted(power_fit, 1j * OM)))
    t = np.linspace(0.0, T, 401)
    exact = np.real(Z * np.exp(1j * OM * t))
    err = float(np.max(np.abs(e.u_at(t)[:, 0] - exact)))
    assert err < 1e-10                                  # amplitude and phase
    assert abs(e.amplitude[0] - abs(Z)) < 1e-10
    assert e.errors["u"] >= err                         # an honest estimate
    # the multipliers: e^{lambda T}, lambda the two rightmost roots of lambda + k + Hhat(lambda)
    roots: list = []
    for x0 in (-0.5, -3.0):
        for y0 in (0.5, 2.0):
            try:
                r = mp.findroot(lambda lam: lam + K + hhat_fitted(power_fit, lam),
                                mp.mpc(x0, y0), tol=1e-24)
            except ValueError:
                continue
            if all(abs(r - q) > 1e-8 for q in roots):
                roots.append(r)
    roots.sort(key=lambda r: -float(mp.re(r)))
    mu = [complex(mp.exp(r * T)) for r in roots[:2]]
    assert abs(mu[0].imag) < 1e-12 and abs(mu[1].imag) < 1e-12    # both real here
    assert abs(e.multipliers[0] - mu[0].real) < 1e-8
    assert abs(e.multipliers[1] - mu[1].real) < 1e-6 * abs(mu[1])
    assert e.stable is True


def _differences(o: da.Orbit, Ls, t, **kw) -> list[float]:
    """max |u_L - u_2L| on t of the orbits collocated on L intervals (each returned on 2 L)."""
    us = [da.collocate(o, intervals=L, multipliers=0, **kw).u_at(t)[:, 0] for L in Ls]
    return [float(np.max(np.abs(a - b))) for a, b in zip(us[:-1], us[1:])]


def test_fitted_power_kernel_nonlinear_order(power_fit):
    o = scheme_orbit(fitted_model(power_fit, 400, cubic=1.0))
    m = 4
    d = _differences(o, (4, 8, 16, 32), np.linspace(0.0, T, 301), degree=m)
    orders = [math.log2(a / b) for a, b in zip(d[:-1], d[1:])]
    assert min(orders) >= m, (d, orders)


def test_near_cells_of_unknown_form_refused(power_fit):
    M = 200

    def make(p: float) -> dmi.Solver:
        s = fitted_model(power_fit, M)(p)
        s.set_kernel_fit(power_fit, near=lambda s: CK * s ** -BETA * (1 + s))   # not c s^-beta
        return s
    o = scheme_orbit(make, M, 4)
    with pytest.raises(ValueError, match="s\\^-beta C"):
        da.collocate(o, intervals=8)

    def make2(p: float) -> dmi.Solver:
        s = fitted_model(power_fit, M)(p)
        s.set_kernel_exp(power_fit.a, power_fit.b, power_fit.C[:, None, None],
                         power_fit.D[:, None, None])            # the sum without its fit
        s.set_kernel_near(lambda s: np.array([[CK * s ** -BETA]]), DELTA)   # no exponent
        return s
    with pytest.raises(ValueError, match="exponent"):
        da.collocate(scheme_orbit(make2, M, 4), intervals=8)


# ---- a kernel with a jump inside (0, tau) -------------------------------------------------------
G1, G2, S1 = 0.6, -0.25, 0.37


def jump_model(M: int):
    """u' + k u + int_0^tau H u = p c cos(w t), H = G1 on (0, S1), G2 on (S1, tau)."""
    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(1, TAU, h=T / M)
        s.set_rhs(lambda t, u: np.array([K * u[0] - p * C * np.cos(OM * t)]))
        s.set_kernel(lambda s: np.array([[G1 if s < S1 else G2]]))
        return s
    return make


def jump_exact(t: np.ndarray) -> np.ndarray:
    lam = 1j * OM
    hh = (G1 * (1 - np.exp(-lam * S1)) + G2 * (np.exp(-lam * S1) - np.exp(-lam * TAU))) / lam
    return np.real(C / (lam + K + hh) * np.exp(lam * t))


def test_kernel_jump_given_keeps_the_order_else_warned():
    o = scheme_orbit(jump_model(400))
    t = np.linspace(0.0, T, 301)
    m = 4
    with warnings.catch_warnings():
        warnings.simplefilter("error", CollocationWarning)
        errs = [float(np.max(np.abs(da.collocate(o, intervals=L, degree=m, multipliers=0,
                                                 kernel_jumps=(S1,)).u_at(t)[:, 0]
                                    - jump_exact(t)))) for L in (4, 8, 16, 32)]
    orders = [math.log2(a / b) for a, b in zip(errs[:-1], errs[1:])]
    assert min(orders) >= m and errs[-1] < 1e-10, (errs, orders)
    with pytest.warns(CollocationWarning, match=r"kernel_jumps=\(0\.37"):
        e = da.collocate(o, intervals=16, degree=m, multipliers=0)
    # and the order is indeed capped without it
    assert np.max(np.abs(e.u_at(t)[:, 0] - jump_exact(t))) > 100 * errs[-1]


def test_kernel_jumps_outside_refused():
    o = scheme_orbit(jump_model(200), 200, 4)
    with pytest.raises(ValueError, match="kernel_jumps"):
        da.collocate(o, intervals=8, kernel_jumps=(1.5,))


def test_kernel_jumps_carried_by_continuation():
    # p scales the forcing of a linear model: the orbit at p is p times the closed form
    o = scheme_orbit(jump_model(400))
    e = da.collocate(o, intervals=16, multipliers=2, kernel_jumps=(S1,))
    assert e.kernel_jumps == (S1,)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CollocationWarning)
        b = da.continue_orbit(e, 1.3, step=0.15)
    t = np.linspace(0.0, T, 301)
    assert len(b.points) >= 3 and abs(b.points[-1].p - 1.3) < 1e-12
    for pt in b.points:
        assert pt.kernel_jumps == (S1,)
        assert np.max(np.abs(pt.u_at(t)[:, 0] - pt.p * jump_exact(t))) < 1e-8   # 1e-4 without


def test_fitted_power_kernel_autonomous_order():
    # van der Pol with the fitted fractional damping 0.2 s^-0.5 on its velocity, tau = 2 (its
    # fit steep past delta: the pieces there graded): the period's order under refinement >= m
    # and the trivial multiplier at 1
    fit = dk.fit(dk.PowerKernel(0.5, 0.2), 2.0, delta=0.05, tol=1e-7)

    def make(p: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, 2.0, h=0.01 if h is None else h)
        s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
        s.set_quadrature("cell")
        s.set_kernel_fit(fit, entry=(1, 1))
        return s
    s = make(1.0)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(6000)
    o = da.periodic_orbit(make, 1.0, None, s, guess_period=6.5, steps=650, multipliers=0)
    es = [da.collocate(o, intervals=L, multipliers=2) for L in (16, 32, 64)]
    d = [abs(a.period - b.period) for a, b in zip(es[:-1], es[1:])]
    assert math.log2(d[0] / d[1]) >= 4, d
    assert abs(es[1].multipliers[0] - 1) < 1e-8


def test_steep_exponential_sum_graded():
    # H = 5 e^{-200 s} + 0.3 e^{-s} on [0, 1] (a fit's fast terms): Hhat in closed form; the
    # pieces near 0 graded at 2^k / 200, the order >= m (without: 8e-7 at 32 intervals)
    rates, coef = np.array([-200.0, -1.0]), np.array([5.0, 0.3])

    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(1, TAU, h=T / 400)
        s.set_rhs(lambda t, u: np.array([K * u[0] - p * C * np.cos(OM * t)]))
        s.set_kernel_exp(rates, [0.0, 0.0], coef[:, None, None])
        return s
    o = scheme_orbit(make)
    lam = 1j * OM
    hh = np.sum(coef * (1 - np.exp(-(lam - rates) * TAU)) / (lam - rates))
    t = np.linspace(0.0, T, 301)
    exact = np.real(C / (lam + K + hh) * np.exp(lam * t))
    errs = [float(np.max(np.abs(da.collocate(o, intervals=L, multipliers=0).u_at(t)[:, 0]
                                - exact))) for L in (8, 16, 32)]
    orders = [math.log2(a / b) for a, b in zip(errs[:-1], errs[1:])]
    assert min(orders) >= 4 and errs[-1] < 1e-9, (errs, orders)


# ---- the circles of a rotating model whose kernel jumps, from the Hopf point ---------------------
W0R, GR, S1R, TAUR = 1.0, 0.5, 0.8, 2.0


def jump_rotating(p: float, h: float | None = None) -> dmi.Solver:
    """u' = (p - |u|^2) u + W0R J u - int_0^TAUR H u, H = GR I on (0, S1R), 0 after."""
    s = dmi.Solver(2, TAUR, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: -((p - u @ u) * u + W0R * np.array([-u[1], u[0]])))
    s.set_kernel(lambda s: (GR if s < S1R else 0.0) * np.eye(2))
    return s


def test_hopf_orbit_of_equation_carries_kernel_jumps():
    # z = r e^{i W t}: i W = p - r^2 + i W0R - Hhat(i W), Hhat(q) = GR (1 - e^{-q S1R}) / q, so
    # W = W0R - Im Hhat(i W), r^2 = p - Re Hhat(i W), the Hopf point at p_H = Re Hhat(i W)
    from scipy.optimize import brentq

    def hhat(q: complex) -> complex:
        return GR * (1 - np.exp(-q * S1R)) / q
    om = brentq(lambda w: w - W0R + hhat(1j * w).imag, 0.1, 3.0, xtol=1e-15)
    muH, T = hhat(1j * om).real, 2 * math.pi / om
    hp = da.HopfPoint(p=muH, omega=om, root=1j * om)
    with warnings.catch_warnings():
        warnings.simplefilter("error", CollocationWarning)
        e = da.hopf_orbit(jump_rotating, hp, [0.0, 0.0], amplitude=0.1, of="equation",
                          kernel_jumps=(S1R,))
        b = da.continue_orbit(e, muH + 0.25, step=0.05, multipliers=0)
    assert e.kernel_jumps == (S1R,)
    assert abs(e.p - (muH + 0.01)) < 1e-10 and abs(e.period - T) < 1e-10
    assert b.status.startswith("reached p_end"), b.status
    for q in b.points:                    # the radius sqrt(p - p_H) at every point, the period T
        assert abs(q.period - T) < 1e-9 and np.all(np.abs(q.amplitude - math.sqrt(q.p - muH))
                                                   < 1e-9), (q.p, q.period, q.amplitude)
    with pytest.raises(ValueError, match="kernel_jumps"):
        da.hopf_orbit(jump_rotating, hp, [0.0, 0.0], amplitude=0.1, steps=64,
                      kernel_jumps=(S1R,))
