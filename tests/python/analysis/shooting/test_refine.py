# refine_orbit: orbits recomputed at M, 2M, 4M steps and extrapolated, against independent
# computations written here: van der Pol with a distributed delay by a fourth-order Runge-Kutta run
# of its equivalent discrete-delay system, a forced linear orbit in closed form with its
# multipliers from the characteristic function in mpmath, the damped Mathieu equation's period
# doubling from scipy's monodromy; and a stick-slip orbit that must not claim order 2.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import scipy.integrate as si
import scipy.optimize as so

import dmi
from dmi import analysis as da

TAU = 1.0


# ---- van der Pol with a distributed delay -------------------------------------------------------
# w'' + eps (w^2 - 1) w' + w + (a / tau) int_0^tau w(t - s) ds = 0, eps = 1, a = 0.5, tau = 1.
EPS, AV = 1.0, 0.5


def vdp(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], EPS * (u[0] ** 2 - 1) * u[1] + u[0]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [AV / TAU, 0.0]]])
    return s


def vdp_period_rk4(m: int, T: float = 120.0) -> float:
    """The limit cycle's period by RK4 with step tau / m on the equivalent system w' = v,
    v' = -eps (w^2 - 1) v - w - (a / tau) Z, Z' = w(t) - w(t - tau) (Z = int_0^tau w(t - s) ds),
    the delayed w at half steps from the cubic Hermite interpolant of (w, w' = v); the period
    from the upward zeros of w (on the same interpolant) over the last 5 periods of a run of T."""
    k = TAU / m
    n = int(round(T / k))
    W, V = np.empty(n + m + 1), np.empty(n + m + 1)
    W[:m + 1], V[:m + 1] = 2.0, 0.0
    Z = 2.0 * TAU

    def F(w, v, z, wd):
        return v, -EPS * (w * w - 1) * v - w - (AV / TAU) * z, w - wd

    def hermite(i, s):
        return ((2 * s ** 3 - 3 * s ** 2 + 1) * W[i] + (s ** 3 - 2 * s ** 2 + s) * V[i] * k
                + (-2 * s ** 3 + 3 * s ** 2) * W[i + 1] + (s ** 3 - s ** 2) * V[i + 1] * k)

    for j in range(n):
        i = m + j
        w, v, z = W[i], V[i], Z
        wd0, wdh, wd1 = W[i - m], hermite(i - m, 0.5), W[i - m + 1]
        k1 = F(w, v, z, wd0)
        k2 = F(w + k / 2 * k1[0], v + k / 2 * k1[1], z + k / 2 * k1[2], wdh)
        k3 = F(w + k / 2 * k2[0], v + k / 2 * k2[1], z + k / 2 * k2[2], wdh)
        k4 = F(w + k * k3[0], v + k * k3[1], z + k * k3[2], wd1)
        W[i + 1] = w + k / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        V[i + 1] = v + k / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        Z = z + k / 6 * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
    idx = np.nonzero((W[m:-1] < 0) & (W[m + 1:] >= 0))[0] + m
    ts = [(i - m + so.brentq(lambda s: hermite(i, s), 0.0, 1.0, xtol=1e-15)) * k
          for i in idx[-6:]]
    return float(np.mean(np.diff(ts)))


def test_van_der_pol_period_refined_against_runge_kutta():
    p200, p400 = vdp_period_rk4(200), vdp_period_rk4(400)
    assert abs(p200 - p400) < 1e-8                 # RK4's own convergence (order 4)
    P_true = p400 + (p400 - p200) / 15
    M = 2000
    s = vdp(0.0, h=5.63 / M)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(round(60 / s.h))
    o = da.periodic_orbit(vdp, 0.0, guess=s, guess_period=5.63, steps=M, multipliers=2)
    assert abs(o.period - P_true) > 5e-3           # the scheme's own period: O(h) off
    r = da.refine_orbit(o)
    assert r.steps == [M, 2 * M, 4 * M] and r.order == 2.0
    assert abs(r.period - P_true) <= 1e-4, (r.period, P_true)
    assert r.errors["period"] >= abs(r.period - P_true), (r.errors, r.period - P_true)
    assert r.errors["period"] <= 1e-4


# ---- a forced linear orbit: closed form, and multipliers exp(lambda P) -------------------------
# u' + a u + (k / tau) int_0^tau u(t - s) ds = cos t: u = Re(X e^(i t)), X = 1 / (i + a + k g),
# g = (1 - e^(-i tau)) / (i tau); multipliers exp(lambda 2 pi), lambda + a + k (1 - e^(-lambda
# tau)) / (lambda tau) = 0.
AL, KL = 0.4, 1.5


