# A periodic orbit's delay integral folded onto one period (dmi.analysis.collocation.fold): the
# collocation system's residual, Jacobian and period column with the fold against the whole memory
# (delay_matrix over [0, tau]) on memories of several periods, cut inside a period or at a whole
# number of them, with oscillating terms and with near cells; and a collocated orbit (the fold
# used) against an independent computation: van der Pol with an oscillating exponential memory of
# five periods whose terms are ODE states of their own, its limit cycle and monodromy integrated
# with scipy's DOP853 (the memory's truncation at tau below 2e-14).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi import analysis as da
from dmi import kernels
from dmi.analysis.collocation import system as S
from dmi.analysis.collocation.mesh import periodic_locator
from dmi.analysis.collocation.signature import Signature
from models.orbit_models import limit_cycle

P = 0.15                        # van der Pol's damping
A1, B1, G1, C1 = 1.0, 1.5, 0.5, 0.06      # c1 e^(-a1 s) (cos b1 s + g1 sin b1 s)
A2, C2 = 1.3, 0.05                        # c2 e^(-a2 s)
TAU = 32.0                                # about five periods; e^(-a1 tau) ~ 1.3e-14
T0 = 6.1                                  # the period of the fold's own checks
SLOW = ([-0.02, -0.04, -0.05], [0.0, 0.11, 0.04], [0.3, 0.2, 0.1], [0.0, 0.1, -0.2])
FAST = ([-0.15, -0.3, -0.4], [0.0, 0.9, 0.3], [0.3, 0.2, 0.1], [0.0, 0.1, -0.2])


def vdp(p: float, h: float | None = None, tau: float = TAU, kernel=None) -> dmi.Solver:
    """w' = v, v' = -p (w^2 - 1) v - w - int_0^tau H(s) w(t - s) ds, H the oscillating sum
    (or ``kernel``: (a, b, C, D) of set_kernel_exp, or a kernels fit)."""
    s = dmi.Solver(2, tau, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], p * (u[0] ** 2 - 1) * u[1] + u[0]]))
    if kernel is None or isinstance(kernel, tuple):
        a, b, c, d = kernel or ([-A1, -A2], [B1, 0.0], [C1, C2], [G1 * C1, 0.0])
        C = np.zeros((len(a), 2, 2))
        D = np.zeros((len(a), 2, 2))
        C[:, 1, 0], D[:, 1, 0] = c, d
        s.set_kernel_exp(np.asarray(a, float), np.asarray(b, float), C, D)
    else:
        s.set_quadrature("cell")
        s.set_kernel_fit(kernel, entry=(1, 0))
    return s


def ode(t: float, y: np.ndarray) -> np.ndarray:
    """The same model, the memory's terms as states: x + i y = int_0^inf e^((-a1 + i b1) s)
    w(t - s) ds, z = int_0^inf e^(-a2 s) w(t - s) ds."""
    w, v, x, yy, z = y
    return np.array([v, -P * (w * w - 1) * v - w - C1 * (x + G1 * yy) - C2 * z,
                     w - A1 * x - B1 * yy, B1 * x - A1 * yy, w - A2 * z])


def ode_jacobian(y: np.ndarray) -> np.ndarray:
    w, v = y[0], y[1]
    J = np.zeros((5, 5))
    J[0, 1] = 1.0
    J[1] = [-2 * P * w * v - 1, -P * (w * w - 1), -C1, -C1 * G1, -C2]
    J[2] = [1.0, 0.0, -A1, -B1, 0.0]
    J[3] = [0.0, 0.0, B1, -A1, 0.0]
    J[4] = [1.0, 0.0, 0.0, 0.0, -A2]
    return J


@pytest.fixture(scope="module")
def reference() -> tuple[float, np.ndarray]:
    """The ODE's period (between two upward crossings of w = 0 on the limit cycle) and its
    multipliers, largest first (the variational equations over a period)."""
    return limit_cycle(ode, ode_jacobian, [2.0, 0, 0, 0, 0], 5)


