# Curves of the stick onsets and grazings of the equation's periodic orbits in two parameters:
# the margin of the inequality that breaks held at 0 on the collocated orbit, continued in (p, q)
# on the one driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The stick-onset and grazing boundaries of collocated orbits continued in the plane (p, q):
:func:`continue_stick_curve`, its points :class:`StickCurvePoint` in a
:class:`dmi.analysis.Curve` of kind ``"stick-onset"`` or ``"grazing"``.

The system: F(x; p, q) = 0 is the collocation system of the orbit on the signature of the side
where its inequalities hold (:mod:`dmi.analysis.collocation.system`), read from the orbit of the
start (the one-parameter branch's point next to the event, no signature written by hand); the
unknowns are (x, p), the driver's parameter is q (:func:`dmi.analysis.continuation.driver.
continuation`: turning points in q, q_end and the user's q landed on exactly), and the extra
equation is the margin m(x, p; q) = 0 of the inequality that breaks
(:class:`dmi.analysis.collocation.margins.Margin`, the kinds and their least values there); by
its stationarity at the minimiser t* the derivative of m in x, p and q is that of the value at
t* held (node columns exact, the switching times' and the period's columns and p, q by central
differences).

Each point carries its :class:`EquationOrbit` (multipliers and their error estimates from the
boundary solved again at the same q on the mesh with every pair of intervals merged, which also
gives the error estimate of p) and the orbit's verified verdict.  Along the curve the sign of
det F_x is followed (``fold_test``): where it changes, a fold of the orbits at fixed q meets the
boundary (a fold curve of the orbits crosses it), located by Newton on F = 0, m = 0 and the fold's
minimally augmented test function g = 0 (:class:`dmi.analysis.plane.orbit_system.FoldSystem`) in
(x, p, q): a curve event of kind ``"orbit-fold"``.  A curve whose orbits would break another
inequality of their signature ends there (the status says which).
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..._solver import Solver
from ..collocation.orbit import EquationOrbit, equation_orbit
from ..collocation.system import Layout, Terms, assemble, full_jacobian
from ..continuation.branch import Branch, Curve, CurveEvent, Event
from ..continuation.driver import bordered_det, continuation, curve_range
from ..core.newton import ShootingError, bordered_solve, newton_loop, sparse_bordered
from ..scheme.problem import AtQ
from ..scheme.stepmap import build
from ..collocation.margins import Margin, MarginValues, margins
from .orbit_system import FoldSystem, OrbitCurvePoint, OrbitSystem, check_period

#: Relative step of the central differences (the margin's non-node columns, F_p, F_q).
DIFF = 1e-7
#: A start's boundary at q0 must lie within this (relative to max(1, |p|)) of the event's p.
START_TOL = 1e-6


@dataclass
class StickCurvePoint(OrbitCurvePoint):
    """A point of a stick-onset or grazing curve (:func:`continue_stick_curve`), as
    :class:`~dmi.analysis.OrbitCurvePoint`.

    Attributes
    ----------
    p, q : float
        The parameters.
    orbit : EquationOrbit
        The orbit there, on the signature of the side where it holds (``orbit.make(p)`` is
        ``make2(p, q)``): period, amplitude, multipliers, their error estimates
        (``orbit.errors``, with ``"p"``) and its verified ``stable``.
    p_error : float or None
        The estimated error of p (the difference to the boundary on the mesh of merged pairs of
        intervals at the same q); None where that solve failed (a warning says so).
    stable : bool or None
        The orbit's verdict (``orbit.stable``: verified against the multipliers' errors, None
        where one is within its error of the unit circle or no estimate exists).
    dqds : float
        The unit tangent's q component.
    t_star : float
        The time of the margin's least value (a reversal's switching time).
    fold_test : float
        det F_x's sign times the fold's test function (a fold of the orbits at fixed q where it
        changes sign).
    side : int
        Where in p, at this q, the orbits stick (stick onset) or graze into a new signature:
        +1 at larger p, -1 at smaller (the sign opposite to d m / d p along the orbits' branch
        at fixed q, m the margin); 0 where that derivative is not computable.
    """
    t_star: float = 0.0
    fold_test: float = math.nan
    side: int = 0


class StickBoundary(OrbitSystem):
    """The boundary's system (see the module) as a discretisation of the one driver: unknowns
    y = (x, p), parameter q.

    Parameters
    ----------
    make2 : callable
        ``make2(p, q) -> dmi.Solver``.
    layout : Layout
        The collocation's layout (the holding side's signature).
    x : numpy.ndarray
        The orbit's unknowns (the phase condition's reference).
    margin : Margin
        The inequality held at 0.
    kind : str
        ``"stick-onset"`` or ``"grazing"``.
    jumps : tuple of float
        The kernel's jumps.
    multipliers : int
        Leading multipliers a point carries.
    tol, max_iter : float, int
        The corrector's tolerance and iterations.
    estimate : bool
        A point's error estimates from the merged mesh (False: none, the verdict None).
    period : callable, optional
        ``period(p, q)``: a forced orbit's period at (p, q) (None: the layout's, fixed).
    """

    def __init__(self, make2: Callable[[float, float], Solver], layout: Layout, x: np.ndarray,
                 margin: Margin, kind: str, *, jumps: tuple[float, ...] = (),
                 multipliers: int = 10, tol: float = 1e-11, max_iter: int = 10,
                 estimate: bool = True, period: Callable[[float, float], float] | None = None):
        super().__init__(make2, layout, x, jumps=jumps, multipliers=multipliers, tol=tol,
                         max_iter=max_iter, estimate=estimate, period=period)
        self.margin, self.kind = margin, kind
        self.t_star = 0.0
        self.y0: np.ndarray | None = None   # the start, solved at q0

    def _margin(self, y: np.ndarray, q: float) -> tuple[float, float]:
        """(m, t*) at (y, q)."""
        p = float(y[-1])
        return MarginValues(self.layout(p, q), self.margin).least(self.terms(p, q), y[:-1])

    def residual(self, y: np.ndarray, q: float) -> np.ndarray:
        """(F, m) at (y, q)."""
        x, p = y[:-1], float(y[-1])
        r = assemble(self.layout(p, q), self.terms(p, q), x, self.ref, jacobian=False)[0]
        m, self.t_star = self._margin(y, q)
        return np.append(r, m)

    def _row(self, y: np.ndarray, q: float, t_star: float) -> tuple[np.ndarray, float]:
        """(d m / d (x, p), d m / d q) at the time held."""
        x, p = y[:-1], float(y[-1])
        lay = self.layout(p, q)
        vals = MarginValues(lay, self.margin)
        first = lay.rows * lay.n
        row = np.zeros(y.size)
        row[:first] = vals.node_row(self.terms(p, q), x, t_star)
        T = lay.split(x)[2]
        for j in range(first, x.size):
            d = DIFF * T
            xp, xm = x.copy(), x.copy()
            xp[j] += d
            xm[j] -= d
            row[j] = (vals.value(self.terms(p, q), xp, t_star)
                      - vals.value(self.terms(p, q), xm, t_star)) / (2 * d)
        dp, dq = DIFF * max(1.0, abs(p)), DIFF * max(1.0, abs(q))
        row[-1] = (self._value(p + dp, q, x, t_star)
                   - self._value(p - dp, q, x, t_star)) / (2 * dp)
        mq = (self._value(p, q + dq, x, t_star) - self._value(p, q - dq, x, t_star)) / (2 * dq)
        return row, mq

    def _value(self, p: float, q: float, x: np.ndarray, t_star: float) -> float:
        """The margin of x at (p, q) at the time held."""
        return MarginValues(self.layout(p, q), self.margin).value(self.terms(p, q), x, t_star)

    def parts(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray,
                                                       float]:
        """(F_x sparse, F_p, d m / d (x, p), F_q, d m / d q) at (y, q)."""
        x, p = y[:-1], float(y[-1])
        r, J = full_jacobian(self.layout(p, q), self.terms(p, q), x, self.ref)
        dp, dq = DIFF * max(1.0, abs(p)), DIFF * max(1.0, abs(q))
        Fp = (assemble(self.layout(p + dp, q), self.terms(p + dp, q), x, self.ref,
                       jacobian=False)[0] - r) / dp
        Fq = (assemble(self.layout(p, q + dq), self.terms(p, q + dq), x, self.ref,
                       jacobian=False)[0] - r) / dq
        _, t_star = self._margin(y, q)
        row, mq = self._row(y, q, t_star)
        return J, Fp, row, Fq, mq

    def jacobian(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray]:
        """(J_y sparse, J_q): the driver's Jacobian in y and in q."""
        J, Fp, row, Fq, mq = self.parts(y, q)
        return sparse_bordered(J, Fp, row), np.append(Fq, mq)

    def solve_at(self, y0: np.ndarray, q: float, what: str) -> np.ndarray:
        """The boundary at fixed q from y0 (Newton on (F, m) in (x, p))."""
        def evaluate_(y: np.ndarray) -> tuple[np.ndarray, None]:
            return self.residual(y, q), None

        def factor(y: np.ndarray, r: np.ndarray, _: None) -> Callable[[np.ndarray], np.ndarray]:
            J, Fp, row, _, _ = self.parts(y, q)
            return lambda rr: bordered_solve(J, Fp, row, -rr)

        y, _ = newton_loop(evaluate_, factor, np.array(y0, dtype=float), tol=self.tol,
                           max_iter=3 * self.max_iter, what=what, converge="correction",
                           stall=False)
        return y

    def accept(self, y: np.ndarray, q: float, step: bool) -> tuple[np.ndarray, float]:
        """The orbit's other inequalities checked: a point whose orbit breaks its signature
        elsewhere is refused (the curve ends there; :meth:`corner` says why)."""
        x, p = y[:-1], float(y[-1])
        bad = self.broken(x, p, q, 1e-7)
        if bad:
            self.breach = (f"near (p, q) = ({p:.10g}, {q:.10g}) the boundary's orbit breaks "
                           f"its signature elsewhere ({bad}): another stick onset or "
                           "grazing meets this curve there")
            raise ShootingError(self.breach, [])
        return y, q

    def adapt(self, y: np.ndarray, q: float) -> np.ndarray:
        """Between steps: the mesh equidistributed again, the phase condition's reference moved
        to the point."""
        return np.concatenate([self.remesh(y[:-1], float(y[-1]), q), y[-1:]])

    def fold_test(self, y: np.ndarray, q: float) -> float:
        """sign(det F_x) |g|, g the fold's bordered test function with fixed uniform borders
        (sign(det F_x) = sign(g) sign(det) of the bordered matrix): its sign changes where the
        orbit's branch at fixed q folds, not where the borders change."""
        x, p = y[:-1], float(y[-1])
        J = full_jacobian(self.layout(p, q), self.terms(p, q), x, self.ref)[1]
        m = x.size
        b = c = np.full(m, 1.0 / math.sqrt(m))
        e1 = np.zeros(m + 1)
        e1[-1] = 1.0
        try:
            vg = bordered_solve(J, b, np.append(c, 0.0), e1)
        except ShootingError:
            return 0.0
        sign = bordered_det(J, b, np.append(c, 0.0))
        return float(math.copysign(abs(vg[-1]), vg[-1] * sign)) if sign != 0 else 0.0

    def point(self, y: np.ndarray, q: float) -> StickCurvePoint:
        """The curve's point at (y, q): the orbit, its errors from the merged mesh's boundary,
        its verdict, the fold test."""
        p = float(y[-1])
        fine, errors, _ = self.levels(y, q)
        orbit = equation_orbit(fine, p, AtQ(self.make2, q), errors, self.jumps)
        _, t_star = self._margin(y, q)
        return StickCurvePoint(p, float(q), orbit, p_error=errors.get("p"), stable=orbit.stable,
                               t_star=t_star, fold_test=self.fold_test(y, q),
                               side=self.side(y, q))

    def side(self, y: np.ndarray, q: float) -> int:
        """-sign(d m / d p) along the orbits' branch at fixed q: from the bordered system
        [[F_x, F_p], [m_x, m_p]] (v, s) = (0, 1), whose s is 1 / (d m / d p)."""
        J, Fp, row, _, _ = self.parts(y, q)
        e1 = np.zeros(y.size)
        e1[-1] = 1.0
        try:
            s = float(bordered_solve(J, Fp, row, e1)[-1])
        except ShootingError:
            return 0
        return -int(np.sign(s))

    def on_mesh(self, lay: Layout, x: np.ndarray, y: np.ndarray, q: float) -> StickBoundary:
        """The same boundary on lay from x."""
        return StickBoundary(self.make2, lay, x, self.margin, self.kind, **self.options)

    def between(self, za: np.ndarray, a: StickCurvePoint, zb: np.ndarray, b: StickCurvePoint,
                middle: Any) -> list[Event]:
        """An ``orbit-fold`` event where the fold test changes sign between a and b: located by
        Newton on (F, m, the fold's g) in (x, p, q) from b (:func:`fold_crossing`); reported
        at b's q, not located, with the detail saying why, where that fails."""
        fa, fb = a.fold_test, b.fold_test
        if not (math.isfinite(fa) and math.isfinite(fb)) or fa * fb >= 0:
            return []
        span = f"the fold test changes sign in the step from q = {a.q!r}"
        try:
            z = fold_crossing(self, zb)
        except (ShootingError, ValueError) as e:
            return [Event("orbit-fold", b.q, 0, None, f"{span}; not located: {e}",
                          u=np.array([b.p]))]
        return [Event("orbit-fold", float(z[-1]), 0, None,
                      f"{span}; located by Newton on the orbit, the margin and the fold's test "
                      "function in (x, p, q)", u=z[:-1].copy())]


def fold_crossing(disc: StickBoundary, zb: np.ndarray) -> np.ndarray:
    """(x, p, q) where the boundary meets a fold of the orbits at fixed q: Newton on F = 0,
    m = 0 and the fold's minimally augmented test function (:class:`FoldSystem`'s, its borders
    from zb) from zb = (x, p, q) on disc's layout.  ShootingError when Newton fails."""
    x0, p0, q0 = zb[:-2], float(zb[-2]), float(zb[-1])
    fold = FoldSystem(disc.make2, disc.lay, x0, jumps=disc.jumps, multipliers=0,
                      tol=disc.tol, estimate=False, period=disc.period)
    fold.ref, fold.problem = disc.ref, disc.problem
    fold.borders(x0, p0, q0)

    def evaluate_(z: np.ndarray) -> tuple[np.ndarray, None]:
        y, q = z[:-1], float(z[-1])
        m, _ = disc._margin(y, q)
        return np.append(fold.residual(y, q), m), None

    def factor(z: np.ndarray, r: np.ndarray, _: None) -> Callable[[np.ndarray], np.ndarray]:
        y, q = z[:-1], float(z[-1])
        Jy, Jq = fold.jacobian(y, q)
        row, mq = disc._row(y, q, disc._margin(y, q)[1])
        return lambda rr: bordered_solve(sp.csc_matrix(Jy), Jq, np.append(row, mq), -rr)

    z, _ = newton_loop(evaluate_, factor, np.array(zb, dtype=float), tol=disc.tol,
                       max_iter=4 * disc.max_iter,
                       what=f"the fold crossing of the boundary near q = {q0!r}",
                       converge="correction", stall=False)
    return z


def _layout_of(orbit: EquationOrbit) -> tuple[Layout, np.ndarray]:
    """The orbit's layout and unknowns."""
    lay = Layout(orbit.degree, orbit.nodes.shape[1], orbit.signature,
                 [f.copy() for f in orbit.fractions], orbit.autonomous, orbit.period,
                 tuple(orbit.carried))
    x = np.concatenate([orbit.nodes.ravel(), orbit.switches,
                        [orbit.period] if orbit.autonomous else []])
    return lay, x


def _sides(start: Any, branch: Any) -> list[tuple[EquationOrbit, EquationOrbit]]:
    """The two points around the event as (holding side, other side), both ways."""
    if not (isinstance(start, Event) and start.kind in ("stick-onset", "grazing")):
        raise ValueError(f"continue_stick_curve: start = {start!r}: give a 'stick-onset' or "
                         "'grazing' event of a branch of EquationOrbits (with branch=)")
    if branch is None or not isinstance(branch, Branch):
        raise ValueError("continue_stick_curve: a stick-onset or grazing event needs branch=, "
                         "the Branch of EquationOrbits it belongs to (continue_orbit of an "
                         "EquationOrbit)")
    pts = branch.points
    if not pts or not all(isinstance(pt, EquationOrbit) for pt in pts):
        raise ValueError("continue_stick_curve: branch= is not a branch of EquationOrbits "
                         "(continue_orbit of an EquationOrbit, from collocate or "
                         "hopf_orbit(..., of='equation'))")
    if not any(e is start for e in branch.events):
        raise ValueError("continue_stick_curve: the event is not one of branch.events")
    k = min(max(int(start.index), 1), len(pts) - 1)
    a, b = pts[k - 1], pts[k]
    if a.signature.describe() == b.signature.describe():
        raise ValueError(f"continue_stick_curve: the points around the event (p = {a.p!r} and "
                         f"{b.p!r}) have the same signature: the event's index does not point "
                         "at the change")
    return [(a, b), (b, a)]


def _start(start: Any, make2: Callable[[float, float], Solver], q0: float, branch: Any,
           options: dict[str, Any]) -> StickBoundary:
    """The boundary's discretisation at q0 with its start solved (``disc.y0``): the side and
    margin whose boundary at q0 lies at the event's p, the margins nearest 0 tried first."""
    tries = []
    for mine, other in _sides(start, branch):
        check_period(options.get("period"), mine.autonomous, mine.period, mine.p, q0,
                     "continue_stick_curve")
        lay, x = _layout_of(mine)
        terms = Terms(build(mine.make, mine.p), tuple(mine.kernel_jumps))
        for m in margins(lay, terms, other.signature):
            got = MarginValues(lay, m).least(terms, x)[0]
            if math.isfinite(got):
                tries.append((abs(got), mine, lay, x, m))
    if not tries:
        raise ValueError("continue_stick_curve: neither orbit around the event has an "
                         "inequality that breaks towards the other's signature")
    p_event, why = float(start.p), []
    a, b = _sides(start, branch)[0]
    lo, hi = sorted((float(a.p), float(b.p)))
    near = START_TOL * max(1.0, abs(p_event))
    if "not located" in start.detail:   # the branch's bracket, widened by its width each side
        lo, hi = lo - (hi - lo), hi + (hi - lo)
    else:
        lo, hi = p_event - near, p_event + near
    for _, mine, lay, x, m in sorted(tries, key=lambda t: t[0]):
        disc = StickBoundary(make2, lay, x, m, start.kind, jumps=tuple(mine.kernel_jumps),
                             **options)
        try:
            y0 = disc.solve_at(np.append(x, p_event), q0, f"the boundary at q0 = {q0!r}")
        except (ShootingError, ValueError) as e:
            why.append(f"{m.describe()}: {e}")
            continue
        if lo <= float(y0[-1]) <= hi:
            disc.y0 = y0
            return disc
        why.append(f"{m.describe()}: at p = {float(y0[-1])!r}")
    raise ValueError(f"continue_stick_curve: no boundary of make2(., q0 = {q0!r}) at the "
                     f"event's p = {p_event!r} (in [{lo!r}, {hi!r}]; is make2(p, q0) the "
                     "branch's model make(p)?): "
                     + "; ".join(why))


def continue_stick_curve(start: Any, make2: Callable[[float, float], Solver], q0: float,
                         q_end: float, *, branch: Branch | None = None,
                         step: float | None = None, at: Iterable[float] = (),
                         max_points: int = 100, min_step: float | None = None,
                         max_step: float | None = None, multipliers: int = 10,
                         tol: float = 1e-10, max_iter: int = 10, estimate: bool = True,
                         period: Callable[[float, float], float] | None = None) -> Curve:
    """Continues a stick onset or grazing of the equation's periodic orbits (collocated) in
    the plane (p, q).

    The curve of (p, q) where the orbit of ``make2(p, q)`` on the signature of the side where
    its inequalities hold reaches the margin 0 of the inequality that breaks there (see
    :mod:`dmi.analysis.plane.stick_curves`), by pseudo-arclength in (x, p, q) from the start at
    q0, through turning points in q, until q_end.

    Parameters
    ----------
    start : Event
        A ``"stick-onset"`` or ``"grazing"`` event of a branch of EquationOrbits of
        ``make2(., q0)`` (:func:`dmi.analysis.continue_orbit` of an EquationOrbit).
    make2 : callable
        The model ``make2(p, q) -> dmi.Solver``, configured, not initialised.
    q0 : float
        The start's q.
    q_end : float
        Where to stop (finite, not q0); the last point lies on it exactly when reached.
    branch : Branch
        The event's branch (required).
    step : float, optional
        The first step (arclength in (x, p, q); default |q_end - q0| / 20).
    at : iterable of float
        Values of q where a point is wanted (a ``user`` event each, on it exactly).
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
        Every point's error estimates (the boundary solved again on the mesh of merged pairs
        of intervals); False: none, every verdict None.
    period : callable, optional
        ``period(p, q)``: a forced orbit's period at (p, q) (as
        :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`'s).

    Returns
    -------
    Curve
        ``kind`` the event's (``"stick-onset"`` or ``"grazing"``); ``points``
        (:class:`StickCurvePoint`), ``events`` (``user``; ``orbit-fold`` where a fold of the
        orbits at fixed q meets the boundary), ``status`` (q_end reached, the range left after
        a turn, max_points, or the orbits breaking another inequality of their signature: the
        curve meets another boundary there).

    Raises
    ------
    ValueError
        A start of another kind, without its branch or not on it; bad q0, q_end or step; no
        boundary of ``make2(., q0)`` at the event's p (within START_TOL); ``period=`` for an
        autonomous orbit, not the start's period at (p, q0), or not finite and > 0.
    """
    q0, q_end, step = curve_range("continue_stick_curve", q0, q_end, step)
    if not callable(make2):
        raise ValueError(f"continue_stick_curve: make2 = {make2!r}: give a function "
                         "(p, q) -> dmi.Solver")
    disc = _start(start, make2, q0, branch, {"multipliers": multipliers, "tol": tol,
                                             "max_iter": max_iter, "estimate": estimate,
                                             "period": period})
    b = continuation(disc, disc.y0, q0, q_end, step=float(step), min_step=min_step,
                     max_step=max_step, max_points=max_points, at=at, tol=tol,
                     max_iter=max_iter, predictor="tangent", easy=4, make=make2,
                     kind=disc.kind)
    return _curve_of(b, disc)


def _curve_of(b: Branch, disc: StickBoundary) -> Curve:
    """The Curve of the driver's branch: its points, the user points and fold crossings, its
    status in q's words."""
    points: list[StickCurvePoint] = list(b.points)
    events: list[CurveEvent] = []
    for e in b.events:
        if e.kind == "user" and e.index < len(points):
            on = [j for j, pt in enumerate(points) if pt.q == e.p]
            i = e.index if e.index in on or not on else min(on, key=lambda j: abs(j - e.index))
            events.append(CurveEvent("user", points[i].p, float(e.p), i, e.detail))
        elif e.kind == "orbit-fold" and e.u is not None:
            events.append(CurveEvent("orbit-fold", float(e.u[-1]), float(e.p), e.index,
                                     e.detail))
    status = b.status.replace("p_end", "q_end").replace(" near p = ", " near q = ")
    return Curve(kind=disc.kind, points=points, events=events, status=status,
                 make2=disc.make2)


__all__ = ["StickCurvePoint", "continue_stick_curve"]
