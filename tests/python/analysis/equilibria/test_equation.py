# The equation's answers (of="equation"): characteristic roots refined on det Delta(lambda) = 0,
# Hopf points, stability charts and equilibria of the continuous equation, against closed forms
# derived here and det Delta computed independently with mpmath (its own quadrature of H).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import functools
import math
import warnings

import mpmath as mp
import numpy as np
import pytest
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.equilibria.equation import RefinementWarning

TAU = 1.0
C0 = 0.3


# ---- w'' + c w' + b w + (a / tau) int_0^tau w(t - s) ds = 0 ------------------------------------
# Delta(i w) = 0 with theta = w tau: a = c w theta / (1 - cos theta), b = w^2 - a sin(theta) / theta
def averaged(a: float, b: float, N: int = 100, c: float = C0) -> dmi.Solver:
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], b * u[0] + c * u[1]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [a / TAU, 0.0]]])
    return s


def d_curve(w: float, c: float = C0) -> tuple[float, float]:
    th = w * TAU
    a = c * w * th / (1 - math.cos(th))
    return a, w * w - a * math.sin(th) / th


def char_averaged(lam, a, b, c=C0):
    return lam * lam + c * lam + b + (a / TAU) * (1 - mp.exp(-lam * TAU)) / lam


def test_roots_of_the_equation_against_its_characteristic_function():
    mp.mp.dps = 30
    make = (lambda a: averaged(a, 1.0, 200))
    got = da.roots(make, 0.8, [0.0, 0.0], 6, of="equation")
    scheme = da.roots(make, 0.8, [0.0, 0.0], 6)
    assert np.max(np.abs(got - scheme)) > 1e-3        # the scheme's are O(h) away
    for lam in got:
        want = complex(mp.findroot(lambda x: char_averaged(x, 0.8, 1.0), mp.mpc(lam)))
        assert abs(want - lam) <= 1e-10 * max(1, abs(lam)), (lam, want)
    # and ordered rightmost first, pairs Im >= 0 first
    assert np.all(np.diff(np.round(got.real, 9)) <= 0)


def test_hopf_of_the_equation_against_the_closed_form():
    b = 1.0
    w = so.brentq(lambda w: d_curve(w)[1] - b, 0.5, 2.0, xtol=1e-15)
    a_h = d_curve(w)[0]
    hp = da.hopf(lambda a: averaged(a, b, 100), 0.5 * a_h, 1.5 * a_h, [0.0, 0.0], of="equation")
    assert abs(hp.p - a_h) <= 1e-10 * a_h and abs(hp.omega - w) <= 1e-10 * w, (hp, a_h, w)
    sch = da.hopf(lambda a: averaged(a, b, 100), 0.5 * a_h, 1.5 * a_h, [0.0, 0.0])
    assert abs(sch.p - a_h) > 1e-4 * a_h               # the scheme's is O(h) off


def averaged_ab(a: float, b: float) -> dmi.Solver:
    return averaged(a, b, 64)


def test_the_equations_chart_traces_the_d_curves():
    chart = da.stability_chart(averaged_ab, np.linspace(0.2, 3.0, 8), np.linspace(0.5, 2.0, 5),
                               [0.0, 0.0], workers=1, of="equation")
    hopf = [c for c in chart.curves if c.is_hopf]
    assert hopf and sum(len(c.p) for c in hopf) >= 5
    for c in hopf:
        for a, b, w in zip(c.p, c.q, c.omega):
            ra, rb = d_curve(w)
            assert abs(a - ra) <= 1e-8 * max(1, ra) and abs(b - rb) <= 1e-8 * max(1, rb), \
                (a, b, w, ra, rb)


# ---- oscillatory matrix kernels: a scalar and a 3 x 3 system ------------------------------------
K3 = [(-0.7, 3.0), (-0.2, 7.0), (0.0, 11.0)]     # (a_k, b_k): damped and undamped oscillations
RNG = np.random.default_rng(7)
C3 = 0.3 * RNG.standard_normal((3, 3, 3))
D3 = 0.3 * RNG.standard_normal((3, 3, 3))
J3 = np.array([[0.5, -1.0, 0.2], [1.0, 0.4, 0.0], [0.1, 0.3, 0.8]])


def matrix_model(p: float, N: int = 400) -> dmi.Solver:
    s = dmi.Solver(3, TAU, N)
    s.set_rhs(lambda t, u: J3 @ u)
    s.set_kernel_exp([a for a, _ in K3], [b for _, b in K3], p * C3, p * D3)
    return s


