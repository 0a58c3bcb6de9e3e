# The period-doubling curve of collocated orbits with switches continued in (p, q)
# (continue_flip_curve on an orbit whose switching times are unknowns): the forced Duffing
# oscillator in a well with dry friction,
#     w'' + D w' - w + w^3 + q sigma(w') ∋ p cos(W t),
# whose T-orbit reverses its velocity twice a period (slip +, slip -) and period-doubles near
# p = 0.287 at q = 0.02; its doubling's curve in (p, q) = (forcing, friction).  Against an
# event-driven integration in the tests' models (orbit_models.reversal_flow): DOP853 (rtol
# 1e-13) between the velocity's zeros, located by its event finder (a reversal where the net
# force exceeds q; a stick, where it does not, held exactly: w' = 0 until |net force| reaches q,
# found by Brent's method), the period map's Jacobian by central differences, the T-orbit by
# Newton, the flip (the multiplier -1) in p by Brent's method at three q.  The reference's own
# accuracy: its flip p moves by less than 1e-9 when the differences' step changes tenfold.
# Also the twisted matrix A_mu of the orbit with switches, singular at the collocated orbit's
# multipliers (floquet) and g's gradient in x against differences (the torus curve of an orbit
# with switches: test_plane_torus_switches.py).  The same two checks on an orbit with stick
# phases (q = 0.2: slip +, stuck, slip -, stuck; its switching times the event-driven
# reference's), without and with a memory 0.3 int_0^7 e^(-s) w(t - s) ds reaching two periods
# back (the past read as mu^-1 and mu^-2 times the period, the saltation's slope u*' in it).  About 110 s on a loaded machine.
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
from dmi.analysis.core.blas import _one_blas_thread
from dmi.analysis.collocation.system import Layout, Terms, node_times
from dmi.analysis.plane.orbit_curves import FlipCurvePoint, SwitchTwisted, continue_flip_curve

from models import orbit_models

D, W = 0.3, 1.2
T = 2 * math.pi / W
Q0, Q1, QM = 0.02, 0.03, 0.025       # the curve's q range and its user point
STEP = {"dx": 1e-5}                  # the central differences' step of the reference


def friction2(p: float, q: float, h: float | None = None) -> dmi.Solver:
    """u = (w, w'): u' + A(u) + f(t, u) ∋ 0, f = (-w', D w' - w + w^3 - p cos(W t)),
    A = (0, q sigma(w'))."""
    s = dmi.Solver(2, T / 400 if h is None else h, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], D * u[1] - u[0] + u[0] ** 3 - p * math.cos(W * t)]))
    s.set_friction([0.0, q])
    return s


# ---- the independent event-driven integration -------------------------------------------------
def flow(p: float, q: float, x0: np.ndarray, t_end: float) -> tuple[np.ndarray, list]:
    """The state at t_end from x0 = (w, w') at t = 0 (w' != 0), and the transitions (t, kind):
    orbit_models.reversal_flow with sticks."""
    def accel(t: float, w: float, v: float) -> float:
        return -D * v + (w - w ** 3 + p * math.cos(W * t))
    return orbit_models.reversal_flow(accel, q, x0, t_end, sticks=True)


def orbit(p: float, q: float, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, M): the T-orbit's point at t = 0 near x by Newton, and its monodromy matrix (the
    period map's Jacobian by central differences)."""
    return orbit_models.map_fixed_point(lambda z: flow(p, q, z, T)[0], x, STEP["dx"])


@lru_cache(maxsize=None)
def near(q: float) -> tuple[float, ...]:
    """The T-orbit's point at t = 0 at (0.28, q), continued from the settled one at (0.27, Q0)."""
    x = flow(0.27, Q0, np.array([0.57, 0.41]), 20 * T)[0]
    x = orbit(0.27, Q0, x)[0]
    for a, b in zip(np.linspace(0.27, 0.28, 3), np.linspace(Q0, q, 3)):
        x = orbit(float(a), float(b), x)[0]
    return tuple(x)


