# period_doubled_orbit on a collocated branch: the forced Duffing oscillator in a well with a
# memory, w'' + d w' - w + w^3 + g int_0^tau e^{-s} w'(t - s) ds = p cos(w t), continued by
# collocation in p through its period doubling; the flip's p and the doubled orbit (and its
# branch) against an independent Fourier (harmonic balance) solve written here: the orbit's
# samples on a uniform grid, the linear part with memory exact on each harmonic, Newton; the flip
# where the linearisation has an antiperiodic solution (its matrix on the antiperiodic samples of
# the period 2 T singular), found by Brent's method; the events' test functions against the
# multipliers' errors; an autonomous branch (Roessler's equations with a memory) doubled, the
# doubled orbit checked by integrating the equation over its period.  About 2 minutes.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import math
from functools import lru_cache

import numpy as np
import pytest
from scipy.optimize import brentq, minimize_scalar

import dmi
from dmi import analysis as da
from dmi.analysis.branches.collocated import EquationBranch

D, BE, W, G, TAU = 0.3, 1.0, 1.2, 0.1, 1.0
T = 2 * math.pi / W
M = 400
N1 = 64                                   # samples of the T-orbit in the Fourier solve


def duffing(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=T / M if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], D * u[1] - u[0] + BE * u[0] ** 3
                                     - p * math.cos(W * t)]))
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [0.0, G]]])
    return s


# ---- the independent Fourier solve ------------------------------------------------------------
def symbol(om: np.ndarray) -> np.ndarray:
    """w'' + d w' - w + g int_0^tau e^{-s} w'(t - s) ds on e^{i om t}."""
    return (-om ** 2 + 1j * D * om - 1.0
            + G * 1j * om * (1 - np.exp(-(1 + 1j * om) * TAU)) / (1 + 1j * om))


