# Hopf and fold curves of the equation's equilibria in two parameters (dmi.analysis.continue_curve)
# against closed forms written here: the Hopf curve of a rotationally symmetric oscillator with a
# distributed memory (its characteristic equation is a scalar one), through two turning points in
# q, with its Bautin point (with and without the derivative hook); the fold curve and the cusp of
# a scalar cubic with a memory; the fold curve and the Bogdanov-Takens point of a planar model
# with a memory; the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from models import hopf_models
from dmi import analysis as da

# ---- z' = (q - (p^3 - p) + i W0) z + c1 |z|^2 z + c2 |z|^4 z - int_0^TAU G e^-s z(t - s) ds ----
# in (x, y), with G = G0 + G1 p and c1 = p + i C1I.  The rotation-commuting memory makes
# Delta(lambda) = diag-like with det = d(lambda) conj-d(lambda), d(lambda) = lambda + g(lambda) -
# alpha - i W0, g(lambda) = G (1 - e^-(1 + lambda) TAU) / (1 + lambda), alpha = q - (p^3 - p):
# the Hopf curve is Om + Im g(i Om) = W0, q = p^3 - p + Re g(i Om) (an S in q: two turning
# points), and in Kuznetsov's normalisation l1 = Re(2 c1 / d'(i Om)) / Om, so the Bautin point is
# Re(c1 / d'(i Om)) = 0.
W0, TAU, G0, G1 = 1.0, 2.0, 0.5, 0.2
C1I = 0.4
C2 = 0.3 - 0.2j


def gmem(p: float) -> float:
    return G0 + G1 * p


def ghat(lam: complex, G: float) -> complex:
    return hopf_models.ghat(lam, G, TAU)


def dghat(lam: complex, G: float) -> complex:
    return hopf_models.dghat(lam, G, TAU)


def exact_hopf(p: float) -> tuple[float, float]:
    """(Om, q) of the Hopf curve at p."""
    G = gmem(p)
    om = so.brentq(lambda w: w + ghat(1j * w, G).imag - W0, 0.1, 3.0, xtol=1e-15, rtol=1e-15)
    return om, p ** 3 - p + ghat(1j * om, G).real


def exact_l1(p: float) -> float:
    om, _ = exact_hopf(p)
    d1 = 1 + dghat(1j * om, gmem(p))
    return (2 * complex(p, C1I) / d1).real / om


def circle_model(p: float, q: float, hook: bool) -> dmi.Solver:
    return hopf_models.circle_solver(complex(q - (p ** 3 - p), W0), complex(p, C1I), C2,
                                     gmem(p), TAU, 40, hook)


def with_hook(p: float, q: float) -> dmi.Solver:
    return circle_model(p, q, True)


def without_hook(p: float, q: float) -> dmi.Solver:
    return circle_model(p, q, False)


def bautin() -> tuple[float, float]:
    """(p, q) of the Bautin point: Re(c1 / d'(i Om)) = 0 on the Hopf curve."""
    p = so.brentq(exact_l1, -1.0, 1.0, xtol=1e-15, rtol=1e-15)
    return p, exact_hopf(p)[1]


def close(got: float, want: float, rel: float) -> bool:
    return abs(got - want) <= rel * max(1.0, abs(want))


