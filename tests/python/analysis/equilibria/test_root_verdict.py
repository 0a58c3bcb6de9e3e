# The verified stability verdict of equilibria (dmi.analysis.equilibria.root_verdict): closed-form stability
# boundaries, the argument principle's count against polynomial roots, roots the root finder
# misses, a root on the imaginary axis, and the opt-out.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import scipy.optimize

import dmi
from dmi import analysis
from dmi.analysis import StabilityWarning
from dmi.analysis.equilibria import stability
from dmi.analysis.core.model import Linearisation
from dmi.analysis.equilibria.equation import Characteristic
from dmi.analysis.equilibria.root_verdict import count_right

TAU = 1.0
#: x' = -(a / tau) int_0^tau x(t - s) ds: Delta(lambda) = lambda + a (1 - e^(-lambda tau)) /
#: (lambda tau); on the axis sin(w tau) = 0, cos(w tau) = -1, w^2 tau = 2 a: the first crossing
#: at w = pi / tau, a* = pi^2 / (2 tau).
A_STAR = math.pi ** 2 / (2 * TAU)


def mean_delay(a: float, N: int = 200) -> dmi.Solver:
    s = dmi.Solver(1, TAU, N)
    s.set_kernel_exp([0.0], [0.0], [[[a / TAU]]])
    return s


def exact_root(a: float, guess: complex) -> complex:
    """The root of lambda^2 tau + a (1 - e^(-lambda tau)) = 0 near guess (scipy's fsolve on its
    real and imaginary parts)."""
    def F(v):
        lam = complex(v[0], v[1])
        r = lam * lam * TAU + a * (1 - np.exp(-lam * TAU))
        return [r.real, r.imag]
    x = scipy.optimize.fsolve(F, [guess.real, guess.imag], xtol=1e-13)
    return complex(x[0], x[1])


def verdict(make, p, guess, **kw):
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        eq = analysis.equilibrium(make, p, guess, **kw)
    return eq, got


@pytest.mark.parametrize("of", ["equation", "scheme"])
def test_mean_delay_boundary(of):
    # the equation's boundary is exact: 1e-3 either side decides; the scheme's lies O(h) away,
    # so it is asked 10 % either side
    rel = 1e-3 if of == "equation" else 0.1
    below, w1 = verdict(mean_delay, A_STAR * (1 - rel), [0.0], of=of)
    above, w2 = verdict(mean_delay, A_STAR * (1 + rel), [0.0], of=of)
    assert below.stable is True and above.stable is False, (below.reason, above.reason)
    assert not [w for w in w1 + w2 if issubclass(w.category, StabilityWarning)]
    for eq in (below, above):
        assert 0 < eq.error <= 1e-8 * max(1.0, abs(eq.roots[0]))
        assert abs(eq.roots[0].real) > eq.error
    if of == "equation":   # the error stated covers the distance to the exact root
        for eq in (below, above):
            lam = exact_root(eq.p, complex(0, math.pi / TAU))
            assert abs(eq.roots[0] - lam) <= eq.error, (eq.roots[0], lam, eq.error)
        assert "0 roots counted" in below.reason


def test_root_on_the_axis_is_none_with_a_warning():
    # at a* the rightmost pair is +-i pi / tau exactly: within any error of the axis
    eq, got = verdict(mean_delay, A_STAR, [0.0], of="equation")
    assert abs(eq.roots[0] - 1j * math.pi / TAU) < 1e-9
    assert eq.stable is None
    msgs = [str(w.message) for w in got if issubclass(w.category, StabilityWarning)]
    assert len(msgs) == 1 and "imaginary axis within its error" in msgs[0], msgs
    assert "simulate" in msgs[0]

    # y' = v implicit (the resolvent), v' = -w^2 y explicit (the rhs): the scheme is symplectic
    # Euler, det M = 1, its multipliers e^(+-i theta) on the unit circle exactly
    def symplectic(w):
        s = dmi.Solver(2, 1.0, 8)
        A = np.array([[0.0, -1.0], [0.0, 0.0]])
        s.set_rhs(lambda t, u: np.array([0.0, w * w * u[0]]))
        s.set_resolvent(lambda lam, x: np.linalg.solve(np.eye(2) + lam * A, x))
        return s
    eq, got = verdict(symplectic, 3.0, [0.1, 0.1])
    h = 1.0 / 8
    theta = math.acos(1 - (3.0 * h) ** 2 / 2)       # trace M = 2 - h^2 w^2 = 2 cos theta
    assert abs(eq.roots[0] - 1j * theta / h) < 1e-12
    assert eq.stable is None
    assert any(issubclass(w.category, StabilityWarning) and "within its error" in str(w.message)
               for w in got)


# x' = -b x - int_0^tau c e^(-k s) cos(nu s) x(t - s) ds with tau = 20:
# Hhat(lambda) = c (lambda + k) / ((lambda + k)^2 + nu^2) to 1e-13 where Re lambda >= -k / 4
# (e^(-(lambda + k) tau) <= 1e-13 there), and the characteristic equation the cubic
# (lambda + b)((lambda + k)^2 + nu^2) + c (lambda + k) = 0 there.  With k = 2, nu^2 = 183 / 62,
# c = 18.3 its roots are 0.5 +- 3 i and -0.8 at b = -4.2; b = -2 has them all in Re < 0.
K, NU, C = 2.0, math.sqrt(183.0 / 62.0), 18.3


