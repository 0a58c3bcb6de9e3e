# The events of a branch of periodic orbits: multipliers' and stick patterns' changes.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Events between consecutive points of a branch of periodic orbits of the scheme.

- ``period-doubling``: the number of real multipliers < -1 changes;
- ``torus``: the number of complex multipliers with |mu| > 1 changes;
- ``stick-onset``: a component starts (or stops) sticking somewhere in the period: its number
  of stuck steps goes from 0 to > 0 (or back);
- ``grazing``: a component's number of stick phases changes while it sticks on both sides.

The multipliers' events are placed by the linear interpolation of their test function
(:func:`test_function`; from the refined multipliers with ``refine=True``,
:func:`dmi.analysis.orbits.refined_event`), the stick events by the driver's bisection along the
branch (:func:`dmi.analysis.continuation.driver.bisect_along`, called by
:meth:`dmi.analysis.branches.shooting.Shooting.between`).  The fold is the driver's
(:mod:`dmi.analysis.continuation.driver`).  A point's stick profile and margins: :func:`stick_profile`.

Verified multipliers' events: where the points carry error bounds of their multipliers (a
scheme's branch with ``verify=``: ``BranchPoint.floquet.errors``; a collocated branch:
``EquationOrbit.errors["multipliers"]``), a period doubling or a torus is reported only when, on
both points, every multiplier of its kind (real negative; non-real) is off the unit circle by
more than its error bound (:func:`undecided`); otherwise no event is reported and an
:class:`EventWarning` says why.  On a collocated branch the test functions are 0 where they lie
within the error bound of their multiplier (:func:`verified_tests`), so that the driver sees a
sign change only between points on which it is verified.  A scheme's branch without
``verify=`` has no error bounds: its events are the Ritz multipliers' (of the scheme), as
before.
"""
from __future__ import annotations

import math
import warnings

import numpy as np

from ..continuation.branch import BranchPoint, Event, EventWarning, non_real
from ..scheme.floquet import phase_free
from ..scheme.orbit import stuck_mask
from ..scheme.stepmap import StepMap
from ..._resolvent import reaches_zero


def stick_profile(F: StepMap, U: np.ndarray, X: np.ndarray | None
                   ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Stuck steps, stick phases and margins (see the module) over one period, from its M + 1
    states U and the resolvent's arguments X of its M steps (:meth:`StepMap.trajectory_terms`);
    X None: the margins are NaN."""
    stuck = stuck_mask(U)
    steps = stuck.sum(axis=0)
    # stick phases on the circle: starts of runs of stuck steps
    phases = np.sum(stuck & ~np.roll(stuck, 1, axis=0), axis=0)
    phases[steps == F.M] = 1
    margin = np.full(F.n, np.nan if X is None else np.inf)
    if X is None:
        return steps, phases, margin
    u0, u1 = U[:-1], U[1:]          # U^p and U^(p+1) of the steps p = 0 .. M - 1
    for i in range(F.n):
        slip = (u1[:, i] != 0.0) & (X[:, i] != u1[:, i])
        if not slip.any():
            continue                    # no friction on this component
        alpha = float(np.median(np.abs(X[slip, i] - u1[slip, i]))) / F.h
        # the steps where the velocity reaches 0 or crosses it (all steps of a component stuck
        # throughout), and the force there besides friction, |X - U^p| / h
        entry = reaches_zero(u0[:, i], u1[:, i])
        if not entry.any():
            entry = stuck[:, i]
        if entry.any():
            margin[i] = float(np.min(np.abs(X[entry, i] - u0[entry, i]))) / F.h - alpha
    return steps, phases, margin



def test_function(kind: str, mu: np.ndarray) -> float:
    """The test function of a multiplier event, zero at it: 1 + min Re mu for a period doubling
    (the multiplier that crosses -1 may have been half of a complex pair at the previous point,
    a pair that met on the negative axis), max |mu| - 1 over the non-real multipliers for a
    torus (-1 if there is none)."""
    if kind == "period-doubling":
        return 1 + float(np.min(mu.real))
    c = np.abs(non_real(mu))
    return float(np.max(c)) - 1 if c.size else -1.0


#: The multipliers' events and the multipliers each reads.
KINDS = {"period-doubling": "real negative", "torus": "non-real"}


def _of_kind(kind: str, mu: np.ndarray) -> np.ndarray:
    """The indices of the multipliers a ``kind`` event reads: the real negative ones (a period
    doubling), the non-real ones (a torus)."""
    real = np.abs(mu.imag) <= 1e-8 * np.maximum(np.abs(mu), 1)
    return np.flatnonzero(real & (mu.real < 0) if kind == "period-doubling" else ~real)


