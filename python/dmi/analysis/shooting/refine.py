# A periodic orbit recomputed at finer steps, its period, amplitude and multipliers extrapolated to
# h = 0 (Richardson) with error estimates.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""refine_orbit: the equation's orbit from the scheme's.

The scheme is first order: a quantity X of the orbit computed with the step h is X* + c1 h +
c2 h^2 + ... where the orbit is smooth in h.  The orbit is recomputed at M, 2 M, 4 M, ... steps a
period (the model takes the step, ``make(p, h=...)``; each level starts from the one before,
resampled), and for each quantity (the period, the amplitude of each component, each leading
multiplier) the levels give:

- the observed order q = log2(|X_0 - X_1| / |X_1 - X_2|) of the last three levels;
- where every quantity shows the scheme's first order (0.7 <= q <= 1.4, or differences at
  rounding level), the values once extrapolated, R_j = 2 X_(j+1) - X_j, are second order: the
  answer is the last R, its error bounded by |R_last - R_before| (three times the O(h^2) term of
  the last R, which is a third of that difference: a margin for the terms beyond), and
  ``order`` is 2;
- elsewhere (a stick-slip orbit: the grid moves the switching times by up to a step, and X is
  not smooth in h) nothing is extrapolated: the answer is the finest level's, its error the
  spread of the levels (the largest difference from the finest), and ``order`` is the smallest
  observed q: it does not claim 2.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.newton import ShootingError
from ..scheme.orbit import Orbit
from .autonomous import autonomous_orbit
from .forced import forced_orbit
from ..scheme.stepmap import build, fixed_step


@dataclass
class Refined:
    """What :func:`refine_orbit` returns: the answers extrapolated to h = 0 where the levels are
    smooth.

    Attributes
    ----------
    period : float
        The period at h = 0 (time units): extrapolated where the levels are smooth, else the
        finest level's.
    amplitude : numpy.ndarray
        Shape (n,): (max - min) / 2 per component at h = 0, as the period (state units).
    multipliers : numpy.ndarray of complex
        The leading Floquet multipliers at h = 0, as the period; largest |mu| first.
    errors : dict
        Their estimated errors, keyed ``"period"``, ``"amplitude"``, ``"multipliers"`` (arrays
        of the same shapes, same units).
    order : float
        The order of those answers as the levels show it (2 after Richardson, else the smallest
        observed order).
    orbits : list of Orbit
        The orbits of the levels, coarsest first.
    steps : list of int
        Their M, the steps per period.
    """
    period: float
    amplitude: np.ndarray
    multipliers: np.ndarray
    errors: dict[str, Any]
    order: float
    orbits: list[Orbit] = field(repr=False)
    steps: list[int] = field(default_factory=list)


def _resampled(o: Orbit, h: float, rows: int) -> np.ndarray:
    """The window of ``rows`` rows at the step h ending at t = 0 (the last row), read off the
    orbit's one period by periodicity and linear interpolation: a guess at a finer step."""
    t = (np.arange(rows) - (rows - 1)) * h
    tt = np.mod(t, o.period) / o.h                  # in steps of the orbit, in [0, M)
    k = np.minimum(np.floor(tt).astype(int), o.steps - 1)
    w = (tt - k)[:, None]
    return ((1 - w) * o.u[k] + w * o.u[k + 1]).ravel()


def _level(o: Orbit, M: int, count: int, tol: float) -> Orbit:
    """The orbit o recomputed at M steps a period."""
    h = o.period / M
    try:
        solver = build(o.make, o.p, h=h)
    except TypeError as e:
        raise ValueError(f"refine_orbit needs a model make(p, h=...) that takes the step, for a "
                         f"forced orbit too ({e})") from e
    guess = _resampled(o, h, solver.N + 1)
    if o.autonomous:
        return autonomous_orbit(o.make, o.p, guess, o.period, steps=M, tol=tol,
                                multipliers=count)
    return forced_orbit(fixed_step(o.make, h), o.p, o.period, guess, tol=tol, multipliers=count)


def _matched(levels: list[np.ndarray]) -> np.ndarray:
    """The multipliers of the levels (k each, largest first) matched to the coarsest's order: for
    each coarse multiplier, the nearest of each finer level not taken yet; (levels, k)."""
    ref = levels[0]
    out = [ref]
    for mu in levels[1:]:
        free = list(range(len(mu)))
        row = []
        for m in ref:
            j = min(free, key=lambda j: abs(mu[j] - m)) if free else None
            row.append(mu[j] if j is not None else np.nan)
            if j is not None:
                free.remove(j)
        out.append(np.array(row))
    return np.array(out)


#: Differences between levels below which there is no order to observe: rounding for the period
#: and amplitudes, the difference quotients' accuracy for the multipliers.
NOISE = {"period": 1e-12, "amplitude": 1e-12, "multipliers": 1e-8}


