# The stability verdict of an equilibrium, checked independently of the root finder.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The verdict ``stable`` of an equilibrium from its rightmost roots, verified.

The roots of :func:`dmi.analysis.roots` come from ARPACK's largest multipliers of the N-step
map (the equation's refined from them by Newton): nothing in them says that no root lies further
right, nor how far the rightmost one's real part can be trusted.  The verdict is decided here by a
check that does not use the root finder:

- **The equation** (``of="equation"``): the number Z of roots of det Delta(lambda) in Re lambda
  > sigma, by the argument principle (:func:`count_right`): the phase of det Delta along the line
  Re lambda = sigma from 0 to i Omega (the real system's other half is its conjugate), closed by
  the large-|lambda| asymptotics det Delta = lambda^m (1 + O(q)), exact beyond Omega =
  (|B| + bound of |Hhat|) / q, q = 1.5^(1/m) - 1, where det(I + E) stays within 1/2 of 1 and
  adds no turn.  The line is sampled adaptively: an interval is halved until the phase changes by
  at most pi/4 across it and its length times |d log det Delta / d lambda| at both ends is at
  most :data:`STEP` (so a root near the line, where the log-derivative grows, is resolved).
- **The scheme**: a second, independent eigen-solve (ARPACK with another start vector and a
  wider Krylov space, :data:`SECOND_MULTIPLIERS` multipliers) must find the same largest
  multiplier; its residual |M^N v - mu v|, by a fresh product, is the multiplier's error: a
  backward error, which a multiplier of a far-from-normal map can exceed (its condition number
  is not estimated; a verdict within a few such errors of the axis deserves a plain run).  A
  state of at most 64 values has all its roots from the dense one-step matrix: its error is the
  least singular value of M - z I times z's condition number (from both eigenvectors).

The verdict (:func:`check`): False when the rightmost root's Re lambda exceeds its error (or a
root the finder missed is counted, or found, beyond its error); True when Re lambda_0 < -error
and no root lies right of sigma = Re lambda_0 / 2 (at most 1 / tau from the axis); otherwise None
with the reason.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as sla

from ..._solver import Solver
from ..core.blas import _one_blas_thread
from ..core.model import Linearisation
from .equation import ROOT_TOL, Characteristic
from .stability import is_dense, rightmost_of

#: Samples of the line at most (beyond them the count is left undecided).
MAX_SAMPLES = 400_000
#: An interval of the line is halved while its length times |d log det Delta / d lambda| exceeds
#: this.
STEP = 0.3
#: The scheme's second eigen-solve: multipliers asked, Krylov space (at least), start vector.
SECOND_MULTIPLIERS = 4
SECOND_KRYLOV = 40
SECOND_SEED = 5


@dataclass
class RootVerdict:
    """A verdict and how it was reached.

    Attributes
    ----------
    stable : bool or None
        True: verified stable; False: verified unstable; None: not decided (``reason``).
    reason : str
        How the verdict was reached, or why there is none.
    error : float
        The error of Re lambda_0, the rightmost root's real part (1 / time unit; nan without one).
    counted : int or None
        ``of="equation"``: the roots counted right of the line the count used (None: no count).
    """
    stable: bool | None
    reason: str
    error: float = math.nan
    counted: int | None = None


def _eval(ch: Characteristic, sigma: float, w: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray]:
    """(phase of det Delta, |d log det Delta / d lambda|) at lambda = sigma + i w."""
    lam = sigma + 1j * w
    D = lam[:, None, None] * np.eye(ch.m) + ch.B + ch.hhat(lam)
    dD = ch.prime(lam)
    sign, _ = np.linalg.slogdet(D)
    if np.any(sign == 0):
        raise np.linalg.LinAlgError
    g = np.trace(np.linalg.solve(D, dD), axis1=1, axis2=2)
    return np.angle(sign), np.abs(g)


def count_right(ch: Characteristic, sigma: float, max_samples: int = MAX_SAMPLES
                ) -> tuple[int | None, str]:
    """The number of roots of det Delta(lambda) with Re lambda > sigma, by the argument principle
    (see the module), and a sentence saying how; (None, why) when it cannot be counted: a root on
    the line, the samples' budget spent, or a phase that does not close on a whole number."""
    m = ch.m
    if m == 0:
        return 0, "no free component: det Delta = 1"
    omega = _omega(ch, sigma)
    if not math.isfinite(omega):
        return None, (f"the kernel's transform has no finite bound on Re lambda >= {sigma:.3g}")
    w = np.linspace(0.0, omega, int(min(max(512, math.ceil(ch.tau * omega)), max_samples // 2)))
    try:
        phase, g = _eval(ch, sigma, w)
        while True:
            dw = np.diff(w)
            dphi = np.angle(np.exp(1j * np.diff(phase)))
            bad = (dw * np.maximum(g[:-1], g[1:]) > STEP) | (np.abs(dphi) > np.pi / 4)
            if not bad.any():
                break
            if w.size + int(bad.sum()) > max_samples:
                return None, (f"the phase of det Delta along Re lambda = {sigma:.3g} is not "
                              f"resolved by {max_samples} samples up to |Im lambda| = "
                              f"{omega:.3g}")
            mid = 0.5 * (w[:-1] + w[1:])[bad]
            pm, gm = _eval(ch, sigma, mid)
            order = np.argsort(np.concatenate([w, mid]), kind="stable")
            w = np.concatenate([w, mid])[order]
            phase = np.concatenate([phase, pm])[order]
            g = np.concatenate([g, gm])[order]
    except np.linalg.LinAlgError:
        return None, f"a root lies on the line Re lambda = {sigma:.3g} (det Delta = 0 there)"
    turned = float(np.sum(np.angle(np.exp(1j * np.diff(phase)))))
    end = complex(sigma, omega)
    # arg(det Delta / lambda^m) at the line's end
    tail = float(np.angle(np.exp(1j * (phase[-1] - m * np.angle(end)))))
    z = (m * math.atan2(omega, sigma) + tail - turned) / math.pi
    count = round(z)
    if abs(z - count) > 0.05 or count < 0:
        return None, (f"the argument principle gave {z:.3f} roots right of Re lambda = "
                      f"{sigma:.3g}, not a whole number")
    return int(count), (f"{count} roots counted right of Re lambda = {sigma:.3g} (argument "
                        f"principle, {w.size} samples up to |Im lambda| = {omega:.3g})")


def _rightmost(lam: np.ndarray) -> complex | None:
    """The rightmost finite root (None without one)."""
    f = lam[np.isfinite(lam)]
    return complex(f[np.argmax(f.real)]) if f.size else None


def equation_verdict(lin: Linearisation, lam: np.ndarray) -> RootVerdict:
    """The verdict of the equation's roots ``lam`` at ``lin``'s equilibrium (see the module)."""
    lam0 = _rightmost(lam)
    reach = 1.0 if lam0 is None else 1.5 * float(np.max(np.abs(lam[np.isfinite(lam)]))) + 1.0
    ch = Characteristic(lin, reach)
    if ch.m == 0:
        return RootVerdict(True, "the resolvent holds every component: no root", 0.0, 0)
    if lam0 is None:
        err, base = math.nan, 1.0 / lin.tau
    else:
        try:
            err = abs(ch.newton_step(lam0))
        except np.linalg.LinAlgError:
            err = 0.0
        err = max(err, ROOT_TOL * max(1.0, abs(lam0)))
        where = f"the rightmost root {lam0:.10g} (error {err:.2g})"
        if lam0.real > err:
            return RootVerdict(False, f"{where} has Re lambda beyond its error", err)
        if lam0.real >= -err:
            return RootVerdict(None, f"{where} lies on the imaginary axis within its error: the "
                               "linearisation does not decide (the nonlinear terms do); take p "
                               "away from the stability boundary, or simulate", err)
        base = -lam0.real
    sigma = -min(0.5 * base, 1.0 / lin.tau)
    ch = Characteristic(lin, max(reach, _omega(ch, sigma)))
    count, how = count_right(ch, sigma)
    if count is None:
        return RootVerdict(None, f"the roots right of the line could not be counted: {how}; "
                           "the verdict needs that count (compare roots with a larger count)",
                           err)
    if count == 0:
        return RootVerdict(True, f"Re lambda_0 < -error and {how}", err, 0)
    right = max(err if math.isfinite(err) else 0.0, 1e-8)
    more, how2 = count_right(ch, right)
    if more:
        return RootVerdict(False, f"{more} roots counted right of Re lambda = {right:.3g} that the "
                           "root finder did not find (it found "
                           f"{np.round(lam[:4], 6)!r}): ask for more roots (count=) or a smaller "
                           "h, so that the scheme's roots reach them", err, more)
    return RootVerdict(None, f"{how}, roots the root finder did not find, none right of "
                       f"Re lambda = {right:.3g} ({how2}): ask for more roots (count=)", err,
                       count)


def _omega(ch: Characteristic, sigma: float) -> float:
    """Omega: beyond it (|lambda| >= Omega, Re lambda >= sigma) |det(I + E) - 1| <= 1/2, E =
    S^-1 (B + Hhat(lambda)) S / lambda, |E| <= q = 1.5^(1/m) - 1; S the diagonal balancing of B
    (det Delta does not change under it, the bound does: a stiffness omega^2 beside a 1 becomes
    omega beside omega)."""
    q = 1.5 ** (1.0 / max(ch.m, 1)) - 1.0
    if ch.m == 0:
        return 1.0
    _, (d, _) = scipy.linalg.matrix_balance(ch.B, permute=False, separate=True)
    Bs = ch.B * (d[None, :] / d[:, None])
    return max((float(np.linalg.norm(Bs, 2)) + ch.bound(sigma, d)) / q, 2.0 * abs(sigma), 1.0)


def _dense_error(lin: Linearisation, lam0: complex) -> float:
    """The error of Re lambda_0 from the dense one-step matrix M: the backward error of
    z_0 = e^(lambda_0 h) (the least singular value of M - z_0 I, and rounding) times z_0's
    condition number |x| |y| / |y^H x| (x, y its right and left eigenvectors: M is far from
    normal for a delay), over |z_0| h."""
    I = np.eye(lin.dim)
    M = np.column_stack([lin.apply(I[:, j], 1) for j in range(lin.dim)])
    z0 = complex(np.exp(lam0 * lin.h))
    s = scipy.linalg.svdvals(M - z0 * I)[-1]
    eps = np.finfo(float).eps
    w, Y, X = scipy.linalg.eig(M, left=True, right=True)
    j = int(np.argmin(np.abs(w - z0)))
    x, y = X[:, j], Y[:, j]
    overlap = abs(np.vdot(y, x))
    cond = np.linalg.norm(x) * np.linalg.norm(y) / overlap if overlap > 0 else math.inf
    return float(cond * (s + 4 * eps * np.linalg.norm(M, 2)) / (abs(z0) * lin.h))


def scheme_verdict(lin: Linearisation, lam: np.ndarray, dense: bool) -> RootVerdict:
    """The verdict of the scheme's roots ``lam`` (``dense``: all of them were computed from the
    one-step matrix) at ``lin``'s equilibrium (see the module)."""
    lam0 = _rightmost(lam)
    if dense:
        if lam0 is None:
            return RootVerdict(True, "every multiplier is 0", 0.0)
        err = _dense_error(lin, lam0)
        how = f"all {lin.dim} roots from the one-step matrix"
    else:
        dim, N = lin.dim, lin.N
        tauN = N * lin.h
        k = min(SECOND_MULTIPLIERS, dim - 2)
        op = sla.LinearOperator((dim, dim), matvec=lambda v: lin.apply(np.real(v), N),
                                dtype=float)
        try:
            with _one_blas_thread():
                mu, V = sla.eigs(op, k=k, which="LM", ncv=min(dim, max(2 * k + 1, SECOND_KRYLOV)),
                                 tol=0, maxiter=50 * dim,
                                 v0=np.random.default_rng(20260529 + SECOND_SEED)
                                 .standard_normal(dim))
        except sla.ArpackError as e:
            return RootVerdict(None, f"the second eigen-solve that checks the roots failed ({e}): "
                               "the verdict is not verified")
        i = int(np.argmax(np.abs(mu)))
        v = V[:, i] / np.linalg.norm(V[:, i])
        r = float(np.linalg.norm(lin.apply(v.real, N) + 1j * lin.apply(v.imag, N) - mu[i] * v))
        top = abs(complex(mu[i]))
        if top == 0:
            return RootVerdict(True, "every multiplier is 0", 0.0)
        re1 = math.log(top) / tauN
        err1 = (r + 1e-13 * top) / (top * tauN)
        first = -math.inf if lam0 is None else lam0.real
        if re1 > first + err1 + 1e-9 * max(1.0, abs(re1)):
            if re1 > err1:
                return RootVerdict(False, f"a second eigen-solve found a multiplier of modulus "
                                   f"{top:.10g} (Re lambda = {re1:.6g}, error {err1:.2g}) that "
                                   f"the root finder missed (its rightmost root {lam0}): ask for "
                                   "more roots (count=)", err1)
            return RootVerdict(None, f"a second eigen-solve found a multiplier of modulus "
                               f"{top:.10g} (Re lambda = {re1:.6g} within its error {err1:.2g} "
                               f"of the axis) that the root finder missed (its rightmost root "
                               f"{lam0}): ask for more roots (count=)", err1)
        if re1 < first - err1 - 1e-9 * max(1.0, abs(first)):
            return RootVerdict(None, f"a second eigen-solve's largest multiplier (Re lambda = "
                               f"{re1:.6g}, error {err1:.2g}) falls short of the rightmost root "
                               f"{lam0:.10g}: the two eigen-solves disagree (ask for more roots, "
                               "count=)", err1)
        err = err1 + abs(re1 - first)
        how = (f"a second eigen-solve ({k} multipliers, another start vector) agrees on the "
               "largest multiplier")
    where = f"the rightmost root {lam0:.10g} (error {err:.2g}; {how})"
    if lam0.real > err:
        return RootVerdict(False, f"{where} has Re lambda beyond its error", err)
    if lam0.real < -err:
        return RootVerdict(True, f"{where} has Re lambda < -error", err)
    return RootVerdict(None, f"{where} lies on the imaginary axis within its error: the "
                       "linearisation does not decide (the nonlinear terms do); take p away "
                       "from the stability boundary, or simulate", err)


def check(lin: Linearisation, lam: np.ndarray, of: str, dense: bool) -> RootVerdict:
    """The verified verdict of the roots ``lam`` (rightmost first) at ``lin``'s equilibrium."""
    if of == "equation":
        return equation_verdict(lin, lam)
    return scheme_verdict(lin, lam, dense)


#: The verdict of roots not verified (``verify=False``).
UNVERIFIED = RootVerdict(None, "not verified (verify=False): the roots are ARPACK's Ritz values "
                         "without an error bound")


def roots_verdict(factory: Callable[[], Solver], u: object, args: tuple, count: int, tol: float,
                  of: str, verify: bool, lam: np.ndarray | None = None
                  ) -> tuple[np.ndarray, RootVerdict]:
    """The ``count`` rightmost roots at the equilibrium u of the model ``factory()`` (``lam``:
    those already computed) and their verdict, verified (:func:`check`) or not
    (:data:`UNVERIFIED`); the errors of :class:`Linearisation` (u not an equilibrium to tol, a
    kink)."""
    with Linearisation(factory, u, args, tol, of) as lin:
        if lam is None:
            lam = rightmost_of(lin, int(count), of)
        if not verify:
            return lam, UNVERIFIED
        return lam, check(lin, lam, of, is_dense(lin, count))


__all__ = ["UNVERIFIED", "RootVerdict", "check", "count_right", "equation_verdict",
           "roots_verdict", "scheme_verdict"]
