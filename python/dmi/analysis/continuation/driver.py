# One pseudo-arclength continuation driver for every discretisation (equilibria, orbits).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Pseudo-arclength continuation of the zeros of a discretisation in one parameter p.

The driver knows nothing of models, steps or orbits: it follows the curve residual(x, p) = 0 of
a *discretisation* object ``disc`` from a point (x0, p0) towards p_end.  The contract (the names
are fixed; a second discretisation, e.g. collocation of the equation's orbits, implements it):

- ``disc.residual(x: np.ndarray, p: float) -> np.ndarray``: len(x) equations in the unknowns x
  at the parameter p.
- ``disc.jacobian(x, p) -> tuple[J_x, J_p]``: J_x a dense array, a ``scipy.sparse`` matrix or a
  ``scipy.sparse.linalg.LinearOperator`` of shape (len(x), len(x)); J_p of shape (len(x),).
- ``disc.point(x, p) -> object``: the branch point the user sees (an Orbit's or an
  equilibrium's record with its stability; its ``stable`` True, False or None when it cannot be
  verified).  When the record has an attribute ``dpds`` the driver sets it to the unit
  tangent's p component.
- optional ``disc.event_functions(x, p, point) -> dict[str, float]``: test functions, one a
  kind of event, whose sign change between two consecutive points is that event; the driver
  locates it by Brent's method in the arclength along the chord of the two points (every
  evaluation a point corrected on the hyperplane across the chord).  A NaN value: not
  computable there (no event of that kind between the two points).
- optional ``disc.describe(kind, x, p, point) -> dict | None``: the located event checked and
  described: the fields of :class:`dmi.analysis.Event` to set (``detail``, ``u``, ``hopf``,
  ``component``), or None when the check refutes it (the event is then dropped, with a
  ``RuntimeWarning`` that says why when the object sets ``disc.why``; an empty ``why``: a
  known false zero of the test function, dropped silently).
- optional ``disc.corner(points) -> str``: when the branch ends because the corrector fails at
  the smallest step, what the discretisation reads from the points so far (e.g. that the
  branch ended at a corner of a stick pattern, and on which side of it the other branch lies);
  it leads the status, the corrector's failure following in parentheses.