def _orders(X: np.ndarray, tiny: np.ndarray) -> np.ndarray:
    """The observed orders of the last three levels of X (levels, ...): nan where the differences
    are below ``tiny`` (nothing to observe)."""
    d1, d2 = np.abs(X[-3] - X[-2]), np.abs(X[-2] - X[-1])
    with np.errstate(divide="ignore", invalid="ignore"):
        q = np.log2(d1 / d2)
    return np.where((d1 <= tiny) & (d2 <= tiny), np.nan, q)


def _isolation(o: Orbit) -> str:
    """Why a level may fail: a multiplier at 1 besides an autonomous orbit's phase multiplier
    (to 1e-3) makes the orbit not isolated at fixed p (a vertical branch, a centre)."""
    mu = np.asarray(o.multipliers)
    near = mu[np.abs(mu - 1) <= 1e-3]
    if near.size > (1 if o.autonomous else 0):
        return (f"; the orbit is not isolated at fixed p = {o.p!r}: it has "
                f"{near.size} multiplier(s) at 1 ({', '.join(f'{m:.6g}' for m in near)})"
                f"{', one its phase' if o.autonomous else ''}: it lies on a vertical branch (a "
                "centre, orbits of many amplitudes at the same p), where shooting at fixed p "
                "has no unique solution; refine an orbit of a branch that is not vertical")
    if mu.size == 0:
        return ("; if the orbit lies on a vertical branch (a centre, orbits of many amplitudes "
                "at the same p) it is not isolated at fixed p and cannot be refined (compute "
                "its multipliers to tell)")
    return ""


def refine_orbit(orbit: Orbit, *, levels: int = 3, tol: float = 1e-10) -> Refined:
    """The orbit recomputed at finer steps and extrapolated to h = 0, with error estimates.

    Levels M, 2 M, ..., 2^(levels - 1) M steps a period, each started from the one before; the
    period, amplitudes and leading multipliers (as many as the orbit has) are extrapolated where
    the levels show the scheme's first order (see the module).

    Parameters
    ----------
    orbit : Orbit
        From :func:`periodic_orbit` or :func:`hopf_orbit`; its model must take the step,
        ``make(p, h=...)``, for a forced orbit too.
    levels : int
        Levels (>= 3).
    tol : float
        Newton's tolerance at each level.

    Returns
    -------
    Refined
        ``period``, ``amplitude``, ``multipliers``, ``errors`` (a dict keyed by those three
        names), ``order`` (2 after Richardson; else the smallest observed order), ``orbits``,
        ``steps``.

    Raises
    ------
    ValueError
        levels < 3, or a model that does not take h.
    TypeError
        Not an Orbit of the scheme (an EquationOrbit is the equation's already).
    ShootingError
        A level's shooting fails (the message says when the orbit is not isolated at fixed p:
        a multiplier at 1 besides the phase's, as on a vertical branch).
    """
    if not isinstance(orbit, Orbit):
        raise TypeError(f"refine_orbit: a {type(orbit).__name__}: refine_orbit takes an Orbit of "
                        "the scheme (an EquationOrbit, from collocate, is the equation's already)")
    if int(levels) != levels or levels < 3:
        raise ValueError(f"levels = {levels!r}: give 3 or more (M, 2 M, 4 M, ...)")
    count = int(orbit.multipliers.size)
    orbits = [orbit]
    for j in range(1, int(levels)):
        try:
            orbits.append(_level(orbits[-1], orbit.steps * 2 ** j, count, tol))
        except ShootingError as e:
            raise ShootingError(f"refine_orbit: the level of {orbit.steps * 2 ** j} steps failed: "
                                f"{e}{_isolation(orbit)}", e.residuals) from e
    P = np.array([o.period for o in orbits])
    A = np.array([o.amplitude for o in orbits])
    mu = _matched([o.multipliers for o in orbits]) if count else np.zeros((len(orbits), 0))
    quantities = {"period": P, "amplitude": A, "multipliers": mu}
    scales = {k: NOISE[k] * np.maximum(1.0, np.abs(v[-1])) for k, v in quantities.items()}
    orders = np.concatenate([np.atleast_1d(_orders(v, scales[k])).ravel()
                             for k, v in quantities.items()
                             if k != "period" or orbit.autonomous])
    orders = orders[np.isfinite(orders)]
    smooth = bool(orders.size == 0 or np.all((orders >= 0.7) & (orders <= 1.4)))
    values, errors = {}, {}
    for k, X in quantities.items():
        if smooth:
            R = 2 * X[1:] - X[:-1]
            values[k] = R[-1]
            errors[k] = np.abs(R[-1] - R[-2])
        else:
            values[k] = X[-1]
            errors[k] = np.max(np.abs(X[:-1] - X[-1]), axis=0)
    order = 2.0 if smooth else float(np.min(orders))
    return Refined(period=float(values["period"]), amplitude=np.asarray(values["amplitude"]),
                   multipliers=np.asarray(values["multipliers"]),
                   errors={"period": float(errors["period"]),
                           "amplitude": np.asarray(errors["amplitude"]),
                           "multipliers": np.asarray(errors["multipliers"])},
                   order=order if math.isfinite(order) else 2.0, orbits=orbits,
                   steps=[o.steps for o in orbits])
