# What the systems of the curves of orbits in two parameters share, and the fold's minimally
# augmented system, below the driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
""":class:`OrbitSystem`: what the systems of the plane's curves of collocated orbits share (the
model's terms at (p, q), the driver's weights, the mesh moved between steps, the signature's
check, the solve on the merged mesh and the error estimates from it); :class:`FoldSystem`: the
fold's minimally augmented system of :mod:`dmi.analysis.plane.orbit_curves` (see there for the
method).  Below the driver, so that the stick-onset boundaries locate where they cross a fold
with it."""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from ..._solver import Solver
from ..collocation.adapt import FLOOR, Solved, adapted, merged, transfer
from ..collocation.adapt import estimate as level_errors
from ..collocation.floquet import multipliers as floquet
from ..collocation.orbit import EquationOrbit
from ..collocation.system import (CollocationWarning, Layout, Terms, check_inequalities,
                                  full_jacobian, reference)
from ..continuation.branch import AlongQ
from ..core.newton import ShootingError, bordered_solve, newton_loop, sparse_bordered
from ..scheme.problem import AtQ, Problem
from ..scheme.stepmap import build

#: Relative step of the one-sided differences of J along v, p and q (they steer Newton only:
#: g's gradient in x is 4e-5 to 1e-3 relative off with it; a central difference, 1e-7 off,
#: took the same Newton iterations at two Jacobians a difference, 25 % slower a point).
DIFF = 1e-7
#: Terms kept (the last few (p, q) evaluated).
KEEP = 12


@dataclass
class OrbitCurvePoint(AlongQ):
    """A point of a curve of orbits in (p, q) (:func:`dmi.analysis.continue_curve`).

    Attributes
    ----------
    p, q : float
        The parameters.
    orbit : EquationOrbit
        The orbit there (at fixed q, ``orbit.make(p)`` is ``make2(p, q)``): its period,
        amplitude, multipliers and their error estimates (``orbit.errors``; with ``"p"``, the
        estimated error of p); its ``stable`` is None (a fold has a multiplier at 1).
    p_error : float or None
        The estimated error of p (the difference to the fold on the mesh of merged pairs of
        intervals at the same q); None where that solve failed (a warning says so).
    stable : bool or None
        Every multiplier but the trivial one and the fold's inside the unit circle (True), one
        outside (False), verified against their estimated errors; None where one is within its
        error of the circle or no error estimate exists (a CollocationWarning says so).
    dqds : float
        The unit tangent's q component (its sign flips at a turning point in q).
    """
    p: float
    q: float
    orbit: EquationOrbit = field(repr=False)
    p_error: float | None = None
    stable: bool | None = None
    dqds: float = 0.0

    @property
    def omega(self) -> float:
        """The orbit's angular frequency 2 pi / period (radians / time unit)."""
        return 2 * math.pi / self.orbit.period

    @property
    def u(self) -> np.ndarray:
        """The orbit's node values (as a curve point's state)."""
        return self.orbit.nodes


