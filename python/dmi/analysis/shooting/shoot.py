# Periodic orbits by shooting on the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Shooting for periodic orbits of the discrete scheme (3.12)-(3.13): Newton on the fixed points
of the M-step map (:mod:`dmi.analysis.scheme.stepmap`, :mod:`dmi.analysis.core.newton`); a forced
orbit (period given) by :mod:`dmi.analysis.shooting.forced`, an autonomous one (period unknown) by
:mod:`dmi.analysis.shooting.autonomous`."""
from __future__ import annotations

from typing import Any

from .autonomous import autonomous_orbit
from .forced import forced_orbit
from ..scheme.floquet import Verify
from ..scheme.orbit import Orbit
from ..scheme.stepmap import Model, StepMap  # noqa: F401  (StepMap: where the tests read it)


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
    return forced_orbit(make, p, period, guess, tol=tol, max_iter=max_iter,
                        multipliers=multipliers, rows=rows, verify=verify, constant=constant)
