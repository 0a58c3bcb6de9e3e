# dmi.identify.profile: the profile likelihood of one parameter and its likelihood-ratio interval.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The profile of one parameter of an :class:`Estimate`: the least cost with that parameter fixed
and the others refitted, its likelihood-ratio interval, and the Wald interval beside it."""
from __future__ import annotations

import dataclasses
import math
import warnings
from collections.abc import Callable

import numpy as np
from scipy import optimize, stats

from .fitting import Estimate, _index, _Problem


@dataclasses.dataclass
class Profile:
    """The profile of one parameter.

    Attributes
    ----------
    name : str
        The parameter.
    values : numpy.ndarray, shape (k,)
        The values at which it was fixed, increasing (the estimate's among them).
    cost : numpy.ndarray, shape (k,)
        The least cost there (the other free parameters refitted).
    p : numpy.ndarray, shape (k, P)
        The refitted parameters there.
    threshold : float
        The cost increase that bounds the interval: chi2(level, 1) / 2 with sigma known (and the
        covariance not scaled), else cost * F(level; 1, dof) / dof.
    interval : tuple of float
        The likelihood-ratio interval (low, high); an end the profile did not reach within
        ``max_steps`` or within the fit's bounds, or reached only through a refit that did not
        converge (a RuntimeWarning then says so), is -inf or inf.
    wald : tuple of float
        The covariance (Wald) interval.
    level : float
        The confidence level.
    quadratic : bool
        Whether the two intervals agree to 10 % of the Wald half-width at both ends (the cost is
        then close to quadratic there).
    message : str
        What the comparison says.
    """

    name: str
    values: np.ndarray
    cost: np.ndarray
    p: np.ndarray
    threshold: float
    interval: tuple
    wald: tuple
    level: float
    quadratic: bool
    message: str


def profile_likelihood(estimate: Estimate, index: int | str, *, level: float = 0.95,
                       step: float | None = None, max_steps: int = 12) -> Profile:
    """The profile likelihood of one fitted parameter and its likelihood-ratio interval.

    Parameters
    ----------
    estimate : Estimate
        A result of :func:`estimate`.
    index : int or str
        The parameter, by position or name; it must have been fitted.
    level : float, optional
        Confidence level in (0, 1).
    step : float, optional
        Spacing of the profile's points (default: half the standard error, or 5 % of the value
        when the standard error is not finite).
    max_steps : int, optional
        Most points on each side before the interval's end is declared not reached.

    Returns
    -------
    Profile
        The profile, the likelihood-ratio and Wald intervals, and whether they agree.

    Raises
    ------
    ValueError
        A parameter that was not fitted, an unknown one, a level outside (0, 1), an estimate
        without its problem (not made by :func:`estimate`), or one that did not converge
        (``success`` False).
    """
    i, thr, step = _setup(estimate, index, level, step)
    base: _Problem = estimate._problem
    p_hat, c_hat = estimate.p.copy(), estimate.cost
    free = base.free.copy()
    free[i] = False
    cache: dict[float, tuple[float, np.ndarray]] = {}
    unconverged: set[float] = set()      # the values whose refit stopped before converging

    def prof(v: float, start: np.ndarray) -> tuple[float, np.ndarray]:
        if v in cache:
            return cache[v]
        q = start.copy()
        q[i] = v
        sub = _Problem(base.makes, q, free, base.data, base.rhs)
        lo, hi = base.bounds
        if free.any():
            res = optimize.least_squares(sub.residuals, q[free], jac=sub.jacobian, method="trf",
                                         x_scale="jac", bounds=(lo[free], hi[free]))
            out = (float(res.cost), sub.full(res.x))
            if res.status <= 0:
                unconverged.add(v)
        else:
            r = sub.residuals(np.empty(0))
            out = (0.5 * float(r @ r), q)
        cache[v] = out
        return out

    cache[float(p_hat[i])] = (c_hat, p_hat)
    ends = []
    unverified = []                      # the ends found through a refit that did not converge
    for sign in (-1.0, 1.0):
        end, verified = _end(prof, unconverged, p_hat, c_hat, i, sign, step, max_steps, thr,
                             base.bounds)
        if not verified:
            unverified.append(end)
            end = sign * math.inf
        ends.append(end)
    values = np.array(sorted(cache))
    wald = estimate.wald_interval(i, level)
    quadratic, message = _verdict(ends, wald, unverified, max_steps)
    if unverified:
        warnings.warn(message, RuntimeWarning, stacklevel=2)
    return Profile(name=estimate.names[i], values=values, cost=np.array([cache[v][0] for v in values]),
                   p=np.array([cache[v][1] for v in values]), threshold=thr,
                   interval=(ends[0], ends[1]), wald=wald, level=level, quadratic=quadratic,
                   message=message)


def _setup(estimate: Estimate, index: int | str, level: float, step: float | None
           ) -> tuple[int, float, float]:
    """(i, threshold, step): the profiled parameter's index, the cost increase that bounds the
    interval and the profile's spacing, after checking the estimate, the parameter and the level
    (ValueError naming the one at fault)."""
    if not isinstance(estimate, Estimate) or estimate._problem is None:
        raise ValueError("profile_likelihood: expected an Estimate returned by dmi.identify.estimate")
    if not estimate.success:
        raise ValueError(f"profile_likelihood: the estimate did not converge ({estimate.message}); its "
                         "cost is not a verified minimum, so no likelihood-ratio interval can be "
                         "measured from it: refit (more max_nfev, another p0 or multistart) and "
                         "profile a converged estimate")
    i = _index(index, estimate.names)
    if not estimate.free[i] and estimate.names[i] not in estimate.insensitive:
        # (a parameter kept at p0 for having no effect there is profiled: its profile says
        # where it starts to matter)
        raise ValueError(f"parameter {estimate.names[i]!r} was fixed in the fit; profile a fitted one")
    if not 0.0 < level < 1.0:
        raise ValueError(f"level = {level!r}: expected a number in (0, 1)")
    c_hat = estimate.cost
    if estimate.sigma_known and not estimate.covar_scaled:
        thr = float(stats.chi2.ppf(level, 1)) / 2.0
    else:
        thr = c_hat * float(stats.f.ppf(level, 1, max(estimate.dof, 1))) / max(estimate.dof, 1)
    se = estimate.stderr[i]
    if step is None:   # (a parameter without effect at p0 has no finite se: steps of its size)
        least = 1.0 if estimate.names[i] in estimate.insensitive else 1e-12
        p_i = estimate.p[i]
        step = 0.5 * se if np.isfinite(se) and se > 0 else 0.05 * max(abs(p_i), least)
    return i, thr, step


def _end(prof: Callable[[float, np.ndarray], tuple[float, np.ndarray]], unconverged: set[float],
         p_hat: np.ndarray, c_hat: float, i: int, sign: float, step: float, max_steps: int,
         thr: float, bounds: tuple[np.ndarray, np.ndarray]) -> tuple[float, bool]:
    """(end, verified): where the profile prof (the least cost at p_i = v, refitted from a start)
    crosses c_hat + thr on the side ``sign`` of p_hat[i], walked in steps of ``step`` and
    placed by Brent between the last two; sign inf where it does not within max_steps or the
    bounds.  Not verified where a refit on the way did not converge (its cost is overstated)."""
    prev_v, prev = float(p_hat[i]), (c_hat, p_hat)
    for k in range(1, max_steps + 1):
        v = float(p_hat[i] + sign * k * step)
        if not bounds[0][i] <= v <= bounds[1][i]:
            break                    # the fit's bounds: the end is not reached within them
        cur = prof(v, prev[1])
        if cur[0] - c_hat > thr:
            def excess(x: float, _start: np.ndarray = prev[1]) -> float:
                return prof(float(x), _start)[0] - c_hat - thr
            a, b = sorted((prev_v, v))
            before = set(unconverged)
            end = optimize.brentq(excess, a, b, xtol=1e-3 * step)
            # a refit stopped early overstates the cost: the crossing is then not verified
            return end, not (v in unconverged or unconverged - before)
        prev_v, prev = v, cur
    return sign * math.inf, True


def _verdict(ends: list[float], wald: tuple, unverified: list[float], max_steps: int
             ) -> tuple[bool, str]:
    """(quadratic, message): whether the likelihood-ratio interval ``ends`` agrees with the Wald
    interval to 10 % of its half-width at both ends, and what the comparison says."""
    half = 0.5 * (wald[1] - wald[0])
    quadratic = bool(np.isfinite(half) and all(np.isfinite(ends))
                     and abs(ends[0] - wald[0]) <= 0.1 * half and abs(ends[1] - wald[1]) <= 0.1 * half)
    if unverified:
        message = (f"a refit of the other parameters did not converge near {unverified}: the "
                   "profile's crossing there is not verified and that end is reported as infinite")
    elif quadratic:
        message = "the likelihood-ratio and Wald intervals agree: the cost is close to quadratic"
    elif not any(np.isfinite(ends)):
        message = (f"the profile stays below the threshold within {max_steps} steps (or the bounds) "
                   "on both sides: the data bound the parameter neither below nor above")
    elif not all(np.isfinite(ends)):
        side = "below" if not np.isfinite(ends[0]) else "above"
        message = (f"the profile stays below the threshold within {max_steps} steps (or the bounds) "
                   f"on one side: the data do not bound the parameter {side}")
    else:
        message = ("the likelihood-ratio interval differs from the Wald interval: the cost is not "
                   "quadratic there; trust the likelihood-ratio interval")
    return quadratic, message
