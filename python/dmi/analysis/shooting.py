# Periodic orbits by shooting on the scheme's step map (issue 30).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Shooting for periodic orbits of the discrete scheme (3.12)-(3.13).

A *model* is a function ``make(p) -> dmi.Solver`` returning a configured solver (rhs, friction,
box or resolvent, kernel, convolution method), not initialised, for the parameter value ``p``.

The state of the M-step map is the *window*: the last L >= N + 1 stored states, oldest first,
flattened (L n values; L = N + 1 unless the caller asks for more, see :class:`StepMap`).  A
forced orbit of period P = M h starts at t = 0: the map is ``init``, ``set_window`` (the last
N + 1 rows), ``run(M)``, and the last L rows of the old rows followed by the M new ones.  Its
fixed points are the M-periodic solutions of the scheme; its Jacobian has the nonzero spectrum of
the window map's (extra old rows are a nilpotent block), whose eigenvalues are the Floquet
multipliers.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse.linalg as sla

from .._errors import Error
from .._solver import Solver

Model = Callable[[float], Solver]


class ShootingError(RuntimeError):
    """Newton's iteration for a periodic orbit failed: ``residuals`` is the history of
    max-norm residuals |F(x) - x| per iteration (state units), ``iterations`` their count."""

    def __init__(self, message: str, residuals: list[float] | None = None):
        super().__init__(message)
        self.residuals = list(residuals or [])
        self.iterations = len(self.residuals)


def build(make: Model, p: float) -> Solver:
    """``make(p)``, with a failure or a wrong return turned into a ValueError naming p."""
    try:
        s = make(p)
    except Exception as e:  # the model refuses p: out of range
        raise ValueError(f"make(p = {p!r}) failed: {type(e).__name__}: {e} "
                         "(parameter out of the model's range?)") from e
    if not isinstance(s, Solver):
        raise ValueError(f"make(p = {p!r}) returned {type(s).__name__}; expected a dmi.Solver")
    return s


def positive_time(name: str, value: Any) -> float:
    """value as a float, finite and > 0 (a period, time units); ValueError naming it otherwise."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} = {value!r} is not a number") from None
    if not (math.isfinite(v) and v > 0):
        raise ValueError(f"{name} = {v}: must be finite and > 0 (time units)")
    return v


def steps_per_period(h: float, period: float) -> int:
    """M = period / h, which must be a whole number (to 1e-9 relative); ValueError otherwise."""
    period = positive_time("period", period)
    M = round(period / h)
    if M < 1 or abs(M * h - period) > 1e-9 * period:
        raise ValueError(f"period = {period!r} is not a whole number of steps h = {h!r} "
                         f"(period / h = {period / h!r}); choose N (or h) so that h divides it")
    return M


class StepMap:
    """The M-step map x -> F(x) of the model at p on states of L rows (L >= N + 1).

    One solver is made and initialised once; every evaluation restores its step counter to 0
    (``load_state`` of the state saved after ``init``), sets the window and runs M steps.
    ``evaluations`` counts the calls (each costs M steps)."""

    def __init__(self, make: Model, p: float, M: int, rows: int | None = None,
                 solver: Solver | None = None):
        self.make, self.p, self.M = make, float(p), int(M)
        # solver: make(p) already built by the caller (not initialised), else built here
        self.solver = build(make, self.p) if solver is None else solver
        self.n, self.N, self.h = self.solver.n, self.solver.N, self.solver.h
        self.L = self.N + 1 if rows is None else int(rows)
        if self.L < self.N + 1:
            raise ValueError(f"rows = {self.L} < N + 1 = {self.N + 1}")
        self.solver.init()
        self._start = self.solver.save_state()
        self.evaluations = 0

    @property
    def dim(self) -> int:
        return self.L * self.n

    def _start_at(self, x: np.ndarray) -> Solver:
        """The solver at step 0 with the window the last N + 1 rows of x (one evaluation)."""
        X = np.asarray(x, dtype=float).reshape(self.L, self.n)
        s = self.solver
        s.load_state(self._start)
        s.set_window(X[self.L - self.N - 1:])
        self.evaluations += 1
        return s

    def trajectory(self, x: np.ndarray) -> np.ndarray:
        """The M + 1 states U^0 .. U^M (rows) from the state x (U^0 its last row)."""
        return self._start_at(x).run(self.M)[1]

    def trajectory_terms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`trajectory` and the resolvent's arguments X^0 .. X^(M-1) (M rows: X^k the
        argument of the step into U^(k+1)), from one run."""
        _, U, X = self._start_at(x).run_terms(self.M)
        return U, X

    def extend(self, x: np.ndarray) -> np.ndarray:
        """x (k >= N + 1 rows, flattened) as a state of L rows: the older rows by M-periodicity
        from one run, row at t = -j being U^(M - j mod M) (exact at an M-periodic orbit; a guess
        elsewhere).  The last L rows when k >= L."""
        X = np.asarray(x, dtype=float).reshape(-1, self.n)
        k = X.shape[0]
        if k >= self.L:
            return X[k - self.L:].ravel()
        if k < self.N + 1:
            raise ValueError(f"a state of {k} rows; the map reads N + 1 = {self.N + 1}")
        s = self.solver
        s.load_state(self._start)
        s.set_window(X[k - self.N - 1:])
        U = s.run(self.M)[1]
        out = np.empty((self.L, self.n))
        out[self.L - k:] = X
        for j in range(k, self.L):
            out[self.L - 1 - j] = U[(self.M - j) % self.M]
        return out.ravel()

    def __call__(self, x: np.ndarray) -> np.ndarray:
        """F(x): the last L rows of x's rows followed by U^1 .. U^M.  Only the last L rows are
        read back: M - (L - N - 1) steps in C (advance), the window, and a run of the last
        L - N - 1 steps (none when L = N + 1)."""
        tail = self.L - self.N - 1
        K = self.M - tail
        if K < 0:  # fewer steps than extra rows: older rows of x move up
            X = np.asarray(x, dtype=float).reshape(self.L, self.n)
            return np.concatenate([X, self.trajectory(X)[1:]])[-self.L:].ravel()
        s = self._start_at(x)
        s.advance(K)
        W = s.get_window()
        if tail:
            W = np.concatenate([W, s.run(tail)[1][1:]])
        return W.ravel()