def linear(N: int, P: float) -> np.ndarray:
    """The linear part's real N x N matrix on N samples of a P-periodic function."""
    k = np.fft.fftfreq(N, 1.0 / N)
    Lk = symbol(2 * math.pi / P * k)
    Lk[N // 2] = Lk[N // 2].real          # the Nyquist harmonic (negligible) kept real
    return np.real(np.fft.ifft(Lk[:, None] * np.fft.fft(np.eye(N), axis=0), axis=0))


def fourier_orbit(p: float, N: int, P: float, w0: np.ndarray) -> np.ndarray:
    """Samples of the P-periodic orbit at p by damped Newton from w0."""
    t = np.arange(N) * P / N
    A = linear(N, P)
    w = np.array(w0, dtype=float)

    def res(w: np.ndarray) -> np.ndarray:
        return A @ w + BE * w ** 3 - p * np.cos(W * t)
    for _ in range(60):
        r = res(w)
        dw = np.linalg.solve(A + np.diag(3 * BE * w ** 2), -r)
        if np.max(np.abs(dw)) < 1e-9:     # quadratic: one more step is at rounding
            w = w + dw
            return w + np.linalg.solve(A + np.diag(3 * BE * w ** 2), -res(w))
        lam = 1.0
        while lam > 1e-3 and np.max(np.abs(res(w + lam * dw))) >= np.max(np.abs(r)):
            lam /= 2
        w = w + lam * dw
    raise AssertionError(f"the Fourier solve did not converge at p = {p}")


@lru_cache(maxsize=None)
def t_orbit(p: float) -> np.ndarray:
    """The T-orbit at p, continued in p from the large orbit of the right well at p = 0.2 (its
    guess: the orbit's mean and leading harmonics to 2 digits, within Newton's quadratic reach;
    a rougher guess sent the damped Newton on a long walk whose end depended on the rounding
    of the linear solves)."""
    t = np.arange(N1) * T / N1
    w = fourier_orbit(0.2, N1, T, 0.83 - 0.033 * np.cos(W * t) + 0.44 * np.sin(W * t)
                      - 0.058 * np.cos(2 * W * t))
    for q in np.linspace(0.2, p, 8)[1:]:
        w = fourier_orbit(float(q), N1, T, w)
    return w


def antiperiodic(p: float) -> np.ndarray:
    """The linearisation about the T-orbit on antiperiodic samples of the period 2 T (phi on
    [0, T), -phi on [T, 2 T))."""
    A2 = linear(2 * N1, 2 * T) + np.diag(3 * BE * np.tile(t_orbit(p), 2) ** 2)
    return (A2[:, :N1] - A2[:, N1:])[:N1]


@lru_cache(maxsize=None)
def flip() -> float:
    def f(p: float) -> float:
        sign, logdet = np.linalg.slogdet(antiperiodic(p))
        return float(sign * math.exp(logdet / N1))
    return brentq(f, 0.285, 0.295, xtol=1e-13)


def doubled(p: float) -> np.ndarray:
    """Samples (2 N1) of the 2 T-orbit at p past the flip: from the T-orbit twice plus the
    antiperiodic direction (the eigenvector of the linearisation's smallest eigenvalue)."""
    ev, vec = np.linalg.eig(antiperiodic(p))
    phi = vec[:, int(np.argmin(np.abs(ev)))].real
    phi /= np.max(np.abs(phi))
    w = fourier_orbit(p, 2 * N1, 2 * T, np.tile(t_orbit(p), 2) + 0.1 * np.concatenate([phi, -phi]))
    assert np.max(np.abs(w[:N1] - w[N1:])) > 1e-2       # not the T-orbit
    return w


def amplitudes(w: np.ndarray, P: float) -> np.ndarray:
    """(max - min) / 2 of w and w' of the trigonometric polynomial through the samples, the
    extrema polished by a bounded scalar search around the finest grid's."""
    N = w.size
    c = np.fft.fft(w) / N
    om = 2 * math.pi / P * np.fft.fftfreq(N, 1.0 / N)
    c[N // 2] = 0.0
    out = []
    for coef in (c, 1j * om * c):
        def u(t: float, coef: np.ndarray = coef) -> float:
            return float(np.real(np.sum(coef * np.exp(1j * om * t))))
        grid = np.linspace(0.0, P, 4096, endpoint=False)
        vals = np.real(np.exp(1j * np.outer(grid, om)) @ coef)
        ext = []
        for sgn in (1.0, -1.0):
            t0 = grid[int(np.argmax(sgn * vals))]
            r = minimize_scalar(lambda t: -sgn * u(t), bounds=(t0 - P / 2048, t0 + P / 2048),
                                method="bounded", options={"xatol": 1e-12})
            ext.append(u(r.x))
        out.append(0.5 * (ext[0] - ext[1]))
    return np.array(out)


# ---- the collocated branch and its doubling ---------------------------------------------------
@pytest.fixture(scope="module")
def branch() -> da.Branch:
    o = da.periodic_orbit(duffing, 0.27, T, [0.57, 0.41], multipliers=2)
    e = da.collocate(o, multipliers=4)
    return da.continue_orbit(e, 0.30, step=0.01, multipliers=4)


def test_fourier_solve_is_converged():
    """The reference itself: doubling the samples changes the flip's orbit by < 1e-12."""
    p = 0.29
    w = t_orbit(p)
    w2 = fourier_orbit(p, 2 * N1, T, np.repeat(w, 2))
    assert np.max(np.abs(w2[::2] - w)) < 1e-12


def test_flip_on_the_collocated_branch(branch):
    pds = [e for e in branch.events if e.kind == "period-doubling"]
    assert len(pds) == 1, branch.events
    assert abs(pds[0].p - flip()) < 1e-6, (pds[0].p, flip())


def test_doubled_orbit_and_its_branch(branch):
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    o2 = da.period_doubled_orbit(branch, pd, multipliers=4)
    assert o2.of == "equation" and o2.p > flip()
    assert o2.period == 2 * T                          # forced: exactly twice the forcing period
    ref = amplitudes(doubled(o2.p), 2 * T)
    assert np.max(np.abs(o2.amplitude - ref)) < 1e-8, (o2.amplitude, ref)
    # distinct from the T-orbit, whose amplitude at that p is another
    assert np.max(np.abs(o2.amplitude - amplitudes(t_orbit(o2.p), T))) > 1e-3
    b2 = da.continue_orbit(o2, o2.p + 0.003, step=0.003, multipliers=4)
    assert b2.points[-1].p == pytest.approx(o2.p + 0.003, abs=1e-12), b2.status
    q = b2.points[-1]
    assert q.period == 2 * T
    ref = amplitudes(doubled(q.p), 2 * T)
    assert np.max(np.abs(q.amplitude - ref)) < 1e-8, (q.amplitude, ref)


def test_doubling_back_to_the_t_orbit_is_refused(branch):
    """No kick: Newton stays on the T-orbit laid twice, which is refused."""
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    with pytest.raises(da.ShootingError, match="returned to the T-orbit"):
        da.period_doubled_orbit(branch, pd, amplitudes=(0.0,), multipliers=4)


def test_collocated_events_verified_against_the_multipliers_errors(branch):
    """The flip's bracketing points: their test functions change sign beyond the multipliers'
    estimated errors; with error bounds wider than the multiplier's distance to -1 both are 0
    (no sign change: no event) with an EventWarning each."""
    from dmi.analysis.branches.events import EventWarning
    pd = next(e for e in branch.events if e.kind == "period-doubling")
    pts = [q for q in branch.points if abs(q.p - pd.p) < 0.02]
    a = max((q for q in pts if q.p < pd.p), key=lambda q: q.p)
    b = min((q for q in pts if q.p > pd.p), key=lambda q: q.p)
    eb, x = EquationBranch.of(a, multipliers=4)
    fa = eb.event_functions(x, a.p, a)["period-doubling"]
    eb, x = EquationBranch.of(b, multipliers=4)
    fb = eb.event_functions(x, b.p, b)["period-doubling"]
    assert fa < 0 < fb
    for q in (a, b):
        wide = dataclasses.replace(q, errors={**q.errors, "multipliers": np.full(
            q.multipliers.shape, 1.5 * abs(abs(q.multipliers[0]) - 1))})
        eb, x = EquationBranch.of(wide, multipliers=4)
        with pytest.warns(EventWarning, match="error bound is larger than their distance"):
            assert eb.event_functions(x, q.p, wide)["period-doubling"] == 0.0


# ---- an autonomous branch: Roessler's equations with a memory on x -----------------------------
# x' = -y - z - g int_0^1 e^{-s} x(t - s) ds, y' = x + a y, z' = b + z (x - c); its orbit doubles
# near c = 2.99.  The doubled orbit is checked by an independent integration of the equation from
# its own past: with m = int_0^1 e^{-s} x(t - s) ds, m' = x(t) - e^{-1} x(t - 1) - m, a delay
# equation integrated by the method of steps (DOP853 on each unit interval, the past from the
# previous one's dense output) over one period 2 T must come back to its start.
RA, RB, RG = 0.2, 0.2, 0.02


def roessler(c: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(3, 1.0, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: -np.array([-u[1] - u[2], u[0] + RA * u[1], RB + u[2] * (u[0] - c)]))
    s.set_kernel_exp([-1.0], [0.0], [[[RG, 0, 0], [0, 0, 0], [0, 0, 0]]])
    return s


def test_doubled_orbit_of_an_autonomous_branch():
    from scipy.integrate import quad, solve_ivp
    c0 = 2.6
    run = solve_ivp(lambda t, u: [-u[1] - u[2], u[0] + RA * u[1], RB + u[2] * (u[0] - c0)],
                    (0, 300), [1, 1, 0], rtol=1e-10, atol=1e-12, dense_output=True)
    ts = np.linspace(250, 300, 50001)
    Y = run.sol(ts)
    i = np.flatnonzero((Y[1][:-1] < 0) & (Y[1][1:] >= 0) & (Y[0][:-1] > 0))
    o = da.periodic_orbit(roessler, c0, None, Y[:, i[-1]], guess_period=ts[i[-1]] - ts[i[-2]],
                          steps=1000, multipliers=3)
    b = da.continue_orbit(da.collocate(o, multipliers=4), 3.0, step=0.05, multipliers=4)
    pd = [e for e in b.events if e.kind == "period-doubling"]
    assert len(pd) == 1, b.events
    o2 = da.period_doubled_orbit(b, pd[0], multipliers=4)
    q = b.points[pd[0].index]
    assert o2.autonomous and abs(o2.period - 2 * q.period) < 0.05 * q.period
    P = o2.period

    def x_past(t: float) -> float:
        return float(o2.u_at(np.array([t % P]))[0, 0])
    m0 = quad(lambda s: math.exp(-s) * x_past(-s), 0.0, 1.0, epsabs=1e-13, epsrel=1e-13, limit=200)[0]
    state = np.concatenate([o2.u_at(np.array([0.0]))[0], [m0]])
    past = x_past
    t0 = 0.0
    while t0 < P - 1e-12:
        t1 = min(t0 + 1.0, P)

        def rhs(t: float, w: np.ndarray, past=past) -> list[float]:
            x, y, z, m = w
            return [-y - z - RG * m, x + RA * y, RB + z * (x - o2.p),
                    x - math.exp(-1.0) * past(t - 1.0) - m]
        seg = solve_ivp(rhs, (t0, t1), state, method="DOP853", rtol=1e-13, atol=1e-13,
                        dense_output=True)
        prev = past

        def past(t: float, seg=seg, t0=t0, prev=prev) -> float:
            return float(seg.sol(t)[0]) if t >= t0 else prev(t)
        state, t0 = seg.y[:, -1], t1
    start = o2.u_at(np.array([0.0]))[0]
    assert np.max(np.abs(state[:3] - start)) < 1e-8, state[:3] - start
    assert np.max(np.abs(o2.u_at(np.array([0.5 * P]))[0] - start)) > 1e-2   # not the T-orbit
