# Periodic orbits of unknown period (autonomous systems) by shooting in (state, h) (issue 30).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Autonomous periodic orbits: the period P = M h with M fixed and the step h unknown.

The model must then take the step: ``make(p, h=h) -> dmi.Solver`` (libdmi 1.2's
``dmi.Solver(n, tau, h=h)``).  Unknowns (x, h); equations F_h(x) - x = 0 and the phase condition
<xdot_0, x_0 - x_ref> = 0 on the last row (the state at t = 0), xdot_0 the guess's velocity there
(central difference over its first run).  Newton with GMRES on the bordered Jacobian
[[D_xF - I, D_hF], [xdot_0' on the last row, 0]] (D_hF by one difference in h a step).  N =
ceil(tau / h) may change with h: the states hold L = ceil(tau / (0.8 h_0)) + 1 rows (h may fall by
20 %), the older ones by periodicity.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from .._solver import Solver
from .shooting import (Model, Orbit, ShootingError, StepMap, _fmt, bordered_step, build,
                       make_orbit, positive_time)


def _with_h(make: Model, h: float) -> Model:
    def made(p: float) -> Solver:
        return make(p, h=h)  # type: ignore[call-arg]
    return made


def autonomous_orbit(make: Model, p: float, guess: Any, guess_period: float, *,
                     steps: int | None = None, tol: float = 1e-10, max_iter: int = 30,
                     multipliers: int = 10) -> Orbit:
    """See :func:`dmi.analysis.periodic_orbit` with ``period=None``.  ``steps``: M (default
    round(guess_period / h) with the h of ``make(p)``).  ``guess``: a state (N + 1 rows of the
    solver ``make(p, h=guess_period / M)``, or n values) or such a solver run near the orbit (its
    window is taken as it is: any phase)."""
    P0 = positive_time("guess_period", guess_period)
    M = int(steps) if steps is not None else max(1, round(P0 / build(make, p).h))
    if M < 1:
        raise ValueError(f"steps = {steps}: must be >= 1")
    h0 = P0 / M
    try:
        s0 = make(p, h=h0)  # type: ignore[call-arg]
    except TypeError as e:
        raise ValueError(f"period=None needs a model make(p, h=...) that takes the step ({e})") \
            from e
    rows = max(s0.N + 1, math.ceil(s0.tau / (0.8 * h0)) + 1)
    cache: dict[float, StepMap] = {}
    res: list[float] = []   # the Newton residuals, also in the errors of F(h)

    def F(h: float) -> StepMap:
        if h not in cache:
            if not (h > 0.5 * h0):
                raise ShootingError(f"autonomous orbit at p = {p!r}: the step went to h = {h!r}, "
                                    f"below half the guess's {h0!r} after {len(res)} Newton "
                                    f"iterations (residuals {_fmt(res)}): no orbit near the "
                                    "guess", res)
            m = StepMap(_with_h(make, h), p, M, rows)
            if m.N + 1 > rows:
                raise ShootingError(f"autonomous orbit at p = {p!r}: the step fell to h = {h!r}: "
                                    f"N + 1 = {m.N + 1} > {rows} rows (residuals {_fmt(res)})",
                                    res)
            if len(cache) > 3:
                cache.pop(next(iter(cache)))
            cache[h] = m
        return cache[h]

    F0 = F(h0)
    if isinstance(guess, Solver):
        if guess.n != F0.n or abs(guess.h - h0) > 1e-12 * h0 or guess.N != F0.N:
            raise ValueError(f"guess: a solver with h = {guess.h!r}, N = {guess.N}; expected the "
                             f"model's at h = guess_period / M = {h0!r} (N = {F0.N})")
        x0 = guess.get_window().ravel()
    else:
        x0 = np.asarray(guess, dtype=float).ravel()
        if x0.size == F0.n:
            x0 = np.tile(x0, F0.N + 1)
    x0 = F0.extend(x0)
    n = F0.n
    U = F0.trajectory(x0)
    xdot = (U[1] - U[M - 1]) / (2 * h0) if M > 1 else U[1] - U[0]
    if not np.any(xdot):
        raise ValueError("the guess does not move at t = 0: no phase condition (an equilibrium?)")
    xdot = xdot / np.linalg.norm(xdot)
    ref = x0[-n:].copy()
    x, h = x0.copy(), h0
    what = f"autonomous orbit at p = {p!r}, M = {M} steps, guess period {P0!r}"
    for _ in range(max_iter + 1):
        Fm = F(h)
        Fx = Fm(x)
        r = Fx - x
        g = float(np.dot(xdot, x[-n:] - ref))
        rn = float(np.max(np.abs(r)))
        res.append(rn)
        scale = max(1.0, float(np.max(np.abs(x))))
        if not math.isfinite(rn):
            raise ShootingError(f"{what}: non-finite residual (residuals {_fmt(res)})", res)
        if rn <= tol * scale and abs(g) <= tol * scale:
            o = _without_phase(make_orbit(Fm, x, res, multipliers))
            k = loops(o.u)
            if k > 1:
                warnings.warn(f"{what}: the orbit found repeats {k} times in its M steps (its "
                              f"least period is about {o.period / k:.6g}, the orbit's "
                              f"{o.period:.6g}): give a guess_period near the period sought, "
                              f"or steps = M / {k}", RuntimeWarning, stacklevel=3)
            return o
        if len(res) > max_iter:
            break
        dh = 1e-7 * h
        Fh = (F(h + dh)(x) - Fx) / dh
        border = np.zeros(x.size + 1)
        border[x.size - n:x.size] = xdot   # the phase condition: xdot . dx_0 (h free)
        dz, lin = bordered_step(Fm, x, Fx, Fh, border, g, rtol=1e-8)
        if lin > 1e-2:
            raise ShootingError(f"{what}: the bordered Jacobian is singular at Newton iteration "
                                f"{len(res)} (GMRES relative residual {lin:.2g}, residuals "
                                f"{_fmt(res)})", res)
        x, h = x + dz[:-1], h + float(dz[-1])
    raise ShootingError(f"{what}: no convergence in {max_iter} Newton iterations (residuals "
                        f"{_fmt(res)})", res)


def loops(u: np.ndarray, most: int = 64) -> int:
    """How many times one period u (M + 1 rows, the last = the first) repeats itself: the largest
    k in 2 .. min(most, M / 8) whose shift by j = round(M / k) steps moves every value by at most
    twice its own travel over the steps next to it, at both ends (a loop of M / k steps shifted
    by a whole number of steps is off by at most half a step's travel; a single loop shifted by
    8 steps or more moves somewhere by about that many steps' travel), else 1 (also for a
    constant u)."""
    U = np.asarray(u, dtype=float)[:-1]
    M = U.shape[0]
    d = np.abs(np.roll(U, -1, axis=0) - U)           # travel of step i -> i + 1, per component
    if M < 16 or not np.any(d):
        return 1
    local = np.maximum(d, np.roll(d, 1, axis=0))       # of the steps on either side of each point
    tiny = 1e-12 * max(1.0, float(np.max(np.abs(U))))
    found = 1
    for k in range(2, min(most, M // 8) + 1):
        j = round(M / k)
        err = np.abs(np.roll(U, -j, axis=0) - U)
        if np.all(err <= 2 * np.maximum(local, np.roll(local, -j, axis=0)) + tiny):
            found = k
    return found


def _without_phase(o: Orbit) -> Orbit:
    """An autonomous orbit always has the multiplier 1 (a shift along the orbit, the phase):
    ``stable`` is judged on the other multipliers (the one nearest 1 left out; False if no other
    was computed).  ``multipliers`` keeps them all."""
    mu = o.multipliers
    if mu.size:
        rest = np.delete(mu, int(np.argmin(np.abs(mu - 1))))
        o.stable = bool(rest.size and np.all(np.abs(rest) < 1))
    return o