class OrbitSystem:
    """What the systems of the plane's curves of collocated orbits share: unknowns y = (x, then
    :attr:`extra` more, p first), parameter q.

    Parameters
    ----------
    make2 : callable
        ``make2(p, q) -> dmi.Solver``.
    layout : Layout
        The collocation's layout.
    x : numpy.ndarray
        The orbit's unknowns on it (the phase condition's reference).
    jumps : tuple of float
        The kernel's jumps (lags).
    multipliers : int
        Leading multipliers a point carries.
    tol, max_iter : float, int
        The corrector's tolerance and iterations.
    estimate : bool
        A point's error estimates from the merged mesh (False: none, the verdict None).
    period : callable, optional
        ``period(p, q)``: a forced orbit's period at (p, q) (None: the layout's, fixed).
    """
    #: The unknowns past x (p first).
    extra = 1
    #: What the system solves, in the warnings.
    what = "the curve's system"

    def __init__(self, make2: Callable[[float, float], Solver], layout: Layout, x: np.ndarray,
                 *, jumps: tuple[float, ...] = (), multipliers: int = 10, tol: float = 1e-12,
                 max_iter: int = 10, estimate: bool = True,
                 period: Callable[[float, float], float] | None = None):
        if period is not None and layout.autonomous:
            raise ValueError(f"period = {period!r}: the orbit is autonomous (its period is an "
                             "unknown): give period= only for a forced orbit")
        self.make2, self.lay, self.jumps = make2, layout, tuple(jumps)
        self.period = period
        self.ref = reference(layout, x) if layout.autonomous else None
        self.count, self.tol, self.max_iter = int(multipliers), float(tol), int(max_iter)
        self.estimate = bool(estimate)
        self.problem = Problem(make2, keep=KEEP)   # the terms of the last few (p, q)
        self.breach = ""                    # why the last correction was refused

    @property
    def weight(self) -> np.ndarray:
        """The driver's weights on y: x's RMS, the extra unknowns as themselves."""
        m = self.lay.size
        return np.concatenate([np.full(m, 1.0 / m), np.ones(self.extra)])

    def terms(self, p: float, q: float) -> Terms:
        """The model's terms at (p, q) (the last few kept)."""
        key = (float(p), float(q))
        return self.problem.cached(("terms", key),
                                   lambda: Terms(build(AtQ(self.make2, key[1]), key[0]),
                                                 self.jumps))

    def layout(self, p: float, q: float, lay: Layout | None = None) -> Layout:
        """The layout (lay, default the system's) of the orbit at (p, q): with the period
        period(p, q) where :attr:`period` is given."""
        lay = self.lay if lay is None else lay
        if self.period is None:
            return lay
        return replace(lay, period=period_at(self.period, p, q))

    @property
    def options(self) -> dict[str, Any]:
        """The options another system on another mesh takes (no estimates)."""
        return {"jumps": self.jumps, "multipliers": self.count, "tol": self.tol,
                "max_iter": self.max_iter, "estimate": False, "period": self.period}

    def remesh(self, x: np.ndarray, p: float, q: float) -> np.ndarray:
        """x, the orbit at (p, q), on the mesh equidistributed again (it becomes the
        system's), the phase condition's reference moved to it."""
        lay = self.layout(p, q)
        new = lay.with_fractions(adapted(lay, x, lay.L))
        x = transfer(lay, x, new)
        self.lay = new
        if new.autonomous:
            self.ref = reference(new, x)
        return x

    def broken(self, x: np.ndarray, p: float, q: float, rel: float) -> str:
        """The first inequality of the signature the orbit x at (p, q) breaks by more than rel
        times its scale, else ""."""
        bad = check_inequalities(self.layout(p, q), self.terms(p, q), x, rel)
        return bad[0] if bad else ""

    def _solved(self, lay: Layout, terms: Terms, x: np.ndarray) -> Solved:
        """x on lay with its amplitudes and leading multipliers."""
        return Solved(lay, x, floquet(lay, terms, x, self.count) if self.count > 0 else None)

    def on_mesh(self, lay: Layout, x: np.ndarray, y: np.ndarray, q: float) -> OrbitSystem:
        """The same system on lay from x (y's extra unknowns), ready to solve at q, without
        estimates."""
        raise NotImplementedError

    def solve_at(self, y0: np.ndarray, q: float, what: str) -> np.ndarray:
        """The system at fixed q from y0."""
        raise NotImplementedError

    def _coarse(self, y: np.ndarray, q: float) -> tuple[Solved, np.ndarray] | None:
        """The system solved at q on the mesh of merged pairs of intervals (its y); None, with
        a CollocationWarning, where that solve fails."""
        m, p = self.lay.size, float(y[self.lay.size])
        here = self.layout(p, q)
        lay = here.with_fractions(merged(here.fractions))
        xc = transfer(here, y[:m], lay)
        try:
            other = self.on_mesh(lay, xc, y, q)
            other.ref, other.problem = self.ref, self.problem
            yc = other.solve_at(np.concatenate([xc, y[m:]]), q,
                                f"{self.what} at q = {q!r} on the merged mesh")
        except (ShootingError, ValueError) as e:
            warnings.warn(f"(p, q) = ({p!r}, {q!r}): {self.what} on the merged mesh failed "
                          f"({e}): no error estimate, the verdict None", CollocationWarning,
                          stacklevel=4)
            return None
        pc = float(yc[lay.size])
        return self._solved(self.layout(pc, q, lay), self.terms(pc, q), yc[:lay.size]), yc

    def levels(self, y: np.ndarray, q: float
               ) -> tuple[Solved, dict[str, Any], np.ndarray | None]:
        """(the orbit of y with its multipliers, its error estimates with p's, the merged mesh's
        y or None): the errors are the differences to the merged mesh's solve."""
        m, p = self.lay.size, float(y[self.lay.size])
        fine = self._solved(self.layout(p, q), self.terms(p, q), y[:m])
        got = self._coarse(y, q) if self.estimate else None
        if got is None:
            return fine, {}, None
        coarse, yc = got
        errors = level_errors(coarse, fine)
        errors["p"] = max(abs(float(yc[coarse.lay.size]) - p), FLOOR * max(1.0, abs(p)))
        return fine, errors, yc

    def corner(self, points: list[Any]) -> str:
        """Why the curve could not go on, else ""."""
        return self.breach


