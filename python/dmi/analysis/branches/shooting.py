# The scheme's shooting as a discretisation for the one continuation driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Periodic orbits of the scheme as zeros of the shooting residual, for
:func:`dmi.analysis.continuation.driver.continuation`.

The unknowns are x = the shooting state (forced orbits, the period M h kept or given by
``period(p)``) or x = (state, h) (autonomous orbits: the period M h free, a phase condition
through the previous point).  :class:`Shooting` implements the driver's contract: the residual
F_p(x) - x (and the phase condition), its Jacobian as a LinearOperator (forward differences of
the map) with dF/dp by one difference, the points (:func:`orbit_point`: multipliers, stick
profile, margins), the orbits' events between two points
(:func:`dmi.analysis.branches.events.orbit_events`, the ``between`` hook; the stick events
located by the driver's :func:`~dmi.analysis.continuation.driver.bisect_along`), and the
linear-solve strategies of the driver's corrector (the ``strategies`` hook): Newton-Picard on the
previous point's dominant subspace (Lust, Roose, Spence and Champneys, SIAM J. Sci. Comput. 19
(1998) 1188), a linear solve and convergence test of the one Newton loop
(:func:`dmi.analysis.core.newton.newton_loop`), then Newton with GMRES on the bordered
matrix-free Jacobian when that contracts too slowly; the ``accept`` hook refuses a point of a
branch of several forcing periods that is periodic over a part of them.  The maps come from one
cache, the model's :class:`dmi.analysis.scheme.problem.Problem`.
"""
from __future__ import annotations

import math
from collections.abc import Callable, Iterator

import numpy as np
import scipy.sparse.linalg as sla

from ..._solver import Solver
from ..continuation.branch import BranchPoint, Event, corner_sentence, thinned, travel
from ..continuation.driver import VERTICAL, bisect_along, corrected
from ..scheme.floquet import Verify, fd_step, floquet_verdict, ritz
from ..core.newton import (NewtonOptions, ShootingError, Strategy, bordered_step, directional,
                           fd_eps, map_strategy)
from .events import orbit_events, stick_profile
from ..scheme.problem import AutonomousMaps, Problem, phase_row, velocity
from ..scheme.stepmap import Model, StepMap, fixed_step, positive_time

def orbit_point(F: StepMap, x: np.ndarray, multipliers: int, sections: int, dpds: float,
           iterations: int, margins: bool = True, warm: list | None = None,
           corrector: str = "", terms: tuple[np.ndarray, np.ndarray] | None = None,
           autonomous: bool = False, verify: Verify | None = None) -> BranchPoint:
    """The BranchPoint at the fixed point x of F; ``warm``: a one-element list holding the
    previous point's (Q, Z) of :func:`ritz` (replaced by this point's): the Ritz step starts
    from Z, one block of products instead of two from random vectors.  ``terms``: x's
    :meth:`StepMap.trajectory_terms` when the caller has them (:meth:`Shooting.accept`).  An
    ``autonomous`` orbit's ``stable`` leaves out its phase multiplier.  ``verify``: the
    multipliers and ``stable`` are :func:`floquet_verdict`'s (verified; the Ritz pairs still
    give the Newton-Picard basis), kept in ``BranchPoint.floquet``; None: the Ritz multipliers
    and ``stable`` None."""
    U, X = F.trajectory_terms(x) if terms is None else terms
    mu = np.empty(0, complex)
    if multipliers > 0:
        prev = warm[0] if warm else None
        eps = fd_step(F, x, U, X)
        if prev is not None and prev[1].shape[0] == x.size:
            mu, Q, Z = ritz(F, x, multipliers, start=prev[1], eps=eps)
        else:
            mu, Q, Z = ritz(F, x, multipliers, eps=eps)
        if warm is not None:
            warm[0] = (Q, Z)
    stable = None   # Ritz values have no error bound: no verdict from them
    fl = None
    if verify is not None and multipliers > 0:
        fl = floquet_verdict(F, x, multipliers, autonomous=autonomous, verify=verify)
        mu, stable = fl.multipliers[:multipliers], fl.stable
    steps, phases, margin = stick_profile(F, U, X if margins else None)
    k = F.M // sections
    t, u = thinned(U, F.h)
    return BranchPoint(p=F.p, period=F.M * F.h, amplitude=0.5 * (U.max(axis=0) - U.min(axis=0)),
                       multipliers=mu, stable=stable, floquet=fl,
                       stick_steps=steps, stick_phases=phases, margin=margin,
                       section=U[[j * k for j in range(sections)]], state=np.array(x),
                       dpds=dpds, iterations=iterations, corrector=corrector,
                       t=t, u=u)


class ForcedMaps:
    """The maps of a forced branch: StepMaps by p (the last few), all on states of ``rows``
    rows; a p whose N + 1 exceeds it is refused (ShootingError: the corrector retries with a
    shorter step).  ``period``: None (make(p) must keep the step h) or p -> the period, the map
    at p then built by make(p, h=period(p) / M).  The unknowns are z = (x, p): k = 1 extra
    unknown, no equation besides the arclength."""
    k = 1
    autonomous = False

    def __init__(self, make: Model, M: int, h: float, rows: int,
                 period: Callable[[float], float] | None = None):
        self.make, self.M, self.h, self.rows, self.period = make, M, h, rows, period
        self.problem = Problem(make)

    def step(self, p: float) -> float:
        """The step h at p: period(p) / M, or the branch's h."""
        if self.period is None:
            return self.h
        try:
            P = self.period(p)
        except Exception as e:  # the period function refuses p: out of range
            raise ValueError(f"period(p = {p!r}) failed: {type(e).__name__}: {e}") from e
        return positive_time(f"period(p = {p!r})", P) / self.M

    def memory(self, p: float) -> int:
        """N at p at its step (the probe's: the map at p takes it over)."""
        return int(self.build(p, take=False).N)

    def model(self, p: float) -> Model:
        """make as a function of p alone at p's step (the StepMap's and an Orbit's ``make``)."""
        if self.period is None:
            return self.make
        return fixed_step(self.make, self.step(p))

    def build(self, p: float, take: bool = True) -> Solver:
        """A solver of the model at p at its step, not initialised: the problem's probe, taken
        out of its cache (``take``: it becomes the map's) or left there (read for N)."""
        h = None if self.period is None else self.step(p)
        try:
            return self.problem.probe(p, h, take=take)
        except TypeError as e:
            if h is None:
                raise
            raise ValueError(f"continue_orbit(period=...) needs a model make(p, h=...) that "
                             f"takes the step (h = period(p) / M = {h!r}): {e}") from e

    def __call__(self, p: float) -> StepMap:
        return self.problem.cached(("map", float(p), self.M, self.rows),
                                   lambda: self._new(float(p)))

    def _new(self, p: float) -> StepMap:
        s = self.build(p)
        h = self.step(p)
        if abs(s.h - h) > 1e-12 * h:
            what = ("the branch keeps the period M h (make(p) must keep h)"
                    if self.period is None else "expected period(p) / M")
            raise ValueError(f"make(p = {p!r}) has h = {s.h!r}; {what}: h = {h!r}")
        if s.N + 1 > self.rows:
            raise ShootingError(f"make(p = {p!r}) has N = {s.N}: the branch's states hold "
                                f"{self.rows} rows (N + 1 at the ends of its range, + 2 %)", [])
        return StepMap(self.model(p), p, self.M, self.rows, solver=s)

    def of(self, q: np.ndarray) -> StepMap:
        """The map at the extra unknowns q = (p,)."""
        return self(float(q[-1]))

    def z_of(self, pt: BranchPoint) -> np.ndarray:
        return np.concatenate([pt.state, [pt.p]])

    def col_steps(self, q: np.ndarray) -> np.ndarray:
        return np.array([1e-7 * max(1.0, abs(float(q[-1])))])

    def conditions(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The equations besides the arclength: none."""
        return np.empty(0), np.empty((0, z.size))

    def weights(self, size: int) -> np.ndarray:
        """The arclength's inner product weights: 1 / dim on x (an RMS), 1 on p."""
        w = np.full(size, 1.0 / (size - 1))
        w[-1] = 1.0
        return w

    def reference(self, z: np.ndarray, U: np.ndarray) -> None:
        """A new point on the branch (nothing to update)."""


class AutoMaps(ForcedMaps):
    """The maps of an autonomous branch: the unknowns are z = (x, h, p) (k = 2), the maps
    StepMaps of make(p, h=h) (:class:`dmi.analysis.shooting.autonomous.AutonomousMaps`), and the phase
    condition <xdot, x_0 - x0_ref> = 0 holds besides the arclength, its reference the last
    point's state at t = 0 and velocity there (:meth:`reference`)."""
    k = 2
    autonomous = True

    def __init__(self, make: Model, M: int, h: float, rows: int):
        super().__init__(make, M, h, rows)
        self.auto = AutonomousMaps(make, M, rows, 0.6 * h, self.problem)
        self.xdot = np.zeros(0)
        self.ref = np.zeros(0)

    def __call__(self, p: float) -> StepMap:
        return self.auto(self.h, p)

    def of(self, q: np.ndarray) -> StepMap:
        return self.auto(float(q[0]), float(q[1]))

    def z_of(self, pt: BranchPoint) -> np.ndarray:
        return np.concatenate([pt.state, [pt.period / self.M, pt.p]])

    def col_steps(self, q: np.ndarray) -> np.ndarray:
        return np.array([1e-7 * float(q[0]), 1e-7 * max(1.0, abs(float(q[1])))])

    def conditions(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g, row = phase_row(z[:-2], self.xdot, self.ref, 2)
        return np.array([g]), row[None, :]

    def weights(self, size: int) -> np.ndarray:
        """1 / dim on x, 1 on p, M^2 on h (the period's change counts as p's)."""
        w = np.full(size, 1.0 / (size - 2))
        w[-2], w[-1] = float(self.M) ** 2, 1.0
        return w

    def reference(self, z: np.ndarray, U: np.ndarray) -> None:
        v = velocity(U, float(z[-2]))
        self.xdot = v / max(float(np.linalg.norm(v)), 1e-300)
        self.ref = z[-2 - v.size:-2].copy()


class _Slow(Exception):
    """The Newton-Picard corrector contracts too slowly; ``z``: its iterate of least residual
    (None if it could not start), ``iterations``: the steps it took."""

    def __init__(self, message: str, z: np.ndarray | None = None, iterations: int = 0):
        super().__init__(message)
        self.z, self.iterations = z, iterations


def _too_slow(rn: float, prev: float, target: float, left: int) -> bool:
    """A linear iteration whose residual went from prev to rn contracts too slowly: by less than
    half, or at a rate that would not bring rn below target in ``left`` more iterations."""
    rate = rn / prev
    if rate > 0.5:
        return True
    return 0 < rate and target < rn and math.log(target / rn) / math.log(rate) > left


def _columns(maps: ForcedMaps, z: np.ndarray, Fx: np.ndarray) -> np.ndarray:
    """dF/dq at z (dim, k) by one forward difference a column."""
    k = maps.k
    x, q = z[:-k], z[-k:]
    d = maps.col_steps(q)
    cols = np.empty((x.size, k))
    for j in range(k):
        qd = q.copy()
        qd[j] += d[j]
        cols[:, j] = (maps.of(qd)(x) - Fx) / d[j]
    return cols


def _borders(maps: ForcedMaps, z: np.ndarray, zp: np.ndarray, t: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """The k equations besides F(x) = x at z: the family's (a phase condition) and the
    arclength <w t, z - zp> = 0; their values and rows (k, dim + k)."""
    g, rows = maps.conditions(z)
    wt = maps.weights(z.size) * t
    return np.concatenate([g, [float(np.dot(wt, z - zp))]]), np.vstack([rows, wt])


def _newton_picard(maps: ForcedMaps, zp: np.ndarray, t: np.ndarray, tol: float, ds: float,
                   Q: np.ndarray, Z: np.ndarray, z0: np.ndarray | None = None,
                   max_iter: int = 16) -> tuple[Strategy, _Picard]:
    """The corrector by Newton-Picard (Lust, Roose, Spence & Champneys 1998) from z0 (default the
    predictor zp) on the hyperplane through zp, as a linear-solve strategy of the driver's
    corrector (its iterations count half): the Jacobian D_xF is replaced by its rank-b
    approximation Z Q' on the previous point's dominant subspace (Q orthonormal, Z = D_xF Q
    there, from :func:`ritz`), D_qF (the k extra unknowns' columns) by one difference each at
    z0, and the bordered system

        (Z Q' - I) dx + F_q dq = -(F(x) - x),     B_x dx + B_q dq = -g,

    (B, g: the k equations of :func:`_borders`) is solved exactly: dx = Q xi + (I - Q Q')(r +
    F_q dq + Z xi), with (xi, dq) from b + k equations.  On the complement of span Q that is a
    Picard step (x takes F(x)'s component), which contracts at the rate of the largest
    multiplier left out; on span Q a chord Newton step.  One evaluation of F an iteration (k
    more for F_q); S = Q' Z gets Broyden's update from each step (ZC = Z - Q S, the leak off
    span Q, is kept).  Returns (the strategy, its :class:`_Picard`); the strategy's run raises
    _Slow (the next strategy is tried; the _Picard's ``restart``: its iterate of least
    residual, or None) when, after the second iteration, the residual falls by less than half
    in one, or at its rate would not reach tol within max_iter; ShootingError (the point
    refused) as :func:`_newton`."""
    w = maps.weights(zp.size)
    np_ = _Picard(maps, zp, t, tol, Q, Z, max_iter)

    def strayed(z: np.ndarray) -> None:
        d = z - zp
        far = math.sqrt(float(np.dot(w * d, d)))
        if far > ds:
            raise ShootingError(f"corrector strayed {far:.3g} > ds = {ds:.3g} from the predictor "
                                f"at p = {float(z[-1])!r}", [np_.prev])

    return Strategy(np_.evaluate, np_.factor,
                    NewtonOptions(tol=tol, max_iter=max_iter, converge=np_.converged,
                                  chord=math.inf, stall=False),
                    f"Newton-Picard near p = {float(zp[-1])!r}", name="newton-picard",
                    weight=0.5, start=zp if z0 is None else z0, check=strayed,
                    retry=(_Slow,)), np_


class _Picard:
    """Newton-Picard as the linear solve of :func:`dmi.analysis.core.newton.newton_loop` (see
    :func:`_newton_picard`): the residual (F(x) - x, the borders), the reduced system factored
    once (a chord: ``chord=inf``) and updated by Broyden from each step, and the convergence
    test (the state's residual to tol, the borders to 1e-8) that raises _Slow on a slow
    contraction."""

    def __init__(self, maps: ForcedMaps, zp: np.ndarray, t: np.ndarray, tol: float,
                 Q: np.ndarray, Z: np.ndarray, max_iter: int):
        self.maps, self.zp, self.t, self.tol, self.Q, self.Z = maps, zp, t, tol, Q, Z
        self.max_iter = max_iter
        self.k = maps.k
        self.dim = zp.size - self.k
        self.started = False
        self.Fx = np.empty(0)        # F(x) at the last iterate evaluated
        self.pending: tuple | None = None   # (xi, dq, F(x) before the step) of the last step
        self.prev, self.best, self.z_best, self.it = math.inf, math.inf, zp, 0
        self.restart: np.ndarray | None = None   # where the next try starts after _Slow

    def _slow(self, message: str, z: np.ndarray | None) -> _Slow:
        self.restart = z
        return _Slow(message, z, self.it)

    def evaluate(self, z: np.ndarray) -> tuple[np.ndarray, None]:
        """(F(x) - x, the borders' values) at z."""
        k, dim = self.k, self.dim
        F = self.maps.of(z[-k:])
        if not self.started:
            if F.dim != dim or self.Q.shape[0] != dim:
                raise self._slow("the state's size changed", None)
            self.started = True
        elif F.dim != dim:
            raise ShootingError(f"the state grew to {F.dim} values at p = {float(z[-1])!r}", [])
        x = z[:-k]
        self.Fx = F(x)
        g, _ = _borders(self.maps, z, self.zp, self.t)
        return np.concatenate([self.Fx - x, g]), None

    def converged(self, z: np.ndarray, r: np.ndarray, res: list[float]) -> bool:
        """The state's residual <= tol max(1, |x|_inf) and the borders' <= 1e-8 max(1, |p|);
        _Slow when, after the second iteration, the residual falls by less than half in one,
        or at its rate would not reach tol within max_iter."""
        it = self.it = len(res) - 1
        x = z[:-self.k]
        rn = float(np.max(np.abs(r[:self.dim])))
        scale = max(1.0, float(np.max(np.abs(x))))
        if rn <= self.tol * scale and float(np.max(np.abs(r[self.dim:]))) <= 1e-8 * max(
                1.0, abs(z[-1])):
            return True
        if rn < self.best:
            self.best, self.z_best = rn, z
        if it == self.max_iter or (it >= 2 and _too_slow(rn, self.prev, self.tol * scale,
                                                         self.max_iter - it)):
            raise self._slow(f"residual {rn:.3g} after {it} iterations (previous "
                             f"{self.prev:.3g})", self.z_best)
        self.prev = rn
        return False

    def factor(self, z: np.ndarray, r: np.ndarray, state: None) -> Callable:
        """The reduced system at the first iterate: S = Q' Z, the leak ZC = Z - Q S, F_q by
        one difference a column, the borders' rows."""
        maps, Q, Z, dim = self.maps, self.Q, self.Z, self.dim
        self.Fq = _columns(maps, z, self.Fx)
        self.S = Q.T @ Z
        self.ZC = Z - Q @ self.S                   # (I - Q Q') Z
        self.FqC = self.Fq - Q @ (Q.T @ self.Fq)
        b = Q.shape[1]
        _, B = _borders(maps, z, self.zp, self.t)   # linear equations: constant rows
        self.Bx, Bq = B[:, :dim], B[:, dim:]
        K = self.K = np.zeros((b + self.k, b + self.k))
        K[:b, :b] = self.S - np.eye(b)
        K[:b, b:] = Q.T @ self.Fq
        K[b:, :b] = self.Bx @ Q + self.Bx @ self.ZC
        K[b:, b:] = self.Bx @ self.FqC + Bq
        return self.solve

    def solve(self, r: np.ndarray) -> np.ndarray:
        """The Newton-Picard correction for the residual r, after Broyden's update of the
        reduced Jacobian S = Q' D_xF Q by the step before (Q' dx = xi): S xi := Q' (F(x_new) -
        F(x_old) - F_q dq); no evaluation, and a multiplier that moved since the previous point
        (near 1, the chord's rate |dmu| / |1 - mu|) is caught."""
        Q, b = self.Q, self.Q.shape[1]
        if self.pending is not None:
            xi, dq, Fold = self.pending
            nxi = float(np.dot(xi, xi))
            if nxi > 0:
                self.S = self.S + np.outer(Q.T @ (self.Fx - Fold - self.Fq @ dq) - self.S @ xi,
                                           xi / nxi)
                self.K[:b, :b] = self.S - np.eye(b)
        rx, g = r[:self.dim], r[self.dim:]
        Qr = Q.T @ rx
        rC = rx - Q @ Qr
        try:
            sol = np.linalg.solve(self.K, np.concatenate([-Qr, -g - self.Bx @ rC]))
        except np.linalg.LinAlgError:
            raise self._slow("singular reduced system", None) from None
        xi, dq = sol[:b], sol[b:]
        self.pending = (xi, dq, self.Fx)
        return np.concatenate([Q @ xi + rC + self.FqC @ dq + self.ZC @ xi, dq])


def _periodic_part(maps: ForcedMaps, z: np.ndarray, sections: int
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The trajectory terms of the point z (:meth:`StepMap.trajectory_terms`, for
    :func:`orbit_point`); refused (ShootingError: the step is halved) when the orbit of a branch
    of ``sections`` > 1 forcing periods is periodic over a part of them: the corrector fell onto
    the branch it was born from (a doubled branch near its doubling, where both cross the first
    step's hyperplane p = p1 close together)."""
    k = maps.k
    F = maps.of(z[-k:])
    U, X = F.trajectory_terms(z[:-k])
    for q in range(2, sections + 1):
        m = F.M // q
        if sections % q == 0 and F.M % q == 0 and \
                np.max(np.abs(U[m:] - U[:-m])) <= 1e-6 * max(1.0, float(np.max(np.abs(U)))):
            raise ShootingError(f"the corrector fell onto an orbit of {m} steps (period "
                                f"{sections // q} of the branch's {sections} forcing periods) "
                                f"at p = {float(z[-1])!r}", [])
    return U, X


def _strategies(maps: ForcedMaps, zp: np.ndarray, t: np.ndarray, tol: float, max_iter: int,
                ds: float, dominant: tuple[np.ndarray, np.ndarray] | None
                ) -> Iterator[Strategy]:
    """The corrector's strategies from the predictor zp, built as the driver asks for the next:
    Newton-Picard on the previous point's ``dominant`` (Q, Z) when there is one; when it
    contracts too slowly, once more from its iterate of least residual with (Q, Z) renewed
    there: one block of forward differences of Newton's step
    (:func:`dmi.analysis.core.newton.fd_eps`) from qr(Z), the dominant subspace of the derivative
    the iteration actually sees (:func:`ritz`); then Newton (GMRES) from zp (not from an
    iterate: near a period doubling, Newton-Picard may have headed for the other branch that
    crosses the first step's hyperplane p = p1)."""
    k = maps.k
    if dominant is not None:
        z = zp
        Q, Z = dominant
        for renew in (False, True):
            if renew:
                F, x = maps.of(z[-k:]), z[:-k]
                if F.dim != x.size:
                    break
                _, Q, Z = ritz(F, x, max(1, Q.shape[1] - 2), start=Z, eps=fd_eps(x),
                               central=False)
            strategy, picard = _newton_picard(maps, zp, t, tol, ds, Q, Z, z)
            yield strategy
            if picard.restart is None:
                break
            z = picard.restart
    yield _newton(maps, zp, t, tol, max_iter, ds)


def _newton(maps: ForcedMaps, zp: np.ndarray, t: np.ndarray, tol: float, max_iter: int,
            ds: float) -> Strategy:
    """Newton (:func:`dmi.analysis.core.newton.map_strategy`) on (F_q(x) - x, the family's
    equations, <w t, z - zp>) from the predictor zp.  ShootingError when an iterate strays more
    than ds from the predictor (weighted norm): the step is then too long for the predictor, and
    another branch may lie on the hyperplane."""
    w = maps.weights(zp.size)
    dim = zp.size - maps.k

    def far(z: np.ndarray) -> None:
        d = z - zp
        if math.sqrt(float(np.dot(w * d, d))) > ds:
            raise ShootingError(f"corrector strayed {math.sqrt(float(np.dot(w * d, d))):.3g} > "
                                f"ds = {ds:.3g} from the predictor at p = {float(z[-1])!r}", [])

    def of(q: np.ndarray) -> StepMap:
        F = maps.of(q)
        if F.dim != dim:
            raise ShootingError(f"the state grew to {F.dim} values at p = {float(q[-1])!r}", [])
        return F

    return map_strategy(of, zp.size, maps.k, lambda z: _borders(maps, z, zp, t), tol=tol,
                        max_iter=max_iter, what=f"corrector near p = {float(zp[-1])!r}",
                        steps=maps.col_steps(zp[-maps.k:]), check=far)


def _first_tangent(maps: ForcedMaps, z: np.ndarray, direction: float) -> np.ndarray:
    """The branch's unit tangent (weighted norm) at its first point z: the null vector of the
    bordered Jacobian [[D_xF - I, F_q], [the family's rows]], from one bordered solve with the
    extra row r . dz = 1, r = e_p + the state's deviation from its mean (not orthogonal to a
    tangent that moves p, nor to one that only scales the orbit, as on a branch leaving a Hopf
    point vertically).  Oriented towards p_end, or, where dp/ds is below VERTICAL, to a growing
    deviation."""
    k = maps.k
    x = z[:-k]
    F = maps.of(z[-k:])
    Fx = F(x)
    g, rows = maps.conditions(z)
    dev = x - np.mean(x)
    r = np.zeros(z.size)
    r[:-k] = dev / max(float(np.linalg.norm(dev)), 1e-300)
    r[-1] = 1.0
    t, lin = bordered_step(F, x, Fx, _columns(maps, z, Fx), np.vstack([rows, r]),
                           np.concatenate([np.zeros(len(g)), [-1.0]]), rtol=1e-8)
    if lin > 1e-2:
        raise ShootingError(f"no tangent at the branch's start (GMRES relative residual "
                            f"{lin:.2g}): a singular point", [])
    w = maps.weights(z.size)
    t = t / math.sqrt(float(np.dot(w * t, t)))
    if abs(t[-1]) > VERTICAL:
        return t if t[-1] * direction > 0 else -t
    return t if float(np.dot(t[:-k], dev)) > 0 else -t


class Shooting:
    """The scheme's shooting for the driver (see the module).

    Parameters
    ----------
    maps : ForcedMaps or AutoMaps
        The branch's maps.
    multipliers : int
        Floquet multipliers a point (also the Newton-Picard basis).
    sections : int
        Forcing periods the orbit spans.
    margins : bool
        Compute the points' margins.
    tol : float
        The corrector's tolerance.
    max_iter : int
        Newton iterations a step.
    iterations : int
        The start's iterations (its point's).
    verify : dmi.analysis.Verify, optional
        Verify each point's multipliers and verdict (:func:`orbit_point`).
    """

    def __init__(self, maps: ForcedMaps, multipliers: int, sections: int, margins: bool,
                 tol: float, max_iter: int, iterations: int = 0, verify: Verify | None = None):
        self.verify = verify
        self.maps, self.multipliers, self.sections = maps, multipliers, sections
        self.margins, self.tol, self.max_iter = margins, tol, max_iter
        self.k = maps.k
        self.warm: list = [None]
        # kind -> the last point whose multipliers decided it (:func:`orbit_events`)
        self.decided: dict[str, BranchPoint] = {}
        # the last corrected z, its iterations, which corrector, and its trajectory terms
        self.last: tuple = (None, iterations, "", None)
        self.tried: list[Strategy] = []   # the strategies of the last corrector

    @property
    def weight(self) -> np.ndarray:
        """The arclength's weights on x: 1 / dim on the state, M^2 on h (autonomous)."""
        return self.maps.weights(self.size + 1)[:-1]

    size = 0   # len(x), set by continue_orbit

    def _map(self, x: np.ndarray, p: float) -> tuple[StepMap, np.ndarray, np.ndarray]:
        q = np.concatenate([x[self.size - self.k + 1:], [p]])
        z = np.concatenate([x, [p]])
        return self.maps.of(q), x[:self.size - self.k + 1], z

    def residual(self, x: np.ndarray, p: float) -> np.ndarray:
        """F_p(x) - x, and the phase condition of an autonomous orbit."""
        F, s, z = self._map(x, p)
        g, _ = self.maps.conditions(z)
        return np.concatenate([F(s) - s, g])

    def jacobian(self, x: np.ndarray, p: float) -> tuple[sla.LinearOperator, np.ndarray]:
        """The residual's Jacobian as a LinearOperator (forward differences of the map along
        each vector, step :func:`dmi.analysis.core.newton.fd_eps`), and dF/dp by one difference."""
        F, s, z = self._map(x, p)
        Fx = F(s)
        cols = _columns(self.maps, z, Fx)
        _, rows = self.maps.conditions(z)
        eps = fd_eps(s)
        n, k = s.size, self.k

        def mv(v: np.ndarray) -> np.ndarray:
            vx = v[:n]
            top = directional(F, s, Fx, vx, eps) - vx + cols[:, :k - 1] @ v[n:]
            return np.concatenate([top, rows[:, :-1] @ v])
        J = sla.LinearOperator((x.size, x.size), matvec=mv, dtype=float)
        return J, np.concatenate([cols[:, -1], rows[:, -1]])

    def strategies(self, x: np.ndarray, p: float, row: np.ndarray, target: float, far: float
                   ) -> Iterator[Strategy]:
        """The driver's corrector's strategies on the hyperplane row . z = target through the
        predictor (x, p) (:func:`_strategies`: Newton-Picard, its iterations counted half, then
        Newton-GMRES), kept for :meth:`accept`."""
        zp = np.concatenate([x, [p]])
        w = self.maps.weights(zp.size)
        self.tried = []
        for s in _strategies(self.maps, zp, row / w, self.tol, self.max_iter, far,
                             self.warm[0]):
            self.tried.append(s)
            yield s

    def accept(self, x: np.ndarray, p: float, step: bool) -> tuple[np.ndarray, float]:
        """The corrected point (x, p) kept with its iterations (of every strategy tried), the
        strategy that converged and its trajectory terms (:func:`_periodic_part`, which refuses
        an orbit periodic over a part of the branch's forcing periods)."""
        z = np.concatenate([x, [p]])
        terms = _periodic_part(self.maps, z, self.sections)
        its = sum(max(0, len(s.history) - 1) for s in self.tried)
        self.last = (z.copy(), its, self.tried[-1].name, terms)
        return x, p

    def point(self, x: np.ndarray, p: float) -> BranchPoint:
        """The branch's point (multipliers, stick profile), and a new phase reference."""
        z = np.concatenate([x, [p]])
        zl, its, how, terms = self.last
        if zl is None or zl.size != z.size or np.any(zl != z):
            its, how, terms = 0, how, None
        F = self.maps.of(z[-self.k:])
        s = z[:-self.k]
        if terms is None:
            terms = F.trajectory_terms(s)
        pt = orbit_point(F, s, self.multipliers, self.sections, 0.0, its, self.margins,
                         self.warm, how, terms, self.maps.autonomous, self.verify)
        self.maps.reference(z, terms[0])
        return pt

    def start_tangent(self, x: np.ndarray, p: float, direction: float) -> np.ndarray | None:
        """The first tangent of an autonomous branch (:func:`_first_tangent`); None (a natural
        step in p) for a forced one."""
        if not self.maps.autonomous:
            return None
        return _first_tangent(self.maps, np.concatenate([x, [p]]), direction)

    def between(self, za: np.ndarray, a: BranchPoint, zb: np.ndarray, b: BranchPoint,
                middle: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> list[Event]:
        """The orbits' events between a and b, stick events located along the branch (each
        middle with the phase condition through the bracket's first point; ``middle``, the
        driver's, is not used: see ``mid``)."""
        out = []
        w = self.maps.weights(za.size)

        def mid(z0: np.ndarray, z1: np.ndarray) -> np.ndarray:
            # Newton (GMRES) from the chord's middle, as the driver's middle but without the
            # Newton-Picard basis of the last point: near the corner the hyperplane may cross
            # the branch twice, and Newton from the middle takes the nearer crossing
            if self.k == 2:   # the phase condition through the bracket's first point
                self.maps.reference(z0, self.maps.of(z0[-self.k:]).trajectory(z0[:-self.k]))
            d = z1 - z0
            t = d / math.sqrt(float(np.dot(w * d, d)))
            zm = 0.5 * (z0 + z1)
            return corrected([_newton(self.maps, zm, t, self.tol, self.max_iter, math.inf)],
                             zm)[0]

        for e in orbit_events(a, b, 0, self.maps.autonomous, self.decided):
            if e.kind in ("stick-onset", "grazing"):
                i = e.component
                key = (lambda st, ph: (st > 0, ph)) if e.kind == "stick-onset" else (
                    lambda st, ph: (True, ph))
                ka = key(a.stick_steps[i], a.stick_phases[i])

                def same(z: np.ndarray, i: int = i, key: Callable = key, ka: tuple = ka
                         ) -> bool:
                    st, ph = self._profile(z)
                    return key(st[i], ph[i]) == ka
                got = bisect_along(za, zb, same, mid, lambda d: math.sqrt(float(np.dot(w * d, d))))
                if got is not None:   # the event at the final bracket's middle
                    pa, pb = float(got[0][-1]), float(got[1][-1])
                    e.p = 0.5 * (pa + pb)
                    e.detail += (f" (located by bisection along the branch in "
                                 f"[{min(pa, pb)!r}, {max(pa, pb)!r}])")
                self.maps.reference(zb, self.maps.of(zb[-self.k:]).trajectory(zb[:-self.k]))
            out.append(e)
        return out

    def corner(self, points: list[BranchPoint]) -> str:
        """Where a branch that failed at the smallest step ended (:func:`corner_of`), the
        friction components read from the branch's map at the last point's p.

        Parameters
        ----------
        points : list of BranchPoint
            The branch's points so far.

        Returns
        -------
        str
            The sentence for the status, or "".
        """
        try:   # the branch's own (cached) map at the last point
            alpha = self.maps(points[-1].p).solver.friction
        except Exception:   # the model's failure there: no component is known to have friction
            alpha = None
        return corner_of(points, alpha)

    def _profile(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        zl, _, _, terms = self.last
        F = self.maps.of(z[-self.k:])
        U = terms[0] if zl is not None and zl.size == z.size and np.all(zl == z) else \
            F.trajectory(z[:-self.k])
        st, ph, _ = stick_profile(F, U, None)
        return st, ph




# a slipping component's least |velocity| that names a grazing ahead, relative to its half range
GRAZING_NEAR = 0.05


def corner_of(points: list[BranchPoint], alpha: np.ndarray | None) -> str:
    """Where a branch that failed at the smallest step ended, read from its last four points,
    in the words of :func:`~dmi.analysis.continuation.branch.corner_sentence`: a component whose stick
    pattern changed among them (the p of the orbits on the other side of the corner, and so which
    way the other branch goes), or else a friction component that slips throughout on all of
    them, its least |velocity| falling to below ``GRAZING_NEAR`` of its half range (a grazing
    ahead, its p extrapolated from the last two points); "" when neither.

    Parameters
    ----------
    points : list of BranchPoint
        The branch's points so far.
    alpha : numpy.ndarray or None
        The model's friction levels (n,), or None (no grazing is read then).

    Returns
    -------
    str
        The sentence for the status, or "".
    """
    last = points[-1]
    recent = points[-4:]
    towards = travel([q.p for q in recent])
    for i in range(len(last.stick_steps)):
        kinds = {(int(q.stick_steps[i]) > 0, int(q.stick_phases[i])) for q in recent}
        if len(kinds) < 2:
            continue
        here = (int(last.stick_steps[i]) > 0, int(last.stick_phases[i]))
        other = [q.p for q in recent if (int(q.stick_steps[i]) > 0,
                                          int(q.stick_phases[i])) != here]
        side = "smaller" if float(np.mean(other)) < last.p else "larger"
        what = "stick" if not here[0] else (
            "slip throughout" if not any(q.stick_steps[i] for q in recent
                                         if q.p in other) else "stick otherwise")
        return corner_sentence(
            i, last.p, towards,
            f"its stick pattern changed over the last points (stuck steps "
            f"{[int(q.stick_steps[i]) for q in recent]}, stick phases "
            f"{[int(q.stick_phases[i]) for q in recent]})",
            f"orbits that {what} were found at p = {', '.join(f'{p:.8g}' for p in other)}, "
            f"{side} than the last point's p = {last.p:.8g}: the other branch goes towards "
            f"{side} p; start a branch from one of them (periodic_orbit at its p, or "
            "hopf_orbit) and continue it that way")
    if alpha is None or len(recent) < 3:
        return ""
    best = None
    for i in np.flatnonzero(np.asarray(alpha) > 0):
        if any(q.stick_steps[i] for q in recent):
            continue
        least = [float(np.min(np.abs(q.u[:, i]))) for q in recent[-3:]]
        half = float(last.amplitude[i])
        if not (least[0] > least[1] > least[2]) or least[2] > GRAZING_NEAR * half:
            continue
        if best is None or least[2] / half < best[1] / best[2]:
            best = (int(i), least[2], half, least[1])
    if best is None:
        return ""
    i, m1, half, m0 = best
    p0, p1 = recent[-2].p, last.p
    at = p1 + m1 * (p1 - p0) / (m0 - m1)
    return corner_sentence(
        i, last.p, towards,
        f"its orbits slip throughout, and their least |u_{i}| over the orbit fell to {m1:.3g} "
        f"(half range {half:.3g}) at the last point, reaching 0 near p = {at:.8g} (extrapolated "
        "from the last two points): a grazing",
        "no orbit past the corner was computed, so which way the branch of the orbits that "
        "stick goes is not known; start one from an orbit past the corner (periodic_orbit near "
        "that p, or collocate and continue the equation's orbit) and continue it either way")
