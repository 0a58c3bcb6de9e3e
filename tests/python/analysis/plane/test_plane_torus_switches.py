# The torus (Neimark-Sacker) curve of collocated orbits with switches continued in (p, q)
# (continue_curve's dispatch to continue_torus_curve, on an orbit whose switching times are
# unknowns): the forced van der Pol oscillator with a small dry friction,
#     x'' + (x^2 - q) x' + x + AL sigma(x') ∋ p sin(W t),
# whose T-orbit reverses its velocity twice a period without sticking and loses its stability
# through a pair e^(+-i theta) near p = 0.767 at q = 0.2; its torus curve in (p, q) = (forcing,
# negative damping).  (The forcing is a sine so that the reversals stay away from t = 0; theta
# passes 2 pi / 3 just past q = 0.2, a 1:3 resonance the curve does not detect nor need to.)
# Against an event-driven integration in the tests' models (orbit_models.reversal_flow): DOP853
# (rtol 1e-13) between the velocity's zeros, located by its event finder (each a reversal: the
# net force there exceeds AL, asserted; no stick), the period map's Jacobian by central
# differences, the T-orbit by Newton, the pair's modulus 1 (det M = 1, the pair complex) in p by
# Brent's method at three q, theta = arg mu.
# The reference's own accuracy: its p moves by less than 1e-10 and its theta by less than 5e-10
# when the differences' step changes tenfold (measured 4e-11 and 2e-10).
# Also the twisted matrix A_mu of the orbit with switches at the complex multipliers, and its
# derivatives in theta and in x against differences.  About 60 s.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest
import scipy.linalg as sl
from scipy.optimize import brentq

import dmi
from dmi import analysis as da
from dmi.analysis.collocation import floquet
from dmi.analysis.collocation.system import Layout, Terms
from dmi.analysis.plane.orbit_curves import SwitchTwisted, TorusCurvePoint

from models import orbit_models

W, AL = 1.5, 0.02                    # the forcing's frequency, the dry friction
T = 2 * math.pi / W
Q0, Q1, QM = 0.2, 0.3, 0.25          # the curve's q range and its user point
STEP = {"dx": 1e-5}                  # the central differences' step of the reference


def vdp_friction(p: float, q: float, h: float | None = None) -> dmi.Solver:
    """u = (x, x'): u' + A(u) + f(t, u) ∋ 0, f = (-x', (x^2 - q) x' + x - p sin(W t)),
    A = (0, AL sigma(x'))."""
    s = dmi.Solver(2, T / 400 if h is None else h, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - q) * u[1] + u[0] - p * math.sin(W * t)]))
    s.set_friction([0.0, AL])
    return s


# ---- the independent event-driven integration -------------------------------------------------
def flow(p: float, q: float, x0: np.ndarray, t_end: float) -> tuple[np.ndarray, list]:
    """The state at t_end from x0 = (x, x') at t = 0 (x' != 0), and the reversals' times:
    orbit_models.reversal_flow, every zero of x' a reversal (the net force there beyond AL,
    asserted)."""
    def accel(t: float, x: float, v: float) -> float:
        return -(x ** 2 - q) * v + (-x + p * math.sin(W * t))
    x, seen = orbit_models.reversal_flow(accel, AL, x0, t_end)
    return x, [t for t, _ in seen]


def orbit(p: float, q: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, M): the T-orbit's point at t = 0 near x by Newton, and its monodromy matrix (the
    period map's Jacobian by central differences)."""
    return orbit_models.map_fixed_point(lambda z: flow(p, q, z, T)[0], x, STEP["dx"])


@lru_cache(maxsize=None)
def near(q: float, p: float) -> tuple[float, ...]:
    """The T-orbit's point at t = 0 at (p, q), from the settled one at (1, q) (stable there:
    its multipliers' modulus about 0.74)."""
    x = flow(1.0, q, np.array([-1.0, 0.5]), 40 * T)[0]
    x = orbit(1.0, q, x)[0]
    return tuple(orbit(p, q, x)[0])


@lru_cache(maxsize=None)
def torus(q: float, guess: float) -> tuple[float, float, tuple[float, ...], tuple[complex, ...]]:
    """(p, theta, the orbit's point at t = 0, the multipliers) where the T-orbit's complex pair
    has modulus 1, p within 0.003 of guess (the curve's p rounded: a bracket that holds it),
    at q."""
    last = {"x": np.array(near(q, guess))}

    def g(p: float) -> float:
        x, M = orbit(p, q, last["x"])
        last["x"] = x
        mu = np.linalg.eigvals(M)
        assert abs(mu[0].imag) > 0.1, mu                 # a complex pair: |mu|^2 = det M
        return math.sqrt(np.linalg.det(M)) - 1.0
    p = brentq(g, guess - 0.003, guess + 0.003, xtol=1e-13)
    x, M = orbit(p, q, last["x"])
    mu = np.linalg.eigvals(M)
    return p, abs(float(np.angle(mu[0]))), tuple(x), tuple(mu)


# ---- the collocated branch and the curve ------------------------------------------------------
@pytest.fixture(scope="module")
def branch() -> da.Branch:
    scheme = da.periodic_orbit(lambda p, h=None: vdp_friction(p, Q0, h), 0.85, T, [-1.0, 0.0],
                               multipliers=2)
    return da.continue_orbit(da.collocate(scheme, multipliers=4, intervals=20), 0.7,
                             step=0.05, multipliers=4)


@pytest.fixture(scope="module")
def curve(branch) -> da.Curve:
    (ev,) = [e for e in branch.events if e.kind == "torus"]
    return da.continue_curve(ev, vdp_friction, Q0, Q1, branch=branch, step=0.05, at=(QM,))