class FoldSystem(OrbitSystem):
    """The minimally augmented system of a fold of collocated orbits (see the module): unknowns
    y = (x, p), parameter q; F, g, their Jacobian and the solve at fixed q (the parameters of
    :class:`OrbitSystem`)."""
    what = "the fold"

    def __init__(self, make2: Callable[[float, float], Solver], layout: Layout, x: np.ndarray,
                 **options: Any):
        super().__init__(make2, layout, x, **options)
        self._last: tuple | None = None     # (key, evaluation) of the last y evaluated
        self.b: np.ndarray | None = None
        self.c: np.ndarray | None = None
        self.gscale = 1.0   # g's unit: 1 / its gradient's largest entry at the start

    def borders(self, x: np.ndarray, p: float, q: float) -> None:
        """b and c from the one-parameter branch's tangent at a fold: with F_p as J's border and
        a uniform row, the null vectors of J and J' (F_p is outside J's range at a fold)."""
        t = self.terms(p, q)
        r, J = full_jacobian(self.layout(p, q), t, x, self.ref)
        d = DIFF * max(1.0, abs(p))
        Fp = (full_jacobian(self.layout(p + d, q), self.terms(p + d, q), x, self.ref)[0]
              - r) / d
        m = x.size
        one = np.full(m, 1.0 / math.sqrt(m))
        v, w = _null_pair(J, Fp, one)
        self.c, self.b = v / np.linalg.norm(v), w / np.linalg.norm(w)
        self._last = None
        self.gscale = 1.0
        row = self._jy(np.concatenate([x, [p]]), q)[2]
        self.gscale = 1.0 / max(float(np.max(np.abs(row))), 1e-300)
        self._last = None

    def _eval(self, y: np.ndarray, q: float) -> dict[str, Any]:
        """F, J, v, w and g at (y, q) (the last kept)."""
        key = (y.tobytes(), float(q), id(self.lay), id(self.b), self.gscale)
        if self._last is not None and self._last[0] == key:
            return self._last[1]
        x, p = y[:-1], float(y[-1])
        t = self.terms(p, q)
        r, J = full_jacobian(self.layout(p, q), t, x, self.ref)
        vg, wh = _pair(J, self.b, self.c)
        ev = {"r": r, "J": J, "v": vg[:-1], "g": float(vg[-1]) * self.gscale, "w": wh[:-1],
              "terms": t}
        self._last = (key, ev)
        return ev

    def residual(self, y: np.ndarray, q: float) -> np.ndarray:
        """(F, g) at (y, q): len(y) values."""
        ev = self._eval(y, q)
        return np.concatenate([ev["r"], [ev["g"]]])

    def _jy(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray, np.ndarray, dict]:
        """(J, F_p, (g_x, g_p), the evaluation) at (y, q): the blocks of the Jacobian in y."""
        ev = self._eval(y, q)
        x, p = y[:-1], float(y[-1])
        J, v, w, t = ev["J"], ev["v"], ev["w"], ev["terms"]
        eps = DIFF * max(1.0, float(np.max(np.abs(x)))) / max(float(np.max(np.abs(v))), 1e-300)
        J1 = full_jacobian(self.layout(p, q), t, x + eps * v, self.ref)[1]
        gx = -self.gscale * (J1.T @ w - J.T @ w) / eps
        d = DIFF * max(1.0, abs(p))
        rp, Jp = full_jacobian(self.layout(p + d, q), self.terms(p + d, q), x, self.ref)
        Fp = (rp - ev["r"]) / d
        gp = -self.gscale * float(w @ (Jp @ v - J @ v)) / d
        return J, Fp, np.append(gx, gp), ev

    def jacobian(self, y: np.ndarray, q: float) -> tuple[Any, np.ndarray]:
        """(J_y sparse, J_q): the driver's Jacobian in the unknowns y and in its parameter q."""
        J, Fp, grow, ev = self._jy(y, q)
        x, p = y[:-1], float(y[-1])
        d = DIFF * max(1.0, abs(q))
        rq, Jq = full_jacobian(self.layout(p, q + d), self.terms(p, q + d), x, self.ref)
        Fq = (rq - ev["r"]) / d
        gq = -self.gscale * float(ev["w"] @ (Jq @ ev["v"] - ev["J"] @ ev["v"])) / d
        return sparse_bordered(J, Fp, grow), np.concatenate([Fq, [gq]])

    def solve_at(self, y0: np.ndarray, q: float, what: str) -> np.ndarray:
        """The fold at fixed q from y0 (Newton on (F, g) in (x, p), sparse LU)."""
        def evaluate(y: np.ndarray) -> tuple[np.ndarray, None]:
            return self.residual(y, q), None

        def factor(y: np.ndarray, r: np.ndarray, _: None) -> Callable[[np.ndarray], np.ndarray]:
            J, Fp, grow, _ = self._jy(y, q)
            return lambda rr: bordered_solve(J, Fp, grow, -rr)

        y, _ = newton_loop(evaluate, factor, np.array(y0, dtype=float), tol=self.tol,
                           max_iter=3 * self.max_iter, what=what, converge="correction",
                           stall=False)
        return y

    def on_mesh(self, lay: Layout, x: np.ndarray, y: np.ndarray, q: float) -> FoldSystem:
        """The fold's system on lay from x, its borders from there."""
        other = type(self)(self.make2, lay, x, **self.options)
        other.ref, other.problem = self.ref, self.problem
        other.borders(x, float(y[self.lay.size]), q)
        return other


