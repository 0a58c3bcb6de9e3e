# Curves of the bifurcations of the equation's periodic orbits in two parameters: the fold, the
# period doubling and the torus of collocated orbits continued in (p, q) by minimally augmented
# systems on the one driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The fold of collocated orbits (limit point of cycles) continued in the plane (p, q):
:func:`continue_orbit_curve`, its points :class:`OrbitCurvePoint` in a
:class:`dmi.analysis.Curve` of kind ``"orbit-fold"``.

The system (minimally augmented, as MatCont's LPC curves; Govaerts, Kuznetsov and Dhooge, SIAM
J. Sci. Comput. 27 (2005) 231): F(x; p, q) = 0 is the collocation system of the orbit
(:mod:`dmi.analysis.collocation.system`: node values, switching times, the period and its phase
condition for an autonomous orbit), J = F_x its sparse Jacobian.  The unknowns are (x, p), the
driver's parameter is q (:func:`dmi.analysis.continuation.driver.continuation`, so that the curve
passes its turning points in q and lands on q_end and on the user's q exactly), and the extra
equation is g(x, p; q) = 0, g from the bordered system

    [[J, b], [c', 0]] (v, g) = (0, 1),     [[J', c], [b', 0]] (w, h) = (0, 1),

one sparse LU for both (g in units of its gradient's largest entry at the start: its rounding is
then comparable to F's).  g = 0 where J is singular: there the orbit's branch in p at fixed q has
dp/ds = 0, a fold.  g's derivatives are -w' J_alpha v: along x the row w' (J(x + eps v) - J(x))
/ eps (one more assembly of J), along p and q the differences of J v; they only steer Newton
(the curve's points solve F = 0, g = 0 to the corrector's tolerance).  The borders start from
the one-parameter branch's tangent at the fold (b = F_p, c uniform: the null vectors of J and
J'), and move to the last point's v and w after every step, when the mesh is equidistributed
again (as the one-parameter branches do) and the phase condition's reference moves.

Each point carries its :class:`EquationOrbit` (the multipliers, their error estimates: the
difference to the fold solved again, at the same q, on the mesh with every pair of intervals
merged, which also gives the error estimate of p) and a verified verdict on the multipliers
other than the trivial one and the fold's (the orbit's own ``stable`` is None at a fold: a
multiplier is 1 there).  A curve that would leave its orbits' signature (a stick onset, a
grazing) ends there, its status saying so; a curve whose orbits shrink towards an equilibrium
(the fold curve's end at a Bautin point of the Hopf curve) ends with a status that says where
the amplitude extrapolates to 0.

Period doubling and torus: :func:`continue_flip_curve` (a :class:`dmi.analysis.Curve` of kind
``"period-doubling"``) and :func:`continue_torus_curve` (kind ``"torus"``), their points
:class:`FlipCurvePoint` and :class:`TorusCurvePoint`.

The systems are the fold's with another test function.  A_mu is the collocation system
linearised at the orbit with the periodic boundary condition replaced by v(t + T) = mu v(t): the
node at T is mu times the node at 0, and the memory reads the past before 0 as mu^k v(t - k T)
(k the periods it reaches back; DDE-BIFTOOL's multiplier condition).  A_mu is singular exactly
when mu is a Floquet multiplier of the collocated orbit.  The extra equation is g = 0, g from
the bordered system

    [[A_mu, b], [c', 0]] (v, g) = (0, 1),     [[A_mu', c], [b', 0]] (w, h) = (0, 1)

(one bordered solve each): mu = -1 for the period doubling (real, one equation), mu = e^(i theta)
for the torus, theta an extra unknown and g complex (two real equations, the complex system
solved in its real form).  g's derivatives are -w' (d A_mu) v: along the node values from the
change of f_u at the collocation points in the direction of v, along T, p and q by differences
of A_mu, along theta exactly; they only steer Newton.  The borders start from a few steps of
inverse iteration at the start and move to the last point's conj(v), conj(w) after every step.

Covered: orbits without switches (smooth orbits; a component held for the whole period is
allowed), with or without a memory, and orbits with switches (:class:`SwitchTwisted`: A_mu from
the collocation system of one period forward from a past, the past read as mu^-k times the
period's perturbation at fixed times, the saltation included; g's gradient also over the
switching times).  A curve ends where its orbit would leave its signature (a
stick onset or grazing meets it), a torus curve where theta reaches 0 or pi (the pair e^(+-i
theta) meets at +1 or -1: a 1:1 or 1:2 resonance, where a neutral saddle follows).
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..._solver import Solver
from ..collocation.adapt import FLOOR
from ..collocation.mesh import interval_of, point_matrix
from ..collocation.orbit import EquationOrbit, equation_orbit
from ..collocation.signature import HI, LO, STUCK
from ..collocation.system import (CollocationWarning, History, Layout, Terms, assemble,
                                  collocation_matrices, force_switches, full_jacobian)
from ..continuation.branch import Branch, Curve, CurveEvent, Event
from ..continuation.driver import Curve as DriverCurve
from ..continuation.driver import continuation, curve_range, newton_strategy
from ..core.newton import ShootingError, Strategy, bordered_solve, sparse_bordered
from ..scheme.problem import AtQ
from .orbit_system import DIFF, FoldSystem, OrbitCurvePoint, check_period

#: A start's fold at q0 must lie within this (relative to max(1, |p|)) of the event's p.
START_TOL = 1e-6
#: A turn back in q where the orbits' amplitude is below this share of the curve's largest is
#: the fold curve's end at a Bautin point (the curve in x passes through the equilibrium).
BAUTIN_SHARE = 0.2
# the step along v (relative, against the orbit's largest |u|) of the one-sided differences of
# f's change at a moved parameter: its truncation and rounding errors balance near 3e-5
CHANGE_STEP = 3e-5
#: The step (relative, against max(1, the point's largest |x|) over the direction's largest
#: entry) of the central differences along a direction of f_u (:func:`central_along`):
#: f_u is a central difference of f itself (its rounding about 1e-11 of f), truncation and
#: rounding balance near 1e-4.
ALONG_STEP = 1e-4


class OrbitFold(FoldSystem):
    """The fold's system (:class:`dmi.analysis.plane.orbit_system.FoldSystem`) as a discretisation
    of the one driver: its step control, the signature's check, the mesh moved between steps,
    the points with their error estimates and verdicts (same parameters)."""

    def __init__(self, make2: Callable[[float, float], Solver], layout: Layout, x: np.ndarray,
                 **options: Any):
        super().__init__(make2, layout, x, **options)
        self._track: list[tuple[float, float]] = []   # (q, amplitude) of the points stepped to

    def strategies(self, y: np.ndarray, q: float, row: np.ndarray, target: float, far: float
                   ) -> Iterator[Strategy]:
        """The driver's Newton strategy (:func:`newton_strategy`), after refusing a step past a
        Bautin point (the curve turned back in q where its orbits shrink)."""
        if math.isfinite(far) and _turned_small(self._track):   # no step past a Bautin point
            self.breach = ("the curve turned back in q where its orbits shrink to the "
                           "equilibrium (a Bautin point)")
            raise ShootingError(self.breach, [])
        yield newton_strategy(DriverCurve(self, y.size), np.concatenate([y, [q]]), row, target,
                              tol=self.tol, max_iter=self.max_iter, far=far,
                              what=f"the orbits' fold near q = {q!r}")

    def accept(self, y: np.ndarray, q: float, step: bool) -> tuple[np.ndarray, float]:
        """The orbit's inequalities checked: an orbit that breaks its signature is refused (the
        curve does not cross signatures yet)."""
        x, p = y[:self.lay.size], float(y[self.lay.size])
        bad = self.broken(x, p, q, 1e-9)
        if bad:
            self.breach = (f"near (p, q) = ({p:.10g}, {q:.10g}) the fold's orbit breaks its "
                           f"signature ({bad}): a stick onset or grazing meets the fold "
                           "curve there (curves across signatures are not continued yet)")
            raise ShootingError(self.breach, [])
        return y, q

    def adapt(self, y: np.ndarray, q: float) -> np.ndarray:
        """Between steps: the borders moved to the point's v and w, the mesh equidistributed
        again, the phase condition's reference moved to the point; where the pieces'
        intervals come to another count (an orbit with switches), the borders from the new
        mesh's null vectors."""
        ev = self._eval(y, q)
        V = y[:self.lay.rows * self.lay.n].reshape(-1, self.lay.n)
        self._track.append((float(q), float(np.max(V.max(axis=0) - V.min(axis=0))) / 2))
        self.c = ev["v"] / np.linalg.norm(ev["v"])
        self.b = ev["w"] / np.linalg.norm(ev["w"])
        x, p = y[:-1], float(y[-1])
        x = self.remesh(x, p, q)
        self._last = None
        if x.size != self.c.size:   # the pieces' intervals rounded to another count (switches)
            unit = self.gscale
            self.borders(x, p, q)    # b and c of the new mesh; g keeps its unit
            self.gscale, self._last = unit, None
        return np.concatenate([x, [p]])

    def point(self, y: np.ndarray, q: float) -> OrbitCurvePoint:
        """The curve's point at (y, q): the orbit, its errors from the merged mesh's fold, the
        verdict on the other multipliers."""
        p = float(y[-1])
        fine, errors, _ = self.levels(y, q)
        p_error = errors.get("p")
        with warnings.catch_warnings():   # a fold's multiplier at 1: the orbit's stable is None
            warnings.simplefilter("ignore", CollocationWarning)
            orbit = equation_orbit(fine, p, AtQ(self.make2, q), errors, self.jumps)
        orbit.stable = None
        return OrbitCurvePoint(p, float(q), orbit, p_error,
                               _others_stable(fine.mu, errors.get("multipliers"),
                                              self.lay.autonomous, p, q))


def _others_stable(mu: np.ndarray, err: Any, autonomous: bool, p: float, q: float
                   ) -> bool | None:
    """The multipliers but the trivial one (autonomous) and the fold's (the nearest 1 of the
    rest) all inside the unit circle (True) or one outside (False) beyond their errors; None
    (with a CollocationWarning) otherwise."""
    if mu.size == 0 or err is None:
        return None
    keep = np.ones(mu.size, bool)
    for _ in range(2 if autonomous else 1):
        rest = np.flatnonzero(keep)
        keep[rest[int(np.argmin(np.abs(mu[rest] - 1)))]] = False
    a, e = np.abs(mu[keep]), np.asarray(err)[keep]
    if np.any(a > 1 + e):
        return False
    if np.all(a < 1 - e):
        return True
    warnings.warn(f"(p, q) = ({p!r}, {q!r}): a multiplier other than the fold's is within its "
                  "estimated error of the unit circle: the verdict is None",
                  CollocationWarning, stacklevel=3)
    return None


def _turned_small(track: list[tuple[float, float]]) -> bool:
    """The last points turned back in q where the amplitude is below BAUTIN_SHARE of the
    largest so far."""
    if len(track) < 3:
        return False
    (q0, _), (q1, a1), (q2, a2) = track[-3:]
    top = max(a for _, a in track)
    return (q2 - q1) * (q1 - q0) < 0 and min(a1, a2) < BAUTIN_SHARE * top


def bautin_end(points: list[OrbitCurvePoint]) -> tuple[int, float, float] | None:
    """Where the curve turns back in q with its orbits' amplitude below BAUTIN_SHARE of the
    largest: (k, p_B, q_B), k the first point past the turn, (p_B, q_B) where q and p,
    fitted as quadratics in the amplitude squared through the last three points before it,
    reach amplitude 0 (near a Bautin point the fold's orbits have amplitude^2 ~ q - q_B).
    None where the curve does not turn so."""
    q = np.array([pt.q for pt in points])
    a = np.array([float(np.max(pt.orbit.amplitude)) for pt in points])
    for k in range(2, len(points)):
        if (q[k] - q[k - 1]) * (q[k - 1] - q[k - 2]) < 0 and \
                min(a[k - 1], a[k]) < BAUTIN_SHARE * float(a[:k + 1].max()):
            j = np.arange(max(0, k - 3), k)
            deg = min(2, j.size - 1)
            s = a[j] ** 2
            pB = float(np.polyval(np.polyfit(s, [points[i].p for i in j], deg), 0.0))
            qB = float(np.polyval(np.polyfit(s, q[j], deg), 0.0))
            return k, pB, qB
    return None


def _start_orbit(start: Any, branch: Branch | None) -> tuple[EquationOrbit, np.ndarray | None,
                                                              float, float]:
    """(the orbit near the fold, the event's unknowns if on its layout, the event's p, how far
    from it the fold at q0 may lie: START_TOL relative for a fold located on the branch, twice
    the event's two points' distance to it for one from a parabola, inf for an orbit)."""
    if isinstance(start, EquationOrbit):
        return start, None, float(start.p), math.inf
    if isinstance(start, Event) and start.kind == "fold":
        if branch is None or not isinstance(branch, Branch):
            raise ValueError("continue_orbit_curve: a fold event needs branch=, the Branch of "
                             "EquationOrbits it belongs to (continue_orbit of an EquationOrbit)")
        pts = branch.points
        if not pts or not all(isinstance(pt, EquationOrbit) for pt in pts):
            raise ValueError("continue_orbit_curve: branch= is not a branch of EquationOrbits "
                             "(continue_orbit of an EquationOrbit, from collocate or "
                             "hopf_orbit(..., of='equation'))")
        if start not in branch.events:
            raise ValueError("continue_orbit_curve: the fold event is not one of branch.events")
        k = min(max(int(start.index), 1), len(pts) - 1)
        before, after = pts[k - 1], pts[k]
        orbit = before if abs(before.p - start.p) <= abs(after.p - start.p) else after
        u = None
        if start.u is not None and np.size(start.u) == after.nodes.size + after.switches.size \
                + int(after.autonomous):   # located on the layout of the point after it
            u = np.array(start.u, dtype=float)
            orbit = after
        p = float(start.p)
        slack = (START_TOL * max(1.0, abs(p)) if start.u is not None else
                 2 * max(abs(before.p - p), abs(after.p - p), abs(after.p - before.p)))
        return orbit, u, p, slack
    raise ValueError(f"continue_orbit_curve: start = {start!r}: give a 'fold' event of a branch "
                     "of EquationOrbits (with branch=) or an EquationOrbit near a fold")


def continue_orbit_curve(start: Any, make2: Callable[[float, float], Solver], q0: float,
                         q_end: float, *, branch: Branch | None = None,
                         step: float | None = None, at: Iterable[float] = (),
                         max_points: int = 100, min_step: float | None = None,
                         max_step: float | None = None, multipliers: int = 10,
                         tol: float = 1e-10, max_iter: int = 10, estimate: bool = True,
                         period: Callable[[float, float], float] | None = None) -> Curve:
    """Continues a fold of the equation's periodic orbits (collocated) in the plane (p, q).

    The curve of (p, q) where the orbit of ``make2(p, q)`` folds (its branch in p at fixed q
    turns back: a limit point of cycles), by pseudo-arclength in (x, p, q) with the minimally
    augmented system of :mod:`dmi.analysis.plane.orbit_curves`, from the start at q0, through
    turning points in q, until q_end.

    Parameters
    ----------
    start : Event or EquationOrbit
        A ``fold`` event of a branch of EquationOrbits of ``make2(., q0)``
        (:func:`dmi.analysis.continue_orbit` of an EquationOrbit; give that Branch as
        ``branch=``), or an EquationOrbit of ``make2(., q0)`` near a fold.
    make2 : callable
        The model ``make2(p, q) -> dmi.Solver``, configured, not initialised.
    q0 : float
        The start's q.
    q_end : float
        Where to stop (finite, not q0); the last point lies on it exactly when the curve gets
        there.
    branch : Branch, optional
        The start event's branch (required with an event).
    step : float, optional
        The first step (arclength in (x, p, q): x as its RMS, p and q as themselves; default
        |q_end - q0| / 20).
    at : iterable of float
        Values of q where a point is wanted (a ``user`` event each, the point on it exactly).
    max_points : int
        Points at most.
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    multipliers : int
        Leading multipliers a point.
    tol : float
        The corrector's tolerance (relative to max(1, |x|_inf)).
    max_iter : int
        The corrector's iterations a step.
    estimate : bool
        Every point's error estimates (the fold solved again on the mesh of merged pairs of
        intervals); False: none, and every verdict None.
    period : callable, optional
        ``period(p, q)``: the period of a forced orbit whose forcing's period changes with
        (p, q) (e.g. ``lambda p, q: 2 * math.pi / q``, q the forcing's angular frequency);
        every evaluation at (p, q) takes the orbit of that period.  None: the start's period,
        fixed.

    Returns
    -------
    Curve
        ``kind`` ``"orbit-fold"``; ``points`` (:class:`OrbitCurvePoint`: ``p``, ``q``,
        ``orbit``, ``p_error``, ``stable``), ``events`` (``user``), ``status`` (it does not
        raise when the corrector fails on the way: the curve ends there, the status says why:
        q_end reached, a turn back past q0, max_points, a signature the orbits would leave, or
        the orbits shrinking towards a Bautin point).

    Raises
    ------
    ValueError
        A start of another kind, an event without its branch, bad q0, q_end or step;
        ``period=`` for an autonomous orbit, or period(p, q0) not the start orbit's period (to
        1e-9 relative), or a period(p, q) that is not finite and > 0; a start
        that is not a fold of ``make2(., q0)`` (Newton fails at q0, or finds the fold farther
        from the event's p than START_TOL relative, or, for a fold the branch did not locate
        (its p from a parabola), than twice its two points' distance to that p).
    """
    orbit, u, p_event, slack = _start_orbit(start, branch)
    q0, q_end, step = curve_range("continue_orbit_curve", q0, q_end, step)
    if not callable(make2):
        raise ValueError(f"continue_orbit_curve: make2 = {make2!r}: give a function "
                         "(p, q) -> dmi.Solver")
    check_period(period, orbit.autonomous, orbit.period, p_event, q0, "continue_orbit_curve")
    n = orbit.nodes.shape[1]
    lay = Layout(orbit.degree, n, orbit.signature, [f.copy() for f in orbit.fractions],
                 orbit.autonomous, orbit.period, tuple(orbit.carried))
    x = u if u is not None else np.concatenate([orbit.nodes.ravel(), orbit.switches,
                                                [orbit.period] if orbit.autonomous else []])
    disc = OrbitFold(make2, lay, x, jumps=tuple(orbit.kernel_jumps), multipliers=multipliers,
                     tol=tol, max_iter=max_iter, estimate=estimate, period=period)
    what = f"the orbits' fold at q0 = {q0!r} from p = {p_event!r}"
    try:
        disc.borders(x, p_event, q0)
        y0 = disc.solve_at(np.concatenate([x, [p_event]]), q0, what)
    except (ShootingError, ValueError) as e:
        raise ValueError(f"continue_orbit_curve: the start is not a fold of make2(., q0 = "
                         f"{q0!r}) near p = {p_event!r}: {e}") from None
    if abs(float(y0[-1]) - p_event) > slack:
        raise ValueError(f"continue_orbit_curve: the fold of make2(., q0 = {q0!r}) is at p = "
                         f"{float(y0[-1])!r}, not at the event's p = {p_event!r} (within "
                         f"{slack:.3g}): is make2(p, q0) the branch's model make(p)?")
    b = continuation(disc, y0, q0, q_end, step=float(step), min_step=min_step,
                     max_step=max_step, max_points=max_points, at=at, tol=tol,
                     max_iter=max_iter, predictor="tangent", easy=4, make=make2,
                     kind="orbit-fold")
    return _curve_of(b, disc)


def _curve_of(b: Branch, disc: OrbitFold) -> Curve:
    """The Curve of the driver's branch: its points, the user points, its status in q's
    words."""
    points: list[OrbitCurvePoint] = list(b.points)
    events: list[CurveEvent] = []
    status = b.status.replace("p_end", "q_end").replace(" near p = ", " near q = ")
    end = bautin_end(points)
    if end is not None:
        k, pB, qB = end
        points = points[:k]
        status = (f"reached a Bautin point near (p, q) = ({pB:.10g}, {qB:.10g}): the fold's "
                  "orbits shrink to the equilibrium there, where the fold curve meets the Hopf "
                  "curve (extrapolated to amplitude 0 from the last three points)")
    for e in b.events:
        if e.kind == "user" and e.index < len(points):
            on = [j for j, pt in enumerate(points) if pt.q == e.p]
            i = e.index if e.index in on or not on else min(on, key=lambda j: abs(j - e.index))
            events.append(CurveEvent("user", points[i].p, float(e.p), i, e.detail))
        # the driver's "fold" (a turning point in q) and "branch-point" are not the curve's
    if end is not None:
        events.append(CurveEvent("bautin", end[1], end[2], len(points), status))
    return Curve(kind="orbit-fold", points=points, events=events, status=status,
                 make2=disc.make2)


#: A torus curve ends where theta comes within this (radians) of 0 or pi.
THETA_END = 0.02
#: Steps of inverse iteration that give the start's borders.
INVERSE_STEPS = 3


@dataclass
class FlipCurvePoint(OrbitCurvePoint):
    """A point of a period-doubling curve (:func:`continue_flip_curve`), as
    :class:`OrbitCurvePoint`.

    Attributes
    ----------
    p, q : float
        The parameters.
    orbit : EquationOrbit
        The orbit there (``orbit.make(p)`` is ``make2(p, q)``), its multipliers and their
        error estimates (``orbit.errors``, with ``"p"``); its ``stable`` is None.
    p_error : float or None
        The estimated error of p (the difference to the merged mesh's solve at the same q);
        None where that solve failed.
    dqds : float
        The unit tangent's q component.
    stable : bool or None
        The verdict on the multipliers but the trivial one and the doubling's -1 (verified
        against their errors; None where one is within its error of the unit circle).
    """


@dataclass
class TorusCurvePoint(OrbitCurvePoint):
    """A point of a torus curve (:func:`continue_torus_curve`), as :class:`OrbitCurvePoint`.

    Attributes
    ----------
    p, q : float
        The parameters.
    orbit : EquationOrbit
        The orbit there (``orbit.make(p)`` is ``make2(p, q)``), its multipliers and their
        error estimates (``orbit.errors``, with ``"p"``); its ``stable`` is None.
    p_error : float or None
        The estimated error of p (the difference to the merged mesh's solve at the same q);
        None where that solve failed.
    dqds : float
        The unit tangent's q component.
    stable : bool or None
        The verdict on the multipliers but the trivial one and the critical pair (verified
        against their errors; None where one is within its error of the unit circle).
    theta : float
        The argument in (0, pi) of the critical pair e^(+-i theta), in radians.
    theta_error : float or None
        Its estimated error (the difference to the merged mesh's); None where that failed.
    """
    theta: float = 0.0
    theta_error: float | None = None


def _unrolled(mesh: np.ndarray, m: int, kmin: int) -> Callable:
    """The locator of node rows of the periods kmin, kmin + 1, ... laid end to end (period k's
    node j is row (k - kmin) L m + j): times of any period keep which period they are in."""
    T = float(mesh[-1])
    Lm = (mesh.size - 1) * m
    k = np.arange(m + 1)

    def locate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.asarray(t, dtype=float)
        per = np.floor(t / T)
        i, z = interval_of(mesh, t - per * T)
        cols = (per.astype(int) - kmin)[:, None] * Lm + i[:, None] * m + k[None, :]
        return i, z, cols
    return locate


def central_along(fn: Callable[[np.ndarray], Any], x: np.ndarray, d: np.ndarray) -> Any:
    """The derivative of fn at x along the real direction d (d != 0), by central differences
    (fn(x + e d) - fn(x - e d)) / (2 e) of step e = ALONG_STEP max(1, max |x|) / max |d|."""
    e = ALONG_STEP * max(1.0, float(np.max(np.abs(x)))) / max(float(np.max(np.abs(d))), 1e-300)
    return (fn(x + e * d) - fn(x - e * d)) / (2 * e)


def fu_along(terms: Terms, t: np.ndarray, U: np.ndarray, E: np.ndarray) -> np.ndarray:
    """The derivative of f_u (P, n, n) at (t, U) along the direction E (P, n; complex: its real
    and imaginary parts in turn), by :func:`central_along` (its step ALONG_STEP relative to
    max(1, |U|) over |E|'s largest part): f_u is itself a central difference of f (rounding
    about 1e-11 of f), which a smaller step would amplify."""
    out = np.zeros(U.shape + (U.shape[1],), dtype=complex)
    for part, unit in ((np.real(E), 1.0), (np.imag(E), 1j)):
        if not np.any(part):
            continue
        out += unit * central_along(lambda Z: np.array(terms.fu(t, Z)), U, part)
    return out


class Twisted:
    """The collocation system linearised at an orbit on the unrolled node rows (:func:`_unrolled`)
    and its fold to one period by v(t + k T) = mu^k v(t): A_mu = A_v Phi(mu).

    Attributes
    ----------
    Av : scipy.sparse.csr_matrix
        The linearised rows (P n, R n) on the unrolled node rows.
    E : scipy.sparse.csr_matrix
        u at the collocation points from the unrolled rows (P n, R n).
    wrap, node : numpy.ndarray
        Each unrolled row's period and node row of the period.
    tc, U, fu : numpy.ndarray
        The collocation times, the orbit there (P, n) and f_u there (P, n, n; given as ``fu``
        for an autonomous f at a moved T, else from ``terms``).
    held : numpy.ndarray
        (P, n) booleans: held components (their rows are E's).
    """

    def __init__(self, lay: Layout, terms: Terms, x: np.ndarray, T: float | None = None,
                 fu: np.ndarray | None = None):
        if lay.S:
            raise ValueError("the orbit has switches: its twisted matrix is SwitchTwisted's "
                             "(the saltation included)")
        m, n, basis = lay.m, lay.n, lay.basis
        V, b, T0 = lay.split(x)
        T = T0 if T is None else float(T)
        mesh = lay.mesh(b, T)
        Lm = (mesh.size - 1) * m
        gz, _ = basis.gauss()
        self.tc = (mesh[:-1, None] + np.diff(mesh)[:, None] * gz[None, :]).ravel()
        kmin = (math.floor(-terms.tau / T) - 1) if terms.has_kernel else 0
        R = (2 - kmin) * Lm + 1
        loc = _unrolled(mesh, m, kmin)
        self.E = point_matrix(self.tc, loc, basis, mesh, n, R)
        D = point_matrix(self.tc, loc, basis, mesh, n, R, derivative=True)
        self.wrap, self.node, self.n = np.arange(R) // Lm + kmin, np.arange(R) % Lm, n
        # u at the collocation points as the periodic system computes it (f_u's kept value)
        self.U = (collocation_matrices(basis, np.diff(mesh), n, lay.rows, periodic=True)[0]
                  @ V.ravel()).reshape(-1, n)
        self.fu = fu = terms.fu(self.tc, self.U) if fu is None else fu
        A = D + sp.block_diag(list(fu), format="csr") @ self.E
        if terms.has_kernel:
            A = A + terms.delay(self.tc, mesh, T, loc, basis, R)[0]   # (matrix, extra rows)
        mode = np.repeat(np.array(lay.piece_modes(b, T))[lay.piece_of_interval()], m, axis=0)
        self.held = (mode == STUCK) | (mode == LO) | (mode == HI)
        hv = self.held.ravel().astype(float)
        self.Av = (sp.diags(1.0 - hv) @ A + sp.diags(hv) @ self.E).tocsr()

    def fold(self, mu: complex, derivative: bool = False) -> sp.csr_matrix:
        """Phi(mu) (R n, L m n): row (r, a) to column (node(r), a) times mu^wrap(r); with
        ``derivative``, d Phi / d theta at mu = e^(i theta) (i wrap mu^wrap)."""
        n, R = self.n, self.wrap.size
        val = (complex(mu) ** self.wrap if isinstance(mu, complex)
               else float(mu) ** self.wrap.astype(float))
        if derivative:
            val = 1j * self.wrap * val
        vals = np.repeat(val, n)
        rows = np.arange(R * n)
        cols = (self.node[:, None] * n + np.arange(n)[None, :]).ravel()
        return sp.csr_matrix((vals, (rows, cols)), shape=(R * n, (self.node.max() + 1) * n))

    def matrix(self, mu: complex) -> sp.csc_matrix:
        """A_mu (L m n square)."""
        return sp.csc_matrix(self.Av @ self.fold(mu))

    def dmatrix(self, mu: complex) -> sp.csc_matrix:
        """d A_mu / d theta at mu = e^(i theta)."""
        return sp.csc_matrix(self.Av @ self.fold(mu, True))

    def fu_row(self, terms: Terms, v: np.ndarray, w: np.ndarray, mu: complex) -> np.ndarray:
        """w' (d A_mu / d x_j) v over the node values x_j: the change of f_u at the collocation
        points along v (one difference a real part), against w, back to the node rows."""
        Ev = (self.E @ (self.fold(mu) @ v)).reshape(-1, self.n)
        W = np.where(self.held, 0.0, w.reshape(-1, self.n))
        out = np.einsum("pa,pab->pb", W, fu_along(terms, self.tc, self.U, Ev))
        return (self.E @ self.fold(1.0)).T @ out.ravel()


    def change(self, terms: Terms, moved: Terms, v: np.ndarray, w: np.ndarray, mu: complex
               ) -> complex:
        """w' (A_mu of ``moved`` - A_mu) v where ``moved`` (the model at a moved parameter) has
        this mesh and this memory: f_u's change along v against w, by one-sided differences of
        the change in f along v (f at the orbit kept by both)."""
        Ev = (self.E @ (self.fold(mu) @ v)).reshape(-1, self.n)
        W = np.where(self.held, 0.0, w.reshape(-1, self.n))
        out = 0j
        for part, unit in ((Ev.real, 1.0), (Ev.imag, 1j)):
            big = float(np.max(np.abs(part)))
            if big == 0:
                continue
            eps = CHANGE_STEP * max(1.0, float(np.max(np.abs(self.U)))) / big
            here = (terms.f_anew(self.tc, self.U + eps * part) - terms.f(self.tc, self.U)) / eps
            d = (moved.f_anew(self.tc, self.U + eps * part) - moved.f(self.tc, self.U)) / eps
            out += unit * complex(np.sum(W * (d - here)))
        return out


class SwitchTwisted:
    """The twisted matrix A_mu of an orbit with switches, from the collocation system of one
    period forward from a history (the monodromy operator's,
    :func:`dmi.analysis.collocation.floquet.monodromy`): its unknowns are the period's node
    values (L m + 1 rows, u(T) too) and the switching times, its rows the collocation, u(0) =
    phi(0-) and the switching conditions; the past's nodes (the perturbation at fixed times) are
    read as mu^-k times the period's: the node's value minus u*' (one-sided, inside its interval)
    times the node's motion with the switches (the saltation), so that A_mu is singular exactly
    at the monodromy's multipliers (the system's Jacobian is the monodromy's own,
    :func:`dmi.analysis.collocation.system.full_jacobian` with the history).

    Attributes
    ----------
    lay, terms, x : Layout, Terms, numpy.ndarray
        The orbit.
    Jcur, Jhist : scipy.sparse.csc_matrix
        The history system's Jacobian: the period's columns (nodes, then switching times) and
        the past's node columns.
    B : scipy.sparse.csr_matrix
        The past's nodes from the period's unknowns before the factor mu^-k.
    back : numpy.ndarray
        The period k >= 1 each past entry lies behind.
    U, fu, held : numpy.ndarray
        The orbit and f_u at the collocation points, the held components there.
    n, mesh, hist, nc, nh : int, numpy.ndarray, History, int, int
        The dimension, the mesh, the past (the orbit's periods), the period's and the past's
        node columns.
    dz, h, node_of, tc, E : numpy.ndarray, ..., scipy.sparse.csr_matrix
        The basis' derivatives at its nodes, the intervals' lengths, x's node row of each node
        row of the history system, the collocation times, u there from the period's nodes.
    """

    def __init__(self, lay: Layout, terms: Terms, x: np.ndarray):
        m, n, L = lay.m, lay.n, lay.L
        V, b, T = lay.split(x)
        mesh = lay.mesh(b, T)
        P = max(1, math.ceil(terms.tau / T - 1e-12))
        k = np.arange(m + 1)
        src = (np.arange(L)[:, None] * m + k[None, :]) % lay.rows           # (L, m + 1)
        one = V[src]
        self.lay, self.terms, self.x, self.n, self.mesh = lay, terms, x, n, mesh
        self.hist = History(mesh, P, np.tile(one, (P, 1, 1)).reshape(-1, n))
        J = sp.csc_matrix(full_jacobian(lay, terms, x, None, history=self.hist)[1])
        nc, nh = (lay.rows + 1) * n, P * L * (m + 1) * n
        self.nc, self.nh = nc, nh
        self.Jcur = sp.hstack([J[:, :nc], J[:, nc + nh:]], format="csc")
        self.Jhist = J[:, nc:nc + nh]
        self.dz = lay.basis.derivatives(lay.basis.nodes)                     # (m + 1, m + 1)
        self.h = np.diff(mesh)
        slope = np.einsum("ij,ljn->lin", self.dz, one) / self.h[:, None, None]
        left, right = lay.node_motion()
        piece = lay.piece_of_interval()
        who = lay.ends(b, T)[1]
        # the past's entries (g, j, c): interval g (oldest first), node j, component c
        g = np.repeat(np.arange(P * L), (m + 1) * n)
        i = g % L
        j = np.tile(np.repeat(k, n), P * L)
        c = np.tile(np.arange(n), P * L * (m + 1))
        self.back = P - g // L
        row = np.arange(nh)
        rr, cc, vv = [row], [(i * m + j) * n + c], [np.ones(nh)]
        for motion, end in ((left, who[piece[i]]), (right, who[piece[i] + 1])):
            on = end >= 0
            rr.append(row[on])
            cc.append(nc + end[on])
            vv.append(-slope[i, j, c][on] * motion[i, j][on])
        self.B = sp.csr_matrix((np.concatenate(vv), (np.concatenate(rr), np.concatenate(cc))),
                               shape=(nh, nc + lay.S))
        # the state's map to x's node values: the period's rows (u(T): row 0), the past's
        self.node_of = np.concatenate([np.arange(lay.rows), [0],     # x's row of each node
                                       src[np.arange(P * L) % L].ravel()])
        gz, _ = lay.basis.gauss()
        self.tc = (mesh[:-1, None] + self.h[:, None] * gz[None, :]).ravel()
        self.E = collocation_matrices(lay.basis, self.h, n, lay.rows + 1, periodic=False)[0]
        self.U = (self.E @ np.concatenate([V.ravel(), V[0]])).reshape(-1, n)
        self.fu = terms.fu(self.tc, self.U)
        mode = np.repeat(np.array(lay.piece_modes(b, T))[piece], m, axis=0)
        self.held = (mode == STUCK) | (mode == LO) | (mode == HI)

    def _phi(self, mu: complex, derivative: bool = False) -> sp.csr_matrix:
        """mu^-k B (with ``derivative``: its derivative in theta at mu = e^(i theta))."""
        k = self.back.astype(float)
        val = complex(mu) ** (-k) if isinstance(mu, complex) else float(mu) ** (-k)
        if derivative:
            val = -1j * k * val
        return sp.diags(val) @ self.B

    def matrix(self, mu: complex) -> sp.csc_matrix:
        """A_mu (square: (L m + 1) n + S)."""
        return sp.csc_matrix(self.Jcur + self.Jhist @ self._phi(mu))

    def dmatrix(self, mu: complex) -> sp.csc_matrix:
        """d A_mu / d theta at mu = e^(i theta)."""
        return sp.csc_matrix(self.Jhist @ self._phi(mu, True))

    def x_row(self, v: np.ndarray, w: np.ndarray, mu: complex) -> np.ndarray:
        """w' (d A_mu / d x_j) v over x: the node values from f_u's change along v at the
        collocation points and the stick endings, the switching-time columns' change along v's
        switching times (two assemblies a real part) and u*' in the past's saltation; the
        switching times (and T) by central differences of A_mu assembled again."""
        lay, n, nc = self.lay, self.n, self.nc
        full = np.zeros(nc + self.nh, dtype=complex)        # over the history system's nodes
        full[:nc] += self._fu_part(v, w)
        full += self._switch_part(v, w)
        full += self._time_part(v, w)
        rows = np.zeros((lay.rows, n), dtype=complex)
        np.add.at(rows, self.node_of, full.reshape(-1, n))
        rows += self._slope_part(v, w, mu)
        out = np.concatenate([rows.ravel(), np.zeros(lay.size - rows.size, dtype=complex)])
        d = 1e-6 * lay.split(self.x)[2]          # central differences, as full_jacobian's
        for jx in range(lay.rows * n, lay.size):
            x1, x2 = self.x.copy(), self.x.copy()
            x1[jx] += d
            x2[jx] -= d
            A1 = SwitchTwisted(lay, self.terms, x1).matrix(mu)
            A2 = SwitchTwisted(lay, self.terms, x2).matrix(mu)
            out[jx] = complex(w @ ((A1 - A2) @ v)) / (2 * d)
        return out

    def _fu_part(self, v: np.ndarray, w: np.ndarray) -> np.ndarray:
        """The collocation rows' f_u changed along v, against w, on the period's nodes."""
        n = self.n
        Ev = (self.E @ v[:self.nc]).reshape(-1, n)
        W = np.where(self.held, 0.0, w[:self.U.size].reshape(-1, n))
        out = np.einsum("pa,pab->pb", W, fu_along(self.terms, self.tc, self.U, Ev))
        return self.E.T @ out.ravel()

    def _switch_part(self, v: np.ndarray, w: np.ndarray) -> np.ndarray:
        """The stick endings' rows -f_u(b, u(b)) changed along v, against w."""
        lay, n = self.lay, self.n
        force = force_switches(lay)
        out = np.zeros(self.nc + self.nh, dtype=complex)
        if not force:
            return out
        b = lay.split(self.x)[1][force]
        Eb = point_matrix(b, _unrolled(self.mesh, lay.m, 0), lay.basis, self.mesh, n,
                          lay.rows + 1)
        ub = (Eb @ np.concatenate([self.x[:lay.rows * n], self.x[:n]])).reshape(-1, n)
        Ev = (Eb @ v[:self.nc]).reshape(-1, n)
        ws = w[w.size - lay.S:][force]
        comp = [lay.signature.switch(k + 1)[0] for k in force]
        d = fu_along(self.terms, b, ub, Ev)
        acc = np.array([-ws[j] * d[j, i] for j, i in enumerate(comp)])
        out[:self.nc] = Eb.T @ acc.ravel()
        return out

    def _time_part(self, v: np.ndarray, w: np.ndarray) -> np.ndarray:
        """The switching-time columns' change along v's switching times: w' (J_u(b + e db) -
        J_u(b - e db)) / (2 e) over the history system's nodes (the past held)."""
        lay = self.lay
        db = v[self.nc:]
        out = np.zeros(self.nc + self.nh, dtype=complex)
        T = lay.split(self.x)[2]
        for part, unit in ((db.real, 1.0), (db.imag, 1j)):
            big = float(np.max(np.abs(part)))
            if big == 0:
                continue
            eps = DIFF * T / big
            J = []
            for sgn in (1.0, -1.0):
                x1 = self.x.copy()
                x1[lay.rows * lay.n:lay.rows * lay.n + lay.S] += sgn * eps * part
                J.append(assemble(lay, self.terms, x1, None, history=self.hist)[1])
            out += unit * ((J[0] - J[1]).T @ w) / (2 * eps)
        return out

    def _slope_part(self, v: np.ndarray, w: np.ndarray, mu: complex) -> np.ndarray:
        """u*' in the past's saltation changed with the node values: (L m, n)."""
        lay, n, m, L = self.lay, self.n, self.lay.m, self.lay.L
        k = self.back.astype(float)
        scale = complex(mu) ** (-k) if isinstance(mu, complex) else float(mu) ** (-k)
        aw = (self.Jhist.T @ w) * scale                                 # (nh,)
        # -move (g, j, c) along v's switching times: the slope entries of B over -slope
        mv = self._move(v)                                              # (P L, m + 1)
        coef = (aw.reshape(-1, m + 1, n) * (-mv[:, :, None])).reshape(-1, L, m + 1, n).sum(0)
        grad = np.einsum("ljn,jk->lkn", coef, self.dz) / self.h[:, None, None]
        out = np.zeros((lay.rows, n), dtype=complex)
        src = (np.arange(L)[:, None] * m + np.arange(m + 1)[None, :]) % lay.rows
        np.add.at(out, src.ravel(), grad.reshape(-1, n))
        return out

    def _move(self, v: np.ndarray) -> np.ndarray:
        """The past nodes' motion (P L, m + 1) along v's switching times."""
        lay = self.lay
        V, b, T = lay.split(self.x)
        left, right = lay.node_motion()
        piece = lay.piece_of_interval()
        who = lay.ends(b, T)[1]
        db = np.append(v[self.nc:], 0.0)                               # index S: no switch
        wl = np.where(who[piece] >= 0, who[piece], lay.S)
        wr = np.where(who[piece + 1] >= 0, who[piece + 1], lay.S)
        one = left * db[wl][:, None] + right * db[wr][:, None]
        return np.tile(one, (self.hist.periods, 1))


def twisted(lay: Layout, terms: Terms, x: np.ndarray) -> Twisted | SwitchTwisted:
    """The twisted matrix's builder of the orbit x: :class:`SwitchTwisted` with switches,
    :class:`Twisted` without."""
    return SwitchTwisted(lay, terms, x) if lay.S else Twisted(lay, terms, x)


def _twisted_pair(A: Any, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, complex, np.ndarray]:
    """(v, g, w) of [[A, b], [c', 0]] (v, g) = (0, 1) and [[A', c], [b', 0]] (w, h) = (0, 1),
    complex ones in their real form (one bordered solve each)."""
    At = sp.csc_matrix(A.T)
    if not (np.iscomplexobj(A.data) or np.iscomplexobj(b) or np.iscomplexobj(c)):
        e1 = np.zeros(c.size + 1)
        e1[-1] = 1.0
        vg = bordered_solve(A, b, np.append(c, 0.0), e1)
        wh = bordered_solve(At, c, np.append(b, 0.0), e1)
        return vg[:-1], float(vg[-1]), wh[:-1]
    v, g = _real_form(A, b, c)
    w, _ = _real_form(At, c, b)
    return v, g, w


def _real_form(M: Any, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, complex]:
    """(v, g) of the complex [[M, b], [c', 0]] (v, g) = (0, 1) in its real form (Re, Im)."""
    N = M.shape[0]
    Mr, Mi = sp.csr_matrix(M.real), sp.csr_matrix(M.imag)
    big = sp.bmat([[Mr, -Mi], [Mi, Mr]], format="csc")
    cols = np.column_stack([np.concatenate([b.real, b.imag]),
                            np.concatenate([-b.imag, b.real])])
    rows = np.array([np.concatenate([c.real, -c.imag, [0.0, 0.0]]),
                     np.concatenate([c.imag, c.real, [0.0, 0.0]])])
    rhs = np.zeros(2 * N + 2)
    rhs[2 * N] = 1.0
    z = bordered_solve(big, cols, rows, rhs)
    return z[:N] + 1j * z[N:2 * N], complex(z[2 * N], z[2 * N + 1])


class OrbitFlip(OrbitFold):
    """The minimally augmented system of a period doubling (``theta`` None: mu = -1, unknowns
    (x, p)) or of a torus (``theta`` the start's angle: mu = e^(i theta), unknowns (x, p,
    theta)) of collocated orbits on the one driver (see the module); parameter q."""
    what = "the bifurcation"

    def __init__(self, make2: Callable[[float, float], Solver], layout: Layout, x: np.ndarray,
                 *, theta: float | None = None, **options: Any):
        super().__init__(make2, layout, x, **options)
        self.torus = theta is not None
        self.theta0 = float(theta) if theta is not None else math.pi

    @property
    def extra(self) -> int:
        """The unknowns past x: p (and theta on a torus curve)."""
        return 2 if self.torus else 1

    def mu(self, y: np.ndarray) -> complex:
        """The multiplier of y: -1, or e^(i theta)."""
        return complex(np.exp(1j * y[-1])) if self.torus else -1.0

    def _split(self, y: np.ndarray) -> tuple[np.ndarray, float]:
        return y[:self.lay.size], float(y[self.lay.size])

    def borders(self, x: np.ndarray, p: float, q: float, scale: bool = True) -> None:
        """b and c by INVERSE_STEPS steps of inverse iteration from fixed pseudo-random vectors,
        and (``scale``) g's unit (1 / its gradient's largest entry there)."""
        y = np.concatenate([x, [p], [self.theta0] if self.torus else []])
        A = twisted(self.layout(p, q), self.terms(p, q), x).matrix(self.mu(y))
        rng = np.random.default_rng(20260)
        shape = (2, A.shape[0])
        b, c = rng.standard_normal(shape) + (1j * rng.standard_normal(shape) if self.torus
                                             else 0.0)
        for _ in range(INVERSE_STEPS):
            v, _, w = _twisted_pair(A, b, c)
            c, b = np.conj(v) / np.linalg.norm(v), np.conj(w) / np.linalg.norm(w)
        self.b, self.c, self._last = b, c, None
        if not scale:
            return
        self.gscale = 1.0
        rows = self._jy(y, q)[2]
        self.gscale = 1.0 / max(float(np.max(np.abs(rows))), 1e-300)
        self._last = None

    def _eval(self, y: np.ndarray, q: float) -> dict[str, Any]:
        """F, J, A_mu's parts, v, w and g at (y, q) (the last kept)."""
        key = (y.tobytes(), float(q), id(self.lay), id(self.b), self.gscale)
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        x, p = self._split(y)
        t, lay = self.terms(p, q), self.layout(p, q)
        r, J = full_jacobian(lay, t, x, self.ref)
        tw = twisted(lay, t, x)
        v, g, w = _twisted_pair(tw.matrix(self.mu(y)), self.b, self.c)
        g = complex(g) * self.gscale
        ev = {"r": r, "J": J, "v": v, "w": w, "g": np.array([g.real, g.imag][:self.extra]),
              "terms": t, "tw": tw}
        self._last = (key, ev)
        return ev

    def residual(self, y: np.ndarray, q: float) -> np.ndarray:
        """(F, g) at (y, q) (g: Re and Im on a torus curve)."""
        ev = self._eval(y, q)
        return np.concatenate([ev["r"], ev["g"]])

    def _grad(self, ev: dict, y: np.ndarray, A1: Any, d: float) -> np.ndarray:
        """-w' (A1 - A_mu) v / d as g's rows (Re, Im)."""
        mu = self.mu(y)
        return self._rows(complex(ev["w"] @ ((A1 - ev["tw"].matrix(mu)) @ ev["v"])), d)

    def _rows(self, change: complex, d: float) -> np.ndarray:
        """-change / d as g's rows (Re, Im)."""
        dg = -self.gscale * change / d
        return np.array([dg.real, dg.imag][:self.extra])

    def _moved(self, ev: dict, y: np.ndarray, p1: float, q1: float, d: float
               ) -> tuple[np.ndarray, np.ndarray]:
        """(F's and g's derivatives) by the difference to (p1, q1) = (p, q) moved by d: g's
        from f's change along v (:meth:`Twisted.change`) where the mesh and the memory stay,
        else from the twisted matrix assembled there."""
        x, _ = self._split(y)
        t1, l1 = self.terms(p1, q1), self.layout(p1, q1)
        F1 = (assemble(l1, t1, x, self.ref, jacobian=False)[0] - ev["r"]) / d
        if not self.lay.S and self.period is None and ev["terms"].same_memory(t1):
            return F1, self._rows(ev["tw"].change(ev["terms"], t1, ev["v"], ev["w"],
                                                  self.mu(y)), d)
        return F1, self._grad(ev, y, twisted(l1, t1, x).matrix(self.mu(y)), d)

    def _jy(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray, np.ndarray, dict]:
        """(J, the columns of p (and theta), g's rows in y, the evaluation) at (y, q)."""
        ev = self._eval(y, q)
        x, p = self._split(y)
        mu, tw, t = self.mu(y), ev["tw"], ev["terms"]
        if self.lay.S:          # the switching times and T included
            gx = -self.gscale * tw.x_row(ev["v"], ev["w"], mu)
        else:
            gx = -self.gscale * tw.fu_row(t, ev["v"], ev["w"], mu)
            gx = np.concatenate([gx, np.zeros(self.lay.size - gx.size, dtype=complex)])
        if self.lay.autonomous and not self.lay.S:
            T = float(x[-1])
            dT = DIFF * T
            # f_u of an autonomous f is the same at the moved times
            gT = self._grad(ev, y, Twisted(self.lay, t, x, T + dT, tw.fu).matrix(mu), dT)
        d = DIFF * max(1.0, abs(p))
        Fp, gp = self._moved(ev, y, p + d, q, d)
        rows = np.vstack([gx.real, gx.imag])[:self.extra]
        if self.lay.autonomous and not self.lay.S:
            rows[:, -1] = gT
        rows = np.column_stack([rows, gp])
        cols = Fp[:, None]
        if self.torus:
            dth = -self.gscale * complex(ev["w"] @ (tw.dmatrix(mu) @ ev["v"]))
            rows = np.column_stack([rows, [dth.real, dth.imag]])
            cols = np.column_stack([Fp, np.zeros(Fp.size)])
        return ev["J"], cols, rows, ev

    def jacobian(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray]:
        """(J_y sparse, J_q): the driver's Jacobian in the unknowns y and in its parameter q."""
        J, cols, rows, ev = self._jy(y, q)
        x, p = self._split(y)
        d = DIFF * max(1.0, abs(q))
        Fq, gq = self._moved(ev, y, p, q + d, d)
        return sparse_bordered(J, cols, rows), np.concatenate([Fq, gq])

    def strategies(self, y: np.ndarray, q: float, row: np.ndarray, target: float, far: float
                   ) -> Iterator[Strategy]:
        """The driver's Newton strategy (:func:`newton_strategy`)."""
        what = "torus" if self.torus else "period doubling"
        yield newton_strategy(DriverCurve(self, y.size), np.concatenate([y, [q]]), row, target,
                              tol=self.tol, max_iter=self.max_iter, far=far,
                              what=f"the orbits' {what} near q = {q!r}")

    def accept(self, y: np.ndarray, q: float, step: bool) -> tuple[np.ndarray, float]:
        """The orbit's inequalities checked (as the fold curve's: a curve does not cross
        signatures), and on a torus curve theta kept away from 0 and pi."""
        x, p = self._split(y)
        super().accept(np.concatenate([x, [p]]), q, step)
        if self.torus:
            th = float(y[-1])
            end = min((abs(th), "+1 (theta -> 0: a 1:1 resonance"),
                      (abs(th - math.pi), "-1 (theta -> pi: a 1:2 resonance"))
            if end[0] < THETA_END or not 0 < th < math.pi:
                self.breach = (f"near (p, q) = ({p:.10g}, {q:.10g}) the pair e^(+-i theta) "
                               f"meets at {end[1]}, theta = {th:.6g}): the torus curve "
                               "ends there (a neutral saddle follows)")
                raise ShootingError(self.breach, [])
        return y, q

    def adapt(self, y: np.ndarray, q: float) -> np.ndarray:
        """Between steps: the borders moved to the point's conj(v) and conj(w), the mesh
        equidistributed again, the phase condition's reference moved to the point."""
        ev = self._eval(y, q)
        self.c = np.conj(ev["v"]) / np.linalg.norm(ev["v"])
        self.b = np.conj(ev["w"]) / np.linalg.norm(ev["w"])
        rest = y[self.lay.size:]
        x = self.remesh(y[:self.lay.size], float(rest[0]), q)
        self._last = None
        if self.lay.S and self.c.size != (self.lay.rows + 1) * self.lay.n + self.lay.S:
            self.borders(x, float(rest[0]), q, scale=False)   # the pieces' intervals moved
        return np.concatenate([x, rest])

    def point(self, y: np.ndarray, q: float) -> OrbitCurvePoint:
        """The curve's point at (y, q): the orbit, its errors from the merged mesh's solve,
        the verdict on the other multipliers."""
        p = float(y[self.lay.size])
        fine, errors, yc = self.levels(y, q)
        p_error, th_error = errors.get("p"), None
        if self.torus and yc is not None:
            th_error = max(abs(float(yc[-1] - y[-1])), FLOOR)
            errors["theta"] = th_error
        with warnings.catch_warnings():   # a multiplier on the circle: the orbit's stable None
            warnings.simplefilter("ignore", CollocationWarning)
            orbit = equation_orbit(fine, p, AtQ(self.make2, q), errors, self.jumps)
        orbit.stable = None
        stable = _others_stable_at(fine.mu, errors.get("multipliers"), self.lay.autonomous,
                                self.mu(y), p, q)
        if self.torus:
            return TorusCurvePoint(p, float(q), orbit, p_error, stable, theta=float(y[-1]),
                                   theta_error=th_error)
        return FlipCurvePoint(p, float(q), orbit, p_error, stable)

    def on_mesh(self, lay: Layout, x: np.ndarray, y: np.ndarray, q: float) -> OrbitFlip:
        """The same system on lay from x (theta from y), its borders from there."""
        other = OrbitFlip(self.make2, lay, x, theta=float(y[-1]) if self.torus else None,
                          **self.options)
        other.ref, other.problem = self.ref, self.problem
        other.borders(x, float(y[self.lay.size]), q)
        return other


def _others_stable_at(mu: np.ndarray, err: Any, autonomous: bool, crit: complex, p: float,
                   q: float) -> bool | None:
    """The multipliers but the trivial one (autonomous) and the critical ones (the nearest
    -1, or the pair nearest e^(+-i theta)) all inside the unit circle (True) or one outside
    (False) beyond their errors; None (with a CollocationWarning) otherwise."""
    if mu.size == 0 or err is None:
        return None
    keep = np.ones(mu.size, bool)
    targets = ([1.0] if autonomous else []) + [crit] + ([np.conj(crit)] if np.imag(crit) else [])
    for z in targets:
        rest = np.flatnonzero(keep)
        if rest.size:
            keep[rest[int(np.argmin(np.abs(mu[rest] - z)))]] = False
    a, e = np.abs(mu[keep]), np.asarray(err)[keep]
    if np.any(a > 1 + e):
        return False
    if np.all(a < 1 - e):
        return True
    warnings.warn(f"(p, q) = ({p!r}, {q!r}): a multiplier other than the critical ones is "
                  "within its estimated error of the unit circle: the verdict is None",
                  CollocationWarning, stacklevel=3)
    return None


def _start(start: Any, branch: Branch | None, kind: str, who: str
           ) -> tuple[EquationOrbit, float, tuple[float, float]]:
    """(the orbit nearest the event, the event's p, the bracket of p the bifurcation at q0 must
    lie in: the event's two points, widened by their distance)."""
    if isinstance(start, EquationOrbit):
        return start, float(start.p), (-math.inf, math.inf)
    if not (isinstance(start, Event) and start.kind == kind):
        raise ValueError(f"{who}: start = {start!r}: give a '{kind}' event of a branch of "
                         "EquationOrbits (with branch=) or an EquationOrbit near it")
    if branch is None or not isinstance(branch, Branch):
        raise ValueError(f"{who}: a '{kind}' event needs branch=, the Branch of EquationOrbits "
                         "it belongs to (continue_orbit of an EquationOrbit)")
    pts = branch.points
    if not pts or not all(isinstance(pt, EquationOrbit) for pt in pts):
        raise ValueError(f"{who}: branch= is not a branch of EquationOrbits (continue_orbit of "
                         "an EquationOrbit, from collocate or hopf_orbit(..., of='equation'))")
    if start not in branch.events:
        raise ValueError(f"{who}: the '{kind}' event is not one of branch.events")
    k = min(max(int(start.index), 1), len(pts) - 1)
    before, after = pts[k - 1], pts[k]
    orbit = before if abs(before.p - start.p) <= abs(after.p - start.p) else after
    wide = abs(after.p - before.p)
    return orbit, float(start.p), (min(before.p, after.p) - wide, max(before.p, after.p) + wide)


def _angle(orbit: EquationOrbit, who: str) -> float:
    """The argument in (0, pi) of the orbit's non-real multiplier nearest the unit circle."""
    mu = np.asarray(orbit.multipliers)
    pick = mu[np.abs(mu.imag) > 1e-9 * np.maximum(np.abs(mu), 1e-300)]
    if pick.size == 0:
        raise ValueError(f"{who}: the start's orbit has no non-real multiplier: not near a "
                         "torus bifurcation (give its event, or an orbit whose multipliers "
                         "include a complex pair near the unit circle)")
    return abs(float(np.angle(pick[int(np.argmin(np.abs(np.abs(pick) - 1)))])))


def _prepared(kind: str, start: Any, make2: Callable[[float, float], Solver], q0: float,
              q_end: float, branch: Branch | None, step: float | None, **options: Any
              ) -> tuple[OrbitFlip, np.ndarray, float]:
    """(the system, its start solved at q0, the first step) of a curve of ``kind``
    (``"period-doubling"`` or ``"torus"``; see :func:`continue_flip_curve`)."""
    who = "continue_flip_curve" if kind == "period-doubling" else "continue_torus_curve"
    orbit, p_event, bracket = _start(start, branch, kind, who)
    q0, q_end, step = curve_range(who, q0, q_end, step)
    if not callable(make2):
        raise ValueError(f"{who}: make2 = {make2!r}: give a function (p, q) -> dmi.Solver")
    check_period(options.get("period"), orbit.autonomous, orbit.period, p_event, q0, who)
    lay = Layout(orbit.degree, orbit.nodes.shape[1], orbit.signature,
                 [f.copy() for f in orbit.fractions], orbit.autonomous, orbit.period,
                 tuple(orbit.carried))
    x = np.concatenate([orbit.nodes.ravel(), orbit.switches,
                        [orbit.period] if orbit.autonomous else []])
    theta = _angle(orbit, who) if kind == "torus" else None
    disc = OrbitFlip(make2, lay, x, theta=theta, jumps=tuple(orbit.kernel_jumps), **options)
    try:
        disc.borders(x, p_event, q0)
        y0 = disc.solve_at(np.concatenate([x, [p_event], [theta] if theta is not None else []]),
                           q0, f"the orbits' {kind} at q0 = {q0!r} from p = {p_event!r}")
    except (ShootingError, ValueError) as e:
        raise ValueError(f"{who}: the start is not a {kind} of make2(., q0 = {q0!r}) near p = "
                         f"{p_event!r}: {e}") from None
    p0 = float(y0[lay.size])
    if not bracket[0] <= p0 <= bracket[1]:
        raise ValueError(f"{who}: the {kind} of make2(., q0 = {q0!r}) is at p = {p0!r}, outside "
                         f"the event's bracket {bracket!r}: is make2(p, q0) the branch's model "
                         "make(p)?")
    return disc, y0, float(step)


def _finished(b: Branch, disc: OrbitFlip, kind: str) -> Curve:
    """The Curve of the driver's branch: its points, the user points, a torus curve's end at a
    resonance, its status in q's words."""
    status = b.status.replace("p_end", "q_end").replace(" near p = ", " near q = ")
    points = list(b.points)
    events = []
    for e in b.events:
        if e.kind == "user" and e.index < len(points):
            on = [j for j, pt in enumerate(points) if pt.q == e.p]
            i = e.index if e.index in on or not on else min(on, key=lambda j: abs(j - e.index))
            events.append(CurveEvent("user", points[i].p, float(e.p), i, e.detail))
    if disc.breach and "meets at" in disc.breach and points and disc.breach in status:
        res = "1:2 resonance" if "theta -> pi" in disc.breach else "1:1 resonance"
        events.append(CurveEvent(res, points[-1].p, points[-1].q, len(points) - 1, disc.breach))
        status = disc.breach   # the driver's words around it repeat it
    return Curve(kind=kind, points=points, events=events, status=status, make2=disc.make2)


def continue_flip_curve(start: Any, make2: Callable[[float, float], Solver], q0: float,
                        q_end: float, *, branch: Branch | None = None,
                        step: float | None = None, at: Iterable[float] = (),
                        max_points: int = 100, min_step: float | None = None,
                        max_step: float | None = None, multipliers: int = 10,
                        tol: float = 1e-10, max_iter: int = 10, estimate: bool = True,
                        period: Callable[[float, float], float] | None = None) -> Curve:
    """Continues a period doubling of the equation's periodic orbits (collocated) in the plane
    (p, q): the curve where a Floquet multiplier of the orbit of ``make2(p, q)`` is -1, by
    pseudo-arclength in (x, p, q) with the minimally augmented system of
    :mod:`dmi.analysis.plane.orbit_curves`, from q0 through turning points in q to q_end.

    Parameters
    ----------
    start : Event or EquationOrbit
        A ``period-doubling`` event of a branch of EquationOrbits of ``make2(., q0)`` (give that
        Branch as ``branch=``), or an EquationOrbit of ``make2(., q0)`` near a period doubling.
        Orbits with switches (stick-slip, reversals) too.
    make2, q0, q_end, branch, step, at, max_points
        As :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`'s.
    min_step, max_step, multipliers, tol, max_iter, estimate, period
        As :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`'s.

    Returns
    -------
    Curve
        ``kind`` ``"period-doubling"``; ``points`` (:class:`FlipCurvePoint`: ``p``, ``q``,
        ``orbit``, ``p_error``, ``stable`` on the multipliers but the trivial one and -1),
        ``events`` (``user``), ``status`` (q_end reached, a turn back past q0, max_points, a
        signature the orbits would leave, or the corrector failing).

    Raises
    ------
    ValueError
        A start of another kind, an event without its branch, bad q0, q_end or step; a start
        that is not a period doubling of ``make2(., q0)`` (Newton fails
        at q0, or finds it outside the event's two points widened by their distance).
    """
    q0, q_end = float(q0), float(q_end)
    disc, y0, step = _prepared("period-doubling", start, make2, q0, q_end, branch, step,
                               multipliers=multipliers, tol=tol, max_iter=max_iter,
                               estimate=estimate, period=period)
    b = continuation(disc, y0, q0, q_end, step=step, min_step=min_step, max_step=max_step,
                     max_points=max_points, at=at, tol=tol, max_iter=max_iter,
                     predictor="tangent", easy=4, make=make2, kind="period-doubling")
    return _finished(b, disc, "period-doubling")


def continue_torus_curve(start: Any, make2: Callable[[float, float], Solver], q0: float,
                         q_end: float, *, branch: Branch | None = None,
                         step: float | None = None, at: Iterable[float] = (),
                         max_points: int = 100, min_step: float | None = None,
                         max_step: float | None = None, multipliers: int = 10,
                         tol: float = 1e-10, max_iter: int = 10, estimate: bool = True,
                         period: Callable[[float, float], float] | None = None) -> Curve:
    """Continues a torus (Neimark-Sacker) bifurcation of the equation's periodic orbits
    (collocated) in the plane (p, q): the curve where a pair of Floquet multipliers is
    e^(+-i theta), theta in (0, pi) an unknown, as :func:`continue_flip_curve` does.

    Parameters
    ----------
    start : Event or EquationOrbit
        A ``torus`` event of a branch of EquationOrbits of ``make2(., q0)`` (with ``branch=``),
        or an EquationOrbit near a torus bifurcation (theta starts from its non-real
        multiplier nearest the unit circle).  Orbits with switches (stick-slip, reversals)
        too.
    make2, q0, q_end, branch, step, at, max_points
        As :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`'s (the arclength also
        counts theta, in radians).
    min_step, max_step, multipliers, tol, max_iter, estimate, period
        As :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`'s.

    Returns
    -------
    Curve
        ``kind`` ``"torus"``; ``points`` (:class:`TorusCurvePoint`: also ``theta`` and
        ``theta_error``), ``events`` (``user``; ``"1:1 resonance"`` or ``"1:2 resonance"`` where
        theta reaches 0 or pi and the curve ends), ``status``.

    Raises
    ------
    ValueError
        As :func:`continue_flip_curve`'s; a start orbit without a non-real multiplier.
    """
    q0, q_end = float(q0), float(q_end)
    disc, y0, step = _prepared("torus", start, make2, q0, q_end, branch, step,
                               multipliers=multipliers, tol=tol, max_iter=max_iter,
                               estimate=estimate, period=period)
    b = continuation(disc, y0, q0, q_end, step=step, min_step=min_step, max_step=max_step,
                     max_points=max_points, at=at, tol=tol, max_iter=max_iter,
                     predictor="tangent", easy=4, make=make2, kind="torus")
    return _finished(b, disc, "torus")


__all__ = ["OrbitCurvePoint", "continue_orbit_curve", "FlipCurvePoint", "TorusCurvePoint",
           "continue_flip_curve", "continue_torus_curve"]
