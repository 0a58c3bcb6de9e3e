# Periodic orbits of unknown period (autonomous systems): shooting in (state, h).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Autonomous periodic orbits: the period P = M h with M fixed and the step h unknown.

The model must then take the step: ``make(p, h=h) -> dmi.Solver`` (libdmi 1.2's
``dmi.Solver(n, tau, h=h)``).  Unknowns (x, h); equations F_h(x) - x = 0 and the phase condition
<xdot_0, x_0 - x_ref> = 0 on the last row (the state at t = 0), xdot_0 the guess's velocity there:
a Poincare section through the guess, across the flow.  Newton with GMRES on the bordered
Jacobian (:func:`dmi.analysis.core.newton.bordered_newton`, D_hF by one difference in h a step).
N = ceil(tau / h) may change with h: the states hold L = ceil(tau / (0.8 h_0)) + 1 rows (h may
fall by 20 %), the older ones by periodicity.

The orbit born at a Hopf point: :mod:`dmi.analysis.hopf_orbits`.
"""
from __future__ import annotations

import math
import warnings
from typing import Any

import numpy as np

from ..._solver import Solver
from ..scheme.floquet import Verify
from ..core.newton import ShootingError, bordered_newton
from ..scheme.orbit import Orbit, loops, make_orbit
from ..scheme.problem import AutonomousMaps, Problem, phase_row, step_model, velocity
from ..scheme.stepmap import Model, guess_rows, positive_time


def no_equilibrium(o: Orbit, tol: float, what: str) -> Orbit:
    """o, refused (ShootingError) when its amplitude is below 1e3 tol: shooting converged to an
    equilibrium, a constant orbit of any period."""
    amp = float(np.max(o.amplitude))
    scale = max(1.0, float(np.max(np.abs(o.u))))
    if amp <= 1e3 * tol * scale:
        raise ShootingError(f"{what}: converged to an equilibrium, not an orbit (amplitude "
                            f"{amp:.3g}; the state {o.u[0]!r}): start nearer the orbit, or from "
                            "a Hopf point with hopf_orbit", [o.residual])
    return o


def autonomous_orbit(make: Model, p: float, guess: Any, guess_period: float, *,
                     steps: int | None = None, tol: float = 1e-10, max_iter: int = 30,
                     multipliers: int = 10, verify: Verify | None = None) -> Orbit:
    """See :func:`dmi.analysis.periodic_orbit` with ``period=None``.  ``steps``: M (default
    round(guess_period / h) with the h of ``make(p)``).  ``guess``: a state (N + 1 rows of the
    solver ``make(p, h=guess_period / M)``, or n values) or such a solver run near the orbit (its
    window is taken as it is: any phase)."""
    P0 = positive_time("guess_period", guess_period)
    problem = Problem(make)
    M = int(steps) if steps is not None else max(1, round(P0 / problem.probe(p).h))
    if M < 1:
        raise ValueError(f"steps = {steps}: must be >= 1")
    h0 = P0 / M
    s0 = step_model(problem, p, h0)      # read for N and tau; the map at h0 takes it over
    rows = max(s0.N + 1, math.ceil(s0.tau / (0.8 * h0)) + 1)
    maps = AutonomousMaps(make, M, rows, 0.8 * h0, problem)
    F0 = maps(h0, p)
    n = F0.n
    if isinstance(guess, Solver):
        if guess.n != F0.n or abs(guess.h - h0) > 1e-12 * h0 or guess.N != F0.N:
            raise ValueError(f"guess: a solver with h = {guess.h!r}, N = {guess.N}; expected the "
                             f"model's at h = guess_period / M = {h0!r} (N = {F0.N})")
        x0 = guess.get_window().ravel()
    else:
        x0 = guess_rows(guess, n, F0.N)
    x0 = F0.extend(x0)
    xdot = velocity(F0.trajectory(x0), h0)
    if not np.any(xdot):
        raise ValueError("the guess does not move at t = 0: no phase condition (an equilibrium?)")
    xdot = xdot / np.linalg.norm(xdot)
    ref = x0[-n:].copy()
    what = f"autonomous orbit at p = {p!r}, M = {M} steps, guess period {P0!r}"

    def spread(x: np.ndarray) -> float:   # how far the state's rows differ: 0 at equilibrium
        X = x.reshape(-1, n)
        return float(np.max(X.max(axis=0) - X.min(axis=0)))

    spreads = [spread(x0)]
    try:
        z, res = bordered_newton(lambda q: maps(q[0], p), np.concatenate([x0, [h0]]), 1,
                                 lambda z: _one(phase_row(z[:-1], xdot, ref, 1)), tol=tol,
                                 max_iter=max_iter, what=what, steps=np.array([1e-7 * h0]),
                                 check=lambda z: spreads.append(spread(z[:-1])))
    except ShootingError as e:
        if min(spreads) <= 1e-3 * spreads[0]:   # Newton went for a constant state
            raise ShootingError(f"{what}: Newton went to an equilibrium, not an orbit (the "
                                f"state's rows came to differ by {min(spreads):.3g}, from "
                                f"{spreads[0]:.3g} in the guess), then failed: {e}; start nearer "
                                "the orbit, or from a Hopf point with hopf_orbit",
                                e.residuals) from e
        raise
    o = make_orbit(maps(z[-1], p), z[:-1], res, multipliers, autonomous=True, verify=verify)
    no_equilibrium(o, tol, what)
    k = loops(o.u)
    if k > 1:
        warnings.warn(f"{what}: the orbit found repeats {k} times in its M steps (its least "
                      f"period is about {o.period / k:.6g}, the orbit's {o.period:.6g}): give a "
                      f"guess_period near the period sought, or steps = M / {k}",
                      RuntimeWarning, stacklevel=3)
    return o


def _one(gr: tuple[float, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    return np.array([gr[0]]), gr[1][None, :]
