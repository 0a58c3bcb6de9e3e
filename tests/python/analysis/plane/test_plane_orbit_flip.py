# The period-doubling and torus curves of collocated orbits continued in (p, q)
# (continue_flip_curve, continue_torus_curve, and continue_curve's dispatch to them), against
# Floquet multipliers computed in the test by scipy's integrator (DOP853 on the orbit and its
# variational equation, the periodic orbit found by shooting):
# - a damped Mathieu equation with a small cubic term, forced so that its orbit moves:
#     x'' + C x' + (d + e cos t) x + GAM x^3 = FM cos t,
#   its period-doubling curve in (d, e): at each point the monodromy has the multiplier -1, the
#   doubling's d solved in the test at the point's e, the other multiplier -exp(-2 pi C)
#   (Liouville: the product of the two is exp(-C T)); and the same with a memory,
#   + K int_0^TAU e^-s x(t - s) ds, TAU = 2 T: on a T-periodic orbit, and on a perturbation
#   with v(t + T) = -v(t), x(t - TAU) = x(t), so the memory is z' = (1 - e^-TAU) x - z there
#   exactly, and the test's integrator runs that ODE in (x, x', z) (its multiplier -1 is the
#   equation's); its one-parameter branch's doubling, where a complex pair meets on the negative
#   axis inside the circle and one of the two crosses -1, reported where the integrator has it;
# - the Roessler system x' = -y - z, y' = x + 0.2 y, z' = b + z (x - c) (autonomous: the period an
#   unknown): its period-doubling curve in (c, b), each point against the doubling solved in the
#   test (x0, T, c with x(T) = x0, a phase condition and det(M + I) = 0);
# - a forced van der Pol oscillator x'' + (x^2 - a) x' + k x = F cos(1.5 t): its torus curve in
#   (F, a) at k = 1: at each point the pair e^(+-i theta) (det M = 1, its argument against
#   theta), the bifurcation's F solved in the test at the point's a; and in (F, k) at a = 0.2,
#   where theta grows to pi (about 2 pi sqrt(k) / 1.5 mod 2 pi: k near 0.56) and the curve ends
#   at the 1:2 resonance, the integrator's pair there within THETA_END of -1.
# Also the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so
from scipy.integrate import solve_ivp

import dmi

from dmi import analysis as da
from dmi.analysis.continuation.branch import Event
from dmi.analysis.plane.orbit_curves import (THETA_END, FlipCurvePoint, TorusCurvePoint,
                                             continue_flip_curve, continue_torus_curve)

C, FM, GAM = 0.1, 0.2, 0.05       # the Mathieu equation's damping, forcing and cubic term
K, TAU = 0.05, 4 * math.pi       # its memory's strength and length (two periods)
MP = 2 * math.pi                  # its period
W = 1.5                           # the van der Pol oscillator's forcing frequency
VP = 2 * math.pi / W


def mathieu2(d: float, e: float, memory: bool = False):
    s = dmi.Solver(2, TAU if memory else 1.0, h=MP / (100 if memory else 400))
    s.set_rhs(lambda t, u: -np.array([u[1], -C * u[1] - (d + e * math.cos(t)) * u[0]
                                      - GAM * u[0] ** 3 + FM * math.cos(t)]))
    if memory:
        s.set_kernel_exp([-1.0], [0.0], [np.array([[0.0, 0.0], [K, 0.0]])])
    return s


def memory2(d: float, e: float):
    return mathieu2(d, e, True)


def rossler2(c: float, b: float, h: float | None = None):
    s = dmi.Solver(3, 1.0, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: -np.array([-u[1] - u[2], u[0] + 0.2 * u[1], b + u[2] * (u[0] - c)]))
    return s


def rossler_rhs(c: float, b: float):
    def rhs(t, y):
        x, yy, z = y[:3]
        A = np.array([[0.0, -1.0, -1.0], [1.0, 0.2, 0.0], [z, 0.0, x - c]])
        return np.concatenate([[-yy - z, x + 0.2 * yy, b + z * (x - c)],
                               (A @ y[3:].reshape(3, 3)).ravel()])
    return rhs, 3


def vdp2(F: float, a: float, k: float = 1.0):
    s = dmi.Solver(2, 1.0, h=VP / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -(u[0] ** 2 - a) * u[1] - k * u[0]
                                      + F * math.cos(W * t)]))
    return s


