# The delay integral of a periodic orbit over one period: the memory's periods folded onto one.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The folded delay integral of :mod:`dmi.analysis.collocation.system`; private to the package.

On a T-periodic u the delay integral over a memory of K = floor(tau / T) periods and a rest
r = tau - K T is one over a period:

    int_0^tau H(s) u(t - s) ds = int_0^T H_T(s) u(t - s) ds,
    H_T(s) = sum_{k=0}^{K-1} H(s + k T) + [s < r] H(s + K T),

H_T jumping at s = r.  For an exponential sum H(s) = Re sum_j e^(lambda_j s) (C_j - i D_j) the fold
is the same sum with each term's factor times sum_k e^(lambda_j k T) (plus e^(lambda_j K T) below
r): one evaluation a lag instead of K + 1.  The near part s^-beta C on (0, delta] belongs to k = 0
only: the folded kernel keeps it and the terms k >= 1 on (0, delta] (the *tail*, smooth) are a
second, short delay integral over [0, delta].  The period derivative at fixed theta = t / T (an
autonomous orbit) is (1 / T) int_0^tau s H(s) u'(t - s) ds; folded, the lag s + k T of period k
adds int_0^T M_T(s) u'(t - s) ds with M_T(s) = sum_k k H(s + k T) (a third integral, its matrix
unused).

Only a periodic u folds: the monodromy operator's past (a perturbation, not periodic) keeps the
whole memory (:func:`dmi.analysis.collocation.mesh.delay_matrix`).  Folded: an exponential sum,
tau > T, a near part shorter than T; otherwise :func:`fold_of` returns None.
"""
from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

from typing import Any

import numpy as np

#: Whether the periodic orbit's delay integral folds (a switch for benchmarks and tests: False
#: integrates over the whole memory; read when a Terms is made).
FOLD = True
#: Relative size (of max(tau, 1)) below which the rest r of the last period, or a folded jump's
#: distance to 0 or T, is dropped (the pieces of delay_matrix drop the same lengths).
FOLD_TOL = 1e-14
#: Exponentials a block of :func:`exp_sum` at most (about 256 kB: the block stays in the cache).
EXP_ENTRIES = 32768
#: The least exponent :func:`exp_sum` evaluates: e^-700 is about 1e-304, which times a term's
#: factor stays a normal double (a subnormal one, from e^-708 on, slows numpy's exp and the
#: products about 30 times; e^-745 underflows to 0).
EXP_LEAST = -700.0


def folding() -> bool:
    """Whether a periodic orbit's delay integral folds (FOLD, read at the call)."""
    return bool(FOLD)