def scalar_model(p: float, N: int = 400) -> dmi.Solver:
    s = dmi.Solver(1, TAU, N)
    s.set_rhs(lambda t, u: 0.3 * u)
    s.set_kernel_exp([a for a, _ in K3], [b for _, b in K3], p * C3[:, :1, :1], p * D3[:, :1, :1])
    return s


def det_delta(lam, J, C, D, p):
    """det(lam I + J + p int_0^tau H(s) e^(-lam s) ds) in mpmath: each term's integral
    int_0^tau e^((a + i b - lam) s) ds = (e^(z tau) - 1) / z, z = a + i b - lam, and its conjugate
    frequency's, H's cos and sin as (e^(i b s) +- e^(-i b s)) / (2 or 2 i)."""
    n = J.shape[0]

    def E(z):
        return (mp.exp(z * TAU) - 1) / z

    M = mp.matrix(n, n)
    for i in range(n):
        for j in range(n):
            h = 0
            for k, (a, b) in enumerate(K3):
                ep, em = E(a + 1j * b - lam), E(a - 1j * b - lam)
                h += C[k, i, j] * (ep + em) / 2 + D[k, i, j] * (ep - em) / (2j)
            M[i, j] = (lam if i == j else 0) + J[i, j] + p * h
    return mp.det(M)


@pytest.mark.parametrize("which", ["scalar", "3x3"])
def test_oscillatory_matrix_kernels_against_mpmath(which):
    mp.mp.dps = 20
    if which == "scalar":
        make, J, C, D = scalar_model, np.array([[0.3]]), C3[:, :1, :1], D3[:, :1, :1]
        u = [0.0]
    else:
        make, J, C, D = matrix_model, J3, C3, D3
        u = [0.0, 0.0, 0.0]
    got = da.roots(make, 1.5, u, 5, of="equation")
    assert np.all(np.isfinite(got))
    for lam in got:
        want = complex(mp.findroot(lambda x: det_delta(x, J, C, D, 1.5), mp.mpc(lam), tol=1e-24))
        assert abs(want - lam) <= 1e-10 * max(1, abs(lam)), (lam, want)


def callback_model(p: float, N: int = 1000) -> dmi.Solver:
    s = dmi.Solver(1, TAU, N)
    s.set_rhs(lambda t, u: 0.3 * u)
    s.set_kernel(lambda x: np.array([[p / (1 + x * x)]]))
    return s


def test_callback_kernel_by_panels_against_mpmath():
    mp.mp.dps = 20
    got = da.roots(callback_model, 2.0, [0.0], 4, of="equation")

    def char(lam):
        return lam + 0.3 + mp.quad(lambda s: 2.0 / (1 + s * s) * mp.exp(-lam * s), [0, TAU])
    for lam in got:
        want = complex(mp.findroot(char, mp.mpc(lam)))
        assert abs(want - lam) <= 1e-10 * max(1, abs(lam)), (lam, want)


def test_a_root_that_cannot_be_refined_is_said():
    # a coarse scheme (N = 4): its deep roots lie far from the equation's, and two of them may
    # converge onto one root; each such root is nan with a warning that says why
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        got = da.roots(functools.partial(matrix_model, N=4), 1.5, [0.0] * 3, 12, of="equation")
    bad = [x for x in w if issubclass(x.category, RefinementWarning)]
    assert len(bad) == int(np.sum(np.isnan(got))) >= 1
    assert "could not be refined" in str(bad[0].message)


# ---- the equation's equilibrium and its branch --------------------------------------------------
def belt_eq(c: float, N: int = 50, vb: float = 0.3) -> dmi.Solver:
    # u' + f + A(u) + int H u ∋ 0 with a memory whose integral the scheme's sum misses by O(h):
    # H(s) = g e^(-s) on the position; equilibrium x (k + g (1 - e^-tau)) = alpha (sliding)
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb), u[0] + c * (u[1] + vb)]))
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [0.8, 0.0]]])
    s.set_friction([0.0, 0.5])
    return s


def test_equilibrium_of_the_equation():
    x_eq = 0.5 / (1 + 0.8 * (1 - math.exp(-TAU)))
    e = da.equilibrium(belt_eq, 0.5, [0.3, -0.3], of="equation")
    assert e.u == pytest.approx([x_eq, -0.3], abs=1e-12)
    s = da.equilibrium(belt_eq, 0.5, [0.3, -0.3])                # the scheme's: O(h) off
    assert abs(s.u[0] - x_eq) > 1e-4
    # the equation's equilibrium is refused by the scheme's roots, and taken by the equation's
    with pytest.raises(ValueError, match="not an equilibrium of the step map"):
        da.roots(belt_eq, 0.5, e.u, 4)
    assert np.all(np.isfinite(e.roots))


