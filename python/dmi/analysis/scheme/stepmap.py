# The M-step map of the scheme on windows of stored states, and the model's construction.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The step map shared by shooting, Floquet multipliers and continuation.

A *model* is a function ``make(p) -> dmi.Solver`` returning a configured solver (rhs, friction,
box or resolvent, kernel, convolution method), not initialised, for the parameter value ``p``.

The state of the M-step map is the *window*: the last L >= N + 1 stored states, oldest first,
flattened (L n values; L = N + 1 unless the caller asks for more, see :class:`StepMap`).  A
forced orbit of period P = M h starts at t = 0: the map is ``init``, ``set_window`` (the last
N + 1 rows), ``run(M)``, and the last L rows of the old rows followed by the M new ones.  Its
fixed points are the M-periodic solutions of the scheme; its Jacobian has the nonzero spectrum of
the window map's (extra old rows are a nilpotent block), whose eigenvalues are the Floquet
multipliers.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from ..._make import call_make
from ..._solver import Solver

Model = Callable[..., Solver]


def user_model(make: Model) -> Model:
    """The user's model behind make: a :class:`FixedStep`'s own, else make itself."""
    return getattr(make, "base", make)


class FixedStep:
    """A model at a fixed step: ``FixedStep(make, h)(p)`` is ``make(p, h=h)``, and
    ``(p, h=other)`` another step (an autonomous Orbit's ``make``).  A class, not a closure, so
    that the branches and orbits holding it pickle (when ``make`` does).

    Parameters
    ----------
    make : callable
        The model ``make(p, h=...) -> dmi.Solver`` (a FixedStep's own model is taken).
    h : float
        The step.
    """

    def __init__(self, make: Model, h: float):
        self.base = user_model(make)
        self.h = float(h)

    def __call__(self, p: float, h: float | None = None) -> Solver:
        """make(p, h=h).

        Parameters
        ----------
        p : float
            The parameter.
        h : float, optional
            The step (default the fixed one).

        Returns
        -------
        dmi.Solver
            The model's solver.
        """
        return self.base(p, h=self.h if h is None else h)

    def __repr__(self) -> str:
        return f"FixedStep({self.base!r}, h={self.h!r})"


def fixed_step(make: Model, h: float) -> Model:
    """make at the step h: a :class:`FixedStep` (``made(p)`` is ``make(p, h=h)``, and
    ``made(p, h=other)`` another step)."""
    return FixedStep(make, h)


def build(make: Model, p: float, **kw: Any) -> Solver:
    """``make(p, **kw)``: the model's own exception, with a note naming the call, when it
    fails (:func:`dmi._make.call_make`); TypeError when it returns no dmi.Solver."""
    return call_make(make, p, **kw)