def state_of(solver: Solver, M: int) -> np.ndarray:
    """The window (N + 1 rows, flattened) of a solver run onto an orbit of M steps, at the next
    step index that is a multiple of M (the orbit's phase 0): the solver is advanced there and
    then restored (``save_state`` / ``load_state``), so it is left as it was."""
    saved = solver.save_state()
    try:
        solver.advance((-solver.step_index) % M)
        return solver.get_window().ravel()
    finally:
        solver.load_state(saved)


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
                  Fq: np.ndarray, border: np.ndarray, g: float, *, rtol: float
                  ) -> tuple[np.ndarray, float]:
    """One Newton step for x = F_q(x) with one more unknown q (the period's step h of an
    autonomous orbit, the parameter p of a continuation) and one more equation g = 0 (a phase
    condition, the pseudo-arclength hyperplane): dz = (dx, dq) solves the bordered system

        (D_xF - I) dx + F_q dq = -(F(x) - x),     border . dz = -g,

    by GMRES on the matrix-free operator (D_xF v by :func:`directional`, step :func:`fd_eps`;
    ``Fq`` = dF/dq, a column computed by the caller).  Returns (dz, GMRES's relative residual
    |J dz - rhs| / |rhs|, one more product): above about 1e-2 the system is singular."""
    eps = fd_eps(x)

    def mv(v: np.ndarray) -> np.ndarray:
        vx = v[:-1]
        return np.concatenate([directional(F, x, Fx, vx, eps) - vx + Fq * v[-1],
                               [np.dot(border, v)]])

    size = x.size + 1
    J = sla.LinearOperator((size, size), matvec=mv, dtype=float)
    rhs = -np.concatenate([Fx - x, [g]])
    dz, _ = sla.gmres(J, rhs, rtol=rtol, atol=0.0, restart=min(size, 60), maxiter=4)
    if not np.all(np.isfinite(dz)):
        return dz, math.inf
    return dz, float(np.linalg.norm(mv(dz) - rhs)) / max(float(np.linalg.norm(rhs)), 1e-300)


