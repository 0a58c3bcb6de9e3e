# period_doubled_orbit on a collocated branch of orbits with switches: the forced Duffing
# oscillator in a well with dry friction, w'' + d w' - w + w^3 + alpha sigma(w') ∋ p cos(om t),
# whose orbit reverses its velocity twice a period (slip +, slip -) and period-doubles near
# p = 0.287.  Against an event-driven integration written here: DOP853 (rtol 1e-13) between the
# velocity's zeros, located by its event finder (a reversal where the net force exceeds alpha; a
# stick is asserted not to happen), the period map's Jacobian by central differences of that
# integration through the reversals, the T-orbit by Newton, the flip where the multiplier crosses
# -1 by Brent's method, the 2T-orbit by Newton on the map laid twice from a kick along the flip's
# eigenvector, its amplitudes from the dense output (the extrema of w at the reversals, those of
# w' where w'' = 0); the doubled orbit's branch.  About a minute.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import dmi
from dmi import analysis as da

D, W, ALPHA = 0.3, 1.2, 0.02
T = 2 * math.pi / W
M = 400
DX = 1e-6                                   # the central differences' step


def friction_duffing(p: float, h: float | None = None) -> dmi.Solver:
    """u = (w, w'): u' + A(u) + f(t, u) ∋ 0, f = (-w', d w' - w + w^3 - p cos(om t)),
    A = (0, alpha sigma(w'))."""
    s = dmi.Solver(2, T / M if h is None else h, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], D * u[1] - u[0] + u[0] ** 3 - p * math.cos(W * t)]))
    s.set_friction([0.0, ALPHA])
    return s


# ---- the independent event-driven integration -------------------------------------------------
def flow(p: float, x0: np.ndarray, t_end: float, dense: bool = False):
    """The state at t_end from x0 = (w, w') at t = 0 (w' != 0), through the reversals; with
    ``dense`` also the pieces' dense outputs and the reversals' times and states."""
    t, x = 0.0, np.array(x0, dtype=float)
    mode = 1.0 if x[1] > 0 else -1.0
    pieces, reversals = [], []
    while t < t_end:
        def rhs(s, y, mode=mode):
            return [y[1], -D * y[1] + y[0] - y[0] ** 3 + p * math.cos(W * s) - ALPHA * mode]

        def zero(s, y):
            return y[1]
        zero.terminal, zero.direction = True, -mode
        sol = solve_ivp(rhs, (t, t_end), x, method="DOP853", rtol=1e-13, atol=1e-14,
                        events=zero, dense_output=dense)
        if dense:
            pieces.append((t, float(sol.t[-1]), sol.sol, mode))
        t, x = float(sol.t[-1]), sol.y[:, -1].copy()
        if sol.status == 1:                 # w' = 0: the net force decides the new slip
            x[1] = 0.0
            F = x[0] - x[0] ** 3 + p * math.cos(W * t)
            assert abs(F) > ALPHA, f"a stick at t = {t} (p = {p}): not this test's orbit"
            mode = 1.0 if F > 0 else -1.0
            reversals.append((t, x.copy()))
    return (x, pieces, reversals) if dense else x


def jacobian(p: float, x: np.ndarray, periods: int) -> np.ndarray:
    """D_x of the map over ``periods`` periods, by central differences."""
    cols = []
    for i in range(2):
        e = np.zeros(2)
        e[i] = DX
        cols.append((flow(p, x + e, periods * T) - flow(p, x - e, periods * T)) / (2 * DX))
    return np.array(cols).T


def orbit(p: float, x: np.ndarray, periods: int = 1) -> tuple[np.ndarray, np.ndarray]:
    """(x, J): the point at t = 0 of the (periods T)-periodic orbit near x, by Newton, and the
    monodromy matrix there."""
    for _ in range(20):
        J = jacobian(p, x, periods)
        dx = np.linalg.solve(J - np.eye(2), -(flow(p, x, periods * T) - x))
        x = x + dx
        if np.max(np.abs(dx)) < 1e-12:
            return x, jacobian(p, x, periods)
    raise AssertionError(f"Newton on the period map did not converge at p = {p}")


@lru_cache(maxsize=None)
def t_orbit(p: float) -> np.ndarray:
    """The T-orbit's point at t = 0, continued from p = 0.27."""
    x = flow(0.27, np.array([0.57, 0.41]), 20 * T)      # stable at p = 0.27: settled
    for q in np.linspace(0.27, p, 5):
        x = orbit(float(q), x)[0]
    return x


@lru_cache(maxsize=None)
def flip() -> float:
    def g(p: float) -> float:
        mu = np.linalg.eigvals(orbit(p, t_orbit(0.28))[1])
        assert np.all(np.abs(mu.imag) < 1e-12)
        return float(np.min(mu.real)) + 1.0
    return brentq(g, 0.28, 0.29, xtol=1e-12)


def amplitudes(p: float, x: np.ndarray, periods: int) -> np.ndarray:
    """(max - min) / 2 of w and w' over the orbit through x at t = 0."""
    _, pieces, reversals = flow(p, x, periods * T, dense=True)
    ws = [r[1][0] for r in reversals]       # w's extrema lie at the reversals (w' = 0)
    vs = []
    for t0, t1, sol, mode in pieces:        # w'' = 0 between them: the extrema of w'
        def acc(s, mode=mode):
            w, v = sol(s)
            return -D * v + w - w ** 3 + p * math.cos(W * s) - ALPHA * mode
        grid = np.linspace(t0, t1, 200)
        a = np.array([acc(s) for s in grid])
        for k in np.flatnonzero(np.sign(a[:-1]) * np.sign(a[1:]) < 0):
            vs.append(float(sol(brentq(acc, grid[k], grid[k + 1], xtol=1e-14))[1]))
    vs.append(0.0)
    return np.array([0.5 * (max(ws) - min(ws)), 0.5 * (max(vs) - min(vs))])