def test_hopf_curve_through_two_turning_points_with_its_bautin_point():
    p0 = -1.5
    om0, q0 = exact_hopf(p0)
    hp = da.hopf(lambda p: with_hook(p, q0), p0 - 0.1, p0 + 0.1, [0.0, 0.0], of="equation")
    curve = da.continue_curve(hp, with_hook, q0, 3.0, u_eq=[0.0, 0.0], step=0.2, at=[0.0])
    assert curve.kind == "hopf" and curve.status == "reached q_end = 3.0", curve.status
    assert curve.q[-1] == 3.0
    for pt in curve.points:
        om, q = exact_hopf(pt.p)
        assert close(pt.q, q, 1e-9) and close(pt.omega, om, 1e-9), (pt.p, pt.q - q, pt.omega - om)
        assert np.max(np.abs(pt.u)) <= 1e-12
        assert close(pt.l1, exact_l1(pt.p), 1e-9), (pt.p, pt.l1, exact_l1(pt.p))
        assert pt.criticality == ("supercritical" if pt.l1 < 0 else "subcritical")
        assert pt.kappa is not None and pt.kappa.shape == (2,)
    # both turning points in q passed: q rises, falls, rises (the S of p^3 - p)
    dq = np.sign(np.diff(curve.q))
    assert np.count_nonzero(dq[1:] != dq[:-1]) == 2 and np.all(np.diff(curve.p) > 0)
    # q = 0 is met three times, each point on it exactly, at the three p where the curve has q = 0
    users = [e for e in curve.events if e.kind == "user"]
    want = sorted(so.brentq(lambda p: exact_hopf(p)[1], a, b, xtol=1e-15)
                  for a, b in ((-1.5, -0.5), (-0.5, 0.4), (0.4, 1.5)))
    assert [e.q for e in users] == [0.0, 0.0, 0.0]
    assert all(close(e.p, w, 1e-9) for e, w in zip(users, want)), ([e.p for e in users], want)
    assert all(curve.points[e.index].q == 0.0 for e in users)
    (b,) = [e for e in curve.events if e.kind == "bautin"]
    pb, qb = bautin()
    assert close(b.p, pb, 1e-9) and close(b.q, qb, 1e-9), (b.p - pb, b.q - qb)
    assert abs(b.hopf.l1) <= 1e-9
    assert {e.kind for e in curve.events} == {"user", "bautin"}


def test_bautin_point_without_the_derivative_hook_from_a_branch_event():
    # the start: the Hopf event of the equation's equilibria u = 0 at q = q0, in p
    q0 = exact_hopf(-0.2)[1]
    eq = da.equilibrium(lambda p: without_hook(p, q0), -0.35, [0.0, 0.0], of="equation")
    br = da.continue_equilibrium(eq, -0.05, step=0.1)
    (ev,) = [e for e in br.events if e.kind == "hopf"]
    assert close(ev.hopf.p, -0.2, 1e-9)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", da.equilibria.normal_form.CriticalityWarning)   # l1 ~ 0 at Bautin
        curve = da.continue_curve(ev, without_hook, q0, 0.1, step=0.1)
    assert curve.status == "reached q_end = 0.1", curve.status
    for pt in curve.points:
        om, q = exact_hopf(pt.p)
        assert close(pt.q, q, 1e-9) and close(pt.omega, om, 1e-9)
        assert close(pt.l1, exact_l1(pt.p), 1e-5)
    (b,) = [e for e in curve.events if e.kind == "bautin"]
    pb, qb = bautin()
    assert close(b.p, pb, 1e-5) and close(b.q, qb, 1e-5), (b.p - pb, b.q - qb)


# ---- u' = -(u^3 - q u + p) - int_0^TAU GM e^-s u(t - s) ds ---------------------------------
# equilibria u^3 - (q - K) u + p = 0, K = GM (1 - e^-TAU); folds where 3 u^2 = q - K, so the
# fold curve is p = 2 u^3, q = K + 3 u^2: p = +-2 ((q - K) / 3)^(3/2), with its cusp at (0, K).
TAU1, GM = 1.5, 0.4
K = GM * (1 - math.exp(-TAU1))


def cubic(p: float, q: float) -> dmi.Solver:
    s = dmi.Solver(1, TAU1, 30)
    s.set_rhs(lambda t, u: np.array([u[0] ** 3 - q * u[0] + p]))
    s.set_kernel_exp([-1.0], [0.0], [[[GM]]])
    return s


def test_fold_curve_through_its_cusp():
    q0 = K + 3.0
    eq = da.equilibrium(lambda p: cubic(p, q0), -3.0, [2.1], of="equation")
    br = da.continue_equilibrium(eq, 3.0, step=0.3)
    fold = [e for e in br.events if e.kind == "fold"][0]
    assert close(fold.p, 2.0, 1e-9)
    curve = da.continue_curve(fold, cubic, q0, K - 1.0, step=0.3)
    assert curve.kind == "fold"
    # the curve turns in q at the cusp and comes back up on the other fold, out of the range
    assert curve.status.startswith("left the range"), curve.status
    assert curve.points[-1].q > q0 and curve.points[-1].p < -2.0
    for pt in curve.points:
        u = pt.u[0]
        want = math.copysign(2 * ((pt.q - K) / 3) ** 1.5, u)
        assert close(pt.p, want, 1e-9), (pt.p, pt.q, want)
        assert close(pt.q, K + 3 * u * u, 1e-9)
        assert pt.omega == 0.0 and pt.l1 is None
    (c,) = [e for e in curve.events if e.kind == "cusp"]
    assert abs(c.p) <= 1e-9 and close(c.q, K, 1e-9), (c.p, c.q - K)
    assert [e.kind for e in curve.events] == ["cusp"]


