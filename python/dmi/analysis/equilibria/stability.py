# Characteristic roots of an equilibrium of the scheme (or of the equation).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis.roots (see docs/stability.md for the method): the rightmost roots of a
linearisation, from the dense one-step matrix or by Arnoldi on the N-step map (:func:`is_dense`
says which), refined to the equation's where asked.  The Hopf point of a one-parameter model is
:mod:`dmi.analysis.equilibria.crossing`'s."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.linalg
import scipy.sparse.linalg as sla

from ..._solver import Solver
from ..core.blas import _one_blas_thread
from ..core.model import Linearisation, call_make
from .equation import equation_roots

#: At most this many state dimensions n N: the one-step matrix is formed and its eigenvalues taken
#: directly (Arnoldi needs a state larger than the roots asked for).
DENSE_MAX = 64
#: Where ARPACK fails twice, the one-step matrix is formed up to this n N.
DENSE_FALLBACK = 2000
#: A tau-multiplier below this fraction of the largest one is taken as 0 (root -inf).
ZERO = 1e-13


def _seed(dim: int, attempt: int = 0) -> np.ndarray:
    """A fixed start vector for Arnoldi (the same roots on every call)."""
    return np.random.default_rng(20260529 + attempt).standard_normal(dim)


def _one_step_roots(lin: Linearisation, count: int) -> np.ndarray:
    """All roots from the dense one-step matrix (small states only)."""
    I = np.eye(lin.dim)
    M = np.column_stack([lin.apply(I[:, j], 1) for j in range(lin.dim)])
    z = scipy.linalg.eigvals(M)
    # as in _arnoldi_roots, 0 where |z|^N < ZERO max|z|^N (written without the powers: they
    # overflow a double for |z| > 1.43 at N = 2000)
    live = (np.abs(z) > 0) & (np.abs(z) >= ZERO ** (1.0 / lin.N) * np.max(np.abs(z)))
    lam = np.full(len(z), -np.inf, dtype=complex)   # a multiplier 0: root -inf (log(0) / h in
    lam[live] = np.log(z[live].astype(complex)) / lin.h   # complex arithmetic is nan, not -inf)
    return lam


def _branch(logmu: complex, z: complex, N: int, h: float) -> tuple[complex, float]:
    """(lambda, miss): lambda = (log(mu) + 2 pi i k) / (N h) on the branch k where
    N log(z) = log(mu) + 2 pi i k + e, miss = |e|; lambda nan if miss > 0.5 (z belongs to another
    mu; deep multipliers, 1e-7 of the largest, miss by 1e-2, as Arnoldi resolves them)."""
    if z == 0:
        return complex(np.nan, np.nan), np.inf
    d = N * np.log(complex(z)) - logmu
    turns = round(d.imag / (2 * np.pi))
    miss = abs(d - 2j * np.pi * turns)
    if miss > 0.5:
        return complex(np.nan, np.nan), miss
    return (logmu + 2j * np.pi * turns) / (N * h), miss


def _arnoldi_roots(lin: Linearisation, count: int) -> np.ndarray:
    """The rightmost roots from the N-step map M^N (Arnoldi), each one's branch of log from the
    one-step map M: Im lambda beyond 2 pi / tau."""
    dim, N, h = lin.dim, lin.N, lin.h
    k = min(count + 2, dim - 2)
    op = sla.LinearOperator((dim, dim), matvec=lambda v: lin.apply(np.real(v), N), dtype=float)
    ncv = min(dim, max(2 * k + 1, 20))
    failure = None
    for ncv_try, seed in ((ncv, 0), (min(dim, 2 * ncv + 1), 1)):
        try:
            mu, V = sla.eigs(op, k=k, which="LM", ncv=ncv_try, tol=0, v0=_seed(dim, seed),
                             maxiter=50 * dim)
            break
        except sla.ArpackError as e:   # also ArpackNoConvergence
            failure = e
    else:
        # ARPACK breaks down where the N-step map has few nonzero multipliers (a resolvent
        # holding most components, as sticking friction does): the one-step matrix, if small
        if dim <= DENSE_FALLBACK:
            return _one_step_roots(lin, count)
        raise RuntimeError(f"dmi.analysis: Arnoldi failed on the {N}-step map (n N = {dim}, "
                           f"{k} multipliers asked): {failure}") from None
    big = np.max(np.abs(mu))
    lam = np.full(len(mu), -np.inf, dtype=complex)  # multipliers below ZERO of the largest:
    logmu = np.log(mu.astype(complex), where=np.abs(mu) >= ZERO * big,  # rounding errors of 0
                   out=np.zeros(len(mu), dtype=complex))
    # M commutes with M^N: the vector v of a simple multiplier mu is M's eigenvector too, of
    # z = v^H M v / v^H v with z^N = mu.  A conjugate pair costs one vector.  A multiple mu (two
    # z with the same z^N) has vectors that mix its z's: then M on the span of all the vectors.
    live = mu[np.abs(mu) >= ZERO * big]
    gaps = np.abs(live[:, None] - live[None, :]) + np.eye(len(live)) * big
    multiple = np.any(gaps <= 1e-6 * np.maximum.outer(np.abs(live), np.abs(live)))
    for i in np.argsort(-np.abs(mu)):
        if abs(mu[i]) < ZERO * big:
            continue
        if multiple:
            lam[i] = np.nan
            continue
        pair = np.nonzero((np.abs(mu - np.conj(mu[i])) <= 1e-12 * abs(mu[i])) & ~np.isinf(lam.real)
                          & ~np.isnan(lam.real))[0]
        if mu[i].imag != 0 and len(pair):
            lam[i] = np.conj(lam[pair[0]])
            continue
        v = V[:, i]
        z = np.vdot(v, lin.apply_complex(v[:, None], 1)[:, 0]) / np.vdot(v, v)
        lam[i] = _branch(logmu[i], z, N, h)[0]
    if np.any(np.isnan(lam.real)):   # M on the span of the vectors
        Q, _ = np.linalg.qr(V)
        z = scipy.linalg.eigvals(Q.conj().T @ lin.apply_complex(Q, 1))
        free = list(z)
        for i in np.nonzero(np.isnan(lam.real))[0]:   # each mu its nearest unused z
            cand = [_branch(logmu[i], zj, N, h) for zj in free]
            if cand:   # (no match: an inaccurate Ritz vector, refused if among count)
                j = min(range(len(cand)), key=lambda j: cand[j][1])
                lam[i] = cand[j][0]
                if not np.isnan(lam[i].real):
                    free.pop(j)
    return lam