def test_equilibrium_branch_of_the_equation_locates_its_hopf_point():
    # the belt's sliding equilibrium: Delta(lambda) = lambda^2 + c lambda + 1 + 0.8 Ghat(lambda),
    # Ghat(lambda) = (1 - e^-(1 + lambda) tau) / (1 + lambda); at lambda = i w both parts vanish
    def F(z):
        c, w = z
        g = (1 - np.exp(-(1 + 1j * w) * TAU)) / (1 + 1j * w)
        d = -w * w + 1j * c * w + 1 + 0.8 * g
        return [d.real, d.imag]
    c_h, w_h = so.fsolve(F, [0.3, 1.2], xtol=1e-15)
    assert max(map(abs, F([c_h, w_h]))) < 1e-13
    e = da.equilibrium(belt_eq, 1.0, [0.3, -0.3], of="equation")
    br = da.continue_equilibrium(e, -0.5, step=0.2)
    hopf = [ev for ev in br.events if ev.kind == "hopf"]
    assert len(hopf) == 1
    hp = hopf[0].hopf
    assert abs(hp.p - c_h) <= 1e-10 * max(1, abs(c_h)) and abs(hp.omega - w_h) <= 1e-10 * w_h


# ---- a fold of equilibria, the scheme's and the equation's -------------------------------------
# u' + u^2 - (p - 1/2) + k int_0^tau e^(-s) u(t - s) ds = 0: equilibria p = 1/2 + u^2 + k K u, a fold
# at u = -k K / 2, p = 1/2 - (k K)^2 / 4, with K = 1 - e^(-tau) for the equation and the scheme's
# K_h = h sum_{l<N} e^(-l h) = h (1 - e^(-N h)) / (1 - e^(-h)).
KF, NF = 1.5, 20


def folding(p: float) -> dmi.Solver:
    s = dmi.Solver(1, TAU, NF)
    s.set_rhs(lambda t, u: np.array([u[0] ** 2 - (p - 0.5)]))
    s.set_kernel_exp([-1.0], [0.0], [[[KF]]])
    return s


@pytest.mark.parametrize("of", ["scheme", "equation"])
def test_fold_of_equilibria_located_on_the_branch(of):
    h = TAU / NF
    K = (1 - math.exp(-TAU)) if of == "equation" else h * (1 - math.exp(-NF * h)) / (1 - math.exp(-h))
    p_fold, u_fold = 0.5 - (KF * K) ** 2 / 4, -KF * K / 2
    u0 = 1.0
    e = da.equilibrium(folding, 0.5 + u0 ** 2 + KF * K * u0, [u0 + 0.01], of=of)
    assert e.u[0] == pytest.approx(u0, abs=1e-12)
    br = da.continue_equilibrium(e, -2.0, step=0.2, max_points=30)
    folds = [ev for ev in br.events if ev.kind == "fold"]
    assert len(folds) == 1, br.events
    tol = 1e-10 if of == "equation" else 1e-8
    assert abs(folds[0].p - p_fold) <= tol * max(1.0, abs(p_fold)), (folds[0].p, p_fold)
    assert folds[0].u[0] == pytest.approx(u_fold, abs=1e-4)
    assert min(q.u[0] for q in br.points) < u_fold - 0.1        # passed to the other side


def sticking_block(p: float, friction: str) -> dmi.Solver:
    # x' = v, v' + x + c v + 2 sigma(v) + p int e^(-s) x(t - s) ds ∋ 0: at x = 0.5 the velocity
    # sticks (the force on it is below 2), and x is then a neutral direction
    s = dmi.Solver(2, TAU, 50)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] + 0.3 * u[1]]))
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
    if friction == "builtin":
        s.set_friction([0.0, 2.0])
    else:
        def r(lam, x):
            y = x.copy()
            y[1] = np.sign(x[1]) * max(abs(x[1]) - lam * 2.0, 0.0)
            return y
        s.set_resolvent(r)
    return s


@pytest.mark.parametrize("friction", ["builtin", "callback"])
def test_a_held_component_is_removed(friction):
    # the stuck velocity is removed: Delta is 1 x 1 on x, lambda + (f_u)_xx = lambda + 0 = 0
    # (x' = v = 0 while stuck): the equation's one root is 0, for the built-in friction and for the
    # same friction as a callback resolvent alike
    got = da.roots(functools.partial(sticking_block, friction=friction), 0.4, [0.5, 0.0], 1,
                   of="equation")
    assert abs(got[0]) <= 1e-12, got