@lru_cache(maxsize=None)
def flip(q: float, guess: float) -> float:
    """The p within 0.003 of guess where the T-orbit's multiplier crosses -1, at q."""
    def g(p: float) -> float:
        mu = np.linalg.eigvals(orbit(p, q, np.array(near(q)))[1])
        assert np.all(np.abs(mu.imag) < 1e-12)
        return float(np.min(mu.real)) + 1.0
    return brentq(g, guess - 0.003, guess + 0.003, xtol=1e-13)


# ---- the collocated branch and the curve ------------------------------------------------------
@pytest.fixture(scope="module")
def branch() -> da.Branch:
    scheme = da.periodic_orbit(lambda p, h=None: friction2(p, Q0, h), 0.28, T, [0.57, 0.41],
                               multipliers=2)
    return da.continue_orbit(da.collocate(scheme, multipliers=4, intervals=20), 0.295,
                             step=0.005, multipliers=4)


@pytest.fixture(scope="module")
def curve(branch) -> da.Curve:
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    return continue_flip_curve(pd, friction2, Q0, Q1, branch=branch, step=0.005, at=(QM,),
                               max_points=12)


def test_the_reference_reverses_twice_and_is_accurate():
    """Two reversals a period and no stick at the curve's ends; the flip's p moves by less
    than 1e-9 with a tenfold smaller differences' step."""
    p = flip(Q1, 0.2984)
    x = orbit(p, Q1, np.array(near(Q1)))[0]
    assert [k for _, k in flow(p, Q1, x, T)[1]] == ["reversal", "reversal"]
    STEP["dx"] = 1e-6
    try:
        other = flip.__wrapped__(Q1, 0.2984)
    finally:
        STEP["dx"] = 1e-5
    assert abs(other - p) < 1e-9, (other, p)


def test_twisted_matrix_singular_at_the_multipliers(branch):
    """A_mu of an orbit with switches (the period's nodes and switching times, the past read
    as mu^-k times the period with its saltation) is singular exactly at the collocated orbit's
    multipliers: its smallest singular value there is rounding, another mu's is not."""
    o = branch.points[-1]
    lay = Layout(o.degree, 2, o.signature, o.fractions, False, o.period, tuple(o.carried))
    x = np.concatenate([o.nodes.ravel(), o.switches])
    terms = Terms(friction2(o.p, Q0))
    mu = floquet.multipliers(lay, terms, x, 2)
    tw = SwitchTwisted(lay, terms, x)
    with _one_blas_thread():
        for z in mu.real:
            s = sl.svdvals(tw.matrix(float(z)).toarray())
            assert s[-1] < 1e-12 * s[0] and s[-2] > 1e-4 * s[0], (z, s[-2:], s[0])
        s = sl.svdvals(tw.matrix(-1.0).toarray())   # the orbit past the flip: -1 not a multiplier
    assert s[-1] > 1e-6 * s[0]


def test_gradient_of_the_test_function_against_differences(branch):
    """w' (d A_mu / d x) v over node values and switching times against central differences of
    A_mu assembled again (3e-4 relative: the differences' own noise, differences of the
    Jacobian's switching-time columns that are differences themselves, is about 1e-4)."""
    o = branch.points[-1]
    lay = Layout(o.degree, 2, o.signature, o.fractions, False, o.period, tuple(o.carried))
    x = np.concatenate([o.nodes.ravel(), o.switches])
    terms = Terms(friction2(o.p, Q0))
    tw = SwitchTwisted(lay, terms, x)
    rng = np.random.default_rng(7)
    v, w = rng.standard_normal((2, tw.matrix(-1.0).shape[0]))
    row = tw.x_row(v, w, -1.0)
    for j in [0, 1, 37, lay.rows, 2 * lay.rows - 1, x.size - 2, x.size - 1]:
        d = 1e-5 if j < 2 * lay.rows else 1e-6
        up, dn = x.copy(), x.copy()
        up[j] += d
        dn[j] -= d
        ref = (w @ (SwitchTwisted(lay, terms, up).matrix(-1.0) @ v)
               - w @ (SwitchTwisted(lay, terms, dn).matrix(-1.0) @ v)) / (2 * d)
        assert abs(row[j] - ref) < 3e-4 * max(1.0, abs(ref)), (j, row[j], ref)


