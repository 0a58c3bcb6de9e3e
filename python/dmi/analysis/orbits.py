# Pseudo-arclength continuation of periodic orbits and their events.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Continuation of a periodic orbit of the scheme in its parameter p.

The loop is the one driver's (:func:`dmi.analysis.continuation.driver.continuation`: predictor, step
control, corners, the fold, landing on p_end, user points ``at=``) on the discretisation
:class:`dmi.analysis.branches.shooting.Shooting` (its maps, corrector and points) and the orbits' events
of :mod:`dmi.analysis.branches.events`.

Pseudo-arclength on z = (x, p), x the shooting state (:mod:`dmi.analysis.shooting.shoot`): a secant
predictor z + ds t (the first step: x at p + step), then a corrector on  F_p(x) - x = 0,
<t, z - z_pred> = 0.  The corrector is Newton-Picard: the previous point's multipliers leave a
basis Q of the dominant subspace and its image Z = D_xF Q (:func:`dmi.analysis.scheme.floquet.ritz`),
and the bordered system with D_xF replaced by Z Q' is solved exactly in b + 1 unknowns, one
evaluation of the map an iteration: a chord Newton step on span Q, a Picard step on its
complement, which contracts at the rate of the largest multiplier left out (Lust, Roose, Spence
and Champneys, SIAM J. Sci. Comput. 19 (1998) 1188).  When that contracts too slowly (by less
than half an iteration) or there is no basis yet (``multipliers=0``), Newton with GMRES on the
bordered matrix-free Jacobian [[D_xF - I, D_pF], [t_x' / dim, t_p]] (D_xF by forward differences
along the Krylov vectors, D_pF by one difference in p per iteration) takes over from the
predictor; ``BranchPoint.corrector`` says which converged.  The inner product weighs
x by 1 / dim (an RMS), so ds is a step in "p or RMS state units".  By default the period M h is
kept: make(p) must keep h.  With ``period=P`` (a function p -> the period, time units, e.g. the
forcing period 2 pi / p of a continuation in the frequency) M is kept and the step follows p:
the map at p is built by ``make(p, h=P(p) / M)`` (libdmi 1.2's ``Solver(n, tau, h=...)``, as for
an autonomous orbit).  A model over tau with a free step h has N = ceil(tau / h) changing with p
(with tau, or with h): the states hold L = max N + 1 over the two ends of the range (+ 2 %) rows,
the older ones filled by M-periodicity (:meth:`StepMap.extend`); the map reads the last
N(p) + 1.  The step grows by 1.5 after an easy corrector (Newton-Picard in <= 6 iterations,
Newton in <= 3),
halves after a failure, and the branch ends on p_end exactly (its last step landed on it), at
``max_points``, when it leaves the p-range it started in, or when the step falls below
``min_step`` (``Branch.status`` says which).

Kinks, where the stick pattern changes, are passed: the map is piecewise smooth, its Newton
semismooth, and a failing corrector retries with a halved step.

Events between consecutive points (``Branch.events``):
- ``fold``: dp/ds changes sign (the tangent's p component);
- ``period-doubling``: the number of real multipliers < -1 changes;
- ``torus``: the number of complex multipliers with |mu| > 1 changes;
- ``stick-onset``: a component starts (or stops) sticking somewhere in the period: its number
  of stuck steps goes from 0 to > 0 (or back);
- ``grazing``: a component's number of stick phases changes while it sticks on both sides.
A step is stuck when U_i == 0 for 2 steps or more (:func:`dmi.analysis.shooting.shoot.stuck_mask`).
Every point carries ``margin``, a component's least force besides friction at its velocity
reversals, less the friction threshold alpha_i (force units): min |X_i - U_i^p| / h - alpha_i
over the steps p where U_i reaches 0 or changes sign (X the resolvent's argument, from the same
run as the point's states, :meth:`dmi.Solver.run_terms`; alpha_i = |X_i - U_i^(p+1)| / h on the
slip steps).  It is > 0 where every reversal slips through (Den Hartog's net force beyond
friction), <= 0 where the component sticks, and crosses 0 at a stick-onset; it does not depend
on where the steps fall about the reversal (a lone zero step or a sign change), to O(h).
Stick-onset and grazing events are located by bisection along the branch (the chord between the
two points shortened 64 times, each middle corrected across the chord).
"""
from __future__ import annotations

import functools
import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np

from .._solver import Solver
from .continuation.branch import Branch, BranchPoint, Event
from .collocation.system import CollocationWarning
from .branches.discretisation import CollocationDiscretisation
from .collocation.floquet import eigenfunction
from .collocation.signature import Signature
from .collocation.system import Layout, evaluate, solve
from .continuation.driver import ContinuationOptions, Predictor, continuation
from .branches.collocated import continue_equation_orbit
from .collocation.orbit import EquationOrbit
from .scheme.floquet import StabilityWarning, Verify, phase_free, ritz
from .core.newton import ShootingError
from .scheme.orbit import Orbit, make_orbit
from .branches.events import test_function
from .branches.shooting import AutoMaps, ForcedMaps, Shooting
from .scheme.problem import step_model
from .shooting.refine import refine_orbit
from .shooting.shoot import periodic_orbit


def continue_orbit(orbit: Orbit | EquationOrbit, p_end: float, step: float = 0.05, *, max_points: int = 200,
                   min_step: float | None = None, max_step: float | None = None,
                   multipliers: int = 6, tol: float = 1e-10, max_iter: int = 8,
                   sections: int = 1, margins: bool = True,
                   period: Callable[[float], float] | None = None,
                   refine: bool = False, at: Any = (), verify: Verify | bool | None = None
                   ) -> Branch:
    """Continues a periodic orbit in its parameter by pseudo-arclength, with its events.

    The corrector is Newton-Picard on the previous point's dominant subspace, Newton-GMRES when
    that contracts too slowly (see the module); every point gets Floquet multipliers and a stick
    profile; events (fold, period doubling, torus, stick onset, grazing) are detected between
    consecutive points, and stick events located along the branch.  Corners (stick onset,
    grazing) are passed by natural steps when the secant's hyperplane misses the branch's new
    piece.

    An :class:`dmi.analysis.EquationOrbit` (from :func:`dmi.analysis.collocate` or
    ``hopf_orbit(..., of="equation")``) is continued by collocation through the same driver
    (:mod:`dmi.analysis.branches.collocated`): the points are EquationOrbits (the equation's
    period, amplitude, multipliers with their error estimates, signature), the tangent predictor
    and Newton's corrector on the sparse collocation system, the mesh equidistributed after
    every step and the signature mended where a segment vanishes or an inequality breaks
    (``stick-onset`` and ``grazing`` events where it changes), the multipliers' events
    (``period-doubling``, ``torus``: verified, reported only where the multiplier crosses the
    unit circle beyond its estimated error on both sides, else an ``EventWarning``; see
    :mod:`dmi.analysis.branches.events`) and the fold, landing on p_end and ``at=``.  Of the
    options, ``step``, ``max_points``, ``min_step``, ``max_step``, ``multipliers`` (a point's
    leading multipliers), ``tol`` (at most 1e-12 is used: the corrector's error stays below
    the collocation's), ``max_iter`` and ``at`` apply; ``period=`` (the period is an
    unknown, or the model's forcing period), ``refine=`` (the orbit is the equation's
    already), ``verify=`` (the verdict is the collocation's: the margin against the
    multipliers' estimated errors), ``sections`` and ``margins`` do not and are refused when
    set.

    Parameters
    ----------
    orbit : Orbit or EquationOrbit
        The start, from :func:`periodic_orbit` or :func:`hopf_orbit`.  An autonomous orbit
        (``orbit.autonomous``) has its period as an unknown: h = P / M with M = orbit.steps, N =
        ceil(tau / h) changing along the branch (the states hold room for h down to 60 % of the
        start's), a phase condition through the previous point, and its phase multiplier left out
        of ``stable`` and of the events.
    p_end : float
        Where to stop (finite, not orbit.p).
    step : float
        The first point's step in p; then arclengths in the norm sqrt(|dx|^2 / dim + dp^2) (p
        and RMS state units; an autonomous branch weighs the period's change as p's).
    max_points : int
        Points at most.
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    multipliers : int
        Floquet multipliers a point (they also make the Newton-Picard basis; 0: Newton-GMRES).
    tol : float
        The corrector's tolerance.
    max_iter : int
        Newton iterations a step.
    sections : int
        The orbit spans this many forcing periods (a period-doubled branch: 2), for
        ``BranchPoint.section``.
    margins : bool
        Compute the points' margins (no extra evaluation; False leaves them NaN).
    period : callable, optional
        None keeps the period M h (make(p) keeps h); a function p -> period (time units; a forced
        orbit in its frequency w: ``period=lambda w: 2 * math.pi / w``) keeps M and gives the model
        the step h = period(p) / M through ``make(p, h=...)``.  Must be None for an autonomous
        orbit.
    refine : bool
        Place period-doubling and torus events from the refined multipliers of their two points
        (:func:`dmi.analysis.refine_orbit`: the equation's, O(h^2)); the model must take h.
    at : iterable of float
        Parameters where a point is wanted (a ``user`` event each, its point at exactly that p).
    verify : dmi.analysis.Verify or bool, optional
        How every point's multipliers and stability are verified (None or True: ``Verify()``;
        :func:`dmi.analysis.floquet_verdict`, kept in ``BranchPoint.floquet``; the multipliers'
        events then leave out the verified trivial multiplier, and are reported only between
        points whose multipliers of their kind lie off the unit circle beyond their error
        bounds, points that decide nothing of the kind passed over with an ``EventWarning``).
        ``False`` opts out (a point costs about 2.5 times less, docs/orbits.md): the points
        keep the Ritz multipliers, which have no error bound, their ``stable`` is None, and a
        ``UserWarning`` says so.

    Returns
    -------
    Branch
        ``kind`` "orbits" or "autonomous"; ``points``, ``events``, ``status``.  A corrector that
        fails at the smallest step, or the model failing there, ends the branch with that
        ``status``: it does not raise.

    Raises
    ------
    ValueError
        A bad ``step``, ``p_end``, ``max_points`` or ``period``; ``period`` for an autonomous
        orbit; ``period(orbit.p)`` not the orbit's period; an option that does not apply to
        an EquationOrbit.
    TypeError
        ``orbit`` is neither an Orbit nor an EquationOrbit.
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: must be finite and > 0 (p units)")
    if max_points < 2:
        raise ValueError(f"max_points = {max_points!r}: must be >= 2")
    options = ContinuationOptions(step=step, min_step=min_step, max_step=max_step,
                                  max_points=max_points, at=tuple(at), tol=tol,
                                  max_iter=max_iter)
    return _continue(orbit, p_end, options, multipliers=multipliers, sections=sections,
                     margins=margins, period=period, refine=refine, verify=verify)


@functools.singledispatch
def _continue(orbit: Any, p_end: float, options: ContinuationOptions, *, multipliers: int,
              sections: int, margins: bool, period: Callable[[float], float] | None,
              refine: bool, verify: Verify | bool | None) -> Branch:
    """:func:`continue_orbit` by the orbit's class: neither an Orbit nor an EquationOrbit."""
    raise TypeError(f"continue_orbit: orbit is a {type(orbit).__name__}: give an Orbit (from "
                    "periodic_orbit or hopf_orbit) or an EquationOrbit (from collocate or "
                    "hopf_orbit(..., of=\"equation\"))")


@_continue.register
def _(orbit: EquationOrbit, p_end: float, options: ContinuationOptions, *, multipliers: int,
      sections: int, margins: bool, period: Callable[[float], float] | None, refine: bool,
      verify: Verify | bool | None) -> Branch:
    """An EquationOrbit's branch: by collocation
    (:func:`dmi.analysis.branches.collocated.continue_equation_orbit`); the scheme's options
    refused."""
    unused = [name for name, given in (("period", period is not None), ("refine", refine),
                                       ("verify", verify is not None),
                                       ("sections", sections != 1),
                                       ("margins", not margins)) if given]
    if unused:
        raise ValueError(f"continue_orbit of an EquationOrbit: {', '.join(unused)}= do not "
                         "apply to a collocated branch (see continue_orbit's docstring)")
    return continue_equation_orbit(orbit, p_end, options, multipliers=multipliers)


@_continue.register
def _(orbit: Orbit, p_end: float, options: ContinuationOptions, *, multipliers: int,
      sections: int, margins: bool, period: Callable[[float], float] | None, refine: bool,
      verify: Verify | bool | None) -> Branch:
    """The scheme's Orbit's branch: shooting (see the module)."""
    verify = _verification(verify, multipliers)
    if not math.isfinite(p_end) or p_end == orbit.p:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the orbit's "
                         f"p = {orbit.p!r}")
    maps, x0, F0 = (_autonomous_maps(orbit, period) if orbit.autonomous else
                    _forced_maps(orbit, float(p_end), period))
    disc = Shooting(maps, multipliers, sections, margins, options.tol, options.max_iter,
                    orbit.iterations, verify)
    disc.size = x0.size
    if orbit.autonomous:   # the phase condition through the start
        maps.reference(np.concatenate([x0, [orbit.p]]), F0.trajectory(x0[:-1]))
    b = continuation(disc, x0, orbit.p, float(p_end), options, predictor=Predictor.SECANT,
                     easy=3, grow_first=False, make=orbit.make,
                     kind="autonomous" if maps.autonomous else "orbits",
                     branch=dict(steps=orbit.steps, h=orbit.h, rows=maps.rows,
                                 sections=sections, period=period))
    open_ = [q for q in b.points if q.floquet is not None and q.stable is None]
    if open_:
        warnings.warn(f"continue_orbit: the stability of {len(open_)} of {len(b.points)} points "
                      f"is not decided (stable None), at p = "
                      f"{', '.join(f'{q.p:.8g}' for q in open_[:6])}"
                      f"{', ...' if len(open_) > 6 else ''}: {open_[0].floquet.reason} (the "
                      "first; BranchPoint.floquet.reason has each point's)", StabilityWarning,
                      stacklevel=4)
    if refine:
        for e in b.events:
            if e.kind in ("period-doubling", "torus"):
                refined_event(maps, b.points[e.index - 1], b.points[e.index], e, multipliers,
                              options.tol)
    return b


def _verification(verify: Verify | bool | None, multipliers: int) -> Verify | None:
    """continue_orbit's ``verify=`` as a Verify, or None (opted out, with a UserWarning)."""
    if verify is None or verify is True:
        return Verify()
    if verify is False:
        if multipliers > 0:
            warnings.warn("continue_orbit(verify=False): the points' multipliers are Ritz "
                          "values without an error bound, so their stable is None; leave "
                          "verify at its default (Verify()) for verified verdicts", UserWarning,
                          stacklevel=5)
        return None
    if not isinstance(verify, Verify):
        raise ValueError(f"verify = {verify!r}: give a dmi.analysis.Verify, or False to opt out "
                         "of the verification")
    return verify


def _autonomous_maps(orbit: Orbit, period: Any) -> tuple[ForcedMaps, np.ndarray, Any]:
    """The maps of an autonomous branch from orbit, its start x0 = (state, h) and its map."""
    if period is not None:
        raise ValueError("period=...: an autonomous orbit's period is an unknown of the "
                         "branch; continue it with period=None")
    n = orbit.u.shape[1]
    x0 = np.array(orbit.state)
    maps = AutoMaps(orbit.make, orbit.steps, orbit.h, 0)
    tau = step_model(maps.problem, orbit.p, orbit.h).tau   # its map's solver later
    maps.rows = maps.auto.rows = max(orbit.rows or x0.size // n,
                                     math.ceil(tau / (0.6 * orbit.h)) + 1)
    F0 = maps(orbit.p)
    if F0.dim != x0.size:
        x0 = F0.extend(x0)
    return maps, np.concatenate([x0, [orbit.h]]), F0


def _forced_maps(orbit: Orbit, p_end: float, period: Any) -> tuple[ForcedMaps, np.ndarray, Any]:
    """The maps of a forced branch from orbit to p_end, its start x0 and its map."""
    if period is not None and not callable(period):
        raise ValueError(f"period = {period!r}: give a function p -> period (time units)")
    n = orbit.u.shape[1]
    x0 = np.array(orbit.state)
    maps = ForcedMaps(orbit.make, orbit.steps, orbit.h, 0, period)
    if period is not None:
        P0 = maps.step(orbit.p) * orbit.steps
        if abs(P0 - orbit.period) > 1e-9 * orbit.period:
            raise ValueError(f"period(p = {orbit.p!r}) = {P0!r} but the orbit's period is "
                             f"{orbit.period!r} (= {orbit.steps} steps h = {orbit.h!r})")
    # rows for the whole range: N may grow with p (tau with a fixed h, or h with the
    # period); the probes of both ends (the start's becomes its map's solver)
    rows = max(orbit.rows or x0.size // n, maps.memory(orbit.p) + 1)
    try:
        rows = max(rows, maps.memory(p_end) + 1)
    except Exception:   # make refuses p_end: the branch will stop where make does
        pass
    maps.rows = rows + max(2, rows // 50)  # room for a corrector a little beyond the ends
    F0 = maps(orbit.p)
    if F0.dim != x0.size:
        x0 = F0.extend(x0)
    return maps, x0, F0


def refined_event(maps: Any, a: BranchPoint, b: BranchPoint, e: Event, multipliers: int,
                   tol: float) -> None:
    """e.p from the test function of the refined multipliers at a and b (linear in p through
    them; up to a spacing of the points beyond them), the phase multiplier left out of an
    autonomous branch's."""
    f = []
    for q in (a, b):
        z = maps.z_of(q)
        F = maps.of(z[-maps.k:])
        o = make_orbit(F, q.state, [0.0], multipliers, maps.autonomous)
        mu = refine_orbit(o, tol=tol).multipliers
        f.append(test_function(e.kind, phase_free(mu) if maps.autonomous else mu))
    w = f[0] / (f[0] - f[1]) if f[0] != f[1] else math.nan
    if 0 <= w <= 1:
        e.p = a.p + (b.p - a.p) * w
        e.detail += " (placed from refined multipliers)"
    elif -1 <= w <= 2:   # the equation's event lies up to a point spacing beyond the scheme's
        e.p = a.p + (b.p - a.p) * w
        e.detail += (" (placed from refined multipliers, extrapolated beyond the points: the "
                     "scheme's event is more than a step of the branch off the equation's)")
    else:
        e.detail += (" (the refined multipliers do not change sign near the points: placed "
                     "from the scheme's)")


def period_doubled_orbit(branch: Branch, event: Event, *, amplitudes: tuple[float, ...] =
                         (0.03, 0.1, 0.3, 1.0), multipliers: int = 6, tol: float = 1e-10
                         ) -> Orbit | EquationOrbit:
    """The period-2M orbit born at a ``period-doubling`` event of a branch (scheme's or
    collocated).

    At the point of the event's pair where the M-periodic orbit has a multiplier < -1 (its
    unstable side, where a supercritical doubling's orbit lives) the M-periodic state x is
    perturbed along the multiplier's Ritz vector v (|v|_inf = 1), x + a A v, A the orbit's
    amplitude, a from ``amplitudes`` (smallest first: the orbit born at the event is the nearest),
    and shot with period 2 M h; the first solution that is not the M-periodic orbit is returned.
    Continue it with ``continue_orbit(..., sections=2 * branch.sections)``, and
    ``period=lambda p: 2 * P(p)`` for a branch continued with ``period=P``.

    On a collocated branch (of EquationOrbits: ``continue_orbit`` of an EquationOrbit,
    ``hopf_orbit(..., of="equation")``), forced or autonomous, smooth or with switches
    (reversals, sticks, box faces): at the point of the pair with a real multiplier below -1 by
    more than its estimated error, the orbit laid twice around (its own mesh on both laps, its
    segments repeated with the switching times b and b + T, period 2 T) plus a A v on the first
    lap and -a A v on the second, v the multiplier's eigenfunction over the period
    (:func:`dmi.analysis.collocation.floquet.eigenfunction`: the node values' perturbation),
    is collocated (Newton with sparse LU, the switching times unknowns, the mesh equidistributed
    and solved again) and returned as an EquationOrbit of period 2 T (a forced one: exactly
    twice the forcing period) with its multipliers and error estimates, once |u(t + T) - u(t)|
    exceeds 100 times the estimated error of u (distinct from the T-orbit, verified).
    ``continue_orbit`` continues it (no ``sections=``).

    Parameters
    ----------
    branch : Branch
        A forced branch from :func:`continue_orbit`.
    event : Event
        One of its ``period-doubling`` events.
    amplitudes : tuple of float
        The relative kicks tried.
    multipliers : int
        Floquet multipliers of the orbit returned.
    tol : float
        Newton's tolerance (the scheme's; a collocated orbit is solved to 1e-12).

    Returns
    -------
    Orbit or EquationOrbit
        The period-doubled orbit (an EquationOrbit on a collocated branch).

    Raises
    ------
    ValueError
        The event is not a period doubling; on a collocated branch: neither point has a real
        multiplier below -1 beyond its estimated error, the multiplier nearest -1 is not real
        and negative, or the orbit's pieces do not repeat on the period 2 T.
    ShootingError
        No period-doubled orbit found (what each kick gave is listed: Newton's failure, or a
        return to the T-orbit).
    """
    if event.kind != "period-doubling":
        raise ValueError(f"event {event.kind!r}: expected a 'period-doubling' event")
    return _doubled(branch.points[event.index - 1], branch.points[event.index], branch,
                    amplitudes, multipliers, tol)


@functools.singledispatch
def _doubled(a: BranchPoint, b: BranchPoint, branch: Branch, amplitudes: tuple[float, ...],
             multipliers: int, tol: float) -> Orbit | EquationOrbit:
    """:func:`period_doubled_orbit` by the class of the branch's points: a scheme's branch
    (BranchPoints), by shooting with period 2 M h from the kicked state."""
    q = a if np.any(a.multipliers.real < -1) else b
    maps = ForcedMaps(branch.make, branch.steps, branch.h, branch.rows, branch.period)
    F = maps(q.p)
    x = F.extend(q.state)
    _, Q, Z = ritz(F, x, 6)
    mu, Y = np.linalg.eig(Q.T @ Z)   # Ritz pairs: the eigenvector Q y
    j = int(np.argmin(np.abs(mu + 1) + 10 * np.abs(mu.imag)))
    v = (Q @ Y[:, j]).real
    v /= np.max(np.abs(v))
    amp = max(float(np.max(q.amplitude)), 0.1 * max(1.0, float(np.max(np.abs(x)))))
    if branch.period is None:
        make = branch.make
    else:   # make(p) at the branch's step period(p) / M unless h is given
        def make(p: float, h: float | None = None) -> Solver:
            return branch.make(p, h=maps.step(p) if h is None else h)  # type: ignore[call-arg]
    tried = []
    for s in amplitudes:
        try:
            o = periodic_orbit(make, q.p, 2 * branch.steps * F.h, x + s * amp * v,
                               rows=F.L, tol=tol, multipliers=multipliers)
        except ShootingError as e:
            tried.append(f"a = {s}: {e}")
            continue
        if np.max(np.abs(F(o.state) - o.state)) > 1e-6 * max(1.0, amp):
            return o
        tried.append(f"a = {s}: converged to the M-periodic orbit")
    raise ShootingError(f"no period-doubled orbit at p = {q.p!r} (multiplier {mu[j]:.4g}): "
                        + "; ".join(tried), [])


@_doubled.register
def _doubled_equation_orbit(a: EquationOrbit, b: EquationOrbit, branch: Branch,
                            amplitudes: tuple[float, ...], multipliers: int, tol: float
                            ) -> EquationOrbit:
    """:func:`period_doubled_orbit` on a collocated branch, between its points a and b.

    At the point of the pair with a real multiplier beyond -1 (beyond its estimated error) the
    orbit is laid twice around a mesh of the period 2 T (:func:`_laid_twice`: its own mesh and
    segments twice, the switching times b and b + T), plus s A v on the
    first lap and -s A v on the second, v the eigenfunction of the multiplier
    (:func:`dmi.analysis.collocation.floquet.eigenfunction`, |v|_inf = 1), A the orbit's
    largest amplitude, s from ``amplitudes``; Newton (sparse LU) on the collocation system of
    the period 2 T, the mesh equidistributed and solved again, the point with its error
    estimates (the merged mesh's).  It is returned when u(t + T) - u(t) exceeds 100 times the
    estimated error of u: verified distinct from the T-orbit."""
    q = next((o for o in (a, b) if _beyond_minus_one(o)), None)
    if q is None:
        raise ValueError(f"period_doubled_orbit: neither point of the event (p = {a.p!r}, "
                         f"{b.p!r}) has a real multiplier beyond -1 by more than its estimated "
                         "error: the doubling is not verified there; continue the branch with "
                         "a smaller step past the event")
    disc, x = CollocationDiscretisation.of(q, multipliers=multipliers)
    lay, terms, T = disc.lay, disc.terms(q.p), float(q.period)
    mu, E = eigenfunction(lay, terms, x, -1.0)
    if not (mu.real < 0 and abs(mu.imag) <= 1e-9 * abs(mu)):
        raise ValueError(f"period_doubled_orbit: the multiplier nearest -1 at p = {q.p!r} is "
                         f"{mu:.6g}, not real and negative: no period doubling to follow there")
    v = E.real / float(np.max(np.abs(E.real)))
    lay2, b2 = _laid_twice(lay, q.switches, T)
    V = q.nodes
    amp = max(float(np.max(q.amplitude)), 1e-3 * max(1.0, float(np.max(np.abs(V)))))
    tried = []
    for s in amplitudes:
        x0 = np.concatenate([np.concatenate([V + s * amp * v, V - s * amp * v]).ravel(), b2,
                             [2 * T] if lay.autonomous else []])
        d2 = CollocationDiscretisation(q.make, lay2, x0, multipliers=multipliers)
        d2.problem = disc.problem
        try:
            xs, _ = solve(lay2, terms, x0, d2.ref, what=f"the doubled orbit at p = {q.p!r}")
            xs = d2.adapt(xs, q.p)
            xs, _ = solve(d2.lay, terms, xs, d2.ref, what=f"the doubled orbit at p = {q.p!r}")
        except (ShootingError, ValueError) as e:
            tried.append(f"s = {s}: {e}")
            continue
        T2 = d2.lay.split(xs)[2]
        t = np.linspace(0.0, 0.5 * T2, 40 * d2.lay.L, endpoint=False)
        gap = float(np.max(np.abs(evaluate(d2.lay, xs, t + 0.5 * T2) - evaluate(d2.lay, xs, t))))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", CollocationWarning)
            o = d2.point(xs, q.p)
        if o is None or not o.errors:
            tried.append(f"s = {s}: no error estimate (the merged mesh's solve failed)")
            continue
        if gap > 100 * float(o.errors["u"]):
            return o
        tried.append(f"s = {s}: returned to the T-orbit (|u(t + T) - u(t)| = {gap:.3g}, its "
                     f"estimated error {float(o.errors['u']):.3g})")
    raise ShootingError(f"no period-doubled orbit at p = {q.p!r} (multiplier {mu:.6g}): "
                        + "; ".join(tried), [])


def _laid_twice(lay: Layout, b: np.ndarray, T: float) -> tuple[Layout, np.ndarray]:
    """The layout of the period 2 T that lays an orbit of the layout ``lay`` (switching times b,
    period T) twice around: its segments repeated (switching times b and b + T), its mesh
    points on both laps, and those switching times."""
    modes = lay.signature.modes
    sig = Signature(np.concatenate([modes, modes])) if lay.S else lay.signature
    b2 = np.concatenate([b, b + T])
    lay2 = Layout(lay.m, lay.n, sig, [], lay.autonomous, 2 * T, lay.carried)
    mesh = lay.mesh(b, T)
    mesh2 = np.concatenate([mesh[:-1], mesh[:-1] + T, [2 * T]])
    ends = lay2.bounds(b2, 2 * T)
    # every piece end of the doubled layout is a mesh point of one of the laps
    at = np.array([int(np.argmin(np.abs(mesh2 - e))) for e in ends])
    if np.max(np.abs(mesh2[at] - ends)) > 1e-12 * T or np.any(np.diff(at) <= 0):
        raise ValueError("period_doubled_orbit: the orbit's pieces do not repeat on the doubled "
                         "period (a carried breakpoint wraps differently around 2 T)")
    fractions = []
    for i, j in zip(at[:-1], at[1:]):
        f = (mesh2[i:j + 1] - mesh2[i]) / (mesh2[j] - mesh2[i])
        f[0], f[-1] = 0.0, 1.0
        fractions.append(f)
    return Layout(lay.m, lay.n, sig, fractions, lay.autonomous, 2 * T, lay.carried), b2


def _beyond_minus_one(o: EquationOrbit) -> bool:
    """A real multiplier of o below -1 by more than its estimated error."""
    mu = np.asarray(o.multipliers)
    err = np.asarray(o.errors.get("multipliers", np.full(mu.shape, np.inf)))
    real = np.abs(mu.imag) <= 1e-9 * np.maximum(1.0, np.abs(mu))
    return bool(np.any(real & (mu.real < -1 - err)))


__all__ = ["Branch", "BranchPoint", "Event", "continue_orbit", "period_doubled_orbit"]
