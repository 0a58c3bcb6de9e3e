# Floquet multipliers of periodic orbits that carry the stick/slip switching, verified.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Floquet multipliers of a periodic orbit of the scheme, right at stick/slip transitions, and
verified before they are reported.

The exact derivative of the step map is piecewise: a perturbation too small to move a switch
(a velocity reversal, the start or end of a stick) by one step sees the switch frozen at its
step, so the product of the step derivatives leaves out the saltation terms of the continuous
system, and its multipliers are wrong by O(1) however small h is.

Here the monodromy operator is applied by *central differences with a step that moves the
switches by many steps*: x +- eps v (|v|_inf = 1), with eps = c A M^(-1/3) (at most 0.05 A),
A the orbit's amplitude and M = period / h the steps per period.  The quotient is the continuous
system's linearisation (with its saltation) up to two errors: the switch's rounding to a step, at most
(jump) h / eps, and the curvature, O(eps^2) (central differences); eps ~ A h^(1/3) balances
them, error O(h^(2/3)) (0.2 % at M = 2e4 against Den Hartog's saltation oracle, see
tests/python/analysis/shooting/test_orbit_oracles.py).  Multipliers of a stuck phase come out exactly
0: a perturbation that keeps the stick is wiped out.

The leading multipliers (:func:`floquet_verdict`, :func:`floquet_multipliers`) are the
eigenvalues of largest modulus of that operator (a ``scipy.sparse.linalg.LinearOperator``) by ARPACK
(``scipy.sparse.linalg.eigs``, implicitly restarted Arnoldi) on a Krylov space wide enough for a
ring of multipliers of nearly equal modulus (a long memory), the whole matrix for states of at
most 64 values.  Each Ritz pair (mu, v) is then *verified* by fresh products: its residual
r = |A v - mu v|_2 (|v|_2 = 1), and the operator's own noise on v, eta = |A_eps v -
A_(eps/2) v|_2 (the same product at half the difference step: the switches' rounding and the
curvature change, the linear part does not).  Its error bound is r + eta (the pair's backward
error plus the noise; the eigenvalue's own condition number is not included); nan where that
exceeds 0.5.  ARPACK's restarts combine products of many directions, which a nonlinear
difference operator does not add up exactly: the fresh residual, not ARPACK's estimate, is the
pair's accuracy (2e-4 on the Bagley-Torvik example's ring, against 1e-6 asked of ARPACK).

The verdict ``stable``: False when a verified multiplier other than the trivial one has
|mu| - 1 above its error; True when the Krylov iteration converged, all pairs are verified and
the largest nontrivial |mu| + error < 1; where the largest nontrivial |mu| - 1 lies inside its
error, or the pairs are not all verified (or, on an autonomous orbit, the trivial pair's error
leaves room for a second multiplier beside 1), a *plain run* decides: the orbit perturbed
along the Ritz vectors (by ``Verify.kick`` of its amplitude, and at least the difference step;
across the orbit, for an autonomous one: the shift along it left out of the kick), run
``Verify.periods`` periods; its distance from the orbit period by period (across the orbit,
for an autonomous one: a scheme's stick-slip orbit kicked by less than a step's worth of switch
motion drifts along itself by fractions of a step for hundreds of periods and locks on again),
the growth rate fitted to its log above the floor (where a run that only drifts along the
orbit lies), or the bound of a run that falls to the floor and stays there.  Growth beyond
three standard errors and by 5 % or more over the periods fitted: False; decay so (and the
pairs verified): True.
Otherwise ``None``, with a :class:`StabilityWarning` saying why: never True unverified.