def newton(F: Callable[[np.ndarray], np.ndarray], x0: np.ndarray, *, tol: float = 1e-10,
           max_iter: int = 30, what: str = "x = F(x)") -> tuple[np.ndarray, list[float]]:
    """Solves x = F(x) by Newton's method with GMRES on the matrix-free Jacobian I - DF
    (forward differences of F, step sqrt(eps_machine) max(1, |x|_inf): the derivative of the
    map's smooth piece, a semismooth Newton).  Converged when |F(x) - x|_inf <=
    tol * max(1, |x|_inf).  Returns (x, residual history).  Raises ShootingError when F fails,
    the Jacobian is singular, or the residual stalls or does not fall below tol within
    max_iter iterations."""
    x = np.array(x0, dtype=float)
    res: list[float] = []
    stall = 0

    def ev(z: np.ndarray) -> np.ndarray:
        try:
            return F(z)
        except Error as e:
            raise ShootingError(f"{what}: the map failed after {len(res)} Newton iterations "
                                f"(residuals {_fmt(res)}): {e}; the guess is too far from any "
                                "orbit, or the orbit leaves the model's domain", res) from e

    Fx = ev(x)
    for _ in range(max_iter + 1):
        r = Fx - x
        rn = float(np.max(np.abs(r)))
        res.append(rn)
        if not math.isfinite(rn):
            raise ShootingError(f"{what}: non-finite residual (residuals {_fmt(res)}): the guess "
                                "is too far from any orbit", res)
        scale = max(1.0, float(np.max(np.abs(x))))
        if rn <= tol * scale:
            return x, res
        if len(res) > max_iter:
            break
        if len(res) >= 4 and rn > 0.5 * res[-4]:
            stall += 1
            if stall >= 2:
                raise ShootingError(f"{what}: Newton stalls after {len(res) - 1} iterations "
                                    f"(residuals {_fmt(res)}; tolerance {tol * scale:.3g}): no "
                                    "orbit near the guess, or the orbit is not isolated", res)
        eps = fd_eps(x)

        def mv(v: np.ndarray, Fx: np.ndarray = Fx, x: np.ndarray = x) -> np.ndarray:
            return v - directional(ev, x, Fx, v, eps)

        J = sla.LinearOperator((x.size, x.size), matvec=mv, dtype=float)
        dx, _info = sla.gmres(J, r, rtol=1e-6, atol=0.0, restart=min(x.size, 60), maxiter=4)
        lin = float(np.linalg.norm(mv(dx) - r)) / max(float(np.linalg.norm(r)), 1e-300)
        if not np.all(np.isfinite(dx)) or lin > 1e-2 or float(np.max(np.abs(dx))) > 1e8 * scale:
            raise ShootingError(f"{what}: the Jacobian I - DF is singular or too ill-conditioned "
                                f"at Newton iteration {len(res)} (GMRES relative residual "
                                f"{lin:.2g}, residuals {_fmt(res)}): a Floquet multiplier at 1, "
                                "a non-isolated orbit, or no orbit", res)
        # the full step, halved (at most 5 times) only while it makes the residual 100 times
        # worse: a step into the next piece of a piecewise-smooth map may raise the residual for
        # one iteration before the next lands on the fixed point
        lam = 1.0
        for _ in range(6):
            xn = x + lam * dx
            Fn = ev(xn)
            if np.max(np.abs(Fn - xn)) < 100 * rn or lam < 0.05:
                break
            lam *= 0.5
        x, Fx = xn, Fn
    raise ShootingError(f"{what}: no convergence in {max_iter} Newton iterations (residuals "
                        f"{_fmt(res)}; tolerance {tol:.3g} relative): the guess is too far from "
                        "any orbit", res)


def _fmt(res: list[float]) -> str:
    return "[" + ", ".join(f"{r:.2g}" for r in res[-8:]) + "]"


@dataclass
class Orbit:
    """A periodic orbit of the scheme.

    ``p``: the parameter; ``period`` = ``steps`` h (time units); ``h``: the step; ``t`` (M + 1,)
    and ``u`` (M + 1, n): one period of U from t = 0; ``state``: the shooting state (L n values,
    rows oldest first, the last at t = 0); ``multipliers``: the leading Floquet multipliers,
    largest |mu| first; ``stable``: all |mu| < 1 (an autonomous orbit: all but
    its phase's multiplier 1); ``stick_fraction`` (n,): the fraction of the M
    steps where component i is stuck (:func:`stuck_mask`: U_i == 0 exactly after the friction
    resolvent, for 2 steps or more);
    ``iterations``: Newton iterations; ``residual``: the final |F(x) - x|_inf (state units)."""
    p: float
    period: float
    steps: int
    h: float
    t: np.ndarray
    u: np.ndarray
    state: np.ndarray
    multipliers: np.ndarray
    stable: bool
    stick_fraction: np.ndarray
    iterations: int
    residual: float
    make: Model = field(repr=False)
    rows: int = 0

    @property
    def amplitude(self) -> np.ndarray:
        """(max - min) / 2 of each component over the period (state units)."""
        return 0.5 * (self.u.max(axis=0) - self.u.min(axis=0))


