# Periodic orbits by shooting on the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Shooting for periodic orbits of the discrete scheme (3.12)-(3.13): Newton on the fixed points
of the M-step map (:mod:`dmi.analysis.scheme.stepmap`, :mod:`dmi.analysis.core.newton`); an autonomous orbit
(period unknown) by :mod:`dmi.analysis.shooting.autonomous`."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..._solver import Solver
from .autonomous import autonomous_orbit
from ..scheme.floquet import Verify
from ..core.newton import ShootingError, newton
from ..scheme.orbit import Orbit, make_orbit
from ..scheme.stepmap import Model, StepMap, build, guess_rows, state_of, steps_per_period

def periodic_orbit(make: Model, p: float, period: float | None = None, guess: Any = None, *,
                   guess_period: float | None = None, steps: int | None = None,
                   tol: float = 1e-10, max_iter: int = 30, multipliers: int = 10,
                   rows: int | None = None, verify: Verify | None = None,
                   constant: bool = False) -> Orbit:
    """The periodic orbit of the model near a guess, by shooting.

    Newton with GMRES on the matrix-free Jacobian of the M-step map (:mod:`dmi.analysis.scheme.stepmap`)
    to ``tol`` in the max norm (relative to max(1, |x|)).  A forced orbit: ``period`` is a whole
    number M of steps h of ``make(p)`` (take h = P / M), and the result is checked to be a period
    of the model (one more period run from t = P, in the model's own time).  An autonomous orbit:
    ``period=None`` with ``guess_period``, M = ``steps`` fixed and h unknown, with a phase
    condition (:mod:`dmi.analysis.shooting.autonomous`); the model must take the step, ``make(p, h=...)``.

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``, configured, not initialised.
    p : float
        The parameter.
    period : float or None
        The period (time units), or None for an autonomous orbit.
    guess : array_like or dmi.Solver
        A state (L n values or (L, n) rows, oldest first, the last at t = 0; N + 1 <= k <= L
        rows; or n values: a constant window), or a solver of the same model run onto the orbit
        (not changed: a copy of its state is advanced to the orbit's phase 0; an autonomous
        orbit takes its window as it is).
    guess_period : float, optional
        An autonomous orbit's period guess (time units).
    steps : int, optional
        An autonomous orbit's M (default guess_period / h of ``make(p)``).
    tol : float
        Newton's tolerance.
    max_iter : int
        Newton iterations at most.
    multipliers : int
        Leading Floquet multipliers to compute (0: none; ``stable`` is then None).
    rows : int, optional
        L, the rows of the state (default N + 1).
    verify : dmi.analysis.Verify, optional
        Tolerances and budgets of the multipliers' verification (default ``Verify()``).
    constant : bool
        Accept a constant orbit of an autonomous model at a fixed ``period`` (the scheme's
        equilibrium as a fixed point of its M-step map, e.g. to continue the map's fixed points
        with :func:`dmi.analysis.continue_orbit`); by default it is refused (ShootingError).

    Returns
    -------
    Orbit
        The orbit: one period ``t``, ``u``, its ``state``, ``multipliers``, ``stable`` (True,
        False, or None when not decided, with a StabilityWarning; an autonomous orbit's leaves
        out its trivial multiplier), ``stick_fraction``.

    Raises
    ------
    ValueError
        Bad input: a period <= 0 or not a whole number of steps, a guess of the wrong shape (the
        message names n and the shapes accepted), a ``period`` that is not a period of the model
        (the mismatch is given), a model that does not take h for an autonomous orbit.
    ShootingError
        Newton fails, with every residual tried: no new least residual in 3 iterations, a
        singular Jacobian, max_iter reached, the map failing (a NaN from the rhs names the call
        and p), an orbit converging to an equilibrium of an autonomous model (a constant state
        is periodic with any period) or a guess period too long.
    Exception
        The model's own, when ``make(p)`` fails (a note names the call).
    """
    if guess is None:
        raise ValueError("guess: give a state or a dmi.Solver run onto the orbit")
    if period is None:
        if guess_period is None:
            raise ValueError("period=None (an autonomous orbit) needs guess_period")
        return autonomous_orbit(make, p, guess, guess_period, steps=steps, tol=tol,
                                max_iter=max_iter, multipliers=multipliers, verify=verify)
    probe = build(make, p)
    M = steps_per_period(probe.h, period)
    F = StepMap(make, p, M, rows, solver=probe)
    if isinstance(guess, Solver):
        if (guess.n, guess.N) != (F.n, F.N) or guess.h != F.h:
            raise ValueError(f"guess: a solver with n = {guess.n}, N = {guess.N}, h = {guess.h!r}; "
                             f"make(p) has n = {F.n}, N = {F.N}, h = {F.h!r}")
        x0 = state_of(guess, M)
    else:
        x0 = guess_rows(guess, F.n, F.N, F.L)
    x0 = F.extend(x0)
    x, res = newton(F, x0, tol=tol, max_iter=max_iter,
                    what=f"periodic orbit at p = {p!r}, period {period!r} = {M} steps")
    period_of_model(F, x, period)
    if not constant:
        constant_of_autonomous(F, x, tol, f"periodic orbit at p = {p!r}, period {period!r}")
    return make_orbit(F, x, res, multipliers, verify=verify)