def test_the_reference_reverses_twice_and_is_accurate():
    """Two reversals a period and no stick at the curve's end; the torus' p moves by less than
    1e-10 and theta by less than 5e-10 with a tenfold smaller differences' step."""
    p, th, x, _ = torus(Q1, 0.965)
    assert len(flow(p, Q1, np.array(x), T)[1]) == 2
    STEP["dx"] = 1e-6
    try:
        p2, th2, _, _ = torus.__wrapped__(Q1, 0.965)
    finally:
        STEP["dx"] = 1e-5
    assert abs(p2 - p) < 1e-10 and abs(th2 - th) < 5e-10, (p2 - p, th2 - th)


def test_the_branch_reports_the_torus(branch):
    """The branch's torus event is the reference's torus at q0 (to 1e-8: the event is located
    on the branch's own tolerance)."""
    (ev,) = [e for e in branch.events if e.kind == "torus"]
    assert abs(ev.p - torus(Q0, round(ev.p, 3))[0]) < 1e-8


def twisted(branch) -> tuple[SwitchTwisted, Layout, Terms, np.ndarray, np.ndarray]:
    """A_mu of the branch's orbit nearest its torus event, and the orbit's multipliers."""
    (ev,) = [e for e in branch.events if e.kind == "torus"]
    o = min(branch.points, key=lambda pt: abs(pt.p - ev.p))
    lay = Layout(o.degree, 2, o.signature, o.fractions, False, o.period, tuple(o.carried))
    x = np.concatenate([o.nodes.ravel(), o.switches])
    terms = Terms(vdp_friction(o.p, Q0))
    return SwitchTwisted(lay, terms, x), lay, terms, x, floquet.multipliers(lay, terms, x, 2)


def test_twisted_matrix_at_the_complex_multipliers(branch):
    """A_mu is singular exactly at the orbit's complex pair (its smallest singular value
    rounding), not at mu of the same modulus turned by 0.1; d A_mu / d theta against central
    differences in theta."""
    tw, _, _, _, mu = twisted(branch)
    assert np.all(np.abs(mu.imag) > 0.1), mu
    for z in mu:
        s = sl.svdvals(tw.matrix(complex(z)).toarray())
        assert s[-1] < 1e-12 * s[0] and s[-2] > 1e-4 * s[0], (z, s[-2:], s[0])
        s = sl.svdvals(tw.matrix(complex(z * np.exp(0.1j))).toarray())
        assert s[-1] > 1e-6 * s[0], (z, s[-1], s[0])
    th, d = 2.0, 1e-6
    ref = (tw.matrix(np.exp(1j * (th + d))) - tw.matrix(np.exp(1j * (th - d)))) / (2 * d)
    err = abs(tw.dmatrix(np.exp(1j * th)) - ref).max()
    assert err < 1e-7 * abs(ref).max(), err


def test_gradient_at_a_complex_mu_against_differences(branch):
    """w' (d A_mu / d x) v at mu = e^(2i) over node values and switching times against central
    differences of A_mu assembled again (3e-4 relative, as the period doubling's test: the
    switching-time columns are differences themselves)."""
    tw, lay, terms, x, _ = twisted(branch)
    mu = complex(np.exp(2j))
    rng = np.random.default_rng(11)
    N = tw.matrix(mu).shape[0]
    v, w = rng.standard_normal((2, N)) + 1j * rng.standard_normal((2, N))
    row = tw.x_row(v, w, mu)
    for j in [0, 1, 37, lay.rows, 2 * lay.rows - 1, x.size - 2, x.size - 1]:
        d = 1e-5 if j < 2 * lay.rows else 1e-6
        up, dn = x.copy(), x.copy()
        up[j] += d
        dn[j] -= d
        ref = (w @ (SwitchTwisted(lay, terms, up).matrix(mu) @ v)
               - w @ (SwitchTwisted(lay, terms, dn).matrix(mu) @ v)) / (2 * d)
        assert abs(row[j] - ref) < 3e-4 * max(1.0, abs(ref)), (j, row[j], ref)


def test_torus_curve_of_orbits_with_switches(curve):
    """The curve reaches q_end; at q0, the user point and q_end its p is the reference's torus
    to 1e-9 (measured 1e-10) and theta the argument of the reference's pair to 1e-9 (measured
    1.5e-10); its orbit reverses twice (two switching times, at the reference's reversals to
    1e-8), its multipliers are the reference's."""
    assert curve.kind == "torus" and curve.status == f"reached q_end = {Q1}", curve.status
    pts = curve.points
    assert all(isinstance(pt, TorusCurvePoint) for pt in pts)
    user = [e for e in curve.events if e.kind == "user"]
    assert len(user) == 1 and pts[user[0].index].q == QM
    assert pts[0].q == Q0 and pts[-1].q == Q1
    for pt in (pts[0], pts[user[0].index], pts[-1]):
        p, th, x, mu_ref = torus(pt.q, round(pt.p, 3))   # one bracket: the cache's key
        assert abs(pt.p - p) < 1e-9, (pt.q, pt.p, p)
        assert abs(pt.theta - th) < 1e-9, (pt.q, pt.theta, th)
        assert pt.p_error is not None and pt.p_error < 1e-8
        assert pt.theta_error is not None and pt.theta_error < 1e-8
        reversals = flow(p, pt.q, np.array(x), T)[1]
        assert np.allclose(np.sort(pt.orbit.switches), reversals, atol=1e-8, rtol=0), (
            pt.orbit.switches, reversals)
        mu = np.asarray(pt.orbit.multipliers)
        for z in mu_ref:
            assert np.min(np.abs(mu - z)) < 1e-8, (mu, z)
        assert pt.stable is True            # no other multiplier than the pair (n = 2, forced)
