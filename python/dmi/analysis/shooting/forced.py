# Periodic orbits of a given period by shooting on the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""A forced orbit (its period P = M h given) of the discrete scheme: Newton on the fixed points of
the M-step map (:mod:`dmi.analysis.scheme.stepmap`, :mod:`dmi.analysis.core.newton`), checked to
be a period of the model and, for an autonomous model, not its equilibrium.  The public entry is
:func:`dmi.analysis.periodic_orbit` (:mod:`dmi.analysis.shooting.shoot`)."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..._solver import Solver
from ..core.newton import ShootingError, newton
from ..scheme.floquet import Verify
from ..scheme.orbit import Orbit, make_orbit
from ..scheme.stepmap import Model, StepMap, build, guess_rows, state_of, steps_per_period


def forced_orbit(make: Model, p: float, period: float, guess: Any, *, tol: float = 1e-10,
                 max_iter: int = 30, multipliers: int = 10, rows: int | None = None,
                 verify: Verify | None = None, constant: bool = False) -> Orbit:
    """See :func:`dmi.analysis.periodic_orbit` with a ``period``."""
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