def _order(lam: np.ndarray) -> np.ndarray:
    """Rightmost first; of a conjugate pair, Im >= 0 first."""
    key = np.round(lam.real, 9) if len(lam) else lam.real
    idx = np.lexsort((-lam.imag, -key))
    return lam[idx]


def is_dense(lin: Linearisation, count: int) -> bool:
    """The rule of the root finder: all roots from the dense one-step matrix when the state has
    at most max(DENSE_MAX, count + 4) values (Arnoldi needs k < n N - 1), else Arnoldi."""
    return lin.dim <= max(DENSE_MAX, count + 4)


def rightmost(lin: Linearisation, count: int) -> np.ndarray:
    """The count rightmost roots of a linearisation."""
    if count > lin.dim:
        raise ValueError(f"dmi.analysis: count = {count} roots asked; the step map has n N = "
                         f"{lin.dim}")
    with _one_blas_thread():
        lam = _one_step_roots(lin, count) if is_dense(lin, count) else _arnoldi_roots(lin, count)
    lam = _order(lam)
    if np.any(np.isnan(lam[:count])):
        raise RuntimeError(f"dmi.analysis: the one-step map has no multiplier z with z^{lin.N} = "
                           "one of the N-step map's rightmost multipliers in Arnoldi's Ritz space "
                           "(inaccurate vectors); try another count")
    return lam[:count]


def check_of(of: str) -> str:
    """``of`` checked: ``"scheme"`` or ``"equation"``."""
    if of not in ("scheme", "equation"):
        raise ValueError(f"dmi.analysis: of = {of!r}: give 'scheme' (the roots that match "
                         "simulation) or 'equation' (the continuous equation's)")
    return of


def rightmost_of(lin: Linearisation, count: int, of: str = "scheme") -> np.ndarray:
    """The count rightmost roots of the scheme, or refined to the equation's (re-ordered)."""
    lam = rightmost(lin, count)
    return _order(equation_roots(lin, lam)) if of == "equation" else lam


def roots(make: Callable[[float], Solver], p: float, u_eq: Any, count: int = 10, *,
          tol: float = 1e-9, of: str = "scheme") -> np.ndarray:
    """The rightmost characteristic roots of an equilibrium.

    The roots lambda (1 / time unit) of the scheme's step map linearised at the constant history
    ``u_eq``: lambda = log(z) / h for a multiplier z of the one-step map.  Re lambda is the mode's
    growth rate, Im lambda its angular frequency (radians / time unit), not reduced modulo
    2 pi / tau.  A root -inf is a multiplier 0 (a component held by the resolvent).

    Parameters
    ----------
    make : callable
        The model: ``make(p) -> dmi.Solver`` (any rhs, resolvent, friction or box, kernel,
        convolution method), configured, not initialised.
    p : float
        The parameter.
    u_eq : array_like or callable
        The equilibrium, shape (n,), or a function ``u_eq(p)``.
    count : int
        How many roots.
    tol : float
        The equilibrium's residual tolerance: one step may move u_eq by tol max(1, |u_eq|,
        |u_eq - X*|).
    of : {"scheme", "equation"}
        ``"equation"``: u_eq is the equation's equilibrium (the continuous integral), and each
        root is refined to one of the continuous equation, det Delta(lambda) = 0
        (:mod:`dmi.analysis.equilibria.equation`), to |dlambda| <= 1e-10 max(1, |lambda|); a root that
        cannot be refined is nan, with a :class:`dmi.analysis.equilibria.equation.RefinementWarning`
        saying why.

    Returns
    -------
    numpy.ndarray of complex, shape (count,)
        Rightmost first; of a conjugate pair, Im >= 0 first.

    Raises
    ------
    ValueError
        u_eq is not an equilibrium (relative residual above ``tol``), count < 1, ``of`` unknown.
    KinkError
        The resolvent has a kink at the equilibrium (a ValueError).
    Exception
        The model's own, when ``make(p)`` fails (a note names the call).
    """
    if int(count) != count or count < 1:
        raise ValueError(f"dmi.analysis.roots: count = {count!r}: must be an integer >= 1")
    check_of(of)
    with Linearisation(lambda: call_make(make, p), u_eq, (p,), tol, of) as lin:
        return rightmost_of(lin, int(count), of)


__all__ = ["check_of", "is_dense", "rightmost", "rightmost_of", "roots"]