def exp_sum(s: np.ndarray, a: np.ndarray, b: np.ndarray, C: np.ndarray, D: np.ndarray
            ) -> np.ndarray:
    """sum_j e^(a_j s) (C_j cos b_j s + D_j sin b_j s) (P, n, n) at the lags s (P,) (C, D:
    (k, n, n); or any (k, ...): then (P, ...), e.g. the entries of a pattern); no cos / sin when
    every b is 0, a constant where every a is 0 too.  The lags are taken in blocks of at most
    EXP_ENTRIES exponentials (those of a long memory's many lags at once would be an array that
    does not fit the cache), each exponent at least EXP_LEAST (an exponential that underflows to
    a subnormal costs numpy about 30 times one that does not): a term below it counts about
    1e-304 |C_j| (below the last bit of any sum that is not itself about 0), and a lag whose
    every exponent is below it gives exactly 0."""
    s = np.asarray(s, dtype=float).ravel()
    k, shape = a.size, (-1,) + C.shape[1:]
    osc = np.any(b)
    if not osc and not np.any(a):
        return np.broadcast_to(np.sum(C, axis=0), (s.size,) + C.shape[1:]).copy()
    Cf = C.reshape(k, -1)
    Df = D.reshape(k, -1) if osc else None
    rows = max(1, EXP_ENTRIES // k)
    # no exponent below EXP_LEAST where |s| |a| stays within it
    low = s.size > 0 and float(np.max(np.abs(s))) * float(np.max(np.abs(a))) > -EXP_LEAST
    if s.size <= rows:
        return _exp_block(s, a, b, Cf, Df, low).reshape(shape)
    out = np.empty((s.size, Cf.shape[1]))
    for i in range(0, s.size, rows):
        out[i:i + rows] = _exp_block(s[i:i + rows], a, b, Cf, Df, low)
    return out.reshape(shape)


def _exp_block(s: np.ndarray, a: np.ndarray, b: np.ndarray, Cf: np.ndarray,
               Df: np.ndarray | None, low: bool) -> np.ndarray:
    """:func:`exp_sum` at the lags s of one block, C and D flattened to (k, -1) (Df None: every
    b is 0; ``low``: some exponent may be below EXP_LEAST, then each is at least that and a lag
    whose every exponent is below it gives exactly 0)."""
    e = np.multiply.outer(s, a)
    dead = None
    if low:
        dead = np.where(s >= 0, s * a.max(), s * a.min()) < EXP_LEAST      # max_j a_j s
        np.maximum(e, EXP_LEAST, out=e)
    np.exp(e, out=e)
    if Df is None:
        out = e @ Cf
    else:
        out = ((e * np.cos(np.multiply.outer(s, b))) @ Cf
               + (e * np.sin(np.multiply.outer(s, b))) @ Df)
    if dead is not None and dead.any():
        out[dead] = 0.0
    return out


def _scaled(C: np.ndarray, D: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The factors (C', D') with C' - i D' = w (C - i D) (w complex (k,))."""
    wr, wi = w.real[:, None, None], w.imag[:, None, None]
    return wr * C + wi * D, wr * D - wi * C


@dataclass(frozen=True)
class Fold:
    """The memory of an exponential sum folded onto one period T.

    Attributes
    ----------
    T : float
        The period.
    K : int
        The whole periods in tau (floor(tau / T)).
    r : float
        The rest tau - K T (0 when below FOLD_TOL max(tau, 1)): H_T jumps there.
    kernel : Kernel
        H_T on (0, T] (a :class:`~.mesh.Kernel`), with H's near part (k = 0 only), its jumps
        folded and r as jumps.
    tail : callable or None
        s -> sum_{k >= 1} H(s + k T) (the same truncation) on (0, delta] (None without near part).
    moment : callable
        s -> T M_T(s) / s, M_T(s) = sum_k k H(s + k T) (the same truncation): the period
        derivative's kernel as delay_matrix's slope weighs it (by s / T).
    jumps : tuple of float
        H_T's jumps in (0, T), sorted (the folded declared lags and r).
    sums : tuple
        H_T's far part as exponential sums without a jump: (the sum on (0, T], the one added on
        (0, r) or None when r = 0), each ((a, b, C, D), s -> its values (k, n, n)) (the near
        part's lags (0, delta] of the second belong to the tail).
    """
    T: float
    K: int
    r: float
    kernel: Any
    tail: Callable[[np.ndarray], np.ndarray] | None
    moment: Callable[[np.ndarray], np.ndarray]
    jumps: tuple[float, ...]
    sums: tuple


def _weights(lam: np.ndarray, T: float, K: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(sum_{k<K} z^k, sum_{1<=k<K} z^k, sum_{k<K} k z^k) with z^k = e^(lambda k T), each
    power in one exponential (no products accumulated)."""
    g0 = np.zeros(lam.size, complex)
    g1 = np.zeros(lam.size, complex)
    g2 = np.zeros(lam.size, complex)
    for k in range(K):
        z = np.exp(lam * (k * T))
        g0 += z
        if k:
            g1 += z
            g2 += k * z
    return g0, g1, g2


def _sum(terms: tuple) -> Callable[[np.ndarray], np.ndarray]:
    """s -> the exponential sum ``terms`` (a, b, C, D) at s."""
    return lambda s: exp_sum(s, *terms)


def _piecewise(a: np.ndarray, b: np.ndarray, below: tuple, above: tuple, r: float
               ) -> Callable[[np.ndarray], np.ndarray]:
    """s -> the exponential sum with the factors ``below`` (C, D) at s < r, ``above`` else."""
    def H(s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        low = s < r
        if not np.any(low):
            return exp_sum(s, a, b, *above)
        if np.all(low):
            return exp_sum(s, a, b, *below)
        out = np.empty((s.size,) + above[0].shape[1:])
        out[low] = exp_sum(s[low], a, b, *below)
        out[~low] = exp_sum(s[~low], a, b, *above)
        return out
    return H


def fold_of(H: Any, terms: tuple, tau: float, T: float) -> Fold | None:
    """The fold of the exponential sum ``terms`` = (a, b, C, D) (the far part of H, a
    :class:`~.mesh.Kernel` whose near part and jumps the fold keeps) onto the period T, a Kernel
    of H's class; None when tau <= T (nothing to fold) or the near part reaches T (its cells
    would meet a later period's lags)."""
    T, tau = float(T), float(tau)
    if not (T > 0 and math.isfinite(T)) or tau <= T:
        return None
    if H.near is not None and H.near.delta >= T:
        return None
    a, b, C, D = (np.asarray(x, dtype=float) for x in terms)
    K = int(math.floor(tau / T))
    r = tau - K * T
    eps = FOLD_TOL * max(tau, 1.0)
    if r >= T - eps:                    # tau is K + 1 periods to rounding
        K, r = K + 1, 0.0
    elif r <= eps:
        r = 0.0
    lam = a + 1j * b
    g0, g1, g2 = _weights(lam, T, K)
    last = np.exp(lam * (K * T)) if r > 0 else np.zeros(lam.size, complex)
    kernel_far = _piecewise(a, b, _scaled(C, D, g0 + last), _scaled(C, D, g0), r)
    tail_far = _piecewise(a, b, _scaled(C, D, g1 + last), _scaled(C, D, g1), r)
    moment_far = _piecewise(a, b, _scaled(C, D, g2 + K * last), _scaled(C, D, g2), r)

    def moment(s: np.ndarray) -> np.ndarray:
        s = np.asarray(s, dtype=float)
        return moment_far(s) * (T / s)[:, None, None]

    folded = {float(j % T) for j in H.jumps} | ({r} if r > 0 else set())
    jumps = tuple(sorted(j for j in folded if eps < j < T - eps))
    kernel = type(H)(kernel_far, H.near, jumps, H.rate)
    first = (a, b) + _scaled(C, D, g0)
    second = (a, b) + _scaled(C, D, last)
    sums = ((first, _sum(first)), (second, _sum(second)) if r > 0 else None)
    return Fold(T, K, r, kernel, tail_far if H.near is not None else None, moment, jumps, sums)