def constant_of_autonomous(F: StepMap, x: np.ndarray, tol: float, what: str) -> None:
    """ShootingError when the fixed point x of F is a constant state u (its rows differ by at
    most 1e3 tol max(1, |x|)) and the model's rhs does not depend on t at u nor at u + 1e-3
    max(1, |x|) e_i (at 8 times over the period): an equilibrium of an autonomous model,
    periodic with any period, no orbit.  (A forced model's constant orbit, a mass stuck
    throughout under a weak forcing, the rest of a parametric forcing, is kept.)"""
    X = np.asarray(x).reshape(F.L, F.n)
    spread = float(np.max(X.max(axis=0) - X.min(axis=0)))
    scale = max(1.0, float(np.max(np.abs(X))))
    if spread > 1e3 * tol * scale:
        return
    s, u = F.solver, X[-1]
    if s.has("rhs"):
        # at u and beside it (a parametric forcing b cos(w t) x vanishes at x = 0 only)
        d = 1e-3 * scale
        for w in [u] + [u + d * e for e in np.eye(F.n)]:
            f0 = s.eval_rhs(0.0, w)
            for t in np.linspace(0.0, F.M * F.h, 9)[1:]:
                if not np.array_equal(s.eval_rhs(float(t), w), f0):
                    return        # forced: a constant orbit under a forcing is an orbit
    raise ShootingError(f"{what}: converged to an equilibrium of an autonomous model, {u!r}, "
                        f"not an orbit (its rows differ by {spread:.3g}; the rhs does not depend "
                        "on t there): a constant state is periodic with any period; for the "
                        "model's own orbits use period=None with guess_period (an autonomous "
                        "orbit) from a guess that moves, or hopf_orbit from a Hopf point; for "
                        "the equilibrium's stability dmi.analysis.equilibrium (constant=True "
                        "accepts it as a fixed point of the M-step map)", [])


def period_of_model(F: StepMap, x: np.ndarray, period: float) -> None:
    """ValueError when the fixed point x of F is no orbit: two periods run from x (the second
    from t = P, with the model's own time) differ by more than 1e-5 max(1, |U|): the model's
    forcing does not have the period P."""
    U = F.trajectory(x, 2)
    miss = float(np.max(np.abs(U[F.M:] - U[:F.M + 1])))
    scale = max(1.0, float(np.max(np.abs(U))))
    if miss > 1e-5 * scale:
        raise ValueError(f"period = {period!r} is not a period of the model at p = {F.p!r}: the "
                         f"run from t = P leaves the orbit found from t = 0 by {miss:.3g} "
                         f"(state units; {miss / scale:.2g} relative): the forcing's period is "
                         "another (a divisor of the period sought?)")