The trivial multiplier of an autonomous orbit (a shift along the orbit) is the Ritz pair whose
vector is most nearly parallel to the orbit's velocity (the window of U'), not the multiplier
nearest 1.
"""
from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import scipy.linalg as sl
import scipy.sparse.linalg as sla


#: c in eps = c A min(M^(-1/3), FD_CAP) (see the module's docstring).
FD_FACTOR = 1.0
#: Few steps a period (M < 8000) have no switch to resolve finely; the cap keeps eps / A <= 5 %
#: there, so that the curvature error O((eps / A)^2) of a mildly nonlinear orbit stays below
#: 0.3 % (an orbit where no resolvent acts takes the small step, see :func:`fd_step`).
FD_CAP = 0.05


class PeriodMap(Protocol):
    """What the multipliers read of the M-step map of an orbit: a
    :class:`dmi.analysis.scheme.stepmap.StepMap` (this module does not import it, so that the
    orbit's record, which imports both, stays two modules deep)."""
    p: float
    M: int
    L: int
    n: int
    h: float
    evaluations: int

    @property
    def dim(self) -> int: ...

    def __call__(self, x: np.ndarray) -> np.ndarray: ...

    def trajectory(self, x: np.ndarray, periods: int = 1) -> np.ndarray: ...

    def trajectory_terms(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


def fd_step(F: PeriodMap, x: np.ndarray, U: np.ndarray | None = None,
            X: np.ndarray | None = None) -> float:
    """The difference step (state units) at the fixed point x, from its trajectory ``U`` and the
    resolvent's arguments ``X`` (:meth:`StepMap.trajectory_terms`, else one run of M steps).

    - An orbit that carries switches (a velocity reversal, a stick, a contact that starts or
      ends: some component where the resolvent acts reaches 0 or changes sign): eps = FD_FACTOR
      A min(M^(-1/3), FD_CAP), A the largest half range (max - min) / 2 of a component over the
      period, large enough to move the switches by many steps (see the module).
    - An orbit with no switch to carry, where the map is smooth: the usual eps_machine^(1/3)
      max(1, |x|) of central differences, at most a tenth of the orbit's *margin*, its distance
      from the nearest switch: the least |U_i| over the period of the components where the
      resolvent acts (X_i != U_i: a friction component that slips throughout, whose velocity
      never reaches the dead zone).  So a perturbed run of a pure-slip orbit near stick onset
      slips too, and its multipliers are the smooth map's.  This covers an equilibrium (a
      constant orbit) and an orbit where no resolvent acts at all (X = U^(p+1))."""
    if U is None or X is None:
        U, X = F.trajectory_terms(x)
    A = float(np.max(0.5 * (U.max(axis=0) - U.min(axis=0))))
    scale = max(1.0, float(np.max(np.abs(U))))
    smooth = float(np.finfo(float).eps) ** (1 / 3) * scale
    if not A > 1e-9 * scale:
        return smooth
    u1 = U[1:]
    acts = np.any(X != u1, axis=0)             # components the resolvent moves somewhere
    if not acts.any():
        return smooth
    v = u1[:, acts]
    if np.all((v > 0).all(axis=0) | (v < 0).all(axis=0)):   # each keeps its sign
        margin = float(np.min(np.abs(v)))      # no switch: the distance to the nearest one
        return min(smooth, 0.1 * margin)
    return FD_FACTOR * A * min(F.M ** (-1.0 / 3.0), FD_CAP)


def monodromy_operator(F: PeriodMap, x: np.ndarray, eps: float | None = None,
                       central: bool = True) -> sla.LinearOperator:
    """The linearisation of the M-step map F at its fixed point x by differences of step
    ``eps`` (default :func:`fd_step`) along v / |v|_inf: central (2 evaluations, 2 M steps, a
    product), or forward from F(x) = x (1 evaluation; curvature error O(eps) instead of
    O(eps^2))."""
    x = np.asarray(x, dtype=float)
    e = fd_step(F, x) if eps is None else float(eps)
    Fx = None if central else F(x)

    def mv(v: np.ndarray) -> np.ndarray:
        v = np.asarray(v).ravel()
        if np.iscomplexobj(v):
            return mv(v.real) + 1j * mv(v.imag)
        nv = float(np.max(np.abs(v)))
        if nv == 0.0:
            return np.zeros_like(v)
        d = (e / nv) * v
        if Fx is None:
            return (F(x + d) - F(x - d)) * (nv / (2 * e))
        return (F(x + d) - Fx) * (nv / e)

    return sla.LinearOperator((x.size, x.size), matvec=mv, dtype=float)


class StabilityWarning(RuntimeWarning):
    """A stability verdict left undecided (``stable`` None), or a multiplier left unverified: the
    message says which and why."""


@dataclass(frozen=True)
class Verify:
    """How :func:`floquet_verdict` verifies the leading multipliers (also ``verify=`` of
    :func:`floquet_multipliers`, :func:`dmi.analysis.periodic_orbit` and
    :func:`dmi.analysis.hopf_orbit`).

    Attributes
    ----------
    fixed_point_tol : float
        The state must be a fixed point: |F(x) - x|_inf <= fixed_point_tol max(1, |x|_inf),
        else ValueError (multipliers of a point that is no orbit mean nothing).
    krylov : int or None
        ARPACK's Krylov space (``ncv``); default min(dim, max(2 k + 1, 60)), k the pairs sought.
    products : int
        ARPACK's budget of operator products (each 2 runs of a period, central differences).
    tol : float
        ARPACK's relative tolerance on the Ritz pairs.
    periods : int
        The plain run's length (periods) where the verdict is left to it; 0: no plain run.
    kick : float
        The plain run's perturbation along the Ritz vectors: the state at t = 0 moved by kick A
        (across the orbit, the history by at most as much, on an autonomous orbit; A the
        orbit's largest half range, or max(1, |x|) for a constant orbit), and at least
        by the difference step (on an orbit with switches: smaller kicks see the scheme's
        switches frozen at their steps, where an orbit can drift along itself and lock on
        again).
    """
    fixed_point_tol: float = 1e-6
    krylov: int | None = None
    products: int = 3000
    tol: float = 1e-6
    periods: int = 200
    kick: float = 1e-3

    def __post_init__(self) -> None:
        for name in ("fixed_point_tol", "tol", "kick"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise ValueError(f"Verify: {name} = {v!r}; expected a finite number > 0")
        for name, least in (("products", 1), ("periods", 0)):
            v = getattr(self, name)
            if not (isinstance(v, int) and v >= least):
                raise ValueError(f"Verify: {name} = {v!r}; expected a whole number >= {least}")
        if self.krylov is not None and not (isinstance(self.krylov, int) and self.krylov >= 3):
            raise ValueError(f"Verify: krylov = {self.krylov!r}; expected None or a whole "
                             "number >= 3")


@dataclass
class Floquet:
    """The leading Floquet multipliers of a periodic orbit and the stability verdict, verified.

    Attributes
    ----------
    multipliers : numpy.ndarray of complex
        Largest |mu| first (dimensionless); below 1e-12 in modulus: 0 (a stuck phase's).
    errors : numpy.ndarray of float
        Each multiplier's error bound (its residual plus the operator's noise); nan where
        that exceeds 0.5 (no bound).
    vectors : numpy.ndarray of complex
        Shape (dim, k): the Ritz vectors, |v|_2 = 1, one for each multiplier.
    trivial : int or None
        An autonomous orbit: the index of its trivial multiplier (the vector along the orbit's
        velocity); None for a forced orbit, or when none of the pairs lies along the velocity.
    stable : bool or None
        True: verified stable; False: verified unstable; None: not decided (see ``reason``).
    reason : str
        How the verdict was reached, or why there is none.
    rate : float or nan
        The plain run's growth per period, when one was run (else nan).
    products : int
        Operator products spent (each 2 runs of a period, central differences).
    """
    multipliers: np.ndarray
    errors: np.ndarray
    vectors: np.ndarray = field(repr=False)
    trivial: int | None
    stable: bool | None
    reason: str
    rate: float = math.nan
    products: int = 0

    def nontrivial(self) -> np.ndarray:
        """The multipliers without the trivial one.

        Returns
        -------
        numpy.ndarray of complex
            ``multipliers`` less the trivial one (all of them for a forced orbit), largest
            |mu| first.
        """
        if self.trivial is None:
            return self.multipliers
        return np.delete(self.multipliers, self.trivial)


def check_fixed_point(F: PeriodMap, x: np.ndarray, tol: float) -> None:
    """ValueError when x is not a fixed point of F to tol max(1, |x|_inf) (the residual given)."""
    r = float(np.max(np.abs(F(x) - x)))
    scale = max(1.0, float(np.max(np.abs(x))))
    if not r <= tol * scale:
        raise ValueError(f"the state is not a fixed point of the {F.M}-step map at p = {F.p!r}: "
                         f"|F(x) - x|_inf = {r:.3g} ({r / scale:.3g} relative; tolerance "
                         f"{tol:g}, Verify.fixed_point_tol): the multipliers of a point that is "
                         "no orbit mean nothing; converge it first (periodic_orbit, "
                         "refine_orbit)")


def window_velocity(F: PeriodMap, U: np.ndarray) -> np.ndarray:
    """The velocity of the window along an M-periodic orbit: row i of the L rows (time
    (i - L + 1) h) is (U^(k+1) - U^(k-1)) / (2 h), k its step, U one period (M + 1 rows) read
    periodically; flattened (L n values)."""
    M = F.M
    k = np.arange(F.L) - (F.L - 1)
    P = np.asarray(U)[:M]
    return ((P[(k + 1) % M] - P[(k - 1) % M]) / (2 * F.h)).ravel()


def _pairs(A: sla.LinearOperator, k: int, opts: Verify, dim: int
           ) -> tuple[np.ndarray, np.ndarray, bool, str]:
    """(mu, V, converged, note): k Ritz pairs of largest modulus by ARPACK (the whole matrix
    for dim <= 64), |V[:, j]|_2 = 1."""
    if dim <= 64:
        mu, V = np.linalg.eig(A.matmat(np.eye(dim)))
        return mu, V, True, ""
    ncv = opts.krylov if opts.krylov is not None else max(2 * k + 1, 60)
    ncv = min(dim, max(ncv, k + 2))
    restarts = max(1, opts.products // max(1, ncv - k))
    v0 = np.random.default_rng(0).standard_normal(dim)
    try:
        mu, V = sla.eigs(A, k=k, ncv=ncv, which="LM", tol=opts.tol, maxiter=restarts, v0=v0)
        return mu, V, True, ""
    except sla.ArpackNoConvergence as e:
        note = (f"ARPACK converged {len(e.eigenvalues)} of {k} pairs in {opts.products} "
                f"products (Krylov space {ncv})")
        return e.eigenvalues, e.eigenvectors, False, note


def _verify_pairs(A: sla.LinearOperator, half: sla.LinearOperator, mu: np.ndarray,
                  V: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(errors, residuals, noises) of the pairs: the residual r = |A v - mu v|_2 by a fresh
    product, the operator's noise eta = |A v - half v|_2 (half: A at half the difference
    step), the error r + eta; nan where it exceeds 0.5 (no multiplier to speak of)."""
    err, res, noise = (np.full(mu.size, np.nan) for _ in range(3))
    for j in range(mu.size):
        if j and mu[j].imag and abs(mu[j] - np.conj(mu[j - 1])) <= 1e-12 * abs(mu[j]):
            err[j], res[j], noise[j] = err[j - 1], res[j - 1], noise[j - 1]   # a conjugate pair
            continue
        v = V[:, j] / np.linalg.norm(V[:, j])
        Av = A.matvec(v)
        res[j] = float(np.linalg.norm(Av - mu[j] * v))
        noise[j] = float(np.linalg.norm(Av - half.matvec(v)))
        if res[j] + noise[j] <= 0.5:
            err[j] = res[j] + noise[j]
    return err, res, noise


def off_orbit(B: np.ndarray, P: np.ndarray, h: float, autonomous: bool) -> float:
    """How far one period B (M rows) of a run lies from the orbit's period P (M rows, the same
    steps of the orbit, read periodically): the median over the steps of |B - P|_2; on an
    autonomous orbit across the orbit only, after the best shift by whole steps (B's first row
    against every row of P, then the whole period within 8 steps of that) and by the fraction
    delta of a step along the velocity P' (least squares), so that a run that only drifts along
    the orbit comes out near 0 (the median passes over the few steps at a switch, where a shift
    by a fraction of a step is no multiple of P')."""
    P = np.asarray(P)
    if not autonomous:
        return float(np.median(np.linalg.norm(B - P, axis=1)))
    M = P.shape[0]
    j0 = int(np.argmin(np.sum((P - B[0]) ** 2, axis=1)))
    rows = np.arange(M)
    best = None
    for j in range(j0 - 8, j0 + 9):
        r = float(np.sum((B - P[(rows + j) % M]) ** 2))
        if best is None or r < best[0]:
            best = (r, j)
    idx = (rows + best[1]) % M
    Pj = P[idx]
    V = (P[(idx + 1) % M] - P[(idx - 1) % M]) / (2 * h)
    vv = float(np.sum(V * V))
    d = float(np.sum((B - Pj) * V)) / vv if vv > 0 else 0.0
    return float(np.median(np.linalg.norm(B - Pj - d * V, axis=1)))


def across_kick(w: np.ndarray, vel: np.ndarray, n: int) -> np.ndarray:
    """A kick of an autonomous orbit's window along w (L n values) with no shift along the
    orbit: w less its projection on the window's velocity ``vel`` (:func:`window_velocity`),
    scaled to |.|_inf = 1 over the window, its last row (the state at t = 0) replaced by that
    row's part across the velocity there, scaled to |.|_inf = 1 (where that part is nonzero), so
    that the state at t = 0 moves across the orbit by the whole kick and no value of the history
    by more."""
    w = np.array(w, dtype=float)
    vv = float(vel @ vel)
    if vv > 0:
        w = w - (float(w @ vel) / vv) * vel
    big = float(np.max(np.abs(w)))
    if big > 0:
        w = w / big
    r, v0 = np.array(w[-n:]), vel[-n:]
    if float(v0 @ v0) > 0:
        r = r - (float(r @ v0) / float(v0 @ v0)) * v0
    if float(np.max(np.abs(r))) > 1e-12:
        w[-n:] = r / float(np.max(np.abs(r)))
    return w


def growth_rate(F: PeriodMap, x: np.ndarray, v: np.ndarray, kick: float, periods: int,
                autonomous: bool = False, least: float = 0.0) -> tuple[float, float, int]:
    """(rate, standard error of its log, periods fitted) of a plain run from x + max(kick A,
    least) w (A the orbit's largest half range, max(1, |x|) for a constant orbit; ``least``: the
    difference step, so that the run sees the scale the multipliers describe, where a switch
    moves by many steps).

    w is Re(v) / |Re v_0|_inf (v_0: v's last row, the state at t = 0) on a forced orbit.  On an
    autonomous one, w is v across the orbit (:func:`across_kick`): a shift along the orbit is no
    distance across it, and the Ritz vectors' sum at t = 0 lies almost along the velocity (the
    trivial vector's), so that a kick along it barely leaves the orbit.

    d_k = :func:`off_orbit` of period k (across the orbit, for an autonomous one: a scheme's
    orbit can drift along itself by fractions of a step for hundreds of periods and lock on
    again), the rate exp(slope) of a least-squares line through log d_k over the periods where
    d_k lies between the floor and 0.1 A (beyond: not linear), the first third of those left
    out (the other modes fade); a run that falls to the floor and never comes back to a tenth of
    d_0: the bound (floor / d_0)^(1 / k) over the k periods it took (standard error 0); (nan,
    nan, 0) with fewer than 5 such periods.  The floor: 100 times the fixed point's residual
    |F(x) - x|, rounding, and on an autonomous orbit the distance across the orbit of a run that
    only drifts along it: d_0 of a run from the orbit shifted by half a step along its velocity
    (the worst fraction; a scheme's stick-slip orbit shifted by a fraction of a step is not the
    orbit shifted, its switches fall on other steps: on the Stribeck belt's orbit 1.6 times the
    shift's interpolation error h^2 |U''| / 8, which is kept as a least floor; one period only,
    since on an unstable orbit the shifted run leaves it too)."""
    U = F.trajectory(x)
    A = float(np.max(0.5 * (U.max(axis=0) - U.min(axis=0))))
    scale = max(1.0, float(np.max(np.abs(x))))
    if not A > 0:
        A = scale
    w = np.real(v) if np.max(np.abs(np.real(v))) >= np.max(np.abs(np.imag(v))) else np.imag(v)
    P = U[1:]
    M = F.M
    drift = 0.0
    if autonomous:
        vel = window_velocity(F, U)
        w = across_kick(w, vel, F.n)
        Q = np.concatenate([P[-1:], P, P[:1]])
        curv = float(np.median(np.linalg.norm(Q[2:] - 2 * Q[1:-1] + Q[:-2], axis=1))) / 8
        S = F.trajectory(x + 0.5 * F.h * vel)
        drift = max(curv, off_orbit(S[1:], P, F.h, True))
    else:
        now = float(np.max(np.abs(w[-F.n:])))     # the kick's size is that of the state at t = 0
        w = w / (now if now > 1e-3 * np.max(np.abs(w)) else np.max(np.abs(w)))
    floor = 100 * float(np.max(np.abs(F(x) - x))) + drift + 1e-13 * scale
    R = F.trajectory(x + max(kick * A, least) * w, periods)
    d = np.array([off_orbit(R[k * M + 1:(k + 1) * M + 1], P, F.h, autonomous)
                  for k in range(periods)])
    inside = (d > floor) & (d < 0.1 * A)
    last = int(np.argmin(inside)) if not inside.all() else inside.size   # the first period out
    if last < inside.size and d[last] <= floor and d[0] > floor \
            and np.max(d[last:]) <= max(floor, 0.1 * d[0]):
        # down to the floor, never back to a tenth of the kick (a stuck phase wipes a
        # perturbation out; what stays is the shift's interpolation as the run drifts along
        # the orbit): a decay by floor / d_0 at least over those periods, no fit
        return (floor / d[0]) ** (1 / max(1, last)), 0.0, max(1, last)
    first = last // 3
    if last - first < 5:
        return math.nan, math.nan, 0
    k = np.arange(first, last, dtype=float)
    y = np.log(d[first:last])
    X = np.column_stack([np.ones_like(k), k])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    resid = y - X @ coef
    se = math.sqrt(float(resid @ resid) / max(1, k.size - 2) / float(np.sum((k - k.mean()) ** 2)))
    return math.exp(float(coef[1])), se, last - first


#: An autonomous orbit's trivial pair with an error above this may hide a second multiplier
#: beside 1 (a noisy operator merges close eigenvalues: 1.012 hidden in 1.0005 +- 0.009 on a
#: stick-slip orbit): a True verdict then needs a plain run.
TRIVIAL_TOL = 1e-6


def _verdict(F: PeriodMap, x: np.ndarray, mu: np.ndarray, V: np.ndarray, err: np.ndarray,
             res: np.ndarray, trivial: int | None, converged: bool, why: list[str],
             opts: Verify, eps: float) -> tuple[bool | None, str, float]:
    """(stable, reason, plain run's rate) from the verified pairs (see the module)."""
    rest = [j for j in range(mu.size) if j != trivial]
    unver = [j for j in rest if not np.isfinite(err[j])]
    if unver:
        why.append(f"{len(unver)} of {len(rest)} multipliers without an error bound (residual "
                   f"{res[unver[0]]:.2g} at |mu| = {abs(mu[unver[0]]):.4g})")
    out = [j for j in rest if np.isfinite(err[j]) and abs(mu[j]) - 1 > err[j]]
    if out:
        j = out[0]
        return False, (f"unstable: |mu| = {abs(mu[j]):.6g} > 1 beyond its error {err[j]:.2g} "
                       "(verified)"), math.nan
    lead = rest[0] if rest else None
    inside = lead is not None and np.isfinite(err[lead]) and abs(mu[lead]) + err[lead] >= 1
    if lead is None:
        why.append("no multiplier besides the trivial one was found")
    elif inside:
        why.append(f"|mu| = {abs(mu[lead]):.6g} is within its error {err[lead]:.2g} of 1")
    if trivial is not None and err[trivial] > TRIVIAL_TOL:
        why.append(f"the trivial multiplier {mu[trivial]:.6g} has an error {err[trivial]:.2g} "
                   "that may hide a second multiplier beside 1")
    if not why and converged and lead is not None:
        return True, (f"stable: the largest |mu| = {abs(mu[lead]):.6g} plus its error "
                      f"{err[lead]:.2g} is below 1 (verified)"), math.nan
    reason = "; ".join(why) if why else "ARPACK did not converge"
    if opts.periods == 0:
        return None, f"undecided: {reason}", math.nan
    # a plain run from the orbit perturbed along every pair found (a multiplier hidden beside
    # one of them is excited too; the shift along the orbit cancels in e_k)
    w = sum((V[:, j] / np.max(np.abs(V[:, j])) for j in range(mu.size)),
            np.random.default_rng(1).standard_normal(x.size) if lead is None else 0.0)
    rate, se, span = growth_rate(F, x, w, opts.kick, opts.periods, trivial is not None, eps)
    what = (f"a plain run of {opts.periods} periods from the orbit perturbed along the Ritz "
            "vectors, its distance from the orbit")
    # decisive: beyond three standard errors, and by 5 % or more over the fit's periods
    g = math.log(rate) if math.isfinite(rate) else 0.0
    decisive = abs(g) > 3 * se and abs(g) * span >= 0.05
    if decisive and g > 0:
        return False, f"unstable: {what} grows by {rate:.6g} a period ({reason})", rate
    if decisive and g < 0 and converged and not unver and lead is not None:
        return True, f"stable: {what} decays by {rate:.6g} a period ({reason})", rate
    change = (f"changes by {rate:.6g} a period, not decisively" if math.isfinite(rate) else
              "stays between its floor and a tenth of the orbit's range for fewer than 5 "
              "periods, too few to fit a rate")
    return None, (f"undecided: {reason}; {what} {change} (Verify.periods, Verify.kick)"), rate


def floquet_verdict(F: PeriodMap, x: np.ndarray, count: int = 10, *, autonomous: bool = False,
            eps: float | None = None, central: bool = True, verify: Verify | None = None
            ) -> Floquet:
    """The leading Floquet multipliers of a periodic orbit, verified, and its stability verdict.

    See the module: ARPACK on the difference operator, each Ritz pair's residual judged against
    the operator's noise, a plain run where the verdict lies inside the errors.

    Parameters
    ----------
    F : StepMap
        The M-step map, e.g. ``StepMap(orbit.make, orbit.p, orbit.steps, orbit.rows)``.
    x : numpy.ndarray
        Its fixed point, e.g. ``orbit.state``.
    count : int
        How many multipliers (>= 1); an autonomous orbit gets one more, its trivial one.
    autonomous : bool
        An orbit of free period: its trivial multiplier (along the velocity) is found and left
        out of the verdict.
    eps : float, optional
        The difference step (state units), instead of :func:`fd_step`'s.
    central : bool
        Central differences (2 evaluations a product), else forward (1).
    verify : Verify, optional
        The verification's tolerances and budgets (default ``Verify()``).

    Returns
    -------
    Floquet
        Multipliers, their errors, the trivial one's index, the verdict and its reason.

    Raises
    ------
    ValueError
        x is not a fixed point of F (the residual is given), count < 1, verify not a Verify.
    """
    opts = Verify() if verify is None else verify
    if not isinstance(opts, Verify):
        raise ValueError(f"verify = {verify!r}: give a dmi.analysis.Verify (or None)")
    if int(count) != count or count < 1:
        raise ValueError(f"count = {count!r}: give a whole number of multipliers >= 1")
    x = np.asarray(x, dtype=float).ravel()
    if x.size != F.dim:
        raise ValueError(f"the state has {x.size} values; the map's is L n = {F.dim}")
    check_fixed_point(F, x, opts.fixed_point_tol)
    U, X = F.trajectory_terms(x)
    e = fd_step(F, x, U, X) if eps is None else float(eps)
    A = monodromy_operator(F, x, e, central)
    half = monodromy_operator(F, x, e / 2, central)
    dim = x.size
    want = min(int(count) + (1 if autonomous else 0), dim)
    k = min(want + 1, dim - 2) if dim > 64 else dim
    start = F.evaluations
    mu, V, converged, note = _pairs(A, k, opts, dim)
    order = np.argsort(-np.abs(mu), kind="stable")[:want]
    mu, V = np.asarray(mu, complex)[order], np.asarray(V, complex)[:, order]
    V = V / np.linalg.norm(V, axis=0)
    err, res, noise = _verify_pairs(A, half, mu, V)
    trivial = None
    why: list[str] = [note] if note else []
    if autonomous and mu.size:
        w = window_velocity(F, U)
        align = np.abs(V.conj().T @ w) / max(float(np.linalg.norm(w)), 1e-300)
        j = int(np.argmax(align))
        if align[j] >= 0.9:
            trivial = j
        else:
            why.append(f"no Ritz vector lies along the orbit's velocity (best alignment "
                       f"{align[j]:.2f}): the trivial multiplier is not among those found")
    mu[np.abs(mu) < 1e-12] = 0.0
    stable, reason, rate = _verdict(F, x, mu, V, err, res, trivial, converged, why, opts, e)
    products = (F.evaluations - start) // (2 if central else 1)
    return Floquet(mu, err, V, trivial, stable, reason, rate, products)


def floquet_multipliers(F: PeriodMap, x: np.ndarray, count: int = 10, *,
                        eps: float | None = None, central: bool = True,
                        autonomous: bool = False, verify: Verify | None = None) -> np.ndarray:
    """The leading Floquet multipliers of a periodic orbit, right at stick/slip transitions,
    verified (:func:`floquet_verdict`, which also gives their errors and the stability verdict).

    The monodromy operator by central differences with a step that moves the switches by many
    steps (:func:`fd_step`; the smooth step on an orbit with no switch to carry); its eigenvalues
    of largest modulus by ARPACK (the whole matrix for states of at most 64 values), each pair's
    error bound from a fresh residual and the operator's noise (``errors`` of
    :func:`floquet_verdict`).
    A multiplier without a bound (residual + noise above 0.5) is still returned, with a
    :class:`StabilityWarning` naming it.

    Parameters
    ----------
    F, x, eps, central : StepMap, numpy.ndarray, float, bool
        The map, its fixed point and the differences, as for :func:`floquet_verdict`.
    count : int
        How many multipliers.
    autonomous : bool
        An autonomous orbit (its trivial multiplier is found by its vector; it stays in the
        list).
    verify : Verify, optional
        Tolerances and budgets of the verification (default ``Verify(periods=0)``: no plain
        run, which only the verdict needs).

    Returns
    -------
    numpy.ndarray of complex, shape (count,)
        Largest |mu| first (dimensionless); below 1e-12 in modulus: 0 (a stuck phase's).

    Raises
    ------
    ValueError
        x is not a fixed point of F (the residual is given), count < 1.
    TypeError
        F not a map (an EquationOrbit carries its multipliers).
    """
    if not callable(F):
        raise TypeError(f"floquet_multipliers: a {type(F).__name__}: this takes a StepMap of the "
                        "scheme (an EquationOrbit, from collocate, carries its own .multipliers)")
    opts = Verify(periods=0) if verify is None else verify
    fl = floquet_verdict(F, x, count, autonomous=autonomous, eps=eps, central=central, verify=opts)
    bad = np.flatnonzero(~np.isfinite(fl.errors[:count]))
    if bad.size:
        warnings.warn(f"floquet_multipliers: {bad.size} of {min(count, fl.multipliers.size)} "
                      f"multipliers have a residual above 0.5 (no error bound): "
                      f"{np.array2string(fl.multipliers[bad], precision=4)}", StabilityWarning,
                      stacklevel=2)
    return fl.multipliers[:count]


def ritz(F: PeriodMap, x: np.ndarray, count: int, *, blocks: int = 2,
         start: np.ndarray | None = None, eps: float | None = None, central: bool = True
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(multipliers, Q, Z) of Rayleigh-Ritz on ``blocks`` blocks of a block Krylov space of b =
    count + 2 vectors (the continuation's multipliers along a branch, unverified; an orbit's
    own are :func:`floquet_verdict`'s): Q (dim, k) an orthonormal basis of the
    dominant invariant subspace of the Ritz matrix (its k >= count + 2 eigenvalues of largest
    modulus; k = b, or b + 1 when a complex pair straddles the cut) and Z = A Q, so that Q' Z is
    the Ritz matrix there and Z Q' the operator's rank-k approximation on that subspace (the
    continuation's Newton-Picard corrector, see :mod:`dmi.analysis.orbits`).  ``start``:
    vectors to begin from instead of random ones, and then a single block (its columns):
    Z of a nearby orbit (a continuation: k products a point, one step of subspace iteration
    along the branch).  A dense state (<= 64 values): Q = I and Z the whole matrix."""
    if start is None and blocks < 2:
        raise ValueError(f"blocks = {blocks!r}: the Krylov space needs 2 blocks or more (one "
                         "block of random vectors has Ritz values of a random subspace)")
    A = monodromy_operator(F, x, eps, central)
    dim = A.shape[0]
    count = min(count, dim)

    def image(V: np.ndarray) -> np.ndarray:
        return np.column_stack([A.matvec(V[:, j]) for j in range(V.shape[1])])

    if dim <= 64:
        Q = np.eye(dim)
        Z = image(Q)
        mu = np.linalg.eigvals(Z)
    else:
        if start is None:
            b = min(dim // blocks, count + 2)
            B = np.linalg.qr(np.random.default_rng(0).standard_normal((dim, b)))[0]
            ZB = last = image(B)
            for _ in range(blocks - 1):
                # the next block: the last image orthogonalised against B, as the last columns
                # of qr([B, last]) (orthogonal to B also where the image is rank-deficient, as
                # when stuck phases zero most directions out)
                V = np.linalg.qr(np.column_stack([B, last]))[0][:, B.shape[1]:]
                last = image(V)
                B, ZB = np.column_stack([B, V]), np.column_stack([ZB, last])
        else:
            B = np.linalg.qr(start)[0]
            ZB = image(B)
        mu, Q, Z = _dominant(B, ZB, min(count + 2, B.shape[1]))
    mu = np.asarray(mu, dtype=complex)
    mu[np.abs(mu) < 1e-12] = 0.0
    return mu[np.argsort(-np.abs(mu), kind="stable")][:count], Q, Z


def phase_free(mu: np.ndarray) -> np.ndarray:
    """The multipliers of an autonomous orbit without its phase multiplier: the one nearest 1
    (a shift along the orbit; 1 up to the scheme's and the differences' errors) left out."""
    mu = np.asarray(mu)
    if not mu.size:
        return mu
    return np.delete(mu, int(np.argmin(np.abs(mu - 1))))


def _dominant(B: np.ndarray, ZB: np.ndarray, k: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Rayleigh-Ritz on span B (orthonormal, ZB = A B): the Ritz values, and (B U, ZB U) for U the
    real Schur vectors of the k Ritz values of largest modulus (k + 1 if a pair straddles)."""
    S = B.T @ ZB
    mu = np.linalg.eigvals(S)
    if k >= S.shape[0]:
        return mu, B, ZB
    cut = np.sort(np.abs(mu))[::-1][k - 1] * (1 - 1e-12)
    try:
        T, U, sdim = sl.schur(S, output="real", sort=lambda re, im: math.hypot(re, im) >= cut)
    except np.linalg.LinAlgError:   # moduli tied at the cut, reordered past LAPACK's tolerance
        return mu, B, ZB
    return mu, B @ U[:, :sdim], ZB @ U[:, :sdim]