def damped(b: float, N: int = 400) -> dmi.Solver:
    s = dmi.Solver(1, 20.0, N)
    s.set_rhs(lambda t, u: b * u)
    s.set_kernel_exp([-K], [NU], [[[C]]])
    return s


def cubic_roots(b: float) -> np.ndarray:
    q = np.polynomial.Polynomial
    p = q([b, 1.0]) * q([K * K + NU * NU, 2 * K, 1.0]) + C * q([K, 1.0])
    return np.roots(p.coef[::-1])


@pytest.mark.parametrize("b", [-4.2, -3.0, -2.0])
def test_count_against_the_cubic(b):
    r = cubic_roots(b)
    counts = set()
    with Linearisation(lambda: damped(b), [0.0], (b,), 1e-9, "equation") as lin:
        ch = Characteristic(lin, 10.0)
        for sigma in (-0.5, -0.3, -0.1, 0.02, 0.2, 0.4, 1.0, 3.0):
            if np.min(np.abs(r.real - sigma)) < 1e-3:
                continue
            n, how = count_right(ch, sigma)
            assert n == int(np.sum(r.real > sigma)), (b, sigma, r, how)
            counts.add(n)
    assert len(counts) >= 2
    eq, _ = verdict(damped, b, [0.0], of="equation")
    assert eq.stable is bool(np.max(r.real) < 0), (r, eq.roots, eq.reason)
    assert np.min(np.abs(r - eq.roots[0])) <= eq.error


# The equation's root the scheme's roots do not reach: a block y'' - 2 zeta w y' + w^2 y = 0 (w
# = 20, zeta = 0.005: roots 0.1 +- 20 i, unstable) in the resolvent (implicit in the scheme,
# which damps it to Re lambda = -1.9 at h = 0.01), beside x' = -(a / tau) int_0^tau x, a = 0.5,
# tau = 4 (stable, with many roots right of -1.9): the 6 rightmost roots of the scheme are all
# x's, and refined to the equation's they miss y's.
W, ZETA = 20.0, 0.005


def hidden(zeta: float, N: int = 400) -> dmi.Solver:
    A = np.array([[0.0, -1.0, 0.0], [W * W, -2 * zeta * W, 0.0], [0.0, 0.0, 0.0]])
    s = dmi.Solver(3, 4.0, N)
    s.set_resolvent(lambda lam, x: np.linalg.solve(np.eye(3) + lam * A, x))
    C3 = np.zeros((1, 3, 3))
    C3[0, 2, 2] = 0.5 / 4.0
    s.set_kernel_exp([0.0], [0.0], C3)
    return s


def test_a_root_the_finder_misses_equation():
    unstable = ZETA * W + 1j * W * math.sqrt(1 - ZETA ** 2)   # the block's root, closed form
    eq, got = verdict(hidden, ZETA, [0.0, 0.0, 0.0], of="equation")
    assert np.min(np.abs(eq.roots - unstable)) > 1.0          # the finder missed it
    assert np.all(eq.roots.real < 0)
    assert eq.stable is False, eq.reason
    assert "did not find" in eq.reason and "count=" in eq.reason
    # with the block damped (zeta < 0: roots -0.1 +- 20 i) the same check says stable
    eq, _ = verdict(hidden, -ZETA, [0.0, 0.0, 0.0], of="equation")
    assert eq.stable is True, eq.reason


def test_a_root_the_finder_misses_scheme(monkeypatch):
    # a first eigen-solve that loses the rightmost pair (as ARPACK could on a harder spectrum):
    # the second, independent one finds it
    first = stability._arnoldi_roots

    def lossy(lin, count):
        lam = first(lin, count)
        return lam[np.argsort(-lam.real)][2:]
    monkeypatch.setattr(stability, "_arnoldi_roots", lossy)
    eq, _ = verdict(mean_delay, 1.1 * A_STAR, [0.0])
    assert np.all(eq.roots.real < 0)
    assert eq.stable is False, eq.reason
    assert "second eigen-solve" in eq.reason and "missed" in eq.reason
    eq, got = verdict(mean_delay, 0.9 * A_STAR, [0.0])   # a stable one lost its rightmost pair
    assert eq.stable is not True, eq.reason


def test_opt_out_and_branch():
    eq, got = verdict(mean_delay, 0.8 * A_STAR, [0.0], of="equation", verify=False)
    assert eq.stable is None and math.isnan(eq.error)
    assert any(issubclass(w.category, UserWarning) and "verify" in str(w.message) for w in got)
    with pytest.raises(ValueError, match="verify"):
        analysis.equilibrium(mean_delay, 1.0, [0.0], verify="yes")
    with pytest.raises(ValueError, match="verify"):
        analysis.continue_equilibrium(eq, 0.9 * A_STAR, verify=1)
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        br = analysis.continue_equilibrium(eq, 0.9 * A_STAR, step=0.5, verify=False)
    assert all(q.stable is None for q in br.points)
    assert any("verify" in str(w.message) for w in got)
    # verified: the points below a* stable, above unstable, each with its error
    eq, _ = verdict(mean_delay, 0.8 * A_STAR, [0.0], of="equation")
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        br = analysis.continue_equilibrium(eq, 1.2 * A_STAR, step=0.5)
    assert [e.kind for e in br.events] == ["hopf"]
    assert abs(br.events[0].p - A_STAR) < 1e-7
    assert len(br.points) >= 4
    for q in br.points:
        assert q.stable is (q.p < A_STAR), (q.p, q.reason)
        assert 0 < q.error < 1e-8 * max(1.0, abs(q.roots[0]))