def stuck_mask(u: np.ndarray) -> np.ndarray:
    """(M, n) booleans: step k (row k + 1 of u, M + 1 rows of one period) is stuck in component
    i: U_i == 0 exactly (the friction resolvent's value in its dead zone |X_i| <= h alpha_i)
    within a run of at least 2 such steps, on the period's circle.  A lone zero step is the
    scheme's transversal crossing of a velocity reversal (|net force| > alpha: the next step
    leaves zero), not a stick."""
    z = np.asarray(u)[1:] == 0.0
    return z & (np.roll(z, 1, axis=0) | np.roll(z, -1, axis=0))


def stick_fraction(u: np.ndarray) -> np.ndarray:
    """Fraction of the steps of one period (u: M + 1 rows) that are stuck (:func:`stuck_mask`)."""
    return np.mean(stuck_mask(u), axis=0)


def periodic_orbit(make: Model, p: float, period: float | None = None, guess: Any = None, *,
                   guess_period: float | None = None, steps: int | None = None,
                   tol: float = 1e-10, max_iter: int = 30, multipliers: int = 10,
                   rows: int | None = None) -> Orbit:
    """The periodic orbit of the model ``make`` at ``p`` near ``guess``, by shooting.

    ``period`` (time units) must be a whole number M of steps h of ``make(p)`` (forced systems
    with period P: take h = P / M).  ``guess``: a state (L n values, or an (L, n) array: the
    last L stored states, the last at t = 0) or a ``dmi.Solver`` of the same model run onto the
    orbit (it is not changed: a copy of its state is advanced to the next step index that is a
    multiple of M, the orbit's phase 0).  ``rows``: L (default N + 1).  Newton with GMRES on
    the matrix-free Jacobian converges to ``tol`` in the max norm (relative to max(1, |x|));
    ``multipliers``: how many leading Floquet multipliers to compute (0: none, ``stable`` is
    then False).  ``period=None`` with ``guess_period``: an autonomous orbit of unknown period
    M h, ``steps`` = M fixed (default guess_period / make(p).h) and h unknown, with a phase
    condition; the model must take the step, ``make(p, h=...)`` (libdmi 1.2's
    ``dmi.Solver(n, tau, h=...)``), see :mod:`dmi.analysis.autonomous`.

    Raises ValueError for bad input (period <= 0 or not a multiple of h, make failing, a guess of
    the wrong shape) and :class:`ShootingError` when Newton fails (with the residuals tried)."""
    if guess is None:
        raise ValueError("guess: give a state or a dmi.Solver run onto the orbit")
    if period is None:
        if guess_period is None:
            raise ValueError("period=None (an autonomous orbit) needs guess_period")
        from .autonomous import autonomous_orbit
        return autonomous_orbit(make, p, guess, guess_period, steps=steps, tol=tol,
                                max_iter=max_iter, multipliers=multipliers)
    probe = build(make, p)
    M = steps_per_period(probe.h, period)
    F = StepMap(make, p, M, rows, solver=probe)
    if isinstance(guess, Solver):
        if (guess.n, guess.N) != (F.n, F.N) or guess.h != F.h:
            raise ValueError(f"guess: a solver with n = {guess.n}, N = {guess.N}, h = {guess.h!r}; "
                             f"make(p) has n = {F.n}, N = {F.N}, h = {F.h!r}")
        x0 = state_of(guess, M)
    else:
        x0 = np.asarray(guess, dtype=float).ravel()
        if x0.size == F.n and F.L > 1:
            x0 = np.tile(x0, F.L)  # a single state: a constant window
        if x0.size % F.n or not F.N + 1 <= x0.size // F.n <= F.L:
            raise ValueError(f"guess has {x0.size} values; the state has L n = {F.L} x {F.n} = "
                             f"{F.dim} (or give k rows, N + 1 = {F.N + 1} <= k <= L, or n = "
                             f"{F.n} values for a constant window)")
    x0 = F.extend(x0)
    x, res = newton(F, x0, tol=tol, max_iter=max_iter,
                    what=f"periodic orbit at p = {p!r}, period {period!r} = {M} steps")
    return make_orbit(F, x, res, multipliers)


def make_orbit(F: StepMap, x: np.ndarray, res: list[float], multipliers: int) -> Orbit:
    """The Orbit at the fixed point x of F (one more run for t, u; the multipliers)."""
    from .floquet import floquet_multipliers

    U = F.trajectory(x)
    mu = floquet_multipliers(F, x, multipliers) if multipliers > 0 else np.empty(0, complex)
    return Orbit(p=F.p, period=F.M * F.h, steps=F.M, h=F.h, t=np.arange(F.M + 1) * F.h, u=U,
                 state=x, multipliers=mu, stable=bool(mu.size and np.all(np.abs(mu) < 1)),
                 stick_fraction=stick_fraction(U), iterations=len(res) - 1, residual=res[-1],
                 make=F.make, rows=F.L)