def test_flip_curve_of_orbits_with_switches(curve):
    """The curve reaches q_end; at q0, the user point and q_end its p is the reference's flip
    to 1e-7, its orbit reverses twice (two switching times), its multiplier -1."""
    assert curve.kind == "period-doubling" and "q_end" in curve.status, curve.status
    pts = curve.points
    assert all(isinstance(pt, FlipCurvePoint) for pt in pts)
    user = [e for e in curve.events if e.kind == "user"]
    assert len(user) == 1 and pts[user[0].index].q == QM
    assert pts[0].q == Q0 and pts[-1].q == Q1
    for pt in (pts[0], pts[user[0].index], pts[-1]):
        ref = flip(pt.q, pt.p)
        assert abs(pt.p - ref) < 1e-7, (pt.q, pt.p, ref)
        assert pt.p_error is not None and pt.p_error < 1e-8
        assert pt.orbit.switches.size == 2
        mu = np.asarray(pt.orbit.multipliers)
        assert np.min(np.abs(mu + 1)) < 1e-8, mu
        other = np.linalg.eigvals(orbit(pt.p, pt.q, np.array(near(pt.q)))[1])
        rest = mu[np.argsort(np.abs(mu + 1))[1]]
        assert abs(rest - other[np.argmax(np.abs(other + 1))]) < 1e-6, (rest, other)
        assert pt.stable is True


# ---- an orbit with stick phases, without and with a memory ------------------------------------
PS, QS = 0.28, 0.2                   # the orbit sticks twice a period (w' = 0 while |force| <= q)
G, TAU = 0.3, 7.0                    # the memory g e^(-s) w(t - s) on [0, 7]: two periods back


def sticky(p: float, q: float, g: float, h: float | None = None) -> dmi.Solver:
    """friction2 with the memory g int_0^TAU e^(-s) w(t - s) ds on w'' (g = 0: none)."""
    h = T / 400 if h is None else h
    s = dmi.Solver(2, TAU if g else h, h=h)
    s.set_rhs(lambda t, u: np.array([-u[1], D * u[1] - u[0] + u[0] ** 3 - p * math.cos(W * t)]))
    s.set_friction([0.0, q])
    if g:
        s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [g, 0.0]]])
    return s


@pytest.fixture(scope="module", params=[0.0, G], ids=["no memory", "memory"])
def stuck(request) -> tuple:
    """(orbit, lay, terms, x) of the collocated stick-slip T-orbit at (PS, QS) with memory g."""
    g = request.param
    scheme = da.periodic_orbit(lambda p, h=None: sticky(p, QS, g, h), PS, T, [0.9694, 0.1471],
                               multipliers=2)
    o = da.collocate(scheme, multipliers=6, intervals=20)
    lay = Layout(o.degree, 2, o.signature, o.fractions, False, o.period, tuple(o.carried))
    return o, lay, Terms(sticky(PS, QS, g)), np.concatenate([o.nodes.ravel(), o.switches])


def test_the_orbit_sticks_twice(stuck):
    """Slip +, stuck, slip -, stuck; without memory its switching times are the event-driven
    reference's (started from the collocated orbit's state at 0) to 1e-8."""
    o, lay, terms, _ = stuck
    assert o.signature.modes[:, 1].tolist() == [1, 2, -1, 2]
    if terms.has_kernel:
        return
    seen = flow(PS, QS, o.nodes[0], T)[1]
    assert [k for _, k in seen] == ["stick", "stick end", "stick", "stick end"]
    assert np.max(np.abs(np.array([t for t, _ in seen]) - o.switches)) < 1e-8, (seen, o.switches)