- optional ``disc.adapt(x, p) -> x``: a change of mesh (or of the unknowns) between steps; the
  driver then restarts its tangent from the new x (oriented by ``disc.carry(t, x)``, a direction
  on the new unknowns, when their number changed; else by t's p part).
- optional ``disc.correct(x, p, row, target, far) -> tuple[x, p, iterations]``: the
  discretisation's own corrector on residual(x, p) = 0, row . (x, p) = target (e.g.
  Newton-Picard for shooting); it raises to refuse the step (the driver halves it), ``far`` the
  largest distance (weighted norm) from the predictor it may stray.  On a step (``far``
  finite) it may return x of another length (a change of the unknowns, e.g. a segment inserted
  where the step's point broke an inequality): the driver restarts its tangent as after
  ``adapt``.
- optional ``disc.orient(x, p) -> np.ndarray``: with the tangent predictor, where the start's
  tangent is vertical (no p part to orient it towards p_end), a direction (len(x) + 1) it is
  oriented along (e.g. the amplitude growing, away from a Hopf point).
- optional ``disc.weight``: a float or an array of len(x), the weight of x in the arclength's
  inner product <a, b> = sum weight a_x b_x + a_p b_p (default 1 / len(x): x's RMS, so that a
  step is in "p or RMS state units").
- optional ``disc.start_tangent(x, p, direction) -> np.ndarray | None``: with the secant
  predictor, the first tangent (len(x) + 1, unit in the weighted norm); None or absent: the
  first step is a natural one in p (the hyperplane p = p0 + step).
- optional ``disc.between(za, a, zb, b, middle) -> list[Event]``: events decided by the
  discretisation from two consecutive points (changes of a count, as a stick pattern's);
  ``middle(z0, z1)`` is the branch's point z on the hyperplane through the middle of z0 and z1
  across their chord (a bisection along the branch, also where it turns at the event); the
  driver sets the events' indices.  za and zb differ in size where ``adapt`` changed the
  unknowns between them.
- optional ``disc.on_current(x, p) -> x | None``: the previous point's solution x at p re-solved
  on the current unknowns (after ``adapt`` changed their number), or None where it cannot be;
  the test functions' sign changes between two such points are then located on the current
  unknowns (without it, or with None, events between points of different sizes are not sought).

The driver: ``continuation(disc, x0, p0, p_end, *, step, min_step, max_step, max_points,
at=(), ...) -> Branch``.

- Predictor: the unit tangent t, the null vector of [J_x, J_p], from the bordered system
  [[J_x, J_p], [w t_prev']] t = (0, 1) (dense: LU; sparse: SuperLU; an operator: GMRES); with
  ``predictor="secant"`` the chord of the last two points (the tangent only at the start):
  no Jacobian a step for discretisations whose Jacobian is an operator.
- Corrector: Newton on (residual(x, p), <w t, z - z_pred>) with the bordered Jacobian, or
  ``disc.correct``.  Converged when |residual|_inf <= tol max(1, |x|_inf) and the last
  correction is as small.  A corrector that strays more than the step from the predictor is
  refused (another branch on the hyperplane).
- Step control: the step grows by 1.5 after a corrector of at most ``easy`` iterations, halves
  after a failure; the branch ends when it falls below ``min_step``.
- Corners: when the step has been halved below step / 8, natural steps are tried once (the
  hyperplanes p = p(z) +- delta and the tangent's state part), as a piecewise-smooth branch
  needs where its secant's hyperplane misses the new piece; a branch that still fails there
  ends with a status saying so.
- Events: ``fold`` (dp/ds changes sign, located by Brent on dp/ds when the tangent is computed
  a point, else from the parabola through the last three points), ``branch-point`` (the sign of
  det [[J_x, J_p], [t']] changes: a null space of [J_x, J_p] of dimension 2; dense and sparse
  Jacobians only), the discretisation's own (above), and ``user`` (a parameter of ``at``).
- Landing: a branch whose new point passes p_end (or a parameter of ``at``) gets the point at
  exactly that parameter, corrected on the hyperplane p = p_end from the chord's
  interpolation (Brent on p along the chord where that fails), whatever the tangent; the
  branch then ends with the status ``reached p_end = ...``.  A branch that turns back past its
  start ends with ``left the range [...] after a fold``.
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Iterable
from typing import Any

import numpy as np
import scipy.optimize
import scipy.sparse
import scipy.sparse.linalg as sla

from .branch import Branch, Event, EventWarning
from ..core.newton import ShootingError, fmt_residuals, newton_loop

#: |dp/ds| below which a branch is vertical: a sign change of dp/ds there is noise, not a fold.
VERTICAL = 1e-6


class Curve:
    """The discretisation with the driver's inner product: z = (x, p), weights w."""

    def __init__(self, disc: Any, size: int):
        self.disc = disc
        self.size = size   # len(x)

    def w(self, n: int | None = None) -> np.ndarray:
        """The inner product's weights on z (len(x) + 1)."""
        m = self.size if n is None else n
        weight = getattr(self.disc, "weight", None)
        if weight is not None and np.ndim(weight) == 1:
            return np.concatenate([np.asarray(weight, dtype=float), [1.0]])
        v = np.full(m + 1, 1.0 / m if weight is None else float(weight))
        v[-1] = 1.0
        return v

    def norm(self, d: np.ndarray) -> float:
        return math.sqrt(float(np.dot(self.w(d.size - 1) * d, d)))

    def residual(self, z: np.ndarray) -> np.ndarray:
        return np.asarray(self.disc.residual(z[:-1], float(z[-1])), dtype=float)

    def jacobian(self, z: np.ndarray) -> tuple[Any, np.ndarray]:
        Jx, Jp = self.disc.jacobian(z[:-1], float(z[-1]))
        return Jx, np.asarray(Jp, dtype=float).ravel()


def bordered_solve(Jx: Any, Jp: np.ndarray, row: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solves [[J_x, J_p], [row]] dz = rhs for a dense, sparse or operator J_x.

    Parameters
    ----------
    Jx : numpy.ndarray, scipy.sparse matrix or scipy.sparse.linalg.LinearOperator
        Shape (m, m).
    Jp : numpy.ndarray
        Shape (m,).
    row : numpy.ndarray
        Shape (m + 1,): the border's row.
    rhs : numpy.ndarray
        Shape (m + 1,).

    Returns
    -------
    numpy.ndarray
        dz, shape (m + 1,).

    Raises
    ------
    ShootingError
        The bordered matrix is singular (dense, sparse) or GMRES does not solve it to 1e-2
        relative (an operator).
    """
    m = Jp.size
    if isinstance(Jx, sla.LinearOperator):
        def mv(v: np.ndarray) -> np.ndarray:
            return np.concatenate([Jx.matvec(v[:-1]) + Jp * v[-1], [float(row @ v)]])
        A = sla.LinearOperator((m + 1, m + 1), matvec=mv, dtype=float)
        dz, _ = sla.gmres(A, rhs, rtol=1e-10, atol=0.0, restart=min(m + 1, 60), maxiter=8)
        lin = float(np.linalg.norm(mv(dz) - rhs)) / max(float(np.linalg.norm(rhs)), 1e-300)
        if not np.all(np.isfinite(dz)) or lin > 1e-2:
            raise ShootingError(f"the bordered Jacobian is singular (GMRES relative residual "
                                f"{lin:.2g})", [])
        return dz
    if scipy.sparse.issparse(Jx):
        A = _sparse_bordered(Jx, Jp, row)
        try:
            dz = sla.splu(A).solve(rhs)
        except RuntimeError as e:   # SuperLU: "Factor is exactly singular"
            raise ShootingError(f"the bordered Jacobian is singular ({e})", []) from None
    else:
        A = np.vstack([np.column_stack([np.asarray(Jx, dtype=float), Jp]), row])
        try:
            dz = np.linalg.solve(A, rhs)
        except np.linalg.LinAlgError:
            raise ShootingError("the bordered Jacobian is singular", []) from None
    if not np.all(np.isfinite(dz)):
        raise ShootingError("the bordered Jacobian is singular (non-finite solution)", [])
    return dz


def _sparse_bordered(Jx: Any, Jp: np.ndarray, row: np.ndarray) -> Any:
    """[[J_x, J_p], [row]] as a CSC matrix."""
    top = scipy.sparse.hstack([Jx, scipy.sparse.csc_matrix(Jp[:, None])])
    return scipy.sparse.vstack([top, scipy.sparse.csc_matrix(row[None, :])], format="csc")


def bordered_det(Jx: Any, Jp: np.ndarray, t: np.ndarray) -> float:
    """The branch-point test function: sign(det) |det|^(1 / (m + 1)) of [[J_x, J_p], [t']].

    A continuous function whose sign changes at a branch point (a null space of [J_x, J_p] of
    dimension 2), not at a fold (t oriented continuously).

    Parameters
    ----------
    Jx, Jp : array, sparse matrix or LinearOperator; numpy.ndarray
        The Jacobian, as for :func:`bordered_solve`.
    t : numpy.ndarray
        Shape (m + 1,): the tangent, the border's row.

    Returns
    -------
    float
        The value; NaN for an operator J_x (no determinant), 0 for a singular matrix.
    """
    m = Jp.size
    if isinstance(Jx, sla.LinearOperator):
        return math.nan
    if scipy.sparse.issparse(Jx):
        A = _sparse_bordered(Jx, Jp, t)
        try:
            lu = sla.splu(A, permc_spec="NATURAL", diag_pivot_thresh=0.0,
                          options={"SymmetricMode": False})
        except RuntimeError:
            return 0.0
        d = lu.U.diagonal()
        sign = float(np.prod(np.sign(d))) * _parity(lu.perm_r) * _parity(lu.perm_c)
        return sign * math.exp(float(np.sum(np.log(np.abs(d)))) / (m + 1))
    A = np.vstack([np.column_stack([np.asarray(Jx, dtype=float), Jp]), t])
    sign, logdet = np.linalg.slogdet(A)
    return float(sign) * math.exp(float(logdet) / (m + 1)) if sign != 0 else 0.0


def _parity(perm: np.ndarray) -> float:
    """The sign of a permutation."""
    seen = np.zeros(perm.size, bool)
    sign = 1.0
    for i in range(perm.size):
        if not seen[i]:
            j, k = i, 0
            while not seen[j]:
                seen[j] = True
                j = int(perm[j])
                k += 1
            if k % 2 == 0:
                sign = -sign
    return sign


def tangent(curve: Curve, z: np.ndarray, prev: np.ndarray) -> tuple[np.ndarray, Any, np.ndarray]:
    """The unit tangent of the curve at z, and the Jacobian it came from.

    The null vector of [J_x, J_p] from the bordered system [[J_x, J_p], [w prev']] t = (0, 1)
    (the SVD where prev is orthogonal to it), unit in the weighted norm, oriented along prev.

    Parameters
    ----------
    curve : Curve
        The discretisation with the driver's inner product.
    z : numpy.ndarray
        The point (x, p).
    prev : numpy.ndarray
        The previous tangent (or a direction): <w t, prev> >= 0.

    Returns
    -------
    tuple
        (t, J_x, J_p).

    Raises
    ------
    ShootingError
        An operator Jacobian whose bordered system GMRES does not solve.
    """
    Jx, Jp = curve.jacobian(z)
    w = curve.w(z.size - 1)
    rhs = np.zeros(z.size)
    rhs[-1] = 1.0
    try:
        t = bordered_solve(Jx, Jp, w * prev, rhs)
    except ShootingError:
        if isinstance(Jx, sla.LinearOperator):
            raise
        # prev orthogonal to the tangent: the null vector of [J_x, J_p] by the SVD
        A = np.column_stack([Jx.toarray() if scipy.sparse.issparse(Jx) else Jx, Jp])
        t = np.linalg.svd(A)[2][-1]
    t = t / curve.norm(t)
    return (t if float(np.dot(w * t, prev)) >= 0 else -t), Jx, Jp


def newton_corrector(curve: Curve, zp: np.ndarray, row: np.ndarray, target: float, *,
                     tol: float, max_iter: int, far: float, what: str) -> tuple[np.ndarray, int]:
    """Newton on (residual(z), row . z - target) = 0 from zp with the bordered Jacobian.

    Parameters
    ----------
    curve : Curve
        The discretisation.
    zp : numpy.ndarray
        The predictor (x, p).
    row : numpy.ndarray
        The hyperplane's row.
    target : float
        Its value.
    tol : float
        Converged when |residual|_inf and the last correction are <= tol max(1, |x|_inf).
    max_iter : int
        Iterations at most.
    far : float
        The largest distance (weighted norm) from zp an iterate may reach.
    what : str
        For the error messages.

    Returns
    -------
    tuple
        (z, iterations).

    Raises
    ------
    ShootingError
        No convergence, no progress, a singular Jacobian, non-finite values, or an iterate
        farther than ``far`` (every residual listed).
    """
    res: list[float] = []

    def evaluate(z: np.ndarray) -> tuple[np.ndarray, None]:
        return np.concatenate([curve.residual(z), [float(row @ z - target)]]), None

    def factor(z: np.ndarray, r: np.ndarray, state: None) -> Callable[[np.ndarray], np.ndarray]:
        Jx, Jp = curve.jacobian(z)

        def solve(r: np.ndarray) -> np.ndarray:
            try:
                return bordered_solve(Jx, Jp, row, -r)
            except ShootingError as e:
                raise ShootingError(f"{what}: {e} (residuals {fmt_residuals(res)})",
                                    res) from None
        return solve

    def check(z: np.ndarray) -> None:
        if curve.norm(z - zp) > far:
            raise ShootingError(f"{what}: the corrector strayed {curve.norm(z - zp):.3g} > "
                                f"{far:.3g} from the predictor", res)

    z, _ = newton_loop(evaluate, factor, zp, tol=tol, max_iter=max_iter, what=what,
                       converge="both", check=check,
                       scale=lambda z: max(1.0, float(np.max(np.abs(z[:-1])))), history=res)
    return z, len(res) - 1


class _Run:
    """One continuation: the curve, the corrector's settings and the points found."""

    def __init__(self, disc: Any, size: int, tol: float, max_iter: int):
        self.curve = Curve(disc, size)
        self.disc = disc
        self.tol, self.max_iter = tol, max_iter

    def correct(self, zp: np.ndarray, row: np.ndarray, target: float, far: float
                ) -> tuple[np.ndarray, int]:
        """The point on row . z = target near zp: the discretisation's corrector or Newton's."""
        what = f"corrector near p = {float(zp[-1])!r}"
        own = getattr(self.disc, "correct", None)
        if own is not None:
            x, p, its = own(zp[:-1].copy(), float(zp[-1]), row, target, far)
            return np.concatenate([np.asarray(x, dtype=float), [float(p)]]), int(its)
        return newton_corrector(self.curve, zp, row, target, tol=self.tol,
                                max_iter=self.max_iter, far=far, what=what)

    def at_p(self, z: np.ndarray, p: float) -> np.ndarray:
        """The point at the parameter p from the guess z (on the hyperplane p = p)."""
        row = np.zeros(z.size)
        row[-1] = 1.0
        zp = z.copy()
        zp[-1] = p
        return self.correct(zp, row, p, math.inf)[0]

    def across(self, za: np.ndarray, c: np.ndarray, s: float) -> np.ndarray:
        """The point on the hyperplane <w c, z - za> = s (c a unit chord)."""
        wc = self.curve.w(za.size - 1) * c
        return self.correct(za + s * c, wc, float(wc @ za) + s, math.inf)[0]

    def middle(self, z0: np.ndarray, z1: np.ndarray) -> np.ndarray:
        """The point on the hyperplane through the middle of z0 and z1, across their chord."""
        L = self.curve.norm(z1 - z0)
        return self.across(z0, (z1 - z0) / L, 0.5 * L)

    def land(self, za: np.ndarray, zb: np.ndarray, p: float) -> np.ndarray:
        """The point at exactly the parameter p between za and zb (p between their p's): from
        the chord's interpolation; where that fails, Brent on p along the chord first."""
        if za.size != zb.size:   # the unknowns changed between them: from zb alone
            return self.at_p(zb, p)
        pa, pb = float(za[-1]), float(zb[-1])
        wgt = (p - pa) / (pb - pa) if pb != pa else 0.5
        try:
            return self.at_p(za + wgt * (zb - za), p)
        except Exception:   # the model's, the map's or the corrector's failure
            pass
        L = self.curve.norm(zb - za)
        c = (zb - za) / L
        cache: dict[float, np.ndarray] = {}

        def g(s: float) -> float:
            cache[s] = za if s == 0 else zb if s == L else self.across(za, c, s)
            return float(cache[s][-1]) - p
        s = scipy.optimize.brentq(g, 0.0, L, xtol=1e-10 * L)
        return self.at_p(cache.get(s, self.across(za, c, s)), p)


def _sign_change(fa: float, fb: float) -> bool:
    return math.isfinite(fa) and math.isfinite(fb) and fa * fb < 0


def continuation(disc: Any, x0: np.ndarray, p0: float, p_end: float, *, step: float = 0.05,
                 min_step: float | None = None, max_step: float | None = None,
                 max_points: int = 200, at: Iterable[float] = (), tol: float = 1e-10,
                 max_iter: int = 8, predictor: str = "tangent", easy: int = 3,
                 grow_first: bool = True,
                 make: Callable[..., Any] | None = None, kind: str = "points",
                 branch: dict[str, Any] | None = None) -> Branch:
    """Continues residual(x, p) = 0 from (x0, p0) to p_end by pseudo-arclength (see the module).

    Parameters
    ----------
    disc : object
        The discretisation (``residual``, ``jacobian``, ``point``; optional
        ``event_functions``, ``describe``, ``adapt``, ``correct``, ``weight``: see the module).
    x0 : numpy.ndarray
        The start's unknowns, a zero of ``disc.residual(., p0)`` to ``tol`` (corrected at p0
        when it is not).
    p0 : float
        The start's parameter.
    p_end : float
        Where to stop (finite, not p0); the last point lies on it exactly.
    step : float
        The first step (weighted arclength: p units when the branch moves in p).
    min_step, max_step : float, optional
        Step bounds (default step / 1000 and 4 step).
    max_points : int
        Points at most (the user points of ``at`` count).
    at : iterable of float
        Parameters where a point is wanted (AUTO's user points): each crossed gets a point at
        exactly that p and a ``user`` event.
    tol : float
        The corrector's tolerance.
    max_iter : int
        Corrector iterations a step.
    predictor : {"tangent", "secant"}
        The tangent at every point, or the secant (the tangent at the start only).
    easy : int
        A corrector of at most this many iterations lets the step grow.
    grow_first : bool
        The step may grow after the first step too (False: the second step is ``step`` again;
        a first step in p alone says little of the arclength's scale).
    make : callable, optional
        The model, stored in the Branch.
    kind : str
        The Branch's ``kind``.
    branch : dict, optional
        More Branch fields (``steps``, ``h``, ``rows``, ``sections``, ``period``).

    Returns
    -------
    Branch
        ``points`` (``disc.point``'s records), ``events``, ``status`` (why it ended: p_end, a
        fold out of the range, max_points, a corner, or the corrector failing at the smallest
        step; it does not raise for these).

    Raises
    ------
    ValueError
        A bad ``step``, ``p_end``, ``max_points``, ``predictor`` or ``at``; x0 not finite.
    ShootingError
        x0 is not a zero at p0 and cannot be corrected there.
    """
    if not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: must be finite and > 0")
    p0 = float(p0)
    if not (math.isfinite(p0) and math.isfinite(p_end)) or p_end == p0:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the start's p = "
                         f"{p0!r}")
    if max_points < 2:
        raise ValueError(f"max_points = {max_points!r}: must be >= 2")
    if predictor not in ("tangent", "secant"):
        raise ValueError(f"predictor = {predictor!r}: 'tangent' or 'secant'")
    users = sorted(float(q) for q in at)
    if not all(math.isfinite(q) for q in users):
        raise ValueError(f"at = {list(at)!r}: give finite parameters")
    x0 = np.array(x0, dtype=float).ravel()
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 has non-finite values at {np.flatnonzero(~np.isfinite(x0))[:5]}")
    direction = 1.0 if p_end > p0 else -1.0
    min_step = step / 1000 if min_step is None else float(min_step)
    max_step = 4 * step if max_step is None else float(max_step)
    lo, hi = sorted((p0, float(p_end)))
    run = _Run(disc, x0.size, tol, max_iter)
    curve = run.curve
    z = np.concatenate([x0, [p0]])
    if float(np.max(np.abs(curve.residual(z)), initial=0.0)) > tol * max(1.0, float(
            np.max(np.abs(x0), initial=0.0))):
        z = run.at_p(z, p0)
    e_p = np.zeros(z.size)
    e_p[-1] = direction
    natural = False   # the first step on the hyperplane p = p0 + step
    Jx = Jp = None
    if predictor == "tangent":
        t, Jx, Jp = tangent(curve, z, e_p)
        orient = getattr(disc, "orient", None)
        if abs(t[-1]) > VERTICAL:
            if t[-1] * direction < 0:
                t = -t
        elif orient is not None:   # a vertical start: the discretisation's way
            if float(np.dot(curve.w(z.size - 1) * t, orient(z[:-1].copy(), p0))) < 0:
                t = -t
    else:
        start = getattr(disc, "start_tangent", None)
        t = None if start is None else start(z[:-1].copy(), p0, direction)
        if t is None:
            t, natural = e_p, True
        t = np.asarray(t, dtype=float)
    between = getattr(disc, "between", None)
    has_events = hasattr(disc, "event_functions")
    describe = getattr(disc, "describe", None)

    def record(z: np.ndarray, dpds: float) -> Any:
        pt = disc.point(z[:-1].copy(), float(z[-1]))
        if pt is not None and hasattr(pt, "dpds"):
            pt.dpds = dpds
        return pt

    def tests(z: np.ndarray, pt: Any, t: np.ndarray, J: tuple | None) -> dict[str, float]:
        f = dict(disc.event_functions(z[:-1], float(z[-1]), pt)) if has_events else {}
        if J is not None:
            f["branch-point"] = bordered_det(J[0], J[1], t)
        return f

    pts = [record(z, float(t[-1]))]
    zs, ts = [z], [t]
    fs = [tests(z, pts[0], t, (Jx, Jp) if Jx is not None else None)]
    events: list[Event] = []
    status = "max_points reached"
    ds = step
    while len(pts) < max_points:
        # the predictor and the corrector, the step halved after a failure
        zn = None
        cornered = False
        while zn is None:
            zp = z + ds * t
            row = curve.w(z.size - 1) * t
            try:
                zn, its = run.correct(zp, row, float(row @ zp), math.inf if natural else ds)
            except Exception as e:   # the model's or the corrector's failure: a shorter step
                ds /= 2
                if ds < step / 8 and not cornered:
                    cornered = True
                    got = _corner(run, z, t, ds, direction)
                    if got is not None:
                        zn, its = got
                        break
                if ds < min_step:
                    status = (f"corrector failed at the smallest step {min_step!r} near p = "
                              f"{float(z[-1])!r}" + (" (natural steps from it failed too)"
                                                     if cornered else "") + f": {e}")
                    corner = getattr(disc, "corner", None)
                    said = corner(pts) if corner is not None else ""
                    if said:   # the corner first, whichever route failed there
                        status = f"{said} (the {status})"
                    break
        if zn is None:
            break
        grow = grow_first or len(pts) > 1   # else the second step is the user's step again
        natural = False
        adapt = getattr(disc, "adapt", None)
        restarted = zn.size != z.size    # the corrector changed the unknowns
        if adapt is not None:
            xa = np.asarray(adapt(zn[:-1].copy(), float(zn[-1])), dtype=float)
            if xa.size != zn.size - 1 or np.any(xa != zn[:-1]):
                zn = np.concatenate([xa, [zn[-1]]])
                restarted = True
        curve.size = zn.size - 1
        J = None
        if predictor == "tangent" or restarted:
            sec = t if restarted else zn - z
            if restarted and zn.size != z.size:   # new unknowns: a direction on them
                carry = getattr(disc, "carry", None)
                sec = (carry(t, zn[:-1]) if carry is not None else
                       np.concatenate([np.zeros(zn.size - 1), [t[-1]]]))
            tn, Jxn, Jpn = tangent(curve, zn, sec)
            J = (Jxn, Jpn) if predictor == "tangent" else None
        else:
            sec = zn - z
            tn = sec / curve.norm(sec)
        pa, pb = float(z[-1]), float(zn[-1])
        pt = record(zn, float(tn[-1]))
        f = tests(zn, pt, tn, J)
        found: list[Event] = []
        _events(run, z, t, fs[-1], zn, tn, f, found, describe, predictor == "tangent",
                zs[-2:])
        if between is not None:
            found += between(z, pts[-1], zn, pt, run.middle)
        # p_end crossed by the new point, or twice inside the step (a located fold beyond it):
        # the last point lands on it exactly, at its first crossing
        past = [e for e in found if e.kind == "fold" and e.u is not None
                and (e.p - p_end) * direction >= 0]
        done = (pa - p_end) * direction < 0 and ((pb - p_end) * direction >= 0 or bool(past))
        if done:
            if pb != p_end:
                zb = np.concatenate([past[0].u, [past[0].p]]) if past else zn
                try:
                    zn = run.land(z, zb, float(p_end))
                except Exception as e:   # the model's or the corrector's failure
                    status = f"the landing on p_end = {p_end!r} failed: {e}"
                    break
                pb = float(p_end)
                if predictor == "tangent":
                    tn, Jxn, Jpn = tangent(curve, zn, tn)
                    J = (Jxn, Jpn)
                pt = record(zn, float(tn[-1]))
                f = tests(zn, pt, tn, J)
                found = [e for e in found if (e.p - p_end) * direction < 0]
            status = f"reached p_end = {p_end!r}"
        # the user points crossed by the step, in the order met, each landed on exactly
        crossed = sorted((q for q in users if min(pa, pb) < q <= max(pa, pb) or q == pb),
                         key=lambda q: abs(q - pa))
        for q in crossed:
            events.append(Event("user", q, len(pts), None, "a point asked with at="))
            if q != pb:
                zq = run.land(z, zn, q)
                pts.append(record(zq, float(tn[-1])))
                zs.append(zq)
                ts.append(tn)
                fs.append(f)
        for e in found:   # the index of the first point after the event
            e.index = len(pts) - sum(1 for q in crossed if q != pb and
                                     abs(q - pa) > abs(e.p - pa))
        events += found
        pts.append(pt)
        zs.append(zn)
        ts.append(tn)
        fs.append(f)
        z, t = zn, tn
        if done:
            break
        # out of the range by more than 1e-7 (relative): a vertical branch's p moves by rounding
        if float(z[-1]) < lo - 1e-7 * max(1, abs(lo)) or float(z[-1]) > hi + 1e-7 * max(
                1, abs(hi)):
            status = f"left the range [{lo!r}, {hi!r}] after a fold"
            break
        if its <= easy and grow:
            ds = min(max_step, ds * 1.5)
    events.sort(key=lambda e: (e.index, 0 if e.kind != "user" else 1))
    return Branch(pts, events, status, make, kind=kind, **(branch or {}))


def _corner(run: _Run, z: np.ndarray, t: np.ndarray, ds: float, direction: float
            ) -> tuple[np.ndarray, int] | None:
    """Natural steps past a corner: the hyperplanes p = p(z) +- delta (towards p_end first)
    and, with p free, the tangent's state part +- delta, delta = ds and 4 ds; the first that
    converges ahead of z along t.  None if none does."""
    w = run.curve.w(z.size - 1)
    e_p = np.zeros(z.size)
    e_p[-1] = 1.0
    t_x = t.copy()
    t_x[-1] = 0.0
    nx = run.curve.norm(t_x)
    tries = [(e_p * s * d, e_p) for d in (ds, 4 * ds) for s in (direction, -direction)]
    if nx > 0:
        t_x /= nx
        tries += [(t_x * s * d, t_x) for d in (ds, 4 * ds) for s in (1.0, -1.0)]
    for move, normal in tries:
        row = w * normal if normal is t_x else normal
        zp = z + move
        try:
            got = run.correct(zp, row, float(row @ zp), math.inf)
        except Exception:   # the model's or the corrector's failure: the next try
            continue
        if float(np.dot(w * t, got[0] - z)) > 0:
            return got
    return None


def _events(run: _Run, za: np.ndarray, ta: np.ndarray, fa: dict[str, float],
            zb: np.ndarray, tb: np.ndarray, fb: dict[str, float], events: list[Event],
            describe: Any, tangents: bool, last: list[np.ndarray]) -> None:
    """The events between the points za and zb (their tangents ta, tb and test functions fa,
    fb), located and checked, appended to events (index 0: the caller sets it)."""
    curve = run.curve
    on_current = getattr(run.disc, "on_current", None)
    if za.size != zb.size and on_current is not None:   # za re-solved on zb's unknowns
        xa = on_current(za[:-1], float(za[-1]))
        if xa is not None and xa.size == zb.size - 1:
            za, tangents = np.concatenate([xa, za[-1:]]), False
    L = curve.norm(zb - za) if za.size == zb.size else 0.0
    if za.size != zb.size:   # no common unknowns to locate on: said, not reported
        for kind in fa:
            if kind in fb and kind != "branch-point" and _sign_change(fa[kind], fb[kind]):
                warnings.warn(f"a {kind} test function changes sign between p = "
                              f"{float(za[-1])!r} and {float(zb[-1])!r}, where the unknowns "
                              "changed (another signature): not located, no event reported",
                              RuntimeWarning, stacklevel=3)
    if L == 0:
        return
    c = (zb - za) / L
    cache: dict[float, np.ndarray] = {0.0: za, L: zb}

    def z_at(s: float) -> np.ndarray:
        if s not in cache:
            cache[s] = run.across(za, c, s)
        return cache[s]

    def locate(fn: Callable[[float], float], f0: float, f1: float) -> float | None:
        if not _sign_change(f0, f1):
            return None
        try:
            return float(scipy.optimize.brentq(fn, 0.0, L, xtol=1e-13 * max(1.0, L),
                                               rtol=1e-15, maxiter=100))
        except (ShootingError, ValueError, RuntimeError):
            return None

    if _sign_change(float(ta[-1]), float(tb[-1])) and min(abs(ta[-1]), abs(tb[-1])) > VERTICAL:
        s = None
        if tangents:
            s = locate(lambda s: float(tangent(curve, z_at(s), ta)[0][-1]), float(ta[-1]),
                       float(tb[-1]))
        if s is not None:
            zf = z_at(s)
            events.append(Event("fold", float(zf[-1]), 0, None,
                                "dp/ds changes sign (located on the branch)", u=zf[:-1].copy()))
        else:
            events.append(Event("fold", _parabola(curve, last + [zb]), 0, None,
                                "dp/ds changes sign (p from a parabola in arclength)"))
    for kind in fa:
        if kind not in fb or not _sign_change(fa[kind], fb[kind]):
            continue
        if kind == "branch-point":
            def fn(s: float) -> float:
                z = z_at(s)
                Jx, Jp = curve.jacobian(z)
                return bordered_det(Jx, Jp, tangent(curve, z, ta)[0])
        else:
            def fn(s: float, kind: str = kind) -> float:
                z = z_at(s)
                x, p = z[:-1], float(z[-1])
                with warnings.catch_warnings():   # the zero sought lies within the error band
                    warnings.simplefilter("ignore", EventWarning)
                    return float(run.disc.event_functions(x, p, run.disc.point(x, p))[kind])
        s = locate(fn, fa[kind], fb[kind])
        if s is None:
            warnings.warn(f"a {kind} test function changes sign between p = {float(za[-1])!r} "
                          f"and {float(zb[-1])!r} but Brent's method could not locate its "
                          "zero on the branch: no event reported", RuntimeWarning, stacklevel=3)
            continue
        ze = z_at(s)
        x, p = ze[:-1].copy(), float(ze[-1])
        fields: dict[str, Any] | None = {"detail": f"the {kind} test function changes sign "
                                                   "(located on the branch)", "u": x}
        if describe is not None:
            got = describe(kind, x, p, run.disc.point(x, p))
            if got is None:
                why = getattr(run.disc, "why", "")
                if why:
                    warnings.warn(f"a {kind} test function changes sign at p = {p!r} but the "
                                  f"check refutes the event: {why}: no event reported",
                                  RuntimeWarning, stacklevel=3)
                continue
            fields.update(got)
        events.append(Event(kind, p, 0, **fields))


def _parabola(curve: Curve, zs: list[np.ndarray]) -> float:
    """The fold's p: the vertex of the parabola p(s) through the last three points (s their
    arclength), or the middle of the last two where it has none between them."""
    zs = [z for z in zs if z.size == zs[-1].size][-3:]
    mid = 0.5 * float(zs[-2][-1] + zs[-1][-1])
    if len(zs) < 3:
        return mid
    s = [0.0]
    for a, b in zip(zs, zs[1:]):
        s.append(s[-1] + curve.norm(b - a))
    c = np.polyfit(s, [float(z[-1]) for z in zs], 2)
    if c[0] != 0:
        sv = -c[1] / (2 * c[0])
        if s[0] <= sv <= s[-1]:
            return float(np.polyval(c, sv))
    return mid


__all__ = ["continuation", "bordered_solve", "bordered_det", "newton_corrector", "tangent",
           "VERTICAL"]
