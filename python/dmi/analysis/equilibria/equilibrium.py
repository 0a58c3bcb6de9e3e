# Equilibria of the scheme: Newton's correction, and their branches with fold and Hopf events.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Equilibria of the scheme and their continuation in a parameter.

An equilibrium of the scheme (3.12)-(3.13) is a constant history u with one step leaving it in
place: G(u) = R(u - h f(0, u) - h W*) - u = 0, W* = h sum_l H(l h) u.  :func:`equilibrium`
solves G(u) = 0 by Newton (the n x n Jacobian by forward differences of single steps: a
semismooth Newton where a resolvent holds a component, as sticking friction does), so that a
rough guess, or the equilibrium of the equation (the continuous integral, O(h) away), is
corrected.  Its roots are those of :func:`dmi.analysis.roots`.

:func:`continue_equilibrium` follows y = (u, p) by pseudo-arclength with the one driver
(:func:`dmi.analysis.continuation.driver.continuation`) on the discretisation :class:`Equilibria`: the
tangent is the null vector of [G_u, G_p], the predictor y + ds t, the corrector Newton on (G(y),
<t, y - y_pred>).  Events between two points, each located by its test function on the branch
(Brent's method in the arclength along their chord, every evaluation a corrected equilibrium),
to 1e-8 relative in p or better, and checked there:

- ``fold``: the tangent's p component dp/ds changes sign;
- ``hopf``: a pair of non-real roots crosses Re lambda = 0 (the test function
  :func:`hopf_test`, whose sign does not change where a pair meets on the real axis and parts
  into two real roots); checked: a non-real pair on the imaginary axis at the located point.
  The event carries its :class:`dmi.analysis.HopfPoint` in ``Event.hopf`` and the equilibrium
  in ``Event.u``;
- ``branch-point``: a real root crosses 0 while dp/ds keeps its sign (det [[G_u, G_p], [t']]
  changes sign); checked: the null space of [G_u, G_p] is two-dimensional there.  The branch
  goes on along the branch it was on.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..._errors import Error
from ..continuation.branch import ON_AXIS, REAL, Branch, HopfPoint
from ..continuation.driver import ContinuationOptions, Curve, continuation, newton_corrector
from ..core.model import KinkError, call_make, equation_step
from ..core.newton import Converge, NewtonOptions, ShootingError
from ..scheme.floquet import StabilityWarning
from ..scheme.problem import Problem
from ..scheme.stepmap import Model
from .normal_form import criticality
from .numerics import forward_jacobian, null_vectors, signed_mean
from .root_verdict import UNVERIFIED, RootVerdict, roots_verdict
from .stability import check_of

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
    stable : bool or None
        The verified verdict (:mod:`dmi.analysis.equilibria.root_verdict`): True when Re roots[0] <
        -error and no root lies further right, False when a root's Re lambda exceeds its
        error; None when not decided (``reason`` says why; a :class:`StabilityWarning` was
        issued), when not verified (``verify=False``), or without roots (a kink,
        ``count=0``).
    residual : float
        |G(u)|_inf (state units).
    iterations : int
        Newton's.
    of : str
        ``"scheme"`` or ``"equation"``: whose equilibrium and roots, see :func:`equilibrium`.
    error : float
        The error of Re roots[0] the verdict used (1 / time unit; nan when not verified).
    reason : str
        How the verdict was reached, or why there is none.
    """
    make: Model = field(repr=False)
    p: float
    u: np.ndarray
    roots: np.ndarray
    stable: bool | None
    residual: float = 0.0
    iterations: int = 0
    of: str = "scheme"
    error: float = math.nan
    reason: str = ""


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
    stable : bool or None
        The verified verdict, as :attr:`Equilibrium.stable`.
    dpds : float
        The unit tangent's p component (its sign flips at a fold).
    error : float
        The error of Re roots[0] the verdict used (nan when not verified).
    reason : str
        How the verdict was reached, or why there is none.
    """
    p: float
    u: np.ndarray
    roots: np.ndarray
    stable: bool | None
    dpds: float = 0.0
    error: float = math.nan
    reason: str = ""

    @property
    def rightmost(self) -> complex:
        """The rightmost root (nan if none was computed)."""
        return complex(self.roots[0]) if self.roots.size else complex(np.nan)


class _OneStep:
    """G(u) = one step from the constant history u, less u, of make(p) (one solver, restored to
    step 0 before each evaluation); ``of="equation"``: the step with the continuous integral
    (:func:`dmi.analysis.equilibria.equation.equation_step`)."""

    def __init__(self, problem: Problem, p: float, of: str = "scheme"):
        self.solver = problem.solver(p)
        self.p = p
        self.n, self.N = self.solver.n, self.solver.N
        self.equation = equation_step(self.solver) if of == "equation" else None
        if self.equation is None:
            self.solver.init()
            self.start = self.solver.save_state()

    def __call__(self, u: np.ndarray) -> np.ndarray:
        try:
            if self.equation is not None:
                return self.equation(u)
            s = self.solver
            s.load_state(self.start)
            s.set_window(np.tile(u, (self.N + 1, 1)))
            s.step()
            return s.state - u
        except Error as e:   # libdmi's non-finite state: name the call
            raise ShootingError(f"one step of the model make(p = {self.p!r}) from the constant "
                                f"history u = {u!r} failed: {e}", []) from e


def _check_guess(guess: Any, n: int) -> np.ndarray:
    u = np.array(guess, dtype=float, ndmin=1).ravel()
    if u.shape != (n,) or not np.all(np.isfinite(u)):
        raise ValueError(f"guess = {guess!r}: give n = {n} finite numbers (the model's n)")
    return u


def _roots(make: Model, p: float, u: np.ndarray, count: int, tol: float, of: str,
           verify: bool, lam: np.ndarray | None = None) -> tuple[np.ndarray, RootVerdict]:
    """The rightmost roots at an equilibrium (``lam``: those already computed) and their
    verdict, verified (:func:`dmi.analysis.equilibria.root_verdict.check`) or not; no roots (empty, verdict
    None) at a kink or where none are asked."""
    if count < 1:
        return np.empty(0, complex), RootVerdict(None, "no root was asked (count=0)")
    if lam is not None and not verify:
        return lam, UNVERIFIED
    try:
        return roots_verdict(lambda: call_make(make, p), u, (p,), count, max(tol * 1e3, 1e-9),
                             of, verify, lam)
    except KinkError as e:
        return np.empty(0, complex), RootVerdict(None, f"no roots: {e}")


def _unverified_warning(what: str) -> None:
    warnings.warn(f"{what}(verify=False): the roots are ARPACK's Ritz values without an error "
                  "bound, so stable is None; leave verify at its default (True) for a verified "
                  "verdict", UserWarning, stacklevel=3)


def hopf_test(lam: np.ndarray) -> float:
    """The Hopf test function of the rightmost roots: the sign of the bialternate product
    prod_{i<j} (lambda_i + lambda_j) over them (its positive factors, those of two distinct
    pairs or of a pair and a real root, left out: Re lambda of each pair of non-real roots and
    (r_i + r_j) / 2 of each two real roots), times the geometric mean of their moduli.  It
    changes sign where a non-real pair crosses Re lambda = 0, and is continuous where a pair
    meets on the real axis and parts into two real roots (the pair's Re lambda becomes their
    mean); a real root through 0 does not change it (unless two real roots sum to 0: the
    event's check refutes that).  NaN without roots."""
    lam = lam[np.isfinite(lam)]
    real = np.abs(lam.imag) <= REAL * np.maximum(1.0, np.abs(lam))
    r = np.sort(lam[real].real)
    upper = lam[~real & (lam.imag > 0)]
    f = list(upper.real) + [0.5 * (r[i] + r[j]) for i in range(r.size)
                            for j in range(i + 1, r.size)]
    return signed_mean(f)


class Equilibria:
    """The discretisation of equilibria for :func:`dmi.analysis.continuation.driver.continuation`: the
    unknowns u (n), the residual G(u) at p (one step of the scheme, or of the equation, from
    the constant history u), its Jacobian [G_u, G_p] by forward differences (dense), the
    points with their roots, the Hopf test function :func:`hopf_test`, and the events'
    checks (:meth:`describe`).

    Parameters
    ----------
    make : callable
        The model.
    of : {"scheme", "equation"}
        Whose equilibria.
    count : int
        Roots a point.
    tol : float
        The corrector's tolerance (the roots' is max(1e3 tol, 1e-9)).
    """

    #: The arclength weighs u as p (Euclidean in (u, p)).
    weight = 1.0

    def __init__(self, make: Model, of: str = "scheme", count: int = ROOTS, tol: float = 1e-10):
        self.problem = Problem(make)
        self.make, self.of, self.count, self.tol = make, check_of(of), int(count), tol
        self.why = ""

    def verdict(self, point: EquilibriumPoint, verify: bool) -> None:
        """The point's ``stable``, ``error`` and ``reason`` from its roots, verified (a
        linearisation of its own) or not."""
        _, v = _roots(self.make, point.p, point.u, self.count, self.tol, self.of, verify,
                      point.roots)
        point.stable, point.error, point.reason = v.stable, v.error, v.reason

    def step(self, p: float) -> _OneStep:
        """G at p (cached)."""
        return self.problem.cached(("one step", self.of, float(p)),
                                   lambda: _OneStep(self.problem, float(p), self.of))

    def residual(self, x: np.ndarray, p: float) -> np.ndarray:
        """G(u) at p."""
        return self.step(p)(x)

    def jacobian(self, x: np.ndarray, p: float) -> tuple[np.ndarray, np.ndarray]:
        """(G_u, G_p) by forward differences of step 1e-7 max(1, |y_j|)."""
        J = forward_jacobian(lambda y: self.residual(y[:-1], float(y[-1])),
                             np.concatenate([x, [p]]), self.residual(x, p))
        return J[:, :-1], J[:, -1]

    def point(self, x: np.ndarray, p: float) -> EquilibriumPoint:
        """The branch's point at (u, p), with its rightmost roots (its verdict is left None:
        :meth:`verdict` gives it to the points a branch keeps)."""
        lam, _ = _roots(self.make, p, x, self.count, self.tol, self.of, False)
        return EquilibriumPoint(p=p, u=x.copy(), roots=lam, stable=None, reason=UNVERIFIED.reason)

    def event_functions(self, x: np.ndarray, p: float, point: EquilibriumPoint
                        ) -> dict[str, float]:
        """{"hopf": :func:`hopf_test` of the point's roots}."""
        return {"hopf": hopf_test(point.roots)}

    def describe(self, kind: str, x: np.ndarray, p: float, point: EquilibriumPoint
                 ) -> dict[str, Any] | None:
        """The located event checked: a Hopf point has a non-real pair on the imaginary axis
        (to ON_AXIS); a branch point a two-dimensional null space of [G_u, G_p] (its smallest
        singular value below 1e-5 of the largest, the forward differences' reach).  None
        when the check refutes it (``why`` says why, empty for a neutral saddle)."""
        if kind == "hopf":
            lam = point.roots
            c = lam[np.isfinite(lam) & (lam.imag > REAL * np.maximum(1.0, np.abs(lam)))]
            if c.size:
                root = complex(c[np.argmin(np.abs(c.real))])
                if abs(root.real) <= ON_AXIS * max(1.0, abs(root)):
                    hp = HopfPoint(p=p, omega=root.imag, root=root)
                    if self.of == "equation":
                        hp = criticality(self.make, hp, x, tol=max(self.tol * 1e3, 1e-9))
                    return {"hopf": hp, "u": x, "detail": "a pair of roots crosses the "
                            f"imaginary axis at omega = {hp.omega:.8g}"}
            r = lam[np.isfinite(lam) & ~(lam.imag > REAL * np.maximum(1.0, np.abs(lam)))].real
            saddle = any(abs(a + b) <= ON_AXIS * max(1.0, abs(a)) for i, a in enumerate(r)
                         for b in r[i + 1:])
            # a neutral saddle (two real roots lambda_i + lambda_j = 0) zeroes the test function
            # too: no event, and nothing to warn of; anything else is said
            self.why = "" if saddle else (
                f"no pair of non-real roots on the imaginary axis there (the rightmost roots "
                f"{np.round(lam[:4], 6)!r}): the set of roots computed changed")
            return None
        if kind == "branch-point":
            Gu, Gp = self.jacobian(x, p)
            sv = null_vectors(np.column_stack([Gu, Gp]))[2]
            if sv[-1] <= 1e-5 * sv[0]:
                return {"u": x, "detail": "a real root crosses 0 where the branch goes on: the "
                        "null space of [G_u, G_p] is two-dimensional (its singular values "
                        f"{sv[-1]:.2g} of {sv[0]:.2g}); another branch of equilibria crosses "
                        "this one (the branch continued is the one it was on)"}
            self.why = (f"the null space of [G_u, G_p] is one-dimensional there (singular "
                        f"values {sv!r})")
            return None
        return {}


def equilibrium(make: Model, p: float, guess: Any, *, tol: float = 1e-10, count: int = ROOTS,
                max_iter: int = 30, of: str = "scheme", verify: bool = True) -> Equilibrium:
    """The equilibrium of the scheme of ``make(p)`` near ``guess``, by Newton's method.

    Newton on one step from a constant history (the n x n Jacobian by forward differences of
    single steps), until |G(u)|_inf and the last correction are <= tol max(1, |u|_inf) (G is
    O(h) times the error: the correction bounds it); with its rightmost roots and their
    verified verdict (:mod:`dmi.analysis.equilibria.root_verdict`: the equation's roots counted by the
    argument principle, the scheme's largest multiplier found again by a second eigen-solve,
    each with its error).

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
    verify : bool
        Verify the verdict (the default; see docs/stability.md for its cost).  False opts out:
        ``stable`` is None, with a ``UserWarning`` saying so.

    Returns
    -------
    Equilibrium
        ``.u``, ``.roots`` (rightmost first), ``.stable`` (verified: True, False, or None with
        a :class:`dmi.analysis.StabilityWarning` saying why; None without roots: ``count=0``
        or a kink), ``.error`` and ``.reason`` of the verdict, ``.residual``.

    Raises
    ------
    ValueError
        A p that is not a finite number, a guess that is not n finite numbers, or ``of`` not
        one of the two.
    ShootingError
        Newton fails: no new least residual in 3 iterations, a singular Jacobian, max_iter
        reached (every residual is listed); a step of the model that fails (named).
    Exception
        The model's own, when ``make(p)`` fails (a note names the call).
    """
    try:
        p = float(p)
    except (TypeError, ValueError):
        raise ValueError(f"equilibrium(make, p = {p!r}, ...): p must be a number") from None
    if not isinstance(verify, bool):
        raise ValueError(f"equilibrium(..., verify = {verify!r}): give True (the default: a "
                         "verified verdict) or False (opt out: stable None)")
    if not math.isfinite(p):
        raise ValueError(f"equilibrium(make, p = {p!r}, ...): p must be finite (the model "
                         "would be made and stepped at a non-finite parameter)")
    disc = Equilibria(make, of, count, tol)
    n = disc.step(p).n
    u0 = _check_guess(guess, n)
    z, its = newton_corrector(Curve(disc, n), np.concatenate([u0, [p]]), _e_p(n), p,
                              NewtonOptions(tol=tol, max_iter=max_iter, converge=Converge.BOTH),
                              far=math.inf,
                              what=f"equilibrium at p = {p!r}")
    u = z[:-1]
    if not verify and count >= 1:
        _unverified_warning("equilibrium")
    lam, v = _roots(make, p, u, count, tol, of, verify)
    if verify and count >= 1 and v.stable is None:
        warnings.warn(f"equilibrium at p = {p!r}: stable is None: {v.reason}", StabilityWarning,
                      stacklevel=2)
    return Equilibrium(make=make, p=p, u=u, roots=lam, stable=v.stable,
                       residual=float(np.max(np.abs(disc.residual(u, p)))), iterations=its,
                       of=of, error=v.error, reason=v.reason)


def _e_p(n: int) -> np.ndarray:
    """The row of the hyperplane p = const over (u, p)."""
    e = np.zeros(n + 1)
    e[-1] = 1.0
    return e


def continue_equilibrium(eq: Equilibrium, p_end: float, step: float = 0.05, *,
                         max_points: int = 200, min_step: float | None = None,
                         max_step: float | None = None, count: int = ROOTS,
                         tol: float = 1e-10, max_iter: int = 8, at: Any = (),
                         verify: bool = True) -> Branch:
    """Continues an equilibrium in p by pseudo-arclength, with fold, Hopf and branch-point events.

    The driver :func:`dmi.analysis.continuation.driver.continuation` on :class:`Equilibria`: the tangent is
    the null vector of [G_u, G_p], the predictor y + ds t, the corrector Newton on (G(y), <t,
    y - y_pred>); each point gets its ``count`` rightmost roots.  Events are located on the
    branch by Brent's method in the arclength and checked (see the module).

    Parameters
    ----------
    eq : Equilibrium
        The start, from :func:`equilibrium` (the branch is of the scheme's or the equation's
        equilibria as ``eq.of`` is).
    p_end : float
        Where to stop (finite, not eq.p); the last point lies on it exactly.
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
    at : iterable of float
        Parameters where a point is wanted (a ``user`` event each).
    verify : bool
        Verify every point's verdict (the default, as :func:`equilibrium`; the events' test
        functions read the roots and are not affected).  False opts out: the points' ``stable``
        is None, with one ``UserWarning``.

    Returns
    -------
    Branch
        ``kind`` "equilibria": ``points`` of :class:`EquilibriumPoint` (their verdicts
        verified; one :class:`dmi.analysis.StabilityWarning` names the points not decided),
        ``events`` (``fold``,
        ``hopf`` with its :class:`HopfPoint` in ``Event.hopf`` and the equilibrium in
        ``Event.u``, ``branch-point`` where a real root crosses 0 and another branch crosses
        this one, ``user``), ``status`` (why it ended: a corrector failing at the smallest
        step, or the model failing there, ends the branch; it does not raise).

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
    if not isinstance(verify, bool):
        raise ValueError(f"continue_equilibrium(..., verify = {verify!r}): give True (the "
                         "default: verified verdicts) or False (opt out: stable None)")
    if not verify and count >= 1:
        _unverified_warning("continue_equilibrium")
    disc = Equilibria(eq.make, eq.of, count, tol)
    options = ContinuationOptions(step=step, min_step=min_step, max_step=max_step,
                                  max_points=max_points, at=tuple(at), tol=tol,
                                  max_iter=max_iter, easy=max_iter)
    b = continuation(disc, eq.u, eq.p, float(p_end), options, make=eq.make, kind="equilibria")
    for q in b.points:
        disc.verdict(q, verify)
    open_ = [q for q in b.points if q.stable is None]
    if verify and count >= 1 and open_:
        warnings.warn(f"continue_equilibrium: the stability of {len(open_)} of {len(b.points)} "
                      f"points is not decided (stable None), at p = "
                      f"{', '.join(f'{q.p:.8g}' for q in open_[:6])}"
                      f"{', ...' if len(open_) > 6 else ''}: {open_[0].reason} (the first; "
                      "EquilibriumPoint.reason has each point's)", StabilityWarning, stacklevel=2)
    return b
