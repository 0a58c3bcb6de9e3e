# Newton's method on fixed points of the step map, plain and bordered, matrix-free.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Newton's method for x = F(x), x a shooting state, with GMRES on the matrix-free Jacobian
(forward differences of F: the derivative of the map's smooth piece, a semismooth Newton), and
the bordered step of a system with extra unknowns and equations (an autonomous orbit's step h,
a continuation's parameter p; a phase condition, an amplitude condition, an arclength):
:func:`bordered_newton`, of which :func:`newton` is the case without extra unknowns, with a
damped step.  It, collocation's sparse-LU Newton and the continuation driver's corrector
(:func:`dmi.analysis.continuation.driver.newton_corrector`) run :func:`newton_loop`, the one Newton loop,
each with its own linear solve.

Every iteration's residual is kept; an iteration gives up when the residual has made no new
minimum in :data:`NO_PROGRESS` iterations (the semismooth Newton may rise once on its way into
the next smooth piece of the map, never three times), and its error lists every residual tried.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
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


def newton_loop(evaluate: Callable[[np.ndarray], tuple[np.ndarray, Any]],
                factor: Callable[[np.ndarray, np.ndarray, Any], Solve], z0: np.ndarray, *,
                tol: float, max_iter: int, what: str, converge: str = "residual",
                chord: float | None = None, search: str = "none",
                reject: tuple[type[Exception], ...] = (), reject_why: str = "",
                check: Callable[[np.ndarray], None] | None = None,
                scale: Callable[[np.ndarray], float] | None = None, hint: str = "",
                far: str = "", history: list[float] | None = None, stall: bool = True,
                floor: int = 0, accuracy: list[float] | None = None
                ) -> tuple[np.ndarray, list[float]]:
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
        (a factored Jacobian, a bordered GMRES step); raises ShootingError when singular.
    z0 : numpy.ndarray
        The start.
    tol : float
        The tolerance, relative to ``scale(z)``.
    max_iter : int
        Iterations at most.
    what : str
        For the error messages.
    converge : str
        ``"residual"``: |r|_inf <= tol scale; ``"correction"``: |dz|_inf <= tol scale, z + dz
        returned; ``"both"``: the residual and the last correction.
    chord : float, optional
        None: a fresh ``factor`` every iteration; c < 1: the factor kept while the residual
        falls by the factor c or more an iteration (chord steps cost a residual).
    search : str
        ``"none"``: full steps; ``"guard"``: the step halved (at most 5 times) while the new
        residual is 100 times the old or more; ``"descent"``: halved until the residual falls
        (a step below 0.05 taken as it is), a stale chord factor refreshed before halving.
    reject : tuple of exception types
        Failures of ``evaluate`` that reject a trial step (it is halved); below 0.05 a
        ShootingError saying ``reject_why``.
    reject_why : str
        What a rejected step means.
    check : callable, optional
        Called on each new iterate; raises to stop.
    scale : callable, optional
        z -> the tolerance's scale (default max(1, |z|_inf)).
    hint : str
        Appended to the no-progress error.
    far : str
        Appended to the no-convergence error.
    history : list of float, optional
        The list the residuals are appended to (a caller's message can list them).
    stall : bool
        Give up when the residual makes no new minimum in NO_PROGRESS iterations (False: a
        loop converged on its correction may sit at the residual's rounding floor a few
        iterations).
    floor : int
        ``"correction"`` only, 0: off.  k > 0: also converged when the residual is at most
        tol scale (its rounding floor) and the correction has not fallen below half its least
        value (over the iterations at that floor) in k iterations: the corrections are then
        the rounding of the residual amplified by an ill-conditioned Jacobian (a nearly
        singular direction), and z is returned as it is, its accuracy the largest of those
        corrections (appended to ``accuracy``).
    accuracy : list of float, optional
        Where the achieved accuracy (max norm, the units of z) is appended on return: the last
        correction's size with ``"correction"`` (or the floor's, above), else the last step's.

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
    """
    if converge not in ("residual", "correction", "both") or \
            search not in ("none", "guard", "descent"):
        raise ValueError(f"newton_loop: converge = {converge!r}, search = {search!r}: give "
                         "'residual', 'correction' or 'both', and 'none', 'guard' or 'descent'")
    size = scale or (lambda z: max(1.0, float(np.max(np.abs(z)))))
    res: list[float] = history if history is not None else []
    z = np.array(z0, dtype=float)
    r, state = evaluate(z)
    solve, age, moved = None, 0, math.inf
    least, since, worst = math.inf, 0, 0.0      # the corrections at the residual's floor
    done_to = accuracy if accuracy is not None else []
    for _ in range(max_iter + 1):
        rn = float(np.max(np.abs(r))) if r.size else 0.0
        sc = size(z)
        verdict = judge(res, rn, -math.inf if converge == "correction" else tol * sc,
                        max_iter, what, hint, stall)
        if verdict == "converged" and (converge == "residual" or moved <= tol * sc):
            done_to.append(moved)
            return z, res
        if verdict == "exhausted":
            break
        if solve is None or chord is None or (len(res) > 1 and rn > chord * res[-2]):
            solve, age = factor(z, r, state), 0
        dz = solve(r)
        age += 1
        step = float(np.max(np.abs(dz)))
        if converge == "correction" and step <= tol * sc:
            done_to.append(step)
            return z + dz, res
        if floor > 0 and converge == "correction" and rn <= tol * sc:
            if step < 0.5 * least:                 # the corrections still fall
                least, since, worst = step, 0, step
            else:
                since, worst = since + 1, max(worst, step)
            if since >= floor:                     # rounding amplified: z is as good as it gets
                done_to.append(worst)
                return z, res
        else:
            least, since, worst = math.inf, 0, 0.0
        lam = 1.0
        # trials: 1, 1 / 2, ..., 1 / 32 (below 0.05: taken); "descent" twice (a refresh between)
        for _ in range({"none": 1, "guard": 6, "descent": 12}[search]):
            try:
                rt, st = evaluate(z + lam * dz)
                done = (search == "none" or lam < 0.05
                        or float(np.max(np.abs(rt))) < (100 * rn if search == "guard" else rn))
            except reject:
                if lam < 0.05:
                    raise ShootingError(f"{what}: {reject_why}", res) from None
                done = False
            if done:
                break
            if search == "descent" and chord is not None and age > 1:
                solve, age = factor(z, r, state), 1   # a stale Jacobian: refresh it, not the step
                dz, lam = solve(r), 1.0
                continue
            lam *= 0.5
        z, r, state = z + lam * dz, rt, st
        moved = float(np.max(np.abs(lam * dz)))
        if check is not None:
            check(z)
    raise ShootingError(f"{what}: no convergence in {max_iter} Newton iterations (residuals "
                        f"{fmt_residuals(res)}; tolerance {tol:.3g} relative)"
                        f"{': ' + far if far else ''}", res)


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


def bordered_step(F: Callable[[np.ndarray], np.ndarray], x: np.ndarray, Fx: np.ndarray,
                  Fq: np.ndarray, border: np.ndarray, g: float | np.ndarray, *, rtol: float
                  ) -> tuple[np.ndarray, float]:
    """One Newton step for x = F_q(x) with k >= 0 more unknowns q (an autonomous orbit's step h, a
    continuation's parameter p) and k more equations g = 0 (a phase condition, an amplitude
    condition, the pseudo-arclength hyperplane): dz = (dx, dq) solves the bordered system

        (D_xF - I) dx + F_q dq = -(F(x) - x),     border dz = -g,

    by GMRES on the matrix-free operator (D_xF v by :func:`directional`, step :func:`fd_eps`).
    ``Fq``: dF/dq, (dim,) or (dim, k) columns computed by the caller; ``border``: (dim + k,) or
    (k, dim + k) rows, linear in dz; ``g``: k values.  Returns (dz, GMRES's relative residual
    |J dz - rhs| / |rhs|, one more product): above about 1e-2 the system is singular."""
    Fq = np.asarray(Fq, dtype=float).reshape(x.size, -1)
    B = np.asarray(border, dtype=float).reshape(-1, x.size + Fq.shape[1])
    g = np.atleast_1d(np.asarray(g, dtype=float))
    k = Fq.shape[1]
    eps = fd_eps(x)

    def mv(v: np.ndarray) -> np.ndarray:
        vx = v[:x.size]
        return np.concatenate([directional(F, x, Fx, vx, eps) - vx + Fq @ v[x.size:], B @ v])

    size = x.size + k
    J = sla.LinearOperator((size, size), matvec=mv, dtype=float)
    rhs = -np.concatenate([Fx - x, g])
    dz, _ = sla.gmres(J, rhs, rtol=rtol, atol=0.0, restart=min(size, 60), maxiter=4)
    if not np.all(np.isfinite(dz)):
        return dz, math.inf
    return dz, float(np.linalg.norm(mv(dz) - rhs)) / max(float(np.linalg.norm(rhs)), 1e-300)


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
    ``conditions(z) -> (g (k,), rows (k, dim + k))`` (values and their linearisation), by
    :func:`bordered_step` (GMRES to ``rtol``; dF/dq by one forward difference of ``steps`` (k,)
    a column, default 1e-7 max(1, |q_j|)).  ``maps(q)`` is the map at q; a map that fails
    (a dmi.Error) is a ShootingError naming the iteration (and ``far``).  ``search``: the step
    halved (at most 5 times) while it makes the residual 100 times worse.  ``check(z)``: called
    on each new iterate, raises to stop (a step outside the model's range).  Converged when
    |F(x) - x|_inf and |g|_inf are <= tol max(1, |x|_inf).  Returns (z, residuals); raises
    ShootingError with every residual tried (no new least residual in NO_PROGRESS iterations
    (``hint`` appended), a singular bordered system (``singular``: what, and why appended),
    non-finite values, max_iter reached)."""
    dim = np.asarray(z0).size - k
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

    return newton_loop(evaluate, factor, z0, tol=tol, max_iter=max_iter, what=what,
                       search="guard" if search else "none", check=check,
                       scale=lambda z: max(1.0, float(np.max(np.abs(z[:dim])))), hint=hint,
                       far=far, history=res)