def vdpk(F: float, k: float):
    return vdp2(F, 0.2, k)


def mathieu_rhs(d: float, e: float, memory: bool):
    """The Mathieu equation and its variational equation in (x, x'[, z]), z' = x - z the memory
    (K z in x'')."""
    k = 3 if memory else 2

    def rhs(t, y):
        x, v = y[0], y[1]
        acc = -C * v - (d + e * math.cos(t)) * x - GAM * x ** 3 + FM * math.cos(t)
        A = np.zeros((k, k))
        A[0, 1], A[1, 0], A[1, 1] = 1.0, -(d + e * math.cos(t)) - 3 * GAM * x * x, -C
        f = [v, acc]
        if memory:
            f = [v, acc - K * y[2], (1 - math.exp(-TAU)) * x - y[2]]
            A[1, 2], A[2, 0], A[2, 2] = -K, 1 - math.exp(-TAU), -1.0
        return np.concatenate([f, (A @ y[k:].reshape(k, k)).ravel()])
    return rhs, k


def vdp_rhs(F: float, a: float, k: float = 1.0):
    def rhs(t, y):
        x, v = y[0], y[1]
        A = np.array([[0.0, 1.0], [-k - 2 * x * v, a - x * x]])
        return np.concatenate([[v, -(x * x - a) * v - k * x + F * math.cos(W * t)],
                               (A @ y[2:].reshape(2, 2)).ravel()])
    return rhs, 2


def monodromy(system, period: float, x0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x(P), M) from x0 by DOP853."""
    rhs, k = system
    s = solve_ivp(rhs, (0, period), np.concatenate([x0, np.eye(k).ravel()]), method="DOP853",
                  rtol=1e-13, atol=1e-13)
    return s.y[:k, -1], s.y[k:, -1].reshape(k, k)


def solved(make_system, period: float, guess: np.ndarray, condition=None
           ) -> tuple[np.ndarray, float]:
    """(x0, p) with x(P) = x0 and condition(M) = 0 (the bifurcation's p at fixed q); without a
    condition, the orbit x0 at the guess's p."""
    k = guess.size - 1

    def eqs(z):
        xe, M = monodromy(make_system(z[-1] if condition else guess[-1]), period, z[:k])
        return np.concatenate([xe - z[:k], [condition(M)] if condition else []])
    z = so.fsolve(eqs, guess if condition else guess[:k], xtol=1e-13)
    assert np.max(np.abs(eqs(z))) < 1e-11
    return z[:k], float(z[-1] if condition else guess[-1])


def start_state(orbit, memory: bool) -> np.ndarray:
    """The orbit's state at t = 0 (with z = int_0^TAU e^-s x(-s) ds for the memory, a guess)."""
    u0 = orbit.u_at(0.0)
    if not memory:
        return u0
    s = np.linspace(0.0, TAU, 2001)
    x = orbit.u_at(np.mod(-s, orbit.period))[:, 0]
    return np.append(u0, np.trapezoid(np.exp(-s) * x, s))


def mathieu_branch(make):
    o = da.periodic_orbit(lambda d: make(d, 0.6), 0.7, MP, np.array([-0.65, 0.0]), steps=400,
                          multipliers=4)
    return da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), 0.3, step=0.02)


@pytest.fixture(scope="module")
def flip():
    b = mathieu_branch(mathieu2)
    (e,) = [e for e in b.events if e.kind == "period-doubling"]
    return b, e, da.continue_curve(e, mathieu2, 0.6, 0.8, branch=b, step=0.05, at=(0.7,))