def doubled(p: float) -> np.ndarray:
    """The 2T-orbit's point at t = 0 past the flip: Newton on the map laid twice from the T-orbit
    kicked along the eigenvector of its multiplier below -1."""
    x, J = orbit(p, t_orbit(0.28))
    mu, V = np.linalg.eig(J)
    v = V[:, int(np.argmin(mu.real))].real
    x2 = orbit(p, x + 0.05 * v / np.max(np.abs(v)), periods=2)[0]
    assert np.max(np.abs(flow(p, x2, T) - x2)) > 1e-3          # not the T-orbit
    return x2


# ---- the collocated branch and its doubling ---------------------------------------------------
@pytest.fixture(scope="module")
def branch() -> da.Branch:
    """The collocated branch from the scheme's orbit at p = 0.27 through the flip."""
    scheme = da.periodic_orbit(friction_duffing, 0.27, T, [0.57, 0.41], multipliers=2)
    return da.continue_orbit(da.collocate(scheme, multipliers=4), 0.295, step=0.01,
                             multipliers=4)


def test_the_reference_reverses_and_is_periodic():
    """The reference's own checks: two reversals a period, the map's Jacobian by central
    differences agrees with another step's (5e-7), the T-orbit returns to 1e-12."""
    p = 0.285
    x = t_orbit(p)
    assert np.max(np.abs(flow(p, x, T) - x)) < 1e-12
    assert len(flow(p, x, T, dense=True)[2]) == 2
    J = jacobian(p, x, 1)
    global DX
    old, DX = DX, 1e-5
    try:
        assert np.max(np.abs(jacobian(p, x, 1) - J)) < 5e-7
    finally:
        DX = old


def test_flip_on_the_collocated_stick_slip_branch(branch):
    pds = [e for e in branch.events if e.kind == "period-doubling"]
    assert len(pds) == 1, (branch.events, branch.status)
    q = branch.points[pds[0].index]
    assert q.switches.size == 2                       # the orbit reverses twice a period
    assert abs(pds[0].p - flip()) < 1e-6, (pds[0].p, flip())


def test_flip_located_from_another_mesh():
    """The branch from the orbit on 154 intervals (intervals=77): the flip is located there too.
    Brent's method evaluated the test function at the bracket's ends, whose values it had; the
    end's point re-solved on the next step's mesh broke its signature (u_1 changing sign on a slip
    + piece just before its reversal) and the flip was lost ("could not locate its zero ... no
    event reported"; so on 67, 108, 154 and 190 intervals, found on 202 only)."""
    scheme = da.periodic_orbit(friction_duffing, 0.27, T, [0.57, 0.41], multipliers=2)
    b = da.continue_orbit(da.collocate(scheme, intervals=77, multipliers=4), 0.295, step=0.01,
                          multipliers=4)
    pds = [e for e in b.events if e.kind == "period-doubling"]
    assert len(pds) == 1, (b.events, b.status)
    assert abs(pds[0].p - flip()) < 1e-6, (pds[0].p, flip())


@pytest.fixture(scope="module")
def doubled_orbit(branch) -> da.EquationOrbit:
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    return da.period_doubled_orbit(branch, pd, multipliers=4)


def test_doubled_orbit_with_reversals(doubled_orbit):
    o2 = doubled_orbit
    assert o2.of == "equation" and o2.p > flip()
    assert o2.period == 2 * T and o2.switches.size == 4
    x2 = doubled(o2.p)
    ref = amplitudes(o2.p, x2, 2)
    assert np.max(np.abs(o2.amplitude - ref)) < 1e-8, (o2.amplitude, ref)
    # the orbit itself: its state at t = 0 is the reference's 2T-orbit's, or that one shifted by T
    u0 = o2.u_at(np.array([0.0]))[0]
    assert min(np.max(np.abs(u0 - x2)), np.max(np.abs(u0 - flow(o2.p, x2, T)))) < 1e-8
    # distinct from the T-orbit, whose amplitudes at that p are others
    assert np.max(np.abs(o2.amplitude - amplitudes(o2.p, t_orbit(o2.p), 1))) > 1e-3


def test_doubled_stick_slip_branch(doubled_orbit):
    """continue_orbit continues the doubled orbit: period 2T, four reversals, its amplitudes at
    the branch's end against the reference's 2T-orbit there."""
    o2 = doubled_orbit
    b2 = da.continue_orbit(o2, o2.p + 0.003, step=0.003, multipliers=4)
    assert b2.points[-1].p == pytest.approx(o2.p + 0.003, abs=1e-12), b2.status
    q = b2.points[-1]
    assert q.period == 2 * T and q.switches.size == 4
    ref = amplitudes(q.p, doubled(q.p), 2)
    assert np.max(np.abs(q.amplitude - ref)) < 1e-8, (q.amplitude, ref)


def test_stick_slip_doubling_back_to_the_t_orbit_is_refused(branch):
    """No kick: Newton stays on the T-orbit laid twice, which is refused."""
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    with pytest.raises(da.ShootingError, match="returned to the T-orbit"):
        da.period_doubled_orbit(branch, pd, amplitudes=(0.0,), multipliers=4)