def undecided(kind: str, mu: np.ndarray, err: np.ndarray) -> str | None:
    """Why the multipliers mu (errors err) do not decide a ``kind`` event, or None: a multiplier
    of its kind whose distance to the unit circle is not larger than its error bound (a nan
    bound decides nothing).

    Parameters
    ----------
    kind : str
        ``"period-doubling"`` or ``"torus"``.
    mu : numpy.ndarray of complex
        The multipliers (the trivial one left out).
    err : numpy.ndarray of float
        Their error bounds, same shape.

    Returns
    -------
    str or None
        The multiplier, its distance and its bound; None when every multiplier of the kind is
        off the circle by more than its bound.

    Raises
    ------
    ValueError
        ``kind`` is not a multipliers' event, or ``err`` has another shape than ``mu``.
    """
    if kind not in KINDS:
        raise ValueError(f"kind = {kind!r}: expected one of {sorted(KINDS)}")
    mu, err = np.asarray(mu, dtype=complex), np.asarray(err, dtype=float)
    if err.shape != mu.shape:
        raise ValueError(f"{err.shape} error bounds for {mu.shape} multipliers")
    for j in _of_kind(kind, mu):
        d = abs(abs(mu[j]) - 1.0)
        if not d > err[j]:
            return (f"the {KINDS[kind]} multiplier {mu[j]:.12g} is {d:.3g} from the unit circle, "
                    f"within its error bound {err[j]:.3g}: the multipliers' error bound is "
                    "larger than their distance to the circle")
    return None


def _doubling(mu: np.ndarray, err: np.ndarray) -> tuple[float, int | None]:
    """The period doubling's test function, -prod (1 + mu) over the multipliers left of the
    imaginary axis (0 where one is -1; of the sign of the number of real multipliers below -1,
    positive when it is odd; continuous where a complex pair meets on the negative axis and
    splits, so that a pair that meets inside the circle and then crosses -1 changes its sign),
    and the index of a multiplier that decides nothing (a real negative one within its error
    bound of the unit circle, a complex one within its bound of -1), None when none does."""
    left = np.flatnonzero(mu.real < 0)
    real = set(_of_kind("period-doubling", mu).tolist())
    for j in left:
        d = abs(abs(mu[j]) - 1.0) if j in real else abs(1.0 + mu[j])
        if not d > err[j]:
            return 0.0, int(j)
    return -float(np.prod(1.0 + mu[left]).real), None


def verified_tests(mu: np.ndarray, err: np.ndarray, p: float) -> dict[str, float]:
    """The multipliers' test functions of a point with error bounds (a collocated branch's):
    ``period-doubling`` -prod (1 + mu) over the multipliers left of the imaginary axis (its
    sign changes where a real multiplier crosses -1, also one split off a complex pair that met
    on the negative axis; -1 without such multipliers), ``torus`` the largest |mu| of the
    non-real ones minus 1 where there are some, and 0 where it lies within its multiplier's
    error bound (with an :class:`EventWarning`: an event is then
    reported only between points on either side of that bound).

    Parameters
    ----------
    mu : numpy.ndarray of complex
        The multipliers (the trivial one left out).
    err : numpy.ndarray of float
        Their error bounds, same shape (nan or inf: no bound).
    p : float
        The point's parameter (for the warning).

    Returns
    -------
    dict
        kind -> value.

    Raises
    ------
    ValueError
        ``err`` has another shape than ``mu``.
    """
    mu, err = np.asarray(mu, dtype=complex), np.asarray(err, dtype=float)
    if err.shape != mu.shape:
        raise ValueError(f"{err.shape} error bounds for {mu.shape} multipliers")
    out: dict[str, float] = {}
    for kind in KINDS:
        idx = _of_kind(kind, mu)
        if kind == "period-doubling":
            f, j = _doubling(mu, err)
        elif idx.size == 0:
            continue
        else:
            j = idx[int(np.argmax(np.abs(mu[idx])))]
            f = float(abs(mu[j])) - 1.0
            j = None if abs(f) > err[j] else j
        if j is None:
            out[kind] = f
            continue
        out[kind] = 0.0
        why = (undecided(kind, mu[j:j + 1], err[j:j + 1]) if j in idx else
               f"the multiplier {mu[j]:.12g} is {abs(1 + mu[j]):.3g} from -1, within its error "
               f"bound {err[j]:.3g}")
        warnings.warn(f"p = {p!r}: {why}; this point "
                      f"does not decide a {kind} (an event is reported only between points on "
                      "either side of the circle beyond their error bounds; one located at "
                      "this point lies within its bound)", EventWarning, stacklevel=3)
    return out


def _crossing(pa: float, pb: float, fa: float, fb: float) -> float:
    """Where the line through (pa, fa) and (pb, fb) crosses 0; the middle without a sign
    change."""
    w = 0.5 if fa == fb or fa * fb > 0 else fa / (fa - fb)
    return pa + (pb - pa) * w