def check_flip(curve, memory: bool) -> None:
    some = (0, -1) if memory else (0, len(curve.points) // 2, -1)
    for pt in [curve.points[i] for i in some]:
        assert isinstance(pt, FlipCurvePoint) and not pt.orbit.autonomous
        system = lambda d: mathieu_rhs(d, pt.q, memory)   # noqa: E731
        x0, _ = solved(system, MP, np.append(start_state(pt.orbit, memory), pt.p))
        assert np.max(np.abs(x0[:2] - pt.orbit.u_at(0.0))) <= 1e-8
        mu = np.linalg.eigvals(monodromy(system(pt.p), MP, x0)[1])
        assert np.min(np.abs(mu + 1)) <= 1e-8                  # measured 8e-11 (1e-10)
        _, d = solved(system, MP, np.append(x0, pt.p),
                      lambda M: np.linalg.det(M + np.eye(M.shape[0])))
        assert abs(pt.p - d) <= 1e-8 and abs(pt.p - d) <= pt.p_error   # measured 3e-12
        if memory:   # the ODE's other multipliers are not the equation's
            continue
        other = mu[np.argsort(np.abs(mu + 1))[1:]]
        assert np.min(np.abs(pt.orbit.multipliers - other[0])) <= 1e-8   # measured 4e-11
        assert abs(other[0] + math.exp(-C * MP)) <= 1e-9   # Liouville: mu_1 mu_2 = exp(-C T)
        assert pt.stable is True


def test_the_flip_curve_against_the_integrators_multipliers(flip):
    _, _, c = flip
    assert c.kind == "period-doubling"
    assert c.status == "reached q_end = 0.8" and c.points[-1].q == 0.8 and len(c.points) >= 3
    (u,) = [e for e in c.events if e.kind == "user"]
    assert u.q == 0.7 and c.points[u.index].q == 0.7
    check_flip(c, False)


def test_a_flip_curve_with_a_memory():
    # the branch's complex pair meets on the negative axis inside the circle, splits, and one of
    # the two crosses -1: the doubling is reported (its test function changes sign although
    # the point before it has no real negative multiplier) where the integrator has it
    b = mathieu_branch(memory2)
    (e,) = [e for e in b.events if e.kind == "period-doubling"]
    near = b.points[e.index - 1]
    mu = near.multipliers
    assert not np.any((np.abs(mu.imag) <= 1e-8 * np.abs(mu)) & (mu.real < 0))
    system = lambda d: mathieu_rhs(d, 0.6, True)   # noqa: E731
    x0, _ = solved(system, MP, np.append(start_state(near, True), near.p))
    _, d = solved(system, MP, np.append(x0, e.p),
                  lambda M: np.linalg.det(M + np.eye(M.shape[0])))
    assert abs(e.p - d) <= 1e-8                                 # measured 3e-12
    c = da.continue_curve(e, memory2, 0.6, 0.7, branch=b, step=0.05)
    assert c.status == "reached q_end = 0.7"
    check_flip(c, True)


def test_an_autonomous_orbits_flip_curve():
    s = rossler2(2.5, 0.2)
    s.set_history(lambda t: np.array([1.0, 1.0, 0.0]))
    s.init()
    s.advance(20000)
    o = da.periodic_orbit(lambda c, h=None: rossler2(c, 0.2, h), 2.5, None, s,
                          guess_period=6.0, steps=600, multipliers=4)
    b = da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), 3.2, step=0.05)
    (e,) = [e for e in b.events if e.kind == "period-doubling"]
    c = da.continue_curve(e, rossler2, 0.2, 0.3, branch=b, step=0.05)
    assert c.kind == "period-doubling" and c.status == "reached q_end = 0.3"
    for pt in (c.points[0], c.points[len(c.points) // 2], c.points[-1]):
        assert pt.orbit.autonomous
        u0, y0 = pt.orbit.u_at(0.0), float(pt.orbit.u_at(0.0)[1])

        def eqs(z, q=pt.q):
            xe, M = monodromy(rossler_rhs(z[4], q), z[3], z[:3])
            return np.concatenate([xe - z[:3], [z[1] - y0],
                                   [np.linalg.det(M + np.eye(3))]])
        z = so.fsolve(eqs, np.concatenate([u0, [pt.orbit.period, pt.p]]), xtol=1e-13)
        assert np.max(np.abs(eqs(z))) < 1e-11
        assert abs(pt.p - z[4]) <= 1e-9 and abs(pt.p - z[4]) <= pt.p_error   # measured 8e-12
        assert abs(pt.orbit.period - z[3]) <= 1e-9                          # measured 4e-13
        mu = np.linalg.eigvals(monodromy(rossler_rhs(pt.p, pt.q), pt.orbit.period, u0)[1])
        assert np.min(np.abs(mu + 1)) <= 1e-8                                # measured 5e-12
        assert pt.stable is True           # the third multiplier is near 0


@pytest.fixture(scope="module")
def torus():
    o = da.periodic_orbit(lambda F: vdp2(F, 0.2), 1.2, VP, np.array([-1.0, 0.0]), steps=400,
                          multipliers=4)
    b = da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), 0.5, step=0.05)
    (e,) = [e for e in b.events if e.kind == "torus"]
    return b, e, da.continue_curve(e, vdp2, 0.2, 0.4, branch=b, step=0.05)