@pytest.fixture(scope="module")
def collocated(reference):
    """The collocated orbit (8 intervals, 2 multipliers) from the scheme's, and the number of
    delay integrals collocate built folded."""
    T, _ = reference
    steps = 400
    s = vdp(P, h=T / steps)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(40 * steps)
    orbit = da.periodic_orbit(vdp, P, None, s, guess_period=T, steps=steps, multipliers=0)
    calls = []
    real = S.Terms.periodic_delay

    def spy(self, times, mesh, T, *a, **k):
        calls.append(self.folded(T) is not None)
        return real(self, times, mesh, T, *a, **k)
    S.Terms.periodic_delay = spy
    try:
        e = da.collocate(orbit, intervals=8, multipliers=2)
    finally:
        S.Terms.periodic_delay = real
    return e, sum(calls)


def layout_of(L: int) -> tuple[S.Layout, np.ndarray]:
    """A smooth autonomous layout of L equal intervals (degree 4) of the period T0 and node
    values of a closed curve (not an orbit: the fold holds for any periodic u)."""
    lay = S.Layout(4, 2, Signature(np.zeros((1, 2), int)), [np.linspace(0, 1, L + 1)], True, T0)
    th = S.node_times(lay, np.empty(0), T0) / T0 * 2 * np.pi
    V = np.column_stack([2 * np.cos(th) + 0.3 * np.sin(3 * th), -2 * np.sin(th)])
    return lay, np.concatenate([V.ravel(), [T0]])


def both(lay: S.Layout, x: np.ndarray, solver: dmi.Solver) -> list:
    """(residual, dense Jacobian with the period column) folded and over the whole memory."""
    out = []
    ref = S.reference(lay, x)
    for on in (True, False):
        terms = S.Terms(solver)
        terms.fold = on
        r, J = S.full_jacobian(lay, terms, x, ref)
        out.append((r, J.toarray(), terms))
    return out


def test_collocated_orbit_against_the_ode(collocated, reference):
    T, mu = reference
    e, calls = collocated
    assert calls > 0                                     # the orbit's Newton folded
    assert abs(e.period - T) <= e.errors["period"] < 1e-5
    assert np.all(np.abs(e.multipliers[:2] - mu[:2]) <= e.errors["multipliers"][:2])
    assert abs(mu[0] - 1.0) < 1e-8 and abs(mu[1]) < 0.9   # the trivial one and a stable one


def differences(lay: S.Layout, x: np.ndarray, tau: float, kernel) -> tuple:
    """The folded system's relative differences from the whole memory's (residual, node columns,
    period column) and the two Terms."""
    (r1, J1, t1), (r2, J2, t2) = both(lay, x, vdp(P, tau=tau, kernel=kernel))
    return (np.max(np.abs(r1 - r2)) / np.max(np.abs(r2)),
            np.max(np.abs(J1[:, :-1] - J2[:, :-1])) / np.max(np.abs(J2)),
            np.max(np.abs(J1[:, -1] - J2[:, -1])) / np.max(np.abs(J2[:, -1])), t1, t2)


@pytest.mark.parametrize("periods", [3.4, 3.0, 1.6])
def test_fold_is_the_whole_memory(periods):
    # slow rates, the memory's cut at tau (inside a period, at three whole periods) large
    # (e^(-0.02 tau) >= 0.66): the same quadrature nodes (Gauss exact on the pieces to rounding)
    lay, x = layout_of(8)
    dr, dJ, dT, t1, t2 = differences(lay, x, periods * T0, SLOW)
    f = t1.folded(T0)
    assert f is not None and f.K == int(periods) and t2.folded(T0) is None
    assert (f.r == 0.0) == (periods == 3.0)
    assert dr <= 1e-14 and dJ <= 1e-14 and dT <= 1e-13
    # the memory's rows at more times (a stick ending's) with the collocation's
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    tc = np.linspace(0.1, T - 0.1, 7)
    more = np.array([0.3 * T, 0.9 * T])
    loc = periodic_locator(mesh, lay.m)
    G1, Gb1 = t1.delay(tc, mesh, T, loc, lay.basis, lay.rows, None, more, periodic=True)
    G2, Gb2 = t2.delay(tc, mesh, T, loc, lay.basis, lay.rows, None, more, periodic=True)
    big = abs(G2).sum(axis=1).max()                      # the rows sum periods of |H|
    assert abs(G1 - G2).max() <= 1e-14 * big and abs(Gb1 - Gb2).max() <= 1e-14 * big


