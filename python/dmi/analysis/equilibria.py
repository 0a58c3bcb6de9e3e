# Equilibria of the scheme: Newton's correction, and their branches with fold and Hopf events.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Equilibria of the scheme and their continuation in a parameter.

An equilibrium of the scheme (3.12)-(3.13) is a constant history u with one step leaving it in
place: G(u) = R(u - h f(0, u) - h W*) - u = 0, W* = h sum_l H(l h) u.  :func:`equilibrium`
solves G(u) = 0 by Newton (the n x n Jacobian by forward differences of single steps: a
semismooth Newton where a resolvent holds a component, as sticking friction does), so that a
rough guess, or the equilibrium of the equation (the continuous integral, O(h) away), is
corrected.  Its roots are those of :func:`dmi.analysis.roots`.

:func:`continue_equilibrium` follows y = (u, p) by pseudo-arclength: the tangent is the null
vector of [G_u, G_p] (SVD), the predictor y + ds t, the corrector Newton on (G(y), <t, y -
y_pred>).  Events between two points, each located by its test function on the branch (Brent's
method in the arclength from the first point, every evaluation a corrected equilibrium), to
1e-8 relative in p or better:

- ``fold``: the tangent's p component dp/ds changes sign;
- ``hopf``: Re of the rightmost non-real root changes sign (the event carries its
  :class:`dmi.analysis.HopfPoint` in ``Event.hopf`` and the equilibrium in ``Event.u``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize

from ._model import KinkError, equation_step
from .branch import Branch, Event
from .newton import ShootingError, fmt_residuals, judge
from .stability import HopfPoint, check_of, non_real, roots
from .stepmap import Model, build

#: Roots computed at each point of a branch (the Hopf test function reads them).
ROOTS = 6


@dataclass
class Equilibrium:
    """An equilibrium of the scheme (or of the equation), as :func:`equilibrium` returns it.

    Attributes
    ----------
    make : callable
        The model ``make(p) -> dmi.Solver``.
    p : float
        The parameter.
    u : numpy.ndarray
        Shape (n,): the equilibrium (state units).
    roots : numpy.ndarray of complex
        The rightmost characteristic roots of :func:`dmi.analysis.roots` (rightmost first,
        1 / time unit; empty at a kink of the resolvent).
    stable : bool
        Re roots[0] < 0.
    residual : float
        |G(u)|_inf (state units).
    iterations : int
        Newton's.
    of : str
        ``"scheme"`` or ``"equation"``: whose equilibrium and roots, see :func:`equilibrium`.
    """
    make: Model = field(repr=False)
    p: float
    u: np.ndarray
    roots: np.ndarray
    stable: bool
    residual: float = 0.0
    iterations: int = 0
    of: str = "scheme"


@dataclass
class EquilibriumPoint:
    """A point of a branch of equilibria (:func:`continue_equilibrium`).

    Attributes
    ----------
    p : float
        The parameter.
    u : numpy.ndarray
        Shape (n,): the equilibrium (state units).
    roots : numpy.ndarray of complex
        The rightmost roots, rightmost first (1 / time unit).
    stable : bool
        Re roots[0] < 0.
    dpds : float
        The unit tangent's p component (its sign flips at a fold).
    """
    p: float
    u: np.ndarray
    roots: np.ndarray
    stable: bool
    dpds: float = 0.0

    @property
    def rightmost(self) -> complex:
        """The rightmost root (nan if none was computed)."""
        return complex(self.roots[0]) if self.roots.size else complex(np.nan)


class _OneStep:
    """G(u) = one step from the constant history u, less u, of make(p) (one solver, restored to
    step 0 before each evaluation); ``of="equation"``: the step with the continuous integral
    (:func:`dmi.analysis.equation.equation_step`)."""

    def __init__(self, make: Model, p: float, of: str = "scheme"):
        self.solver = build(make, p)
        self.n, self.N = self.solver.n, self.solver.N
        self.equation = equation_step(self.solver) if of == "equation" else None
        if self.equation is None:
            self.solver.init()
            self.start = self.solver.save_state()

    def __call__(self, u: np.ndarray) -> np.ndarray:
        if self.equation is not None:
            return self.equation(u)
        s = self.solver
        s.load_state(self.start)
        s.set_window(np.tile(u, (self.N + 1, 1)))
        s.step()
        return s.state - u


class _Steps:
    """_OneStep by p, the last few kept."""

    def __init__(self, make: Model, of: str = "scheme"):
        self.make, self.of = make, of
        self._cache: dict[float, _OneStep] = {}

    def __call__(self, p: float) -> _OneStep:
        G = self._cache.get(p)
        if G is None:
            G = _OneStep(self.make, p, self.of)
            if len(self._cache) > 4:
                self._cache.pop(next(iter(self._cache)))
            self._cache[p] = G
        return G

    def G(self, y: np.ndarray) -> np.ndarray:
        return self(float(y[-1]))(y[:-1])

    def jacobian(self, y: np.ndarray, Gy: np.ndarray) -> np.ndarray:
        """[G_u, G_p] at y = (u, p) by forward differences, (n, n + 1)."""
        m = y.size
        J = np.empty((m - 1, m))
        for j in range(m):
            d = 1e-7 * max(1.0, abs(y[j]))
            e = y.copy()
            e[j] += d
            J[:, j] = (self.G(e) - Gy) / d
        return J


def _check_guess(guess: Any, n: int) -> np.ndarray:
    u = np.array(guess, dtype=float, ndmin=1).ravel()
    if u.shape != (n,) or not np.all(np.isfinite(u)):
        raise ValueError(f"guess = {guess!r}: give n = {n} finite numbers (the model's n)")
    return u


def _newton(steps: _Steps, y0: np.ndarray, tol: float, max_iter: int, what: str,
            row: np.ndarray | None = None, target: float = 0.0) -> tuple[np.ndarray, list[float]]:
    """Newton on G(y) = 0 with p fixed (row None) or with the extra equation row . y = target
    (the pseudo-arclength hyperplane).  Returns (y, residuals); ShootingError (every residual
    listed) when it fails."""
    y = np.array(y0, dtype=float)
    res: list[float] = []
    moved = math.inf   # the last Newton correction (max norm)
    for _ in range(max_iter + 1):
        Gy = steps.G(y)
        g = 0.0 if row is None else float(row @ y - target)
        rn = max(float(np.max(np.abs(Gy))), abs(g))
        scale = tol * max(1.0, float(np.max(np.abs(y[:-1]))))
        verdict = judge(res, rn, scale, max_iter, what)
        # G is one step's movement, O(h) times the error: the correction must be small too
        if verdict == "converged" and moved <= scale:
            return y, res
        if verdict == "exhausted":
            break
        J = steps.jacobian(y, Gy)
        if row is None:
            A, b = J[:, :-1], -Gy
        else:
            A, b = np.vstack([J, row]), -np.concatenate([Gy, [g]])
        try:
            d = np.linalg.solve(A, b)
        except np.linalg.LinAlgError:
            raise ShootingError(f"{what}: the Jacobian is singular (residuals "
                                f"{fmt_residuals(res)}): a fold, or no isolated equilibrium",
                                res) from None
        moved = float(np.max(np.abs(d)))
        if row is None:
            y[:-1] += d
        else:
            y += d
    raise ShootingError(f"{what}: no convergence in {max_iter} iterations (residuals "
                        f"{fmt_residuals(res)})", res)


def _roots(make: Model, p: float, u: np.ndarray, count: int, tol: float, of: str
           ) -> np.ndarray:
    """The roots at an equilibrium (empty at a kink; none asked: empty)."""
    if count < 1:
        return np.empty(0, complex)
    try:
        return roots(make, p, u, count, tol=max(tol * 1e3, 1e-9), of=of)
    except KinkError:
        return np.empty(0, complex)


def equilibrium(make: Model, p: float, guess: Any, *, tol: float = 1e-10, count: int = ROOTS,
                max_iter: int = 30, of: str = "scheme") -> Equilibrium:
    """The equilibrium of the scheme of ``make(p)`` near ``guess``, by Newton's method.

    Newton on one step from a constant history (the n x n Jacobian by forward differences of
    single steps), until |G(u)|_inf and the last correction are <= tol max(1, |u|_inf) (G is
    O(h) times the error: the correction bounds it); with its rightmost roots.

    Parameters
    ----------
    make : callable
        The model: ``make(p) -> dmi.Solver``, configured, not initialised.
    p : float
        The parameter.
    guess : array_like
        Shape (n,): a rough guess (state units); the equation's equilibrium is corrected too.
    tol : float
        Tolerance, relative to max(1, |u|_inf).
    count : int
        How many rightmost roots (:func:`roots`) to compute (0: none).
    max_iter : int
        Newton iterations at most.
    of : {"scheme", "equation"}
        ``"equation"``: the equation's equilibrium, with the continuous integral int_0^tau H
        instead of the scheme's h sum_l H(l h) (O(h) apart), and the equation's roots.

    Returns
    -------
    Equilibrium
        ``.u``, ``.roots`` (rightmost first), ``.stable`` (Re roots[0] < 0), ``.residual``.

    Raises
    ------
    ValueError
        A guess that is not n finite numbers, or ``of`` not one of the two.
    ShootingError
        Newton fails: no new least residual in 3 iterations, a singular Jacobian, max_iter
        reached (every residual is listed).
    Exception
        The model's own, when ``make(p)`` fails (a note names the call).
    """
    steps = _Steps(make, check_of(of))
    n = steps(float(p)).n
    u0 = _check_guess(guess, n)
    y, res = _newton(steps, np.concatenate([u0, [float(p)]]), tol, max_iter,
                     f"equilibrium at p = {p!r}")
    u = y[:-1]
    lam = _roots(make, float(p), u, count, tol, of)
    return Equilibrium(make=make, p=float(p), u=u, roots=lam,
                       stable=bool(lam.size and lam[0].real < 0), residual=res[-1],
                       iterations=len(res) - 1, of=of)


def _tangent(J: np.ndarray, prev: np.ndarray) -> np.ndarray:
    """The unit null vector of J (n, n + 1), oriented along prev."""
    t = np.linalg.svd(J)[2][-1]
    return t if float(t @ prev) >= 0 else -t


def _complex_re(lam: np.ndarray) -> float:
    """Re of the rightmost non-real root (-inf if none)."""
    c = non_real(lam)
    c = c[np.isfinite(c.real)]
    return float(np.max(c.real)) if c.size else -math.inf


def continue_equilibrium(eq: Equilibrium, p_end: float, step: float = 0.05, *,
                         max_points: int = 200, min_step: float | None = None,
                         max_step: float | None = None, count: int = ROOTS,
                         tol: float = 1e-10, max_iter: int = 8) -> Branch:
    """Continues an equilibrium in p by pseudo-arclength, with fold and Hopf events.

    The tangent is the null vector of [G_u, G_p], the predictor y + ds t, the corrector Newton
    on (G(y), <t, y - y_pred>); each point gets its ``count`` rightmost roots.  Events are
    located on the branch by Brent's method in the arclength (see the module).

    Parameters
    ----------
    eq : Equilibrium
        The start, from :func:`equilibrium` (the branch is of the scheme's or the equation's
        equilibria as ``eq.of`` is).
    p_end : float
        Where to stop (finite, not eq.p).
    step : float
        The first step (p units); later steps are arclengths in the Euclidean norm of (u, p).
    max_points : int
        Points at most.
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    count : int
        Roots a point.
    tol : float
        Newton's tolerance.
    max_iter : int
        Corrector iterations a step.

    Returns
    -------
    Branch
        ``kind`` "equilibria": ``points`` of :class:`EquilibriumPoint`, ``events`` (``fold``,
        ``hopf`` with its :class:`HopfPoint` in ``Event.hopf`` and the equilibrium in
        ``Event.u``), ``status`` (why it ended: a corrector failing at the smallest step, or
        the model failing there, ends the branch; it does not raise).

    Raises
    ------
    ValueError
        ``eq`` not an Equilibrium, a bad ``step`` or ``p_end``.
    """
    if not isinstance(eq, Equilibrium):
        raise ValueError(f"eq = {eq!r}: give a dmi.analysis.Equilibrium")
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: must be finite and > 0 (p units)")
    if not math.isfinite(p_end) or p_end == eq.p:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from eq.p = {eq.p!r}")
    direction = 1.0 if p_end > eq.p else -1.0
    min_step = step / 1000 if min_step is None else min_step
    max_step = 4 * step if max_step is None else max_step
    make, of = eq.make, eq.of
    steps = _Steps(make, of)
    y = np.concatenate([eq.u, [eq.p]])
    m = y.size
    t = np.zeros(m)
    t[-1] = direction
    t = _tangent(steps.jacobian(y, steps.G(y)), t)

    def point(y: np.ndarray, t: np.ndarray) -> EquilibriumPoint:
        lam = _roots(make, float(y[-1]), y[:-1], count, tol, of)
        return EquilibriumPoint(p=float(y[-1]), u=y[:-1].copy(), roots=lam,
                                stable=bool(lam.size and lam[0].real < 0), dpds=float(t[-1]))

    def correct(yp: np.ndarray, row: np.ndarray, target: float) -> np.ndarray:
        return _newton(steps, yp, tol, max_iter, f"equilibrium branch near p = {yp[-1]!r}",
                       row, target)[0]

    pts = [point(y, t)]
    ts = [t]
    ys = [y]
    events: list[Event] = []
    status = "max_points reached"
    ds = step
    while len(pts) < max_points:
        if (y[-1] - p_end) * direction >= -1e-12 * max(1.0, abs(p_end)):
            status = f"reached p_end = {p_end!r}"
            break
        while True:
            yp, row = y + ds * t, t
            target = float(t @ yp)
            if (yp[-1] - p_end) * direction > 0 and abs(t[-1]) > 0.5:   # end on p = p_end
                yp = y + ((p_end - y[-1]) / t[-1]) * t
                row = np.zeros(m)
                row[-1] = 1.0
                target = float(p_end)
            try:
                yn = correct(yp, row, target)
                break
            except Exception as e:   # the model's or the corrector's failure: a shorter step
                ds /= 2
                if ds < min_step:
                    status = f"corrector failed at the smallest step {min_step!r} near p = " \
                             f"{float(y[-1])!r}: {e}"
                    yn = None
                    break
        if yn is None:
            break
        tn = _tangent(steps.jacobian(yn, steps.G(yn)), t)
        pts.append(point(yn, tn))
        events += _events(steps, make, ys[-1], ts[-1], pts[-2], yn, pts[-1], len(pts) - 1,
                          count, tol, correct, of)
        y, t = yn, tn
        ys.append(y)
        ts.append(t)
        ds = min(max_step, ds * 1.5)
    return Branch(pts, events, status, make, kind="equilibria")


def _events(steps: _Steps, make: Model, ya: np.ndarray, ta: np.ndarray, a: EquilibriumPoint,
            yb: np.ndarray, b: EquilibriumPoint, index: int, count: int, tol: float,
            correct: Any, of: str) -> list[Event]:
    """The fold and Hopf events between a and b, each located by Brent's method on its test
    function in the arclength s along ta from ya (the equilibrium at s on the hyperplane
    <ta, y - ya> = s)."""
    sb = float(ta @ (yb - ya))
    out: list[Event] = []
    if sb <= 0:
        return out
    cache: dict[float, np.ndarray] = {0.0: ya, sb: yb}

    def at(s: float) -> np.ndarray:
        if s not in cache:
            cache[s] = correct(ya + s * ta, ta, float(ta @ ya) + s)
        return cache[s]

    def locate(fn: Any, fa: float, fb: float) -> float | None:
        if not (fa * fb < 0):
            return None
        try:
            return float(scipy.optimize.brentq(fn, 0.0, sb, xtol=1e-12 * max(1.0, sb),
                                               rtol=1e-15, maxiter=100))
        except (ShootingError, ValueError, RuntimeError):
            return None

    if a.dpds * b.dpds < 0:
        def dpds(s: float) -> float:
            y = at(s)
            return float(_tangent(steps.jacobian(y, steps.G(y)), ta)[-1])
        s = locate(dpds, a.dpds, b.dpds)
        if s is not None:
            y = at(s)
            out.append(Event("fold", float(y[-1]), index, None,
                             "dp/ds changes sign (located on the branch)", u=y[:-1].copy()))
    fa, fb = _complex_re(a.roots), _complex_re(b.roots)
    if math.isfinite(fa) and math.isfinite(fb) and fa * fb < 0:
        roots_at: dict[float, np.ndarray] = {}

        def re(s: float) -> float:
            y = at(s)
            roots_at[s] = _roots(make, float(y[-1]), y[:-1], count, tol, of)
            return _complex_re(roots_at[s])
        s = locate(re, fa, fb)
        if s is not None:
            y = at(s)
            lam = roots_at[s] if s in roots_at else _roots(make, float(y[-1]), y[:-1], count,
                                                           tol, of)
            c = non_real(lam)
            root = c[np.argmax(c.real)]
            root = complex(root.real, abs(root.imag))
            hp = HopfPoint(p=float(y[-1]), omega=root.imag, root=root)
            out.append(Event("hopf", hp.p, index, None,
                             f"a pair of roots crosses the imaginary axis at omega = "
                             f"{hp.omega:.8g}", u=y[:-1].copy(), hopf=hp))
    return out
