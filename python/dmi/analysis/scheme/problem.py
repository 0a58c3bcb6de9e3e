# The problem of a continuation: the model, its step policy and one cache of what is built from it.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""One value for what every analysis builds from a model ``make(p) -> dmi.Solver``.

A :class:`Problem` holds the model, its step policy (the model keeps its own step h, or gets
h through ``make(p, h=...)``), one cache of the recent objects built from it (a
:class:`dmi._cache.Cache`: step maps, one-step maps of equilibria: each built once per key), and the probe solvers read for h, tau
and N through Solver's public accessors (built once per (p, h), never run; the map at (p, h)
takes the probe over, ``Problem.probe(..., take=True)``).  The memory a
step h needs, N = ceil(tau / h) steps, is asked of the probe (:meth:`Problem.probe`): one
place for the rule.  The step maps of a model whose step h is free (autonomous orbits) by (h,
p): :class:`AutonomousMaps`, in the same cache; the phase condition through a point of an
autonomous orbit: :func:`phase_row` with :func:`velocity`.
"""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from ..._cache import Cache
from ..._solver import Solver
from ..core.newton import ShootingError
from .stepmap import Model, StepMap, build, fixed_step, user_model

#: Objects the cache keeps (the least recently used goes first).
KEEP = 8


class AtQ:
    """make2 at a fixed q as a one-parameter model make(p) (picklable where make2 is)."""

    def __init__(self, make2: Callable[[float, float], Solver], q: float):
        self.make2, self.q = make2, float(q)

    def __call__(self, p: float) -> Solver:
        return self.make2(p, self.q)


class Problem:
    """A model, its step policy and one cache of recent objects built from it.

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver`` (configured, not initialised); with ``make(p,
        h=...)`` when the step is given.
    keep : int
        Objects the cache keeps.
    """

    def __init__(self, make: Model, keep: int = KEEP):
        self.model = make                        # make(p) as given
        self.make = user_model(make)
        self.keep = int(keep)
        self._cache = Cache(keep)

    def solver(self, p: float, h: float | None = None) -> Solver:
        """A new solver of the model at p (and the step h when given).

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step (the model must take ``h=``).

        Returns
        -------
        dmi.Solver
            Configured, not initialised; the caller owns it.

        Raises
        ------
        Exception
            The model's own, with a note naming the call.
        """
        if h is None:
            return build(self.model, p)
        return build(self.make, p, h=h)

    def cached(self, key: Any, factory: Callable[[], Any]) -> Any:
        """The object cached under key, built by factory() when absent.

        Parameters
        ----------
        key : hashable
            What the object is of (its kind, p, h, ...).
        factory : callable
            Builds it.

        Returns
        -------
        object
            The cached or new object.
        """
        return self._cache.cached(key, factory)

    def probe(self, p: float, h: float | None = None, *, take: bool = False) -> Solver:
        """The probe solver at (p, h): read for its h, tau, N (N = ceil(tau / h), the memory a
        step needs) and model, never run while cached.

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step.
        take : bool
            Take it out of the cache (or build one): the caller owns it and may initialise it,
            so that a solver read for N is not built twice (a step map's).

        Returns
        -------
        dmi.Solver
            Configured, not initialised.
        """
        key = ("probe", float(p), h)
        if take:
            got = self._cache.pop(key)
            return got if got is not None else self.solver(p, h)
        return self.cached(key, lambda: self.solver(p, h))



def step_model(problem: Problem, p: float, h: float, take: bool = False) -> Solver:
    """The problem's probe solver make(p, h=h) (taken out of the cache with ``take``), with a
    model that does not take the step named."""
    try:
        return problem.probe(p, h, take=take)
    except TypeError as e:
        if "h" in str(e) or "argument" in str(e):
            raise ValueError(f"an autonomous orbit needs a model make(p, h=...) that takes the "
                             f"step ({e})") from e
        raise


class AutonomousMaps:
    """The StepMaps of make(p, h=h) by (h, p) on states of ``rows`` rows, in the cache of a
    :class:`dmi.analysis.scheme.problem.Problem`; a step h <= h_min, or an N + 1 above ``rows``, is
    refused (ShootingError)."""

    def __init__(self, make: Model, M: int, rows: int, h_min: float,
                 problem: Problem | None = None):
        self.make, self.M, self.rows, self.h_min = make, int(M), int(rows), float(h_min)
        self.problem = Problem(make) if problem is None else problem

    def __call__(self, h: float, p: float) -> StepMap:
        return self.problem.cached(("map", float(p), float(h), self.M, self.rows),
                                   lambda: self._new(float(h), float(p)))

    def _new(self, h: float, p: float) -> StepMap:
        if not h > self.h_min:
            raise ShootingError(f"the period M h went to {self.M * h:.6g} (h = {h:.6g}), "
                                f"below the least the state holds, {self.M * self.h_min:.6g}: "
                                f"the guess period is too long for the orbit (a period near "
                                f"the orbit's?), or there is no orbit near the guess", [])
        s = step_model(self.problem, p, h, take=True)
        if s.N + 1 > self.rows:
            raise ShootingError(f"the period M h went to {self.M * h:.6g}: its N + 1 = "
                                f"{s.N + 1} steps of memory exceed the {self.rows} rows the "
                                "state holds (the guess period is too long for the orbit?)", [])
        return StepMap(fixed_step(self.make, h), p, self.M, self.rows, solver=s)


def velocity(U: np.ndarray, h: float) -> np.ndarray:
    """The velocity at t = 0 of one period U (M + 1 rows), by a central difference across it."""
    M = U.shape[0] - 1
    return (U[1] - U[M - 1]) / (2 * h) if M > 1 else (U[1] - U[0]) / h


def phase_row(x: np.ndarray, xdot: np.ndarray, ref: np.ndarray, k: int
              ) -> tuple[float, np.ndarray]:
    """The phase condition <xdot, x_0 - ref> (x_0 the last row of x) and its row over (x, q)."""
    n = xdot.size
    row = np.zeros(x.size + k)
    row[x.size - n:x.size] = xdot
    return float(np.dot(xdot, x[-n:] - ref)), row