def test_fold_differs_by_the_quadrature_error():
    # faster rates, and a fitted s^-1/2 with exact near cells (k = 0 only): the fold cuts the
    # pieces at the lag T where the whole memory has one, so the two differ by the Gauss rule's
    # error on those pieces, which falls by more than 100 when the intervals double
    fit = kernels.fit(kernels.PowerKernel(0.5, 0.1 / math.sqrt(math.pi)), 2.5 * T0, tol=1e-8,
                      relative=True, delta=0.002)
    for tau, kernel in ((3.4 * T0, FAST), (2.5 * T0, fit)):
        coarse = differences(*layout_of(8), tau, kernel)
        fine = differences(*layout_of(16), tau, kernel)
        assert max(coarse[:3]) <= 1e-9
        for c, f in zip(coarse[:3], fine[:3]):
            assert f <= max(c / 100, 2e-14)
    assert fine[3].folded(T0).tail is not None and fine[3].folded(T0).K == 2


def test_no_fold_within_a_period():
    terms = S.Terms(vdp(P, tau=0.9 * T0))
    assert terms.fold and terms.folded(T0) is None        # nothing to fold: the whole memory
    fit = kernels.fit(kernels.PowerKernel(0.5, 0.1), 2.0, tol=1e-4, relative=True, delta=0.5)
    near = S.Terms(vdp(P, tau=2.0, kernel=fit))
    assert near.folded(0.4) is None and near.folded(1.5) is not None   # near cells reach T


def test_exp_sum_in_blocks_against_mpmath():
    # a fitted s^-1/2's rates (the fast ones underflow at most lags), oscillating terms, over
    # several blocks of EXP_ENTRIES: each lag's sum against mpmath at 30 digits; a lag whose
    # every term underflows gives exactly 0 (the breakpoint rule H(tau) != 0 relies on it)
    import mpmath
    from dmi.analysis.collocation.fold import EXP_ENTRIES, exp_sum
    rng = np.random.default_rng(5)
    k = 12
    a = -np.logspace(-2, 3, k)
    b = np.where(np.arange(k) % 3 == 0, 0.7, 0.0)
    C, D = rng.standard_normal((k, 2, 2)), rng.standard_normal((k, 2, 2))
    s = np.concatenate([np.linspace(0.0, 40.0, 3 * EXP_ENTRIES // k + 7), [1e5]])
    got = exp_sum(s, a, b, C, D)
    assert got.shape == (s.size, 2, 2)
    mpmath.mp.dps = 30
    for i in list(range(0, s.size - 1, 397)) + [s.size - 2]:
        terms = [mpmath.exp(mpmath.mpf(a[j]) * s[i])
                 * (C[j] * mpmath.cos(b[j] * s[i]) + D[j] * mpmath.sin(b[j] * s[i]))
                 for j in range(k)]
        want = np.array(sum(terms).tolist(), dtype=float)
        size = np.sum([np.abs(np.array(t.tolist(), dtype=float)) for t in terms], axis=0)
        # double precision's promise for a sum: a few ulp of the sum of its terms' moduli
        assert np.all(np.abs(got[i] - want) <= 1e-14 * size + 1e-300), (s[i], got[i], want)
    assert np.all(got[-1] == 0.0)                    # e^(-0.01 * 1e5): every term below e^-708