def orbit_events(a: BranchPoint, b: BranchPoint, index: int, autonomous: bool = False,
                 decided: dict[str, BranchPoint] | None = None) -> list[Event]:
    """The events of the orbits' multipliers and stick patterns between the points a and b
    (period doubling, torus, stick onset, grazing; the fold is the driver's); an
    ``autonomous`` branch's phase multiplier is left out of the multipliers' events: the
    verified trivial one (``BranchPoint.floquet``'s ``nontrivial()``) where a verdict is
    there, else the multiplier nearest 1.

    A point whose verified multipliers do not decide a kind (one of them lies within its error
    bound of the unit circle: :func:`undecided`) is passed over for that kind: ``decided``
    (kind -> the last point that decided it, kept by the caller along the branch, updated here)
    then brackets the event between the last point that decided the kind and the next one, so
    that an event whose middle point is undecided is reported between decided points, not
    lost (an :class:`EventWarning` says so at the undecided point).  Without ``decided`` the
    bracket is (a, b)."""
    ev: list[Event] = []
    decided = {} if decided is None else decided

    def rest(q: BranchPoint) -> np.ndarray:
        if q.floquet is not None:
            return q.floquet.nontrivial()
        return phase_free(q.multipliers) if autonomous else q.multipliers

    def doubt(kind: str, q: BranchPoint) -> str | None:   # q's multipliers do not decide kind
        if q.floquet is None:
            return None
        e = q.floquet.errors
        if q.floquet.trivial is not None:
            e = np.delete(e, q.floquet.trivial)
        why = undecided(kind, rest(q), e)
        return None if why is None else f"at p = {q.p!r}, {why}"

    def real_neg(m: np.ndarray) -> np.ndarray:
        return m[(np.abs(m.imag) <= 1e-8 * np.maximum(np.abs(m), 1)) & (m.real < 0)].real

    counts = {"period-doubling": (lambda m: int(np.sum(real_neg(m) < -1)),
                                  "real multipliers < -1"),
              "torus": (lambda m: int(np.sum(np.abs(non_real(m)) > 1)),
                        "complex multipliers with |mu| > 1")}
    for kind, (count, what) in counts.items():
        ref = decided.get(kind)
        first = doubt(kind, a) if ref is None else None
        if ref is None and first is None:
            ref = a
        base = a if ref is None else ref
        change = f"({what}: {count(rest(base))} -> {count(rest(b))})"
        why = doubt(kind, b)
        if why is not None:     # b decides nothing of this kind: the bracket stays open
            if count(rest(base)) != count(rest(b)):
                warnings.warn(f"a {kind} between p = {base.p!r} and {b.p!r} {change} is not "
                              f"reported there: {why}; it is sought between the points that "
                              "decide it", EventWarning, stacklevel=3)
            if ref is not None:
                decided[kind] = ref
            continue
        decided[kind] = b
        if ref is None:         # a, the first point, decided nothing of it
            if count(rest(a)) != count(rest(b)):
                warnings.warn(f"a {kind} between p = {a.p!r} and {b.p!r} {change} is not "
                              f"reported: {first}; no earlier point decides it", EventWarning,
                              stacklevel=3)
            continue
        na, nb = count(rest(ref)), count(rest(b))
        if na == nb:
            continue
        verified = ref.floquet is not None and b.floquet is not None
        span = "" if ref is a else (f" (bracketed by the points at p = {ref.p!r} and {b.p!r}, "
                                    "those between deciding nothing of it)")
        ev.append(Event(kind, _crossing(ref.p, b.p, test_function(kind, rest(ref)),
                                        test_function(kind, rest(b))), index, None,
                        f"{what}: {na} -> {nb}" + span +
                        (" (verified: beyond the multipliers' error bounds on both sides)"
                         if verified else " (not verified: the Ritz multipliers have no error "
                         "bound; continue_orbit verifies them unless verify=False)")))

    def at(fa: float, fb: float) -> float:
        return _crossing(a.p, b.p, fa, fb)

    for i in range(len(a.stick_steps)):
        sa, sb = int(a.stick_steps[i]), int(b.stick_steps[i])
        if (sa == 0) != (sb == 0):
            ma, mb = a.margin[i], b.margin[i]
            ev.append(Event("stick-onset", at(ma, mb) if math.isfinite(ma + mb) else b.p, index,
                            i, f"component {i}: stuck steps {sa} -> {sb}"))
        elif sa and a.stick_phases[i] != b.stick_phases[i]:
            ev.append(Event("grazing", 0.5 * (a.p + b.p), index, i,
                            f"component {i}: stick phases {a.stick_phases[i]} -> "
                            f"{b.stick_phases[i]} (stuck steps {sa} -> {sb})"))
    return ev