def forced_linear(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(1, TAU, h=2 * math.pi / 100 if h is None else h)
    s.set_rhs(lambda t, u: np.array([AL * u[0] - math.cos(t)]))
    s.set_kernel_exp([0.0], [0.0], [[[KL / TAU]]])
    return s


def test_forced_smooth_orbit_refined_to_second_order():
    o = da.periodic_orbit(forced_linear, 0.0, 2 * math.pi, [0.0], multipliers=2)
    r = da.refine_orbit(o)
    assert r.order == 2.0
    X = 1 / (1j + AL + KL * (1 - np.exp(-1j * TAU)) / (1j * TAU))
    err_raw = abs(o.amplitude[0] - abs(X))
    err = abs(r.amplitude[0] - abs(X))
    assert err <= r.errors["amplitude"][0] and err < err_raw / 20, (err, err_raw, r.errors)
    mp.mp.dps = 30

    def char(lam):
        return lam + AL + KL * (1 - mp.exp(-lam * TAU)) / (lam * TAU)
    for mu, e, mu0 in zip(r.multipliers, r.errors["multipliers"], o.multipliers):
        lam = complex(mp.findroot(char, mp.mpc(complex(np.log(mu0)) / (2 * math.pi))))
        want = np.exp(lam * 2 * math.pi)
        assert abs(mu - want) <= max(e, 1e-7), (mu, want, e)
        assert abs(mu - want) < abs(mu0 - want) / 10, (mu, mu0, want)


# ---- a stick-slip orbit: the levels are not smooth in h ----------------------------------------
def belt(c: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + 0.3), u[0] + c * (u[1] + 0.3)]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [0.8, 0.0]]])
    s.set_friction([0.0, 0.5])
    return s


def test_stick_slip_orbit_does_not_claim_order_two():
    M = 200
    s = belt(0.2, h=5.2 / M)
    s.set_history(lambda t: np.array([0.5 / 1.8 + 0.05, -0.3]))
    s.init()
    s.advance(round(60 / s.h))
    o = da.periodic_orbit(belt, 0.2, guess=s, guess_period=5.2, steps=M, multipliers=4)
    assert np.max(o.stick_fraction) > 0.1
    r = da.refine_orbit(o)
    assert r.order < 1.5, r.order
    P = [q.period for q in r.orbits]
    assert r.period == P[-1] and r.errors["period"] >= max(abs(x - P[-1]) for x in P[:-1])
    # the estimate covers a plain run at twice the finest level's steps (the period from the
    # upward crossings of x's mean over its last periods, interpolated)
    h = r.period / (8 * M)
    s = belt(0.2, h=h)
    s.set_history(lambda t: np.array([0.5 / 1.8 + 0.05, -0.3]))
    s.init()
    _, U = s.run(round(120 / h))
    x = U[-round(40 / h):, 0]
    y = x - 0.5 * (x.max() + x.min())
    k = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    P_fine = float(np.mean(np.diff((k + y[k] / (y[k] - y[k + 1])) * h)))
    assert abs(r.period - P_fine) <= r.errors["period"], (r.period, P_fine, r.errors)


# ---- events placed from refined multipliers: the damped Mathieu equation's period doubling -----
# w'' + c w' + (delta + eps cos t) w = 0: the trivial orbit's multipliers are those of the
# linear periodic system; one crosses -1 where det(Monodromy + I) = 0 (scipy, rtol 1e-12).
CM, EM = 0.1, 0.5


def mathieu(delta: float, h: float | None = None) -> dmi.Solver:
    hh = 2 * math.pi / 100 if h is None else h
    s = dmi.Solver(2, hh, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], CM * u[1] + (delta + EM * math.cos(t)) * u[0]]))
    return s


def mathieu_pd() -> float:
    def g(delta):
        def rhs(t, y):
            return [y[1], -CM * y[1] - (delta + EM * math.cos(t)) * y[0]]
        cols = [si.solve_ivp(rhs, (0, 2 * math.pi), e, method="DOP853", rtol=1e-12,
                             atol=1e-14).y[:, -1] for e in ([1.0, 0.0], [0.0, 1.0])]
        return float(np.linalg.det(np.column_stack(cols) + np.eye(2)))
    return so.brentq(g, 0.4, 0.5, xtol=1e-13)


def test_period_doubling_placed_from_refined_multipliers():
    d_true = mathieu_pd()
    o = da.periodic_orbit(mathieu, 0.6, 2 * math.pi, [0.0, 0.0], multipliers=2)
    kw = dict(step=0.04, max_points=8, multipliers=2)
    plain = da.continue_orbit(o, 0.35, **kw)
    refined = da.continue_orbit(o, 0.35, refine=True, **kw)
    (e0,) = [e for e in plain.events if e.kind == "period-doubling"]
    (e1,) = [e for e in refined.events if e.kind == "period-doubling"]
    assert "refined" in e1.detail
    assert abs(e1.p - d_true) < abs(e0.p - d_true) / 5, (e0.p, e1.p, d_true)
    # the same with the period given as a function of p (the branch's maps build make(p, h=...))
    timed = da.continue_orbit(o, 0.35, refine=True, period=lambda p: 2 * math.pi, **kw)
    (e2,) = [e for e in timed.events if e.kind == "period-doubling"]
    assert "refined" in e2.detail and abs(e2.p - d_true) < abs(e0.p - d_true) / 5, e2