def test_the_torus_curve_ends_at_the_1_2_resonance(torus):
    b, e, _ = torus
    c = continue_torus_curve(e, vdpk, 1.0, 0.3, branch=b, step=0.1, min_step=0.005)
    assert c.status.startswith("near (p, q) = (") and "1:2 resonance" in c.status
    (r,) = [ev for ev in c.events if ev.kind == "1:2 resonance"]
    last = c.points[-1]
    assert r.index == len(c.points) - 1 and r.q == last.q and 0.5 < last.q < 0.65
    assert np.all(np.diff(c.q) < 0) and np.all(np.diff([pt.theta for pt in c.points]) > 0)
    assert math.pi - THETA_END - 0.01 < last.theta < math.pi
    mu = np.linalg.eigvals(monodromy(vdp_rhs(last.p, 0.2, last.q), VP, last.orbit.u_at(0.0))[1])
    assert np.all(np.abs(np.abs(mu) - 1) <= 1e-8)
    assert np.all(np.abs(np.abs(np.angle(mu)) - last.theta) <= 1e-8)


def test_the_torus_curve_against_the_integrators_multipliers(torus):
    _, _, c = torus
    assert c.kind == "torus" and c.status == "reached q_end = 0.4" and c.points[-1].q == 0.4
    for pt in (c.points[0], c.points[len(c.points) // 2], c.points[-1]):
        assert isinstance(pt, TorusCurvePoint)
        system = lambda F: vdp_rhs(F, pt.q)   # noqa: E731
        x0, M = monodromy(system(pt.p), VP, pt.orbit.u_at(0.0))
        mu = np.linalg.eigvals(M)
        assert abs(mu[0].imag) > 0.1                              # a complex pair
        assert np.all(np.abs(np.abs(mu) - 1) <= 1e-8)             # measured 1e-12
        assert abs(abs(np.angle(mu[0])) - pt.theta) <= 1e-8       # measured 2e-12
        assert abs(abs(np.angle(mu[0])) - pt.theta) <= pt.theta_error
        _, F = solved(system, VP, np.append(x0, pt.p), lambda M: np.linalg.det(M) - 1)
        assert abs(pt.p - F) <= 1e-8 and abs(pt.p - F) <= pt.p_error   # measured 9e-13
        assert pt.stable is True           # no other multiplier than the pair (n = 2, forced)


def test_refusals(flip, torus):
    b, e, _ = flip
    tb, te, _ = torus
    with pytest.raises(ValueError, match=r"a 'period-doubling' event needs branch="):   # OB01
        continue_flip_curve(e, mathieu2, 0.6, 0.8)
    with pytest.raises(ValueError, match=r"give a 'torus' event of a branch"):   # bad-inputs OB02
        continue_torus_curve(e, mathieu2, 0.6, 0.8, branch=b)
    with pytest.raises(ValueError, match=r"not one of branch.events"):   # bad-inputs OB03
        continue_flip_curve(Event("period-doubling", e.p, e.index), mathieu2, 0.6, 0.8,
                            branch=b)
    with pytest.raises(ValueError, match=r"give two different finite values"):   # OB04
        continue_flip_curve(e, mathieu2, 0.6, 0.6, branch=b)
    with pytest.raises(ValueError, match=r"step = 0: must be finite and > 0"):   # OB05
        continue_torus_curve(te, vdp2, 0.2, 0.4, branch=tb, step=0)
    # the branch's orbits at the doubling have no complex pair: no torus there
    pd = b.points[e.index]
    with pytest.raises(ValueError, match=r"no non-real multiplier"):   # bad-inputs OB06
        continue_torus_curve(pd, mathieu2, 0.6, 0.8)
    # make2 at q0 is not the branch's model: no doubling between the event's points
    with pytest.raises(ValueError, match=r"make2\(\., q0 = 0.9\)"):   # bad-inputs OB07
        continue_flip_curve(e, mathieu2, 0.9, 1.0, branch=b)