def positive_time(name: str, value: Any) -> float:
    """value as a float, finite and > 0 (a period, time units); ValueError naming it otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} = {v}: must be finite and > 0 (time units)")
    return v


def steps_per_period(h: float, period: float) -> int:
    """M = period / h, which must be a whole number (to 1e-9 relative); ValueError otherwise."""
    period = positive_time("period", period)
    M = round(period / h)
    if M < 1 or abs(M * h - period) > 1e-9 * period:
        raise ValueError(f"period = {period!r} is not a whole number of steps h = {h!r} "
                         f"(period / h = {period / h!r}); choose N (or h) so that h divides it")
    return M


class StepMap:
    """The M-step map x -> F(x) of the model at p on states of L rows (L >= N + 1).

    One solver is made and initialised once; every evaluation restores its step counter to 0
    (``load_state`` of the state saved after ``init``), sets the window and runs M steps.
    ``evaluations`` counts the calls (each costs M steps).

    Parameters
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``.
    p : float
        The parameter.
    M : int
        Steps of the map (a period).
    rows : int, optional
        L, the state's rows (default N + 1; extra rows are a nilpotent block).
    solver : dmi.Solver, optional
        ``make(p)`` already built by the caller (not initialised).

    Raises
    ------
    ValueError
        rows < N + 1.
    Exception
        The model's own, when ``make(p)`` fails (a note names the call).
    """

    def __init__(self, make: Model, p: float, M: int, rows: int | None = None,
                 solver: Solver | None = None):
        self.make, self.p, self.M = make, float(p), int(M)
        # solver: make(p) already built by the caller (not initialised), else built here
        self.solver = build(make, self.p) if solver is None else solver
        self.n, self.N, self.h = self.solver.n, self.solver.N, self.solver.h
        self.L = self.N + 1 if rows is None else int(rows)
        if self.L < self.N + 1:
            raise ValueError(f"rows = {self.L} < N + 1 = {self.N + 1}")
        self.solver.init()
        self._start = self.solver.save_state()
        self.evaluations = 0

    @property
    def dim(self) -> int:
        """The state's size, L n values."""
        return self.L * self.n

    def _start_at(self, x: np.ndarray) -> Solver:
        """The solver at step 0 with the window the last N + 1 rows of x (one evaluation)."""
        X = np.asarray(x, dtype=float).reshape(self.L, self.n)
        s = self.solver
        s.load_state(self._start)
        s.set_window(X[self.L - self.N - 1:])
        self.evaluations += 1
        return s

    def trajectory(self, x: np.ndarray, periods: int = 1) -> np.ndarray:
        """The states of a run from a state, in the model's own time from t = 0.

        Parameters
        ----------
        x : numpy.ndarray
            A state (L n values).
        periods : int
            Periods to run (one evaluation).

        Returns
        -------
        numpy.ndarray
            Shape (periods M + 1, n): U^0 .. U^(periods M) (U^0 is x's last row).
        """
        return self._start_at(x).run(int(periods) * self.M)[1]

    def trajectory_terms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The trajectory and the resolvent's arguments, from one run.

        Parameters
        ----------
        x : numpy.ndarray
            A state (L n values).

        Returns
        -------
        tuple of numpy.ndarray
            U, shape (M + 1, n), as :meth:`trajectory`; X, shape (M, n): X^k the resolvent's
            argument of the step into U^(k+1).
        """
        _, U, X = self._start_at(x).run_terms(self.M)
        return U, X

    def extend(self, x: np.ndarray) -> np.ndarray:
        """A state of k rows as one of L rows.

        The older rows by M-periodicity from one run, the row at t = -j being U^(M - j mod M)
        (exact at an M-periodic orbit; a guess elsewhere); the last L rows when k >= L.

        Parameters
        ----------
        x : numpy.ndarray
            k >= N + 1 rows of n, flattened.

        Returns
        -------
        numpy.ndarray
            L n values.

        Raises
        ------
        ValueError
            k < N + 1.
        """
        X = np.asarray(x, dtype=float).reshape(-1, self.n)
        k = X.shape[0]
        if k >= self.L:
            return X[k - self.L:].ravel()
        if k < self.N + 1:
            raise ValueError(f"a state of {k} rows; the map reads N + 1 = {self.N + 1}")
        s = self.solver
        s.load_state(self._start)
        s.set_window(X[k - self.N - 1:])
        U = s.run(self.M)[1]
        out = np.empty((self.L, self.n))
        out[self.L - k:] = X
        for j in range(k, self.L):
            out[self.L - 1 - j] = U[(self.M - j) % self.M]
        return out.ravel()

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """F(x): the last L rows of x's rows followed by U^1 .. U^M.  Only the last L rows are
        read back: M - (L - N - 1) steps in C (advance), the window, and a run of the last
        L - N - 1 steps (none when L = N + 1)."""
        tail = self.L - self.N - 1
        K = self.M - tail
        if K < 0:  # fewer steps than extra rows: older rows of x move up
            X = np.asarray(x, dtype=float).reshape(self.L, self.n)
            return np.concatenate([X, self.trajectory(X)[1:]])[-self.L:].ravel()
        s = self._start_at(x)
        s.advance(K)
        W = s.get_window()
        if tail:
            W = np.concatenate([W, s.run(tail)[1][1:]])
        return W.ravel()


def guess_rows(guess: Any, n: int, N: int, most: int | None = None) -> np.ndarray:
    """A guess given as values: n values (a constant window of ``most`` or N + 1 rows) or k rows
    of n, N + 1 <= k (<= most when given), flattened; the shooting of forced and autonomous
    orbits both read their guesses here.

    Parameters
    ----------
    guess : array_like
        The values.
    n : int
        The model's n.
    N : int
        Its memory: the map reads N + 1 rows.
    most : int, optional
        The most rows the state holds (L).

    Returns
    -------
    numpy.ndarray
        k n values.

    Raises
    ------
    ValueError
        A value that is not finite (its index named), or a shape that is none of these.
    """
    x0 = np.asarray(guess, dtype=float).ravel()
    bad = np.flatnonzero(~np.isfinite(x0))
    if bad.size:
        where = ", ".join(f"row {i // n} component {i % n} = {float(x0[i])!r}"
                          for i in bad[:4])
        raise ValueError(f"guess has {bad.size} non-finite value(s) ({where}"
                         f"{', ...' if bad.size > 4 else ''}): give finite values")
    if x0.size == n:
        x0 = np.tile(x0, most if most is not None else N + 1)   # a constant window
    k = x0.size // n
    if x0.size % n or k < N + 1 or (most is not None and k > most):
        upper = f" <= k <= L = {most}" if most is not None else " <= k"
        raise ValueError(f"guess has {x0.size} values (shape {np.shape(guess)}); the model has "
                         f"n = {n}: give n = {n} values (a constant window), or k rows of n, "
                         f"N + 1 = {N + 1}{upper} (an (k, {n}) array or k {n} values), the "
                         "last at t = 0, or a dmi.Solver run onto the orbit")
    return x0


def state_of(solver: Solver, M: int) -> np.ndarray:
    """The window (N + 1 rows, flattened) of a solver run onto an orbit of M steps, at the next
    step index that is a multiple of M (the orbit's phase 0): the solver is advanced there and
    then restored (``save_state`` / ``load_state``), so it is left as it was."""
    saved = solver.save_state()
    try:
        solver.advance((-solver.step_index) % M)
        return solver.get_window().ravel()
    finally:
        solver.load_state(saved)