def _pair(J: Any, b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(v, g) of [[J, b], [c', 0]] (v, g) = (0, 1) and (w, h) of its transpose."""
    e1 = np.zeros(c.size + 1)
    e1[-1] = 1.0
    try:
        return (bordered_solve(J, b, np.append(c, 0.0), e1),
                bordered_solve(J.T.tocsc(), c, np.append(b, 0.0), e1))
    except ShootingError as e:
        raise ShootingError(f"the fold's bordered matrix is singular: {e}", []) from None


def _null_pair(J: Any, border: np.ndarray, row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """v and w of [[J, border], [row', 0]] (v, .) = (0, 1) and its transpose (w, .) = (0, 1)."""
    vg, wh = _pair(J, border, row)
    return vg[:-1], wh[:-1]


def period_at(period: Callable[[float, float], float], p: float, q: float) -> float:
    """period(p, q), refused (ValueError) unless finite and > 0."""
    T = period(p, q)
    try:
        T = float(T)
    except (TypeError, ValueError):
        T = math.nan
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"period(p = {p!r}, q = {q!r}) = {T!r}: a forced orbit's period must "
                         "be finite and > 0")
    return T


def check_period(period: Callable[[float, float], float] | None, autonomous: bool,
                 start: float, p: float, q: float, who: str) -> None:
    """Refuses (ValueError, naming who) period= for an autonomous orbit, not callable, or
    disagreeing with the start orbit's period at (p, q) by more than 1e-9 relative."""
    if period is None:
        return
    if autonomous:
        raise ValueError(f"{who}: period = {period!r}: the start orbit is autonomous (its "
                         "period is an unknown): give period= only for a forced orbit")
    if not callable(period):
        raise ValueError(f"{who}: period = {period!r}: give a function (p, q) -> the forced "
                         "orbit's period")
    T = period_at(period, p, q)
    if abs(T - start) > 1e-9 * abs(start):
        raise ValueError(f"{who}: period(p = {p!r}, q0 = {q!r}) = {T!r} but the start orbit's "
                         f"period is {start!r}: the branch's period and period= disagree (is "
                         "make2(p, q0) the branch's model, and period(p, q) its forcing's "
                         "period?)")
