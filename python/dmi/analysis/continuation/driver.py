# One pseudo-arclength continuation driver for every discretisation (equilibria, orbits).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Pseudo-arclength continuation of the zeros of a discretisation in one parameter p.

The driver knows nothing of models, steps or orbits: it follows the curve residual(x, p) = 0 of
a *discretisation* object ``disc`` from a point (x0, p0) towards p_end.  The contract is typed:
a discretisation is a :class:`Discretisation` (three required methods; one missing is a
``TypeError`` naming it when ``continuation`` is called), and each optional hook is a small
protocol the driver tests with ``isinstance``:

- :class:`Discretisation`: ``residual(x, p)`` (len(x) equations), ``jacobian(x, p) -> (J_x,
  J_p)`` (J_x dense, ``scipy.sparse`` or a ``LinearOperator``; J_p of shape (len(x),)) and
  ``point(x, p)``, the branch point the user sees (its ``stable`` True, False or None; the
  driver sets its ``dpds``, where it has one, to the unit tangent's p component).
- :class:`HasEvents`: ``event_functions(x, p, point) -> dict[str, float]``, test functions whose
  sign change between two consecutive points is an event, located by Brent's method in the
  arclength along the chord (every evaluation a point corrected on the hyperplane across the
  chord); NaN: not computable there.
- :class:`Describes`: ``describe(kind, x, p, point) -> dict | None``, the located event checked
  and described (the fields of :class:`dmi.analysis.Event` to set), or None when the check
  refutes it (dropped, with a ``RuntimeWarning`` naming its ``why`` where that is not empty).
- :class:`Corners`: ``corner(points) -> str``, what the discretisation reads from the points
  when the branch ends because the corrector fails at the smallest step (it leads the status).
- :class:`Accepts`: ``accept(x, p, step) -> (x, p)``, called on every point the driver's
  corrector converged to (``step``: a step's point, else a point at fixed p or across a chord);
  it may return the point on other unknowns (a mended signature: the driver restarts its tangent
  as after ``adapt``), or raise to refuse it (a failed step: the driver halves it).
- :class:`Recovers`: ``recover(x, p, row, target, step, error) -> (x, p) | None``, called when the
  driver's corrector fails from the predictor (x, p) on row . (x, p) = target: a point found
  otherwise (e.g. past a corner where segments vanish), or None (the failure stands).
- :class:`Adapts`: ``adapt(x, p) -> x``, a change of mesh (or of the unknowns) between steps;
  the driver then restarts its tangent from the new x (oriented by :class:`Carries`'s
  ``carry(t, x)``, a direction on the new unknowns, when their number changed; else by t's p
  part).
- :class:`Orients`: ``orient(x, p)``, with the tangent predictor, the direction (len(x) + 1) a
  vertical start's tangent is oriented along.
- :class:`Weighted`: ``weight``, a float or an array of len(x), the weight of x in the
  arclength's inner product <a, b> = sum weight a_x b_x + a_p b_p (default 1 / len(x)).
- :class:`StartsTangent`: ``start_tangent(x, p, direction)``, with the secant predictor, the
  first tangent, or None (a natural first step in p).
- :class:`Between`: ``between(za, a, zb, b, middle) -> list[Event]``, events decided from two
  consecutive points (``middle(z0, z1)``: the branch's point on the hyperplane through the
  middle of z0 and z1 across their chord).
- :class:`OnCurrent`: ``on_current(x, p) -> x | None``, the previous point re-solved on the
  current unknowns after ``adapt`` changed their number (events between points of different
  sizes are located there; without it they are not sought).
- :class:`HasStrategies`: ``strategies(x, p, row, target, far) -> iterable of
  :class:`~dmi.analysis.core.newton.Strategy``, the linear-solve strategies the driver's
  corrector tries in order on the hyperplane row . z = target through the predictor (x, p)
  (``far``: the step, the distance an iterate may stray; inf off a step), the next after one
  fails (from the predictor, or the start it names; e.g. shooting's Newton-Picard, then
  Newton-GMRES); an iterable may be lazy and build the next from what the failed one left.
  Without it, Newton with the bordered Jacobian.  There is no corrector of a discretisation's
  own: what it checks of a converged point goes through ``accept``.

Options are values: :class:`ContinuationOptions` (step control, predictor, the corrector's
:class:`~dmi.analysis.core.newton.NewtonOptions`).

The driver: ``continuation(disc, x0, p0, p_end, options=ContinuationOptions(...)) -> Branch``
(the options' fields also as keywords: ``step=``, ``min_step=``, ``at=``, ...).  Its locators
along a branch: Brent's method on a test function across the chord of two points (:class:`Along`),
:func:`locate` (a discretisation's own function of the points, from one point along a
direction) and :func:`bisect_along` (a predicate, e.g. a stick pattern).

- Predictor: the unit tangent t, the null vector of [J_x, J_p], from the bordered system
  [[J_x, J_p], [w t_prev']] t = (0, 1) (dense: LU; sparse: SuperLU; an operator: GMRES); with
  ``predictor="secant"`` the chord of the last two points (the tangent only at the start):
  no Jacobian a step for discretisations whose Jacobian is an operator.
- Corrector: Newton (:func:`~dmi.analysis.core.newton.newton_loop`) on (residual(x, p),
  <w t, z - z_pred>) with the bordered Jacobian (:func:`~dmi.analysis.core.newton.bordered_solve`),
  or the discretisation's strategies (:func:`corrected`), then ``accept`` (or ``recover`` when
  it fails).  Converged when |residual|_inf <= tol max(1, |x|_inf) and the last correction
  is as small.  The iterations the step control counts: those of every strategy tried, at the
  weight of the one that converged.  A corrector that strays more than the step from the
  predictor is refused (another branch on the hyperplane).
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

import dataclasses
import enum
import math
import warnings
from collections.abc import Callable, Iterable
from typing import Any, Protocol, runtime_checkable

import numpy as np
import scipy.optimize
import scipy.sparse
import scipy.sparse.linalg as sla

from .branch import Branch, Event, EventWarning
from ..core.newton import (Converge, NewtonOptions, ShootingError, Strategy, bordered_solve,
                           fmt_residuals, sparse_bordered)

#: |dp/ds| below which a branch is vertical: a sign change of dp/ds there is noise, not a fold.
VERTICAL = 1e-6


@runtime_checkable
class Discretisation(Protocol):
    """What the driver requires of a discretisation (see the module)."""

    def residual(self, x: np.ndarray, p: float) -> np.ndarray:
        """len(x) equations in the unknowns x at the parameter p."""

    def jacobian(self, x: np.ndarray, p: float) -> tuple[Any, np.ndarray]:
        """(J_x, J_p): J_x dense, sparse or a LinearOperator (len(x), len(x)); J_p (len(x),)."""

    def point(self, x: np.ndarray, p: float) -> Any:
        """The branch point the user sees at (x, p)."""


@runtime_checkable
class HasEvents(Protocol):
    """Test functions whose sign changes are events."""

    def event_functions(self, x: np.ndarray, p: float, point: Any) -> dict[str, float]:
        """kind -> value at (x, p) (NaN: not computable there)."""


@runtime_checkable
class Describes(Protocol):
    """The located events checked and described; ``why``: why the last check refuted its
    event ("" for a known false zero of the test function, dropped silently)."""
    why: str

    def describe(self, kind: str, x: np.ndarray, p: float, point: Any
                 ) -> dict[str, Any] | None:
        """The Event's fields to set, or None (refuted; ``why`` says why, "" silently)."""


@runtime_checkable
class Corners(Protocol):
    """What a branch that failed at the smallest step ended at."""

    def corner(self, points: list[Any]) -> str:
        """The sentence that leads the status, or ""."""


@runtime_checkable
class Accepts(Protocol):
    """A converged point checked, and changed (a mend) or refused."""

    def accept(self, x: np.ndarray, p: float, step: bool) -> tuple[np.ndarray, float]:
        """The point to keep (possibly on other unknowns); raises to refuse it."""


@runtime_checkable
class Recovers(Protocol):
    """A point found where the driver's corrector failed."""

    def recover(self, x: np.ndarray, p: float, row: np.ndarray, target: float, step: bool,
                error: Exception) -> tuple[np.ndarray, float] | None:
        """The point, or None (the failure stands)."""


@runtime_checkable
class Adapts(Protocol):
    """A change of mesh (or unknowns) between steps."""

    def adapt(self, x: np.ndarray, p: float) -> np.ndarray:
        """The unknowns on the adapted mesh."""


@runtime_checkable
class Carries(Protocol):
    """A direction on new unknowns to orient the restarted tangent by."""

    def carry(self, t: np.ndarray, x: np.ndarray) -> np.ndarray:
        """len(x) + 1 values."""


@runtime_checkable
class Orients(Protocol):
    """The direction a vertical start's tangent is oriented along."""

    def orient(self, x: np.ndarray, p: float) -> np.ndarray:
        """len(x) + 1 values."""


@runtime_checkable
class Weighted(Protocol):
    """The weight of x in the arclength's inner product."""
    weight: Any


@runtime_checkable
class StartsTangent(Protocol):
    """The secant predictor's first tangent."""

    def start_tangent(self, x: np.ndarray, p: float, direction: float) -> np.ndarray | None:
        """len(x) + 1 values, unit in the weighted norm; None: a natural first step."""


@runtime_checkable
class Between(Protocol):
    """Events decided from two consecutive points."""

    def between(self, za: np.ndarray, a: Any, zb: np.ndarray, b: Any,
                middle: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> list[Event]:
        """The events between a and b (the driver sets their indices)."""


@runtime_checkable
class OnCurrent(Protocol):
    """The previous point re-solved on the current unknowns."""

    def on_current(self, x: np.ndarray, p: float) -> np.ndarray | None:
        """x on the current unknowns, or None."""


@runtime_checkable
class HasStrategies(Protocol):
    """The linear-solve strategies of the driver's corrector."""

    def strategies(self, x: np.ndarray, p: float, row: np.ndarray, target: float, far: float
                   ) -> Iterable[Strategy]:
        """The strategies on row . (x, p) = target from the predictor (x, p), in order."""


def _required(disc: Any) -> None:
    """Raises TypeError naming the methods of :class:`Discretisation` that ``disc`` lacks."""
    missing = [name for name in ("residual", "jacobian", "point")
               if not callable(getattr(disc, name, None))]
    if missing:
        raise TypeError(f"continuation: the discretisation {type(disc).__name__} lacks "
                        f"{', '.join(missing)} (a Discretisation has residual(x, p), "
                        "jacobian(x, p) and point(x, p))")


class Predictor(enum.Enum):
    """The driver's predictor."""
    #: The tangent at every point (a Jacobian a step).
    TANGENT = "tangent"
    #: The chord of the last two points (the tangent at the start only).
    SECANT = "secant"


@dataclasses.dataclass(frozen=True)
class ContinuationOptions:
    """How :func:`continuation` steps (a value, as BifurcationKit's ``ContinuationPar``).

    Attributes
    ----------
    step : float
        The first step (weighted arclength: p units when the branch moves in p).
    min_step, max_step : float or None
        Step bounds (None: step / 1000 and 4 step).
    max_points : int
        Points at most (the user points of ``at`` count).
    at : tuple of float
        Parameters where a point is wanted (AUTO's user points): each crossed gets a point at
        exactly that p and a ``user`` event.
    tol : float
        The start's tolerance (corrected at p0 when its residual exceeds tol max(1, |x0|_inf)),
        and the corrector's unless ``newton`` is given.
    max_iter : int
        Corrector iterations a step unless ``newton`` is given.
    predictor : Predictor
        Tangent or secant (a string of its values is accepted).
    easy : int
        A corrector of at most this many iterations lets the step grow (by 1.5).
    grow_first : bool
        The step may grow after the first step too (False: the second step is ``step`` again).
    newton : NewtonOptions or None
        The corrector's options (None: ``tol``, ``max_iter``, the residual and the last
        correction both converged).
    """
    step: float = 0.05
    min_step: float | None = None
    max_step: float | None = None
    max_points: int = 200
    at: tuple[float, ...] = ()
    tol: float = 1e-10
    max_iter: int = 8
    predictor: Predictor = Predictor.TANGENT
    easy: int = 3
    grow_first: bool = True
    newton: NewtonOptions | None = None

    def __post_init__(self) -> None:
        step = self.step
        if not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0):
            raise ValueError(f"step = {step!r}: must be finite and > 0")
        if self.max_points < 2:
            raise ValueError(f"max_points = {self.max_points!r}: must be >= 2")
        if not isinstance(self.predictor, Predictor):
            try:
                object.__setattr__(self, "predictor", Predictor(self.predictor))
            except ValueError:
                raise ValueError(f"predictor = {self.predictor!r}: 'tangent' or 'secant'") from None
        users = tuple(sorted(float(q) for q in self.at))
        if not all(math.isfinite(q) for q in users):
            raise ValueError(f"at = {list(self.at)!r}: give finite parameters")
        object.__setattr__(self, "at", users)

    @property
    def corrector(self) -> NewtonOptions:
        """The corrector's Newton options."""
        if self.newton is not None:
            return self.newton
        return NewtonOptions(tol=self.tol, max_iter=self.max_iter, converge=Converge.BOTH)

    @property
    def smallest(self) -> float:
        """The smallest step."""
        return self.step / 1000 if self.min_step is None else float(self.min_step)

    @property
    def largest(self) -> float:
        """The largest step."""
        return 4 * self.step if self.max_step is None else float(self.max_step)


class Curve:
    """The discretisation with the driver's inner product: z = (x, p), weights w."""

    def __init__(self, disc: Discretisation, size: int):
        self.disc = disc
        self.size = size   # len(x)
        self.weighted = isinstance(disc, Weighted)

    def w(self, n: int | None = None) -> np.ndarray:
        """The inner product's weights on z (len(x) + 1)."""
        m = self.size if n is None else n
        weight = self.disc.weight if self.weighted else None
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
        A = sparse_bordered(Jx, Jp, t)
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


def newton_corrector(curve: Curve, zp: np.ndarray, row: np.ndarray, target: float,
                     options: NewtonOptions | None = None, *, far: float = math.inf,
                     what: str = "corrector",
                     scale: Callable[[np.ndarray], float] | None = None,
                     tol: float | None = None, max_iter: int | None = None,
                     strategies: Iterable[Strategy] | None = None) -> tuple[np.ndarray, int]:
    """Newton on (residual(z), row . z - target) = 0 from zp with the bordered Jacobian, or
    with the discretisation's ``strategies`` (:func:`corrected`): the one corrector of
    :mod:`dmi.analysis`.

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
    options : NewtonOptions, optional
        Newton's options (default: converged when |residual|_inf and the last correction are
        <= tol max(1, |x|_inf), ``Converge.BOTH``).
    far : float
        The largest distance (weighted norm) from zp an iterate may reach.
    what : str
        For the error messages.
    scale : callable, optional
        z -> the tolerance's scale (default max(1, |x|_inf)).
    tol, max_iter : float, int, optional
        Replace the options' (the keywords of the corrector before its options were a value).
    strategies : iterable of Strategy, optional
        Tried in order in place of the bordered Newton (their own options, checks and scales).

    Returns
    -------
    tuple
        (z, iterations: with strategies, as :func:`corrected` counts them).

    Raises
    ------
    ShootingError
        No convergence, no progress, a singular Jacobian, non-finite values, or an iterate
        farther than ``far`` (every residual listed).
    """
    if strategies is not None:
        return corrected(strategies, zp)
    return corrected([newton_strategy(curve, zp, row, target, options, far=far, what=what,
                                      scale=scale, tol=tol, max_iter=max_iter)], zp)


def newton_strategy(curve: Curve, zp: np.ndarray, row: np.ndarray, target: float,
                    options: NewtonOptions | None = None, *, far: float = math.inf,
                    what: str = "corrector",
                    scale: Callable[[np.ndarray], float] | None = None,
                    tol: float | None = None, max_iter: int | None = None) -> Strategy:
    """The driver's own linear-solve strategy (the arguments of :func:`newton_corrector`): the
    bordered Jacobian [[J_x, J_p], [row]] solved by
    :func:`~dmi.analysis.core.newton.bordered_solve`, the iterates kept within ``far`` of zp."""
    o = options or NewtonOptions(converge=Converge.BOTH)
    o = o.but(**{k: v for k, v in (("tol", tol), ("max_iter", max_iter)) if v is not None})
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

    return Strategy(evaluate, factor, o, what, check=check, history=res,
                    scale=scale or (lambda z: max(1.0, float(np.max(np.abs(z[:-1]))))))


def corrected(strategies: Iterable[Strategy], zp: np.ndarray) -> tuple[np.ndarray, int]:
    """The corrector's loop over its linear-solve strategies: each run by
    :func:`~dmi.analysis.core.newton.newton_loop` from its start (default the predictor zp);
    after a failure of one of its ``retry`` types the next is tried, any other failure refuses
    the point.  Returns (z, iterations): those of every strategy tried, times the weight of the
    one that converged, rounded up.  Raises the last failure when none converges."""
    total = 0
    last: BaseException = ShootingError("corrector: no linear-solve strategy", [])
    for s in strategies:
        try:
            z, res = s.run(zp)
        except s.retry as e:
            total += max(0, len(s.history) - 1)
            last = e
            continue
        total += len(res) - 1
        return z, math.ceil(s.weight * total)
    raise last


#: The optional hooks: the name a run's ``has`` table gives each, and its protocol.
HOOKS = {"events": HasEvents, "describe": Describes, "corner": Corners, "accept": Accepts,
         "recover": Recovers, "adapt": Adapts, "carry": Carries, "orient": Orients,
         "start_tangent": StartsTangent, "between": Between, "on_current": OnCurrent,
         "strategies": HasStrategies}


class _Run:
    """One continuation: the curve, the corrector's settings, and the discretisation's hooks
    (``has``: name -> whether it implements that protocol, tested once)."""

    def __init__(self, disc: Discretisation, size: int, options: ContinuationOptions):
        self.curve = Curve(disc, size)
        self.disc = disc
        self.newton = options.corrector
        self.has = {name: isinstance(disc, proto) for name, proto in HOOKS.items()}

    def correct(self, zp: np.ndarray, row: np.ndarray, target: float, far: float
                ) -> tuple[np.ndarray, int]:
        """The point on row . z = target near zp: Newton's, with the discretisation's
        strategies where it has them (then its ``accept``, or its ``recover`` where Newton
        fails)."""
        disc = self.disc
        step = math.isfinite(far)
        try:
            tries = disc.strategies(zp[:-1].copy(), float(zp[-1]), row, target, far) \
                if self.has["strategies"] else None
            z, its = newton_corrector(self.curve, zp, row, target, self.newton, far=far,
                                      what=f"corrector near p = {float(zp[-1])!r}",
                                      strategies=tries)
        except (ShootingError, ValueError) as e:   # ValueError: the residual refuses z
            if not self.has["recover"]:
                raise
            got = disc.recover(zp[:-1].copy(), float(zp[-1]), row, target, step, e)
            if got is None:
                raise
            return np.concatenate([np.asarray(got[0], dtype=float), [float(got[1])]]), 0
        if self.has["accept"]:
            x, p = disc.accept(z[:-1], float(z[-1]), step)
            z = np.concatenate([np.asarray(x, dtype=float), [float(p)]])
        return z, its

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
        along = Along(self, za, c, L, zb)
        s = scipy.optimize.brentq(lambda s: float(along(s)[-1]) - p, 0.0, L, xtol=1e-10 * L)
        return self.at_p(along(s), p)


class Along:
    """The branch's points on the hyperplanes across a unit direction c from za (s its
    arclength; with L and zb given, s = 0 is za and s = L is zb), each corrected once: the one
    locator of events along a branch (:meth:`root`, :func:`locate`)."""

    def __init__(self, run: _Run, za: np.ndarray, c: np.ndarray, L: float = math.inf,
                 zb: np.ndarray | None = None):
        self.run, self.za, self.c, self.L = run, za, c, L
        self.memo: dict[float, np.ndarray] = {} if zb is None else {0.0: za, L: zb}

    def __call__(self, s: float) -> np.ndarray:
        if s not in self.memo:
            self.memo[s] = self.run.across(self.za, self.c, s)
        return self.memo[s]

    def root(self, fn: Callable[[float], float], f0: float, f1: float) -> float | None:
        """Where fn (a function of the arclength s, fn(0) = f0, fn(L) = f1) changes sign, by
        Brent's method (at an end where fn fails, f0 or f1); None when f0, f1 do not bracket a
        root or the corrector or Brent fails."""
        if not _sign_change(f0, f1):
            return None

        # an end whose evaluation fails takes the driver's value there: its point re-solved on
        # another layout (a collocated branch's next mesh, the chord's on_current) can break
        # its signature and fail, while the bracket is the driver's, from its own points
        def inner(s: float) -> float:
            if s not in (0.0, self.L):
                return fn(s)
            try:
                return fn(s)
            except (ShootingError, ValueError):
                return f0 if s == 0.0 else f1
        try:
            return float(scipy.optimize.brentq(inner, 0.0, self.L,
                                               xtol=1e-13 * max(1.0, self.L), rtol=1e-15,
                                               maxiter=100))
        except (ShootingError, ValueError, RuntimeError):
            return None


def locate(disc: Discretisation, z: np.ndarray, t: np.ndarray,
           g: Callable[[np.ndarray], float], g0: float, spans: Iterable[float],
           newton: NewtonOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """Where a function g of the branch's points changes sign along the branch of ``disc`` from
    its point z in the direction t: the driver's locator for a discretisation's own events (the
    signature's margins of a collocated branch).

    The points on the hyperplanes <w t, z' - z> = s are corrected by Newton (``newton``) at the
    arclengths ``spans`` until g's sign differs from g0's, then Brent's method on s.

    Parameters
    ----------
    disc : Discretisation
        The discretisation of the branch.
    z : numpy.ndarray
        The branch's point (x, p) to start from.
    t : numpy.ndarray
        The direction, unit in the driver's weighted norm.
    g : callable
        A point (x, p) -> a float.
    g0 : float
        g at z.
    spans : iterable of float
        The arclengths tried for a sign change (signed, increasing in size).
    newton : NewtonOptions
        The corrector's options.

    Returns
    -------
    tuple or None
        (the point at the root, the points 2 xtol before and after it: g of opposite signs),
        or None when g0's sign holds at every span.

    Raises
    ------
    ValueError
        Brent's method does not converge, or g's sign does not change around its root.
    ShootingError
        A point on the way cannot be corrected.
    """
    along = Along(_Run(disc, z.size - 1, ContinuationOptions(newton=newton)), z, t)
    lo, hi = 0.0, None
    for s in spans:
        if g(along(s)) * g0 <= 0:
            hi = s
            break
        lo = s
    if hi is None:
        return None
    lo, hi = min(lo, hi), max(lo, hi)
    xtol = 1e-13 * max(1.0, abs(hi), abs(lo))
    root, info = scipy.optimize.brentq(lambda s: g(along(s)), lo, hi, xtol=xtol,
                                       full_output=True, disp=False)
    if not info.converged:
        raise ValueError(f"Brent's method did not converge ({info.flag})")
    s0, s1 = max(lo, root - 2 * xtol), min(hi, root + 2 * xtol)
    if g(along(s0)) * g(along(s1)) > 0:
        raise ValueError("the sign does not change around Brent's root")
    return along(root), along(s0), along(s1)


def bisect_along(za: np.ndarray, zb: np.ndarray, same: Callable[[np.ndarray], bool],
                 middle: Callable[[np.ndarray, np.ndarray], np.ndarray],
                 norm: Callable[[np.ndarray], float], halvings: int = 6
                 ) -> tuple[np.ndarray, np.ndarray] | None:
    """Bisection along the branch between two points on a predicate: the driver's locator of
    an event that a test function cannot place (a change of a count, as a stick pattern's).

    Parameters
    ----------
    za, zb : numpy.ndarray
        The bracket's points (x, p).
    same : callable
        z -> True when z is on za's side (e.g. its stick pattern is za's).
    middle : callable
        (z0, z1) -> the branch's point on the hyperplane through the middle of z0 and z1
        across their chord (the driver's, or a discretisation's corrector of it).
    norm : callable
        The norm of a chord.
    halvings : int
        The bracket's chord ends at 2^-halvings of the first (at most 4 halvings as many
        middles: a corrected middle off a bent chord shortens it by less than half).

    Returns
    -------
    tuple or None
        The final bracket (za, zb), or None when a middle cannot be corrected (the model's,
        the map's or the corrector's failure).
    """
    first = norm(zb - za)
    for _ in range(4 * halvings):
        if norm(zb - za) <= first * 2.0 ** -halvings:
            break
        try:
            zm = middle(za, zb)
            on_a = same(zm)
        except Exception:   # the model's, the map's or the corrector's failure
            return None
        if on_a:
            za = zm
        else:
            zb = zm
    return za, zb


def _sign_change(fa: float, fb: float) -> bool:
    return math.isfinite(fa) and math.isfinite(fb) and fa * fb < 0


def curve_range(who: str, q0: float, q_end: float, step: float | None = None
                ) -> tuple[float, float, float]:
    """(q0, q_end, the first step) of a curve in (p, q), checked: a ValueError naming ``who``
    where q0 and q_end are not two different finite values, or the step (default
    |q_end - q0| / 20) is not finite and > 0."""
    q0, q_end = float(q0), float(q_end)
    if not (math.isfinite(q0) and math.isfinite(q_end)) or q0 == q_end:
        raise ValueError(f"{who}: q0 = {q0!r}, q_end = {q_end!r}: give two different finite "
                         "values")
    if step is None:
        step = abs(q_end - q0) / 20
    if not (isinstance(step, (int, float)) and math.isfinite(step) and step > 0):
        raise ValueError(f"{who}: step = {step!r}: must be finite and > 0")
    return q0, q_end, float(step)


def continuation(disc: Discretisation, x0: np.ndarray, p0: float, p_end: float,
                 options: ContinuationOptions | None = None, *,
                 make: Callable[..., Any] | None = None, kind: str = "points",
                 branch: dict[str, Any] | None = None, **fields: Any) -> Branch:
    """Continues residual(x, p) = 0 from (x0, p0) to p_end by pseudo-arclength (see the module).

    Parameters
    ----------
    disc : Discretisation
        The discretisation (``residual``, ``jacobian``, ``point``; optional hooks: see the
        module).
    x0 : numpy.ndarray
        The start's unknowns, a zero of ``disc.residual(., p0)`` to ``tol`` (corrected at p0
        when it is not).
    p0 : float
        The start's parameter.
    p_end : float
        Where to stop (finite, not p0); the last point lies on it exactly.
    options : ContinuationOptions, optional
        Step control, predictor and corrector (default ``ContinuationOptions()``).
    make : callable, optional
        The model, stored in the Branch.
    kind : str
        The Branch's ``kind``.
    branch : dict, optional
        More Branch fields (``steps``, ``h``, ``rows``, ``sections``, ``period``).
    **fields
        Fields of :class:`ContinuationOptions` (``step=``, ``min_step=``, ``max_step=``,
        ``max_points=``, ``at=``, ``tol=``, ``max_iter=``, ``predictor=``, ``easy=``,
        ``grow_first=``, ``newton=``) that replace those of ``options``.

    Returns
    -------
    Branch
        ``points`` (``disc.point``'s records), ``events``, ``status`` (why it ended: p_end, a
        fold out of the range, max_points, a corner, or the corrector failing at the smallest
        step; it does not raise for these).

    Raises
    ------
    TypeError
        ``disc`` lacks a method of :class:`Discretisation` (named), or a field that
        ContinuationOptions does not have.
    ValueError
        A bad ``step``, ``p_end``, ``max_points``, ``predictor`` or ``at``; x0 not finite.
    ShootingError
        x0 is not a zero at p0 and cannot be corrected there.
    """
    _required(disc)
    o = _options(options, fields)
    p0 = float(p0)
    if not (math.isfinite(p0) and math.isfinite(p_end)) or p_end == p0:
        raise ValueError(f"p_end = {p_end!r}: must be finite and differ from the start's p = "
                         f"{p0!r}")
    x0 = np.array(x0, dtype=float).ravel()
    if not np.all(np.isfinite(x0)):
        raise ValueError(f"x0 has non-finite values at {np.flatnonzero(~np.isfinite(x0))[:5]}")
    walk = _Walk(disc, x0, p0, float(p_end), o)
    walk.run_to_end()
    walk.events.sort(key=lambda e: (e.index, 0 if e.kind != "user" else 1))
    return Branch(walk.pts, walk.events, walk.status, make, kind=kind, **(branch or {}))


def _options(options: ContinuationOptions | None, fields: dict[str, Any]) -> ContinuationOptions:
    """The options with the keyword fields replaced (a TypeError names an unknown one)."""
    o = options or ContinuationOptions(**{k: fields.pop(k) for k in ("step",) if k in fields})
    names = {f.name for f in dataclasses.fields(ContinuationOptions)}
    unknown = sorted(set(fields) - names)
    if unknown:
        raise TypeError(f"continuation: ContinuationOptions has no field {', '.join(unknown)} "
                        f"(fields: {', '.join(sorted(names))})")
    return dataclasses.replace(o, **fields) if fields else o


class _Walk:
    """One branch's walk: the points, tangents, test functions and events so far."""

    def __init__(self, disc: Discretisation, x0: np.ndarray, p0: float, p_end: float,
                 o: ContinuationOptions):
        self.disc, self.o, self.p_end = disc, o, p_end
        self.direction = 1.0 if p_end > p0 else -1.0
        self.lo, self.hi = sorted((p0, p_end))
        self.run = _Run(disc, x0.size, o)
        self.curve = self.run.curve
        self.tangents = o.predictor is Predictor.TANGENT
        z = np.concatenate([x0, [p0]])
        if float(np.max(np.abs(self.curve.residual(z)), initial=0.0)) > o.tol * max(1.0, float(
                np.max(np.abs(x0), initial=0.0))):
            z = self.run.at_p(z, p0)
        t, J, self.natural = self._first_tangent(z)
        self.pts = [self.record(z, float(t[-1]))]
        self.zs, self.ts = [z], [t]
        self.fs = [self.tests(z, self.pts[0], t, J)]
        self.events: list[Event] = []
        self.status = "max_points reached"
        self.ds = o.step

    def _first_tangent(self, z: np.ndarray) -> tuple[np.ndarray, tuple | None, bool]:
        """(t, the Jacobian it came from or None, natural: the first step on p = p0 + step)."""
        e_p = np.zeros(z.size)
        e_p[-1] = self.direction
        disc = self.disc
        if self.tangents:
            t, Jx, Jp = tangent(self.curve, z, e_p)
            if abs(t[-1]) > VERTICAL:
                if t[-1] * self.direction < 0:
                    t = -t
            elif self.run.has["orient"]:   # a vertical start: the discretisation's way
                if float(np.dot(self.curve.w(z.size - 1) * t,
                                disc.orient(z[:-1].copy(), float(z[-1])))) < 0:
                    t = -t
            return t, (Jx, Jp), False
        t = (disc.start_tangent(z[:-1].copy(), float(z[-1]), self.direction)
             if self.run.has["start_tangent"] else None)
        if t is None:
            return e_p, None, True
        return np.asarray(t, dtype=float), None, False

    def record(self, z: np.ndarray, dpds: float) -> Any:
        pt = self.disc.point(z[:-1].copy(), float(z[-1]))
        if pt is not None and hasattr(pt, "dpds"):
            pt.dpds = dpds
        return pt

    def tests(self, z: np.ndarray, pt: Any, t: np.ndarray, J: tuple | None) -> dict[str, float]:
        f = (dict(self.disc.event_functions(z[:-1], float(z[-1]), pt))
             if self.run.has["events"] else {})
        if J is not None:
            f["branch-point"] = bordered_det(J[0], J[1], t)
        return f

    def run_to_end(self) -> None:
        """Steps until p_end, max_points, the range left, or the smallest step failing."""
        while len(self.pts) < self.o.max_points:
            got = self.corrected()
            if got is None or self.advance(*got):
                break

    def corrected(self) -> tuple[np.ndarray, int] | None:
        """The predictor and the corrector, the step halved after a failure; natural steps once
        past a corner.  None (the status set) when the step falls below the smallest."""
        z, t, o = self.zs[-1], self.ts[-1], self.o
        cornered = False
        while True:
            zp = z + self.ds * t
            row = self.curve.w(z.size - 1) * t
            try:
                return self.run.correct(zp, row, float(row @ zp),
                                        math.inf if self.natural else self.ds)
            except Exception as e:   # the model's or the corrector's failure: a shorter step
                self.ds /= 2
                if self.ds < o.step / 8 and not cornered:
                    cornered = True
                    got = _corner(self.run, z, t, self.ds, self.direction)
                    if got is not None:
                        return got
                if self.ds < o.smallest:
                    self.status = (f"corrector failed at the smallest step {o.smallest!r} near "
                                   f"p = {float(z[-1])!r}" + (" (natural steps from it failed "
                                                              "too)" if cornered else "") +
                                   f": {e}")
                    said = self.disc.corner(self.pts) if self.run.has["corner"] else ""
                    if said:   # the corner first, whichever route failed there
                        self.status = f"{said} (the {self.status})"
                    return None

    def advance(self, zn: np.ndarray, its: int) -> bool:
        """The step's point zn (after ``its`` corrector iterations) adapted, its tangent,
        events, landing and user points recorded.  True when the branch ends here."""
        z, t = self.zs[-1], self.ts[-1]
        grow = self.o.grow_first or len(self.pts) > 1   # else the second step is the first's
        self.natural = False
        zn, tn, J = self.adapted(z, t, zn)
        pa, pb = float(z[-1]), float(zn[-1])
        pt = self.record(zn, float(tn[-1]))
        f = self.tests(zn, pt, tn, J)
        found: list[Event] = []
        _events(self.run, z, t, self.fs[-1], zn, tn, f, found, self.tangents, self.zs[-2:])
        if self.run.has["between"]:
            found += self.disc.between(z, self.pts[-1], zn, pt, self.run.middle)
        # p_end crossed by the new point, or twice inside the step (a located fold beyond it):
        # the last point lands on it exactly, at its first crossing
        d, p_end = self.direction, self.p_end
        past = [e for e in found if e.kind == "fold" and e.u is not None
                and (e.p - p_end) * d >= 0]
        done = (pa - p_end) * d < 0 and ((pb - p_end) * d >= 0 or bool(past))
        if done:
            if pb != p_end:
                zb = np.concatenate([past[0].u, [past[0].p]]) if past else zn
                try:
                    zn = self.run.land(z, zb, p_end)
                except Exception as e:   # the model's or the corrector's failure
                    self.status = f"the landing on p_end = {p_end!r} failed: {e}"
                    return True
                tn, pt, f = self.landed(zn, tn)
                pb = p_end
                found = [e for e in found if (e.p - p_end) * d < 0]
            self.status = f"reached p_end = {p_end!r}"
        self.users(z, zn, tn, f, pa, pb, found)
        self.pts.append(pt)
        self.zs.append(zn)
        self.ts.append(tn)
        self.fs.append(f)
        if done:
            return True
        # out of the range by more than 1e-7 (relative): a vertical branch's p moves by rounding
        lo, hi = self.lo, self.hi
        if float(zn[-1]) < lo - 1e-7 * max(1, abs(lo)) or float(zn[-1]) > hi + 1e-7 * max(
                1, abs(hi)):
            self.status = f"left the range [{lo!r}, {hi!r}] after a fold"
            return True
        if its <= self.o.easy and grow:
            self.ds = min(self.o.largest, self.ds * 1.5)
        return False

    def adapted(self, z: np.ndarray, t: np.ndarray, zn: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, tuple | None]:
        """zn after ``adapt``, its tangent (restarted where the unknowns changed) and the
        Jacobian that came with it (tangent predictor), or None."""
        disc = self.disc
        restarted = zn.size != z.size    # the corrector changed the unknowns
        if self.run.has["adapt"]:
            xa = np.asarray(disc.adapt(zn[:-1].copy(), float(zn[-1])), dtype=float)
            if xa.size != zn.size - 1 or np.any(xa != zn[:-1]):
                zn = np.concatenate([xa, [zn[-1]]])
                restarted = True
        self.curve.size = zn.size - 1
        if not (self.tangents or restarted):
            sec = zn - z
            return zn, sec / self.curve.norm(sec), None
        sec = t if restarted else zn - z
        if restarted and zn.size != z.size:   # new unknowns: a direction on them
            sec = (disc.carry(t, zn[:-1]) if self.run.has["carry"] else
                   np.concatenate([np.zeros(zn.size - 1), [t[-1]]]))
        tn, Jxn, Jpn = tangent(self.curve, zn, sec)
        return zn, tn, ((Jxn, Jpn) if self.tangents else None)

    def landed(self, zn: np.ndarray, tn: np.ndarray
               ) -> tuple[np.ndarray, Any, dict[str, float]]:
        """The tangent, record and test functions of the point zn landed on p_end."""
        J = None
        if self.tangents:
            tn, Jxn, Jpn = tangent(self.curve, zn, tn)
            J = (Jxn, Jpn)
        pt = self.record(zn, float(tn[-1]))
        return tn, pt, self.tests(zn, pt, tn, J)

    def users(self, z: np.ndarray, zn: np.ndarray, tn: np.ndarray, f: dict[str, float],
              pa: float, pb: float, found: list[Event]) -> None:
        """The user points crossed by the step, in the order met, each landed on exactly; the
        step's events indexed and kept."""
        crossed = sorted((q for q in self.o.at if min(pa, pb) < q <= max(pa, pb) or q == pb),
                         key=lambda q: abs(q - pa))
        for q in crossed:
            self.events.append(Event("user", q, len(self.pts), None, "a point asked with at="))
            if q != pb:
                zq = self.run.land(z, zn, q)
                self.pts.append(self.record(zq, float(tn[-1])))
                self.zs.append(zq)
                self.ts.append(tn)
                self.fs.append(f)
        for e in found:   # the index of the first point after the event
            e.index = len(self.pts) - sum(1 for q in crossed if q != pb and
                                          abs(q - pa) > abs(e.p - pa))
        self.events += found


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
            tangents: bool, last: list[np.ndarray]) -> None:
    """The events between the points za and zb (their tangents ta, tb and test functions fa,
    fb), located and checked, appended to events (index 0: the caller sets it)."""
    curve = run.curve
    disc = run.disc
    if za.size != zb.size and run.has["on_current"]:   # za re-solved on zb's unknowns
        xa = disc.on_current(za[:-1], float(za[-1]))
        if xa is not None and xa.size == zb.size - 1:
            za, tangents = np.concatenate([xa, za[-1:]]), False
    if za.size != zb.size:   # no common unknowns to locate on: said, not reported
        for kind in fa:
            if kind in fb and kind != "branch-point" and _sign_change(fa[kind], fb[kind]):
                warnings.warn(f"a {kind} test function changes sign between p = "
                              f"{float(za[-1])!r} and {float(zb[-1])!r}, where the unknowns "
                              "changed (another signature): not located, no event reported",
                              RuntimeWarning, stacklevel=4)
        return
    L = curve.norm(zb - za)
    if L == 0:
        return
    along = Along(run, za, (zb - za) / L, L, zb)
    if _sign_change(float(ta[-1]), float(tb[-1])) and min(abs(ta[-1]), abs(tb[-1])) > VERTICAL:
        s = None
        if tangents:
            s = along.root(lambda s: float(tangent(curve, along(s), ta)[0][-1]),
                           float(ta[-1]), float(tb[-1]))
        if s is not None:
            zf = along(s)
            events.append(Event("fold", float(zf[-1]), 0, None,
                                "dp/ds changes sign (located on the branch)", u=zf[:-1].copy()))
        else:
            near = [z for z in last if z.size == zb.size]
            if not near or not np.array_equal(near[-1], za):
                near.append(za)
            events.append(Event("fold", _parabola(curve, near + [zb]), 0, None,
                                "dp/ds changes sign (p from a parabola in arclength)"))
    for kind in fa:
        if kind in fb and _sign_change(fa[kind], fb[kind]):
            got = _located(run, along, kind, ta, fa[kind], fb[kind])
            if got is not None:
                events.append(got)


def _located(run: _Run, along: Along, kind: str, ta: np.ndarray, fa: float, fb: float
             ) -> Event | None:
    """The event of the test function ``kind`` whose sign changes from fa to fb along the
    chord: located by Brent's method, then checked and described (:class:`Describes`); None,
    with a warning saying why, when it cannot be located or the check refutes it."""
    curve, disc = run.curve, run.disc
    if kind == "branch-point":
        def fn(s: float) -> float:
            z = along(s)
            Jx, Jp = curve.jacobian(z)
            return bordered_det(Jx, Jp, tangent(curve, z, ta)[0])
    else:
        def fn(s: float) -> float:
            z = along(s)
            x, p = z[:-1], float(z[-1])
            with warnings.catch_warnings():   # the zero sought lies within the error band
                warnings.simplefilter("ignore", EventWarning)
                return float(disc.event_functions(x, p, disc.point(x, p))[kind])
    s = along.root(fn, fa, fb)
    za, zb = along.za, along.memo[along.L]
    if s is None:
        warnings.warn(f"a {kind} test function changes sign between p = {float(za[-1])!r} "
                      f"and {float(zb[-1])!r} but Brent's method could not locate its "
                      "zero on the branch: no event reported", RuntimeWarning, stacklevel=5)
        return None
    ze = along(s)
    x, p = ze[:-1].copy(), float(ze[-1])
    fields: dict[str, Any] = {"detail": f"the {kind} test function changes sign (located on "
                                        "the branch)", "u": x}
    if run.has["describe"]:
        got = disc.describe(kind, x, p, disc.point(x, p))
        if got is None:
            why = disc.why
            if why:
                warnings.warn(f"a {kind} test function changes sign at p = {p!r} but the "
                              f"check refutes the event: {why}: no event reported",
                              RuntimeWarning, stacklevel=5)
            return None
        fields.update(got)
    return Event(kind, p, 0, **fields)


def _parabola(curve: Curve, zs: list[np.ndarray]) -> float:
    """The fold's p: the vertex of the parabola p(s) through the last three points (s their
    arclength), or the middle of the last two where it has none between them (the last's p
    where it is the only one of its size)."""
    zs = [z for z in zs if z.size == zs[-1].size][-3:]
    if len(zs) < 2:
        return float(zs[-1][-1])
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


__all__ = ["continuation", "ContinuationOptions", "Predictor", "bordered_solve", "bordered_det",
           "newton_corrector", "tangent", "locate", "bisect_along", "VERTICAL"]
