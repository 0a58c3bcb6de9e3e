# The one Newton loop, its options, and the one bordered solve (dense, sparse, matrix-free).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Newton's method for x = F(x), x a shooting state, with GMRES on the matrix-free Jacobian
(forward differences of F: the derivative of the map's smooth piece, a semismooth Newton), and
the bordered step of a system with extra unknowns and equations (an autonomous orbit's step h,
a continuation's parameter p; a phase condition, an amplitude condition, an arclength):
:func:`bordered_newton`, of which :func:`newton` is the case without extra unknowns, with a
damped step.  It, collocation's sparse-LU Newton, the continuation driver's corrector
(:func:`dmi.analysis.continuation.driver.newton_corrector`) and shooting's Newton-Picard (its
reduced system the linear solve, its contraction test the convergence test; a
:class:`Strategy` the driver's corrector tries) run :func:`newton_loop`, the one Newton loop,
each with its own linear solve, its options a value (:class:`NewtonOptions`: the convergence
test :class:`Converge` or a callable, the line search :class:`Search`).  Their bordered
systems are solved by :func:`bordered_solve` (dense LU, SuperLU, or GMRES on an operator), the
one bordered solve.

Every iteration's residual is kept; an iteration gives up when the residual has made no new
minimum in :data:`NO_PROGRESS` iterations (the semismooth Newton may rise once on its way into
the next smooth piece of the map, never three times), and its error lists every residual tried.
"""
from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse
import scipy.sparse.linalg as sla

from ..._errors import Error

#: Iterations without a new least residual after which Newton gives up.
NO_PROGRESS = 3


class ShootingError(RuntimeError):
    """Newton's iteration for a periodic orbit (or an equilibrium) failed (a ``RuntimeError``).

    Parameters
    ----------
    message : str
        What failed, and what to try.
    residuals : list of float, optional
        The history of max-norm residuals |F(x) - x| per iteration (state units).

    Attributes
    ----------
    residuals : list of float
        As given (empty if None).
    iterations : int
        Their count.
    """

    def __init__(self, message: str, residuals: list[float] | None = None):
        super().__init__(message)
        self.residuals = list(residuals or [])
        self.iterations = len(self.residuals)


def fmt_residuals(res: list[float]) -> str:
    """Every residual tried, for an error message."""
    return "[" + ", ".join(f"{r:.2g}" for r in res) + "]"


def stalled(res: list[float]) -> bool:
    """The residuals ``res`` (one an iteration) made no new minimum in the last NO_PROGRESS."""
    return len(res) > NO_PROGRESS and min(res[-NO_PROGRESS:]) >= min(res[:-NO_PROGRESS])


def judge(res: list[float], rn: float, tol: float, max_iter: int, what: str, hint: str = "",
          stall: bool = True) -> str:
    """Appends an iteration's residual rn to res and judges it: ``"converged"`` (rn <= tol),
    ``"exhausted"`` (max_iter iterations done) or ``"go on"``; raises ShootingError on a
    non-finite residual or (``stall``) when there is no new least residual in NO_PROGRESS
    iterations."""
    res.append(rn)
    if not math.isfinite(rn):
        raise ShootingError(f"{what}: non-finite residual (residuals {fmt_residuals(res)}): "
                            "the guess is too far from any orbit", res)
    if rn <= tol:
        return "converged"
    if len(res) > max_iter:
        return "exhausted"
    if stall and stalled(res):
        raise ShootingError(f"{what}: Newton makes no progress: no new least residual in "
                            f"{NO_PROGRESS} iterations (residuals {fmt_residuals(res)}; tolerance "
                            f"{tol:.3g}){hint}", res)
    return "go on"


#: Linear solve of one Newton iteration: the residual r -> the correction dz (J dz = -r).
Solve = Callable[[np.ndarray], np.ndarray]


class Converge(enum.Enum):
    """Newton's convergence test (the loop's, as SUNDIALS' convergence-test callback)."""
    #: |r|_inf <= tol scale.
    RESIDUAL = "residual"
    #: |dz|_inf <= tol scale, z + dz returned.
    CORRECTION = "correction"
    #: The residual and the last correction.
    BOTH = "both"


class Search(enum.Enum):
    """The step length a Newton iteration takes along its correction."""
    #: Full steps.
    NONE = "none"
    #: The step halved (at most 5 times) while the new residual is 100 times the old or more.
    GUARD = "guard"
    #: Halved until the residual falls (a step below 0.05 taken as it is), a stale chord
    #: factor refreshed before halving.
    DESCENT = "descent"


#: Trial step lengths a line search tries at most.
_TRIALS = {Search.NONE: 1, Search.GUARD: 6, Search.DESCENT: 12}


@dataclasses.dataclass(frozen=True)
class NewtonOptions:
    """How :func:`newton_loop` iterates (a value, as BifurcationKit's ``NewtonPar``).

    Attributes
    ----------
    tol : float
        The tolerance, relative to the caller's scale of z (default max(1, |z|_inf)).
    max_iter : int
        Iterations at most.
    converge : Converge or callable
        The convergence test (a string of its values is accepted), or the caller's, as
        SUNDIALS' convergence-test callback: ``converge(z, r, residuals) -> bool``, called on
        each iterate after its residual's max norm is appended to ``residuals`` (True: z is
        returned); it may raise to stop the loop (e.g. a contraction too slow for its method).
    chord : float or None
        None: a fresh factor every iteration; c < 1: the factor kept while the residual falls by
        the factor c or more an iteration (chord steps cost a residual).
    search : Search
        The line search (a string of its values is accepted).
    reject : tuple of exception types
        Failures of the residual that reject a trial step (it is halved); below 0.05 a
        ShootingError saying ``reject_why``.
    reject_why : str
        What a rejected step means.
    stall : bool
        Give up when the residual makes no new minimum in NO_PROGRESS iterations (False: a loop
        converged on its correction may sit at the residual's rounding floor a few iterations).
    floor : int
        With ``Converge.CORRECTION``, 0: off; k > 0: also converged when the residual is at most
        tol scale (its rounding floor) and the correction has not fallen below half its least
        value (over the iterations at that floor) in k iterations: the corrections are then the
        rounding of the residual amplified by an ill-conditioned Jacobian, and z is returned as
        it is, its accuracy the largest of those corrections.
    hint : str
        Appended to the no-progress error.
    far : str
        Appended to the no-convergence error.
    """
    tol: float = 1e-10
    max_iter: int = 30
    converge: Converge | Callable[[np.ndarray, np.ndarray, list[float]], bool] = \
        Converge.RESIDUAL
    chord: float | None = None
    search: Search = Search.NONE
    reject: tuple[type[Exception], ...] = ()
    reject_why: str = ""
    stall: bool = True
    floor: int = 0
    hint: str = ""
    far: str = ""

    def __post_init__(self) -> None:
        for name, kind in (("converge", Converge), ("search", Search)):
            value = getattr(self, name)
            if not isinstance(value, kind) and not (name == "converge" and callable(value)):
                try:
                    object.__setattr__(self, name, kind(value))
                except ValueError:
                    raise ValueError(f"NewtonOptions: {name} = {value!r}: give one of "
                                     f"{[k.value for k in kind]} or a {kind.__name__}") from None

    def but(self, **changes: Any) -> NewtonOptions:
        """These options with some fields changed (a TypeError names an unknown field)."""
        names = {f.name for f in dataclasses.fields(self)}
        unknown = sorted(set(changes) - names)
        if unknown:
            raise TypeError(f"NewtonOptions has no field {', '.join(unknown)} (fields: "
                            f"{', '.join(sorted(names))})")
        return dataclasses.replace(self, **changes)


def newton_loop(evaluate: Callable[[np.ndarray], tuple[np.ndarray, Any]],
                factor: Callable[[np.ndarray, np.ndarray, Any], Solve], z0: np.ndarray,
                options: NewtonOptions | None = None, *, what: str,
                check: Callable[[np.ndarray], None] | None = None,
                scale: Callable[[np.ndarray], float] | None = None,
                history: list[float] | None = None, accuracy: list[float] | None = None,
                **fields: Any) -> tuple[np.ndarray, list[float]]:
    """Newton's method on r(z) = 0: the one loop of :mod:`dmi.analysis` (the step maps'
    matrix-free :func:`bordered_newton`, collocation's sparse LU, the continuation driver's
    corrector), its linear solve given by the caller.

    Parameters
    ----------
    evaluate : callable
        z -> (r, state): the residual vector (its max norm is judged by :func:`judge`) and what
        ``factor`` needs at z.
    factor : callable
        (z, r, state) -> solve: the linear solve at z, solve(r) the correction dz of J dz = -r
        (a factored Jacobian, a bordered GMRES step, a Newton-Picard reduced system); raises
        ShootingError when singular.
    z0 : numpy.ndarray
        The start.
    options : NewtonOptions, optional
        How to iterate (default ``NewtonOptions()``).
    what : str
        For the error messages.
    check : callable, optional
        Called on each new iterate; raises to stop.
    scale : callable, optional
        z -> the tolerance's scale (default max(1, |z|_inf)).
    history : list of float, optional
        The list the residuals are appended to (a caller's message can list them).
    accuracy : list of float, optional
        Where the achieved accuracy (max norm, the units of z) is appended on return: the last
        correction's size with ``Converge.CORRECTION`` (or the floor's), else the last step's.
    **fields
        Fields of :class:`NewtonOptions` (``tol=``, ``max_iter=``, ``converge=``, ...) that
        replace those of ``options``.

    Returns
    -------
    tuple
        (z, the residuals, one an iteration).

    Raises
    ------
    ShootingError
        A non-finite residual, no new least residual in NO_PROGRESS iterations (``stall``),
        max_iter reached, a rejected step at the smallest length, or as ``factor`` and
        ``check``; every residual listed.
    ValueError
        ``converge`` or ``search`` not one of theirs.
    TypeError
        A field that NewtonOptions does not have.
    """
    o = (options or NewtonOptions()).but(**fields) if fields else (options or NewtonOptions())
    size = scale or (lambda z: max(1.0, float(np.max(np.abs(z)))))
    res: list[float] = history if history is not None else []
    z = np.array(z0, dtype=float)
    r, state = evaluate(z)
    solve, age, moved = None, 0, math.inf
    floor = _Floor(o.floor if o.converge is Converge.CORRECTION else 0)
    done_to = accuracy if accuracy is not None else []
    own = not isinstance(o.converge, Converge)   # the caller's convergence test
    for _ in range(o.max_iter + 1):
        rn = float(np.max(np.abs(r))) if r.size else 0.0
        sc = size(z)
        verdict = judge(res, rn, -math.inf if own or o.converge is Converge.CORRECTION else
                        o.tol * sc, o.max_iter, what, o.hint, o.stall)
        if (verdict == "converged" and (o.converge is Converge.RESIDUAL or moved <= o.tol * sc)
                or own and o.converge(z, r, res)):
            done_to.append(moved)
            return z, res
        if verdict == "exhausted":
            break
        if solve is None or o.chord is None or (len(res) > 1 and rn > o.chord * res[-2]):
            solve, age = factor(z, r, state), 0
        dz = solve(r)
        age += 1
        step = float(np.max(np.abs(dz)))
        if o.converge is Converge.CORRECTION and step <= o.tol * sc:
            done_to.append(step)
            return z + dz, res
        if floor.reached(step, rn <= o.tol * sc):   # rounding amplified: z is as good as it gets
            done_to.append(floor.worst)
            return z, res
        z, r, state, moved, solve, age = _line_search(evaluate, factor, o, z, r, state, dz,
                                                      rn, solve, age, what, res)
        if check is not None:
            check(z)
    raise ShootingError(f"{what}: no convergence in {o.max_iter} Newton iterations (residuals "
                        f"{fmt_residuals(res)}; tolerance {o.tol:.3g} relative)"
                        f"{': ' + o.far if o.far else ''}", res)


class _Floor:
    """The corrections at the residual's rounding floor (:attr:`NewtonOptions.floor`)."""

    def __init__(self, iterations: int):
        self.iterations = iterations
        self.least, self.since, self.worst = math.inf, 0, 0.0

    def reached(self, step: float, at_floor: bool) -> bool:
        """A correction of size ``step`` (``at_floor``: the residual at its floor): True when
        the corrections have not halved in ``iterations`` iterations at the floor."""
        if self.iterations <= 0:
            return False
        if not at_floor:
            self.least, self.since, self.worst = math.inf, 0, 0.0
            return False
        if step < 0.5 * self.least:                 # the corrections still fall
            self.least, self.since, self.worst = step, 0, step
        else:
            self.since, self.worst = self.since + 1, max(self.worst, step)
        return self.since >= self.iterations


def _line_search(evaluate: Callable[[np.ndarray], tuple[np.ndarray, Any]],
                 factor: Callable[[np.ndarray, np.ndarray, Any], Solve], o: NewtonOptions,
                 z: np.ndarray, r: np.ndarray, state: Any, dz: np.ndarray, rn: float,
                 solve: Solve, age: int, what: str, res: list[float]) -> tuple:
    """The step along dz by ``o.search``: trials 1, 1 / 2, ..., 1 / 32 (below 0.05: taken);
    ``Search.DESCENT`` twice, a stale chord factor refreshed between.  Returns (z, r, state,
    the step's size, solve, age)."""
    lam = 1.0
    for _ in range(_TRIALS[o.search]):
        try:
            rt, st = evaluate(z + lam * dz)
            done = (o.search is Search.NONE or lam < 0.05
                    or float(np.max(np.abs(rt))) < (100 * rn if o.search is Search.GUARD
                                                     else rn))
        except o.reject:
            if lam < 0.05:
                raise ShootingError(f"{what}: {o.reject_why}", res) from None
            done = False
        if done:
            break
        if o.search is Search.DESCENT and o.chord is not None and age > 1:
            solve, age = factor(z, r, state), 1   # a stale Jacobian: refresh it, not the step
            dz, lam = solve(r), 1.0
            continue
        lam *= 0.5
    return z + lam * dz, rt, st, float(np.max(np.abs(lam * dz))), solve, age


def fd_eps(x: np.ndarray) -> float:
    """The forward-difference step of Newton's matrix-free Jacobians: sqrt(eps_machine)
    max(1, |x|_inf) (state units)."""
    return math.sqrt(np.finfo(float).eps) * max(1.0, float(np.max(np.abs(x))))


def directional(F: Callable[[np.ndarray], np.ndarray], x: np.ndarray, Fx: np.ndarray,
                v: np.ndarray, eps: float) -> np.ndarray:
    """DF(x) v by a forward difference of step eps along v / |v|_2 (one evaluation of F; 0 for
    v = 0)."""
    nv = float(np.linalg.norm(v))
    if nv == 0.0:
        return np.zeros_like(v)
    return (F(x + (eps / nv) * v) - Fx) * (nv / eps)


def bordered_solve(Jx: Any, Jp: np.ndarray, rows: np.ndarray, rhs: np.ndarray, *,
                   rtol: float = 1e-10, maxiter: int = 8) -> np.ndarray:
    """Solves the bordered system [[J_x, J_p], [rows]] dz = rhs: the one bordered solve of
    :mod:`dmi.analysis` (the continuation driver's corrector and tangent, the maps' matrix-free
    Newton, collocation's Newton with a held length).

    Parameters
    ----------
    Jx : numpy.ndarray, scipy.sparse matrix, scipy.sparse.linalg.LinearOperator or callable
        Shape (m, m); a callable: v -> J_x v (matrix-free, as an operator).
    Jp : numpy.ndarray
        Shape (m,) or (m, k): the columns of the k extra unknowns.
    rows : numpy.ndarray
        Shape (m + k,) or (k, m + k): the border's rows.
    rhs : numpy.ndarray
        Shape (m + k,).
    rtol, maxiter : float, int
        GMRES's relative tolerance and restarts (an operator J_x).

    Returns
    -------
    numpy.ndarray
        dz, shape (m + k,).

    Raises
    ------
    ShootingError
        The bordered matrix is singular (dense, sparse) or GMRES does not solve it to 1e-2
        relative (an operator).
    """
    dz, lin = bordered_system(Jx, Jp, rows, rhs, rtol=rtol, maxiter=maxiter)
    if lin > 1e-2:
        raise ShootingError(f"the bordered Jacobian is singular (GMRES relative residual "
                            f"{lin:.2g})", [])
    return dz


def bordered_system(Jx: Any, Jp: np.ndarray, rows: np.ndarray, rhs: np.ndarray, *,
                    rtol: float, maxiter: int) -> tuple[np.ndarray, float]:
    """:func:`bordered_solve`'s solution and its relative residual |A dz - rhs| / |rhs| (0 for
    a direct solve; GMRES's, one more product, for an operator J_x: above about 1e-2 the
    system is singular; inf for a non-finite solution).  A singular direct solve raises
    ShootingError."""
    m = np.shape(Jp)[0]
    Jc = np.asarray(Jp, dtype=float).reshape(m, -1)
    B = np.asarray(rows, dtype=float).reshape(-1, m + Jc.shape[1])
    if isinstance(Jx, sla.LinearOperator) or callable(Jx):
        jv = Jx.matvec if isinstance(Jx, sla.LinearOperator) else Jx

        def mv(v: np.ndarray) -> np.ndarray:
            return np.concatenate([jv(v[:m]) + Jc @ v[m:], B @ v])
        size = m + Jc.shape[1]
        A = sla.LinearOperator((size, size), matvec=mv, dtype=float)
        dz, _ = sla.gmres(A, rhs, rtol=rtol, atol=0.0, restart=min(size, 60), maxiter=maxiter)
        if not np.all(np.isfinite(dz)):
            return dz, math.inf
        return dz, float(np.linalg.norm(mv(dz) - rhs)) / max(float(np.linalg.norm(rhs)), 1e-300)
    if scipy.sparse.issparse(Jx):
        try:
            dz = sla.splu(sparse_bordered(Jx, Jc, B)).solve(rhs)
        except RuntimeError as e:   # SuperLU: "Factor is exactly singular"
            raise ShootingError(f"the bordered Jacobian is singular ({e})", []) from None
    else:
        A = np.vstack([np.column_stack([np.asarray(Jx, dtype=float), Jc]), B])
        try:
            dz = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            raise ShootingError("the bordered Jacobian is singular", []) from None
    if not np.all(np.isfinite(dz)):
        raise ShootingError("the bordered Jacobian is singular (non-finite solution)", [])
    return dz, 0.0


def sparse_bordered(Jx: Any, Jp: np.ndarray, rows: np.ndarray) -> Any:
    """[[J_x, J_p], [rows]] as a CSC matrix (J_p (m,) or (m, k), rows (m + k,) or (k, m +
    k))."""
    m = Jx.shape[0]
    Jc = np.asarray(Jp, dtype=float).reshape(m, -1)
    top = scipy.sparse.hstack([Jx, scipy.sparse.csc_matrix(Jc)])
    B = np.asarray(rows, dtype=float).reshape(-1, m + Jc.shape[1])
    return scipy.sparse.vstack([top, scipy.sparse.csc_matrix(B)], format="csc")


def bordered_step(F: Callable[[np.ndarray], np.ndarray], x: np.ndarray, Fx: np.ndarray,
                  Fq: np.ndarray, border: np.ndarray, g: float | np.ndarray, *, rtol: float
                  ) -> tuple[np.ndarray, float]:
    """One Newton step for x = F_q(x) with k >= 0 more unknowns q (an autonomous orbit's step h, a
    continuation's parameter p) and k more equations g = 0 (a phase condition, an amplitude
    condition, the pseudo-arclength hyperplane): dz = (dx, dq) solves the bordered system

        (D_xF - I) dx + F_q dq = -(F(x) - x),     border dz = -g,

    by :func:`bordered_system` (GMRES, 4 restarts) on the matrix-free operator (D_xF v by
    :func:`directional`, step :func:`fd_eps`).  ``Fq``: dF/dq, (dim,) or (dim, k) columns
    computed by the caller; ``border``: (dim + k,) or (k, dim + k) rows, linear in dz; ``g``: k
    values.  Returns (dz, GMRES's relative residual |J dz - rhs| / |rhs|, one more product):
    above about 1e-2 the system is singular."""
    Fq = np.asarray(Fq, dtype=float).reshape(x.size, -1)
    g = np.atleast_1d(np.asarray(g, dtype=float))
    eps = fd_eps(x)
    return bordered_system(lambda v: directional(F, x, Fx, v, eps) - v, Fq, border,
                           -np.concatenate([Fx - x, g]), rtol=rtol, maxiter=4)


def newton(F: Callable[[np.ndarray], np.ndarray], x0: np.ndarray, *, tol: float = 1e-10,
           max_iter: int = 30, what: str = "x = F(x)") -> tuple[np.ndarray, list[float]]:
    """Solves x = F(x) by Newton's method with GMRES on the matrix-free Jacobian I - DF
    (forward differences of F, step sqrt(eps_machine) max(1, |x|_inf): the derivative of the
    map's smooth piece, a semismooth Newton): :func:`bordered_newton` with no extra unknown,
    its step halved (at most 5 times) only while it makes the residual 100 times worse (a step
    into the next piece of a piecewise-smooth map may raise the residual for one iteration
    before the next lands on the fixed point).  Converged when |F(x) - x|_inf <= tol * max(1,
    |x|_inf).  Returns (x, residual history).  Raises ShootingError, with every residual tried,
    when F fails, the Jacobian is singular, the residual makes no new minimum in
    :data:`NO_PROGRESS` iterations, or it does not fall below tol within max_iter
    iterations."""
    return bordered_newton(lambda q: F, x0, 0, _no_conditions, tol=tol, max_iter=max_iter,
                           what=what, rtol=1e-6, search=True,
                           hint=": no orbit near the guess, or the orbit is not isolated",
                           singular=("the Jacobian I - DF is singular or too ill-conditioned",
                                     ": a Floquet multiplier at 1, a non-isolated orbit, or no "
                                     "orbit"),
                           far="the guess is too far from any orbit")


def _no_conditions(z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """No equation besides the fixed point."""
    return np.empty(0), np.empty((0, z.size))


@dataclasses.dataclass
class Strategy:
    """One linear-solve strategy of :func:`newton_loop`: what the loop takes (the residual, the
    linear solve, the options, the iterates' check and the tolerance's scale), where it starts
    (None: the corrector's predictor), the weight its iterations count for a continuation's step
    control, and the failures after which a corrector tries its next strategy (others refuse the
    point).  ``history``: the residuals of its run, one an iteration."""
    evaluate: Callable[[np.ndarray], tuple[np.ndarray, Any]]
    factor: Callable[[np.ndarray, np.ndarray, Any], Solve]
    options: NewtonOptions
    what: str
    name: str = "newton"
    weight: float = 1.0
    start: np.ndarray | None = None
    check: Callable[[np.ndarray], None] | None = None
    scale: Callable[[np.ndarray], float] | None = None
    retry: tuple[type[BaseException], ...] = (Exception,)
    history: list[float] = dataclasses.field(default_factory=list)

    def run(self, z0: np.ndarray) -> tuple[np.ndarray, list[float]]:
        """:func:`newton_loop` from ``start`` (or z0); returns (z, the residuals)."""
        return newton_loop(self.evaluate, self.factor, z0 if self.start is None else self.start,
                           self.options, what=self.what, check=self.check, scale=self.scale,
                           history=self.history)


def bordered_newton(maps: Callable[[np.ndarray], Callable[[np.ndarray], np.ndarray]],
                    z0: np.ndarray, k: int,
                    conditions: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], *,
                    tol: float = 1e-10, max_iter: int = 30, what: str = "x = F_q(x)",
                    steps: np.ndarray | None = None,
                    check: Callable[[np.ndarray], None] | None = None, rtol: float = 1e-8,
                    search: bool = False, hint: str = "",
                    singular: tuple[str, str] = ("the bordered Jacobian is singular", ""),
                    far: str = "") -> tuple[np.ndarray, list[float]]:
    """Newton on z = (x, q), q the last k >= 0 values: F_q(x) - x = 0 and the k equations
    ``conditions(z)``: the strategy of :func:`map_strategy` run from z0.  Returns (z,
    residuals); raises ShootingError as :func:`map_strategy` says."""
    return map_strategy(maps, np.asarray(z0).size, k, conditions, tol=tol, max_iter=max_iter,
                        what=what, steps=steps, check=check, rtol=rtol, search=search,
                        hint=hint, singular=singular, far=far).run(z0)


def map_strategy(maps: Callable[[np.ndarray], Callable[[np.ndarray], np.ndarray]],
                 size: int, k: int,
                 conditions: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]], *,
                 tol: float = 1e-10, max_iter: int = 30, what: str = "x = F_q(x)",
                 steps: np.ndarray | None = None,
                 check: Callable[[np.ndarray], None] | None = None, rtol: float = 1e-8,
                 search: bool = False, hint: str = "",
                 singular: tuple[str, str] = ("the bordered Jacobian is singular", ""),
                 far: str = "", start: np.ndarray | None = None) -> Strategy:
    """Newton on z = (x, q), q the last k >= 0 values: F_q(x) - x = 0 and the k equations
    ``conditions(z) -> (g (k,), rows (k, dim + k))`` (values and their linearisation), by
    :func:`bordered_step` (GMRES to ``rtol``; dF/dq by one forward difference of ``steps`` (k,)
    a column, default 1e-7 max(1, |q_j|)).  ``maps(q)`` is the map at q; a map that fails
    (a dmi.Error) is a ShootingError naming the iteration (and ``far``).  ``search``: the step
    halved (at most 5 times) while it makes the residual 100 times worse.  ``check(z)``: called
    on each new iterate, raises to stop (a step outside the model's range).  Converged when
    |F(x) - x|_inf and |g|_inf are <= tol max(1, |x|_inf).  Returns the :class:`Strategy`
    (from ``start``, default the caller's z0); its run returns (z, residuals) and raises
    ShootingError with every residual tried (no new least residual in NO_PROGRESS iterations
    (``hint`` appended), a singular bordered system (``singular``: what, and why appended),
    non-finite values, max_iter reached)."""
    dim = size - k
    res: list[float] = []

    def ev(q: np.ndarray, x: np.ndarray) -> np.ndarray:
        try:
            return maps(q)(x)
        except Error as e:
            raise ShootingError(f"{what}: the map failed after {len(res)} Newton iterations "
                                f"(residuals {fmt_residuals(res)}): {e}; "
                                f"{far + ', or' if far else 'the iterate is off any orbit:'} "
                                "the orbit leaves the model's domain", res) from e

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, tuple]:
        Fx = ev(z[dim:], z[:dim])
        g, rows = conditions(z)
        return np.concatenate([Fx - z[:dim], np.atleast_1d(g)]), (Fx, g, rows)

    def factor(z: np.ndarray, r: np.ndarray, state: tuple) -> Solve:
        Fx, g, rows = state
        x, q = z[:dim], z[dim:]
        cols = np.empty((dim, k))
        for j in range(k):
            d = 1e-7 * max(1.0, abs(q[j])) if steps is None else float(steps[j])
            qd = q.copy()
            qd[j] += d
            cols[:, j] = (ev(qd, x) - Fx) / d
        dz, lin = bordered_step(maps(q), x, Fx, cols, rows, g, rtol=rtol)
        if lin > 1e-2 or float(np.max(np.abs(dz))) > 1e8 * max(1.0, float(np.max(np.abs(x)))):
            raise ShootingError(f"{what}: {singular[0]} at Newton iteration {len(res)} (GMRES "
                                f"relative residual {lin:.2g}, residuals {fmt_residuals(res)})"
                                f"{singular[1]}", res)
        return lambda _r: dz

    options = NewtonOptions(tol=tol, max_iter=max_iter, hint=hint, far=far,
                            search=Search.GUARD if search else Search.NONE)
    return Strategy(evaluate, factor, options, what, start=start, check=check,
                    scale=lambda z: max(1.0, float(np.max(np.abs(z[:dim])))), history=res)
