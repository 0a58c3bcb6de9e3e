# Periodic orbits by shooting on the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Shooting for periodic orbits of the discrete scheme (3.12)-(3.13): Newton on the fixed points
of the M-step map (:mod:`dmi.analysis.stepmap`, :mod:`dmi.analysis.newton`); an autonomous orbit
(period unknown) by :mod:`dmi.analysis.autonomous`."""
from __future__ import annotations

from typing import Any

import numpy as np

from .._solver import Solver
from .autonomous import autonomous_orbit
from .newton import newton
from .orbit import Orbit, make_orbit
from .stepmap import Model, StepMap, build, state_of, steps_per_period

def periodic_orbit(make: Model, p: float, period: float | None = None, guess: Any = None, *,
                   guess_period: float | None = None, steps: int | None = None,
                   tol: float = 1e-10, max_iter: int = 30, multipliers: int = 10,
                   rows: int | None = None) -> Orbit:
    """The periodic orbit of the model ``make`` at ``p`` near ``guess``, by shooting.

    ``period`` (time units) must be a whole number M of steps h of ``make(p)`` (forced systems
    with period P: take h = P / M).  ``guess``: a state (L n values, or an (L, n) array: the
    last L stored states, the last at t = 0) or a ``dmi.Solver`` of the same model run onto the
    orbit (it is not changed: a copy of its state is advanced to the next step index that is a
    multiple of M, the orbit's phase 0).  ``rows``: L (default N + 1).  Newton with GMRES on
    the matrix-free Jacobian converges to ``tol`` in the max norm (relative to max(1, |x|));
    ``multipliers``: how many leading Floquet multipliers to compute (0: none, ``stable`` is
    then False).  ``period=None`` with ``guess_period``: an autonomous orbit of unknown period
    M h, ``steps`` = M fixed (default guess_period / make(p).h) and h unknown, with a phase
    condition; the model must take the step, ``make(p, h=...)`` (libdmi 1.2's
    ``dmi.Solver(n, tau, h=...)``), see :mod:`dmi.analysis.autonomous`.

    Raises ValueError for bad input (period <= 0 or not a multiple of h, a guess of the wrong
    shape, a ``period`` that is not a period of the model: one more period run from t = P, not
    from t = 0, differs from the first), the model's own exception when ``make(p)`` fails (with a
    note naming the call), and :class:`ShootingError` when Newton fails (with every residual
    tried)."""
    if guess is None:
        raise ValueError("guess: give a state or a dmi.Solver run onto the orbit")
    if period is None:
        if guess_period is None:
            raise ValueError("period=None (an autonomous orbit) needs guess_period")
        return autonomous_orbit(make, p, guess, guess_period, steps=steps, tol=tol,
                                max_iter=max_iter, multipliers=multipliers)
    probe = build(make, p)
    M = steps_per_period(probe.h, period)
    F = StepMap(make, p, M, rows, solver=probe)
    if isinstance(guess, Solver):
        if (guess.n, guess.N) != (F.n, F.N) or guess.h != F.h:
            raise ValueError(f"guess: a solver with n = {guess.n}, N = {guess.N}, h = {guess.h!r}; "
                             f"make(p) has n = {F.n}, N = {F.N}, h = {F.h!r}")
        x0 = state_of(guess, M)
    else:
        x0 = np.asarray(guess, dtype=float).ravel()
        if x0.size == F.n and F.L > 1:
            x0 = np.tile(x0, F.L)  # a single state: a constant window
        if x0.size % F.n or not F.N + 1 <= x0.size // F.n <= F.L:
            raise ValueError(f"guess has {x0.size} values (shape {np.shape(guess)}); the model has "
                             f"n = {F.n}: give n = {F.n} values (a constant window), or k rows "
                             f"of n, N + 1 = {F.N + 1} <= k <= L = {F.L} (an (k, {F.n}) array "
                             f"or k {F.n} values), the last at t = 0, or a dmi.Solver")
    x0 = F.extend(x0)
    x, res = newton(F, x0, tol=tol, max_iter=max_iter,
                    what=f"periodic orbit at p = {p!r}, period {period!r} = {M} steps")
    period_of_model(F, x, period)
    return make_orbit(F, x, res, multipliers)


def period_of_model(F: StepMap, x: np.ndarray, period: float) -> None:
    """ValueError when the fixed point x of F is no orbit: two periods run from x (the second
    from t = P, with the model's own time) differ by more than 1e-5 max(1, |U|): the model's
    forcing does not have the period P."""
    U = F.run_from(x, 2 * F.M)
    miss = float(np.max(np.abs(U[F.M:] - U[:F.M + 1])))
    scale = max(1.0, float(np.max(np.abs(U))))
    if miss > 1e-5 * scale:
        raise ValueError(f"period = {period!r} is not a period of the model at p = {F.p!r}: the "
                         f"run from t = P leaves the orbit found from t = 0 by {miss:.3g} "
                         f"(state units; {miss / scale:.2g} relative): the forcing's period is "
                         "another (a divisor of the period sought?)")

