# A periodic orbit of the scheme: its record, its stick profile, its multipliers.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The :class:`Orbit` record made at a fixed point of the step map, with the helpers that read a
period's states: where a friction component sticks, and how many times the period loops."""
from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np

from ... import _resolvent as rule

from .floquet import Floquet, StabilityWarning, Verify, floquet_verdict
from .stepmap import Model, StepMap

@dataclass
class Orbit:
    """A periodic orbit of the scheme.

    Attributes
    ----------
    p : float
        The parameter.
    period : float
        ``steps`` h (time units).
    steps : int
        M, the steps of one period.
    h : float
        The step (time units).
    t : numpy.ndarray, shape (M + 1,)
        The times of one period from t = 0 (time units).
    u : numpy.ndarray
        Shape (M + 1, n): U over that period (state units).
    state : numpy.ndarray
        The shooting state: L n values, rows oldest first, the last at t = 0.
    multipliers : numpy.ndarray of complex
        The leading Floquet multipliers, largest |mu| first (their error bounds:
        ``floquet.errors``).
    stable : bool or None
        True: verified stable, all |mu| < 1 beyond their errors (an autonomous orbit: all but
        its trivial multiplier, found by its vector along the velocity); False: verified
        unstable; None: not decided (no multipliers computed, or neither the multipliers nor
        a plain run decided: ``floquet.reason`` says why, and a :class:`StabilityWarning` was
        issued).  Test it with ``is True`` / ``is False``: None is falsy.
    stick_fraction : numpy.ndarray
        Shape (n,): the fraction of the M steps where component i is stuck (:func:`stuck_mask`: U_i
        == 0 exactly after the friction resolvent, for 2 steps or more).
    iterations : int
        Newton iterations.
    residual : float
        The final |F(x) - x|_inf (state units).
    make : callable
        The model ``make(p) -> dmi.Solver``.
    rows : int
        L, the rows of the shooting state.
    autonomous : bool
        True for an orbit of free period (its phase's multiplier is 1).
    floquet : Floquet or None
        The multipliers' errors, vectors, the trivial one's index and the verdict's reason
        (:func:`dmi.analysis.floquet_verdict`); None without multipliers.
    """
    p: float
    period: float
    steps: int
    h: float
    t: np.ndarray
    u: np.ndarray
    state: np.ndarray
    multipliers: np.ndarray
    stable: bool | None
    stick_fraction: np.ndarray
    iterations: int
    residual: float
    make: Model = field(repr=False)
    rows: int = 0
    autonomous: bool = False
    floquet: Floquet | None = field(default=None, repr=False)

    @property
    def amplitude(self) -> np.ndarray:
        """(max - min) / 2 of each component over the period (state units)."""
        return 0.5 * (self.u.max(axis=0) - self.u.min(axis=0))

    def _repr_html_(self) -> str:
        from ..plot.interactive import orbit_summary
        return orbit_summary(self)



def stuck_mask(u: np.ndarray) -> np.ndarray:
    """(M, n) booleans: step k (row k + 1 of u, M + 1 rows of one period) is stuck in component
    i: U_i == 0 exactly (the friction resolvent's value in its dead zone |X_i| <= h alpha_i)
    within a run of at least 2 such steps, on the period's circle.  A lone zero step is the
    scheme's transversal crossing of a velocity reversal (|net force| > alpha: the next step
    leaves zero), not a stick."""
    z = np.asarray(u)[1:]
    modes = rule.friction_mode(np.roll(z, 1, axis=0), z, np.roll(z, -1, axis=0))
    return modes == rule.STUCK


def stick_fraction(u: np.ndarray) -> np.ndarray:
    """Fraction of the steps of one period (u: M + 1 rows) that are stuck (:func:`stuck_mask`)."""
    return np.mean(stuck_mask(u), axis=0)


def make_orbit(F: StepMap, x: np.ndarray, res: list[float], multipliers: int,
               autonomous: bool = False, verify: Verify | None = None) -> Orbit:
    """The Orbit at the fixed point x of F (one more run for t, u; the multipliers, verified by
    :func:`dmi.analysis.floquet_verdict` with ``verify``).  An ``autonomous`` orbit's ``stable``
    leaves out its trivial multiplier; ``stable`` None (with a StabilityWarning) when nothing
    decided, or without multipliers."""
    U = F.trajectory(x)
    fl = None
    if multipliers > 0:
        fl = floquet_verdict(F, x, multipliers, autonomous=autonomous, verify=verify)
        if fl.stable is None:
            warnings.warn(f"periodic orbit at p = {F.p!r}: stability not decided: {fl.reason}",
                          StabilityWarning, stacklevel=3)
    mu = fl.multipliers[:multipliers] if fl else np.empty(0, complex)
    return Orbit(p=F.p, period=F.M * F.h, steps=F.M, h=F.h, t=np.arange(F.M + 1) * F.h, u=U,
                 state=x, multipliers=mu, stable=fl.stable if fl else None,
                 stick_fraction=stick_fraction(U), iterations=len(res) - 1, residual=res[-1],
                 make=F.make, rows=F.L, autonomous=autonomous, floquet=fl)


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