def test_twisted_matrix_with_sticks_singular_at_the_multipliers(stuck):
    """A_mu of the stick-slip orbit (with a memory: the past two periods back, mu^-1 and
    mu^-2, complex pairs among the multipliers) is singular at each multiplier the collocation
    reports but its zeros (a held component's; mu^-k is not defined there): the smallest
    singular value rounding, 1e-12 of the largest, the next beyond 1e-8; at mu = -1, 0.9 and
    0.6i (no multipliers) the smallest is beyond 1e-8."""
    o, lay, terms, x = stuck
    tw = SwitchTwisted(lay, terms, x)
    mu = np.asarray(o.multipliers)
    live = mu[np.abs(mu) > 1e-3]
    assert live.size >= (3 if terms.has_kernel else 1), mu
    with _one_blas_thread():      # a loaded machine's spinning BLAS threads: 100 times slower
        for z in live:
            s = sl.svdvals(tw.matrix(complex(z) if z.imag else float(z.real)).toarray())
            assert s[-1] < 1e-12 * s[0] and s[-2] > 1e-8 * s[0], (z, s[-2:], s[0])
        for z in (-1.0, 0.9, 0.6j):
            s = sl.svdvals(tw.matrix(z).toarray())
            assert s[-1] > 1e-8 * s[0], (z, s[-1], s[0])


def _wAv(lay: Layout, terms: Terms, x: np.ndarray, v: np.ndarray, w: np.ndarray) -> float:
    """w' A_(-1) v of the orbit x and its history part w' Jhist Phi v."""
    tw = SwitchTwisted(lay, terms, x)
    return float(w @ (tw.matrix(-1.0) @ v)), float(w @ (tw.Jhist @ (tw._phi(-1.0) @ v)))


def test_gradient_with_sticks_against_differences(stuck):
    """w' (d A_mu / d x) v at mu = -1 on the stick-slip orbit against central differences of
    A_mu assembled again (steps 1e-5 on node values, 1e-6 on switching times): every switching
    time, the node values of the node rows at and after each switch (the stick endings' rows,
    the switching-time columns' change), random directions over each piece's node values and
    over all of x; with a memory also the history part alone (the saltation's slope u*'
    changed with the node values) at its four largest entries.  To 2e-5 relative (node values;
    the differences' noise, from a tenfold step, is below 2e-5) and 3e-4 (switching times,
    where both sides are differences of differences)."""
    o, lay, terms, x = stuck
    tw = SwitchTwisted(lay, terms, x)
    rng = np.random.default_rng(11)
    v, w = rng.standard_normal((2, tw.matrix(-1.0).shape[0]))
    row = tw.x_row(v, w, -1.0).real
    first = lay.rows * 2
    times = node_times(lay, o.switches, T)
    idx = list(range(first, x.size))
    for b in o.switches:
        r = int(np.argmin(np.abs(times - b)))
        idx += [2 * ((r + k) % lay.rows) + c for k in (0, 1) for c in (0, 1)]
    dirs = [np.eye(x.size)[j] for j in idx]
    piece = np.searchsorted(np.append(o.switches, T), times[:lay.rows], side="right")
    for k in range(lay.S + 1):
        d = np.zeros(x.size)
        d[:first] = np.repeat(piece == k, 2) * rng.standard_normal(first)
        dirs.append(d)
    dirs.append(rng.standard_normal(x.size) * np.r_[np.ones(first), 0.1 * np.ones(lay.S)])
    for d in dirs:
        step = 1e-6 if np.all(d[:first] == 0) else 1e-5
        ref = (_wAv(lay, terms, x + step * d, v, w)[0]
               - _wAv(lay, terms, x - step * d, v, w)[0]) / (2 * step)
        got = float(row @ d)
        tol = 2e-5 if step == 1e-5 else 3e-4
        assert abs(got - ref) < tol * max(1.0, abs(ref)), (np.flatnonzero(d)[:3], got, ref)
    if not terms.has_kernel:
        return
    slope = tw._slope_part(v, w, -1.0).real.ravel()
    for j in np.argsort(-np.abs(slope))[:4]:
        up, dn = x.copy(), x.copy()
        up[j] += 1e-5
        dn[j] -= 1e-5
        ref = (_wAv(lay, terms, up, v, w)[1] - _wAv(lay, terms, dn, v, w)[1]) / 2e-5
        assert abs(slope[j] - ref) < 2e-5 * max(1.0, abs(ref)) and abs(ref) > 1e-3, \
            (j, slope[j], ref)