# ---- x' = y, y' = p + q y + x^2 + x y - int_0^TAU2 GB e^-s x(t - s) ds ------------------------
# Delta(lambda) = [[lambda, -1], [-2 x + g(lambda), lambda - q - x]] at (x, 0), det = lambda^2 -
# (q + x) lambda - 2 x + g(lambda), g = GB (1 - e^-(1 + lambda) TAU2) / (1 + lambda): a root 0
# where x = g(0) / 2, so the fold curve is p = g(0)^2 / 4 for every q, and the root 0 is double
# (a Bogdanov-Takens point) where q = g'(0) - g(0) / 2.
TAU2, GB = 2.0, 0.5


def planar(p: float, q: float) -> dmi.Solver:
    s = dmi.Solver(2, TAU2, 30)
    s.set_rhs(lambda t, u: -np.array([u[1], p + q * u[1] + u[0] ** 2 + u[0] * u[1]]))
    s.set_kernel_exp([-1.0], [0.0], [np.array([[0.0, 0.0], [GB, 0.0]])])
    return s


@pytest.mark.filterwarnings("ignore::dmi.analysis.equilibria.equation.RefinementWarning")   # the branch in p
def test_fold_curve_with_its_bogdanov_takens_point():
    g0 = ghat(0.0, GB).real
    q_bt = dghat(0.0, GB).real - g0 / 2
    eq = da.equilibrium(lambda p: planar(p, 0.0), 0.0, [g0, 0.0], of="equation")
    br = da.continue_equilibrium(eq, 0.2, step=0.02)
    fold = [e for e in br.events if e.kind == "fold"][0]
    curve = da.continue_curve(fold, planar, 0.0, -1.0, step=0.1)
    assert curve.status == "reached q_end = -1.0", curve.status
    for pt in curve.points:
        assert close(pt.p, g0 * g0 / 4, 1e-9) and close(pt.u[0], g0 / 2, 1e-9), (pt.p, pt.u)
    (bt,) = [e for e in curve.events if e.kind == "bogdanov-takens"]
    assert close(bt.q, q_bt, 1e-9) and close(bt.p, g0 * g0 / 4, 1e-9), (bt.q - q_bt, bt.p)
    assert [e.kind for e in curve.events] == ["bogdanov-takens"]


# ---- refusals --------------------------------------------------------------------------------
def test_refusals():
    om0, q0 = exact_hopf(-1.5)
    hp = da.HopfPoint(p=-1.5, omega=om0, root=complex(0, om0))
    with pytest.raises(ValueError, match="needs u_eq"):
        da.continue_curve(hp, with_hook, q0, 3.0)
    with pytest.raises(ValueError, match="give a HopfPoint of the equation"):
        da.continue_curve([0.0, 1.0], with_hook, q0, 3.0)
    with pytest.raises(ValueError, match="two different finite values"):
        da.continue_curve(hp, with_hook, q0, q0, u_eq=[0.0, 0.0])
    with pytest.raises(ValueError, match="omega = 0.0 is not > 0"):
        da.continue_curve(da.HopfPoint(p=-1.5, omega=0.0, root=0j), with_hook, q0, 3.0,
                          u_eq=[0.0, 0.0])
    with pytest.raises(ValueError, match="the fold event has no equilibrium"):
        da.continue_curve(da.Event("fold", 2.0, 3), cubic, K + 3.0, K)
    # a point that is not a Hopf point of make2 at q0
    with pytest.raises(ValueError, match="is not a Hopf point"):
        da.continue_curve(da.HopfPoint(p=-1.0, omega=om0, root=complex(0, om0)), with_hook,
                          q0 + 5.0, 6.0, u_eq=[0.0, 0.0])
