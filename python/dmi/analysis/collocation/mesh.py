# Piecewise polynomials on a mesh of one period: the Lagrange basis, evaluation, the delay
# integral's quadrature matrix.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The mesh machinery of :mod:`dmi.analysis.collocation.collocate`; private to the package.

A function on one period [0, T] is a continuous piecewise polynomial of degree m on a mesh
0 = t_0 < t_1 < ... < t_L = T: on interval i it interpolates m + 1 equispaced nodes t_i + k h_i / m
(k = 0..m), the last node of an interval being the first of the next.  A *locator* maps times
(any real numbers) to (interval, local coordinate in [0, 1], the columns of that interval's m + 1
nodes in the unknowns): the periodic one wraps times mod T (the orbit), the history one sends
negative times to a separate, discontinuous copy of the mesh (the monodromy operator).

The delay integral I(t) = int_0^tau H(s) u(t - s) ds is exact for the piecewise polynomial up to
the kernel's own smoothness: [0, tau] is cut at every lag s where t - s crosses a mesh point (all
shifted periods) and at the kernel's own breakpoints, and each piece takes ``q`` Gauss-Legendre
nodes (exact for H polynomial of degree 2 q - 1 - m on the piece).  A :class:`Kernel` brings its
jumps inside (0, tau) as more cuts (a jump at a lag not given caps the order at 1: the pieces do
not see it) and its near part s^-beta C on (0, delta] (a fitted PowerKernel's), integrated on each
piece by product integration with the Gauss-Jacobi rule of the weight s^-beta.

An exponential sum's far lags go faster by separated factors (:func:`delay_matrix_separable`,
:func:`folded_matrix`; the comment above them): a matrix product instead of an exponential a lag
and term.
"""
from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..._transform import gauss_jacobi

#: Locator: times -> (interval (k,), local coordinate (k,), columns (k, m + 1) of node rows).
Locator = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class Basis:
    """The Lagrange basis of degree m on the equispaced nodes k / m of [0, 1], with the m Gauss
    points (collocation) and the Gauss-Legendre rule of q nodes (quadrature) on [0, 1].  Its
    values and derivatives are evaluated in the Legendre form (:func:`_legendre_form`): to a few
    units of rounding at degree 8, where the monomial form loses two digits (its coefficients
    reach 213, and a collocation's derivatives divide that rounding by the interval's length)."""
    m: int
    q: int

    @property
    def nodes(self) -> np.ndarray:
        """The m + 1 interpolation nodes k / m."""
        return np.linspace(0.0, 1.0, self.m + 1)

    @property
    def weights(self) -> np.ndarray:
        """Barycentric weights 1 / prod_{j != k} (x_k - x_j)."""
        x = self.nodes
        d = x[:, None] - x[None, :]
        np.fill_diagonal(d, 1.0)
        return 1.0 / np.prod(d, axis=1)

    def gauss(self, count: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Gauss-Legendre nodes and weights on [0, 1] (``count`` nodes, default m)."""
        return _legendre(self.m if count is None else count)

    def values(self, z: np.ndarray) -> np.ndarray:
        """(len(z), m + 1): the basis polynomials at the local coordinates z."""
        y = 2.0 * np.asarray(z, dtype=float).ravel() - 1.0
        return _legendre_values(y, self.m) @ _legendre_form(self.m)[0]

    def derivatives(self, z: np.ndarray) -> np.ndarray:
        """(len(z), m + 1): the basis polynomials' first derivatives at z (d/dz, z in [0, 1])."""
        y = 2.0 * np.asarray(z, dtype=float).ravel() - 1.0
        return _legendre_values(y, self.m - 1) @ _legendre_form(self.m)[1]

    @property
    def top(self) -> np.ndarray:
        """(m + 1,): the m-th derivative (d/dz) of each basis polynomial, a constant."""
        return self.weights * math.factorial(self.m)


def _legendre_values(y: np.ndarray, m: int) -> np.ndarray:
    """(len(y), m + 1): the Legendre polynomials P_0 .. P_m at y (their three-term recurrence)."""
    P = np.empty((m + 1, y.size))
    P[0] = 1.0
    if m >= 1:
        P[1] = y
    for j in range(1, m):
        P[j + 1] = ((2 * j + 1) * y * P[j] - j * P[j - 1]) / (j + 1)
    return P.T


@functools.lru_cache(maxsize=16)
def _legendre_form(m: int) -> tuple[np.ndarray, np.ndarray]:
    """The Lagrange polynomials l_k of the equispaced nodes of [-1, 1] (y = 2 z - 1) in the
    Legendre basis: A (m + 1, m + 1), l_k(y) = sum_j A[j, k] P_j(y), and B (m, m + 1), d l_k / d z
    = sum_j B[j, k] P_j(y); both computed exactly in rationals and rounded once (read-only)."""
    y = [Fraction(2 * k, m) - 1 for k in range(m + 1)]
    legendre = [[Fraction(1)], [Fraction(0), Fraction(1)]]       # P_j's monomial coefficients
    for j in range(1, m):
        up = [Fraction(0)] + [Fraction(2 * j + 1, j + 1) * c for c in legendre[j]]
        down = [Fraction(j, j + 1) * c for c in legendre[j - 1]] + [Fraction(0)] * 2
        legendre.append([a - b for a, b in zip(up, down)])

    def in_legendre(c: list[Fraction]) -> list[Fraction]:
        c, out = list(c), [Fraction(0)] * len(c)
        for j in range(len(c) - 1, -1, -1):           # peel off the top degree
            out[j] = c[j] / legendre[j][j]
            c = [a - out[j] * b for a, b in zip(c, legendre[j] + [Fraction(0)] * len(c))]
        return out

    A = np.empty((m + 1, m + 1))
    B = np.empty((m, m + 1))
    for k in range(m + 1):
        c = [Fraction(1)]
        for j in range(m + 1):
            if j != k:                                # times (y - y_j) / (y_k - y_j)
                c = [(a - y[j] * b) / (y[k] - y[j]) for a, b in zip([Fraction(0)] + c,
                                                                      c + [Fraction(0)])]
        A[:, k] = [float(a) for a in in_legendre(c)]
        B[:, k] = [float(2 * a) for a in in_legendre([i * c[i] for i in range(1, m + 1)])]
    return _frozen(A, B)  # type: ignore[return-value]


def interval_of(mesh: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For times t in [mesh[0], mesh[-1]]: the interval index and the local coordinate in [0, 1]."""
    L = mesh.size - 1
    i = np.clip(np.searchsorted(mesh, t, side="right") - 1, 0, L - 1)
    z = (t - mesh[i]) / (mesh[i + 1] - mesh[i])
    return i, z


def periodic_locator(mesh: np.ndarray, m: int) -> Locator:
    """The locator of the periodic continuous piecewise polynomial: L m node rows, times mod T."""
    T = float(mesh[-1])
    L = mesh.size - 1
    k = np.arange(m + 1)

    def locate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        i, z = interval_of(mesh, np.mod(t, T))
        return i, z, (i[:, None] * m + k[None, :]) % (L * m)
    return locate


def history_locator(mesh: np.ndarray, hist: np.ndarray, m: int, periods: int) -> Locator:
    """The locator of one period forward from a history: times t >= 0 on ``mesh`` (L m + 1
    continuous node rows, node 0 at t = 0), times t < 0 on ``periods`` copies of ``hist`` shifted
    back by whole periods, each interval with its own m + 1 rows (a discontinuous piecewise
    polynomial: a perturbation may jump at a switch), after the L m + 1 rows of the period."""
    T = float(hist[-1])
    L = mesh.size - 1
    k = np.arange(m + 1)
    base = L * m + 1

    def locate(t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.asarray(t, dtype=float)
        i, z = interval_of(mesh, np.clip(t, 0.0, mesh[-1]))
        cols = i[:, None] * m + k[None, :]
        back = t < 0
        if np.any(back):
            per = np.ceil(-t[back] / T).astype(int)            # 1 .. periods
            ih, zh = interval_of(hist, t[back] + per * T)
            i[back], z[back] = ih, zh
            g = (periods - per) * L + ih                        # history interval, oldest first
            cols[back] = base + g[:, None] * (m + 1) + k[None, :]
        return i, z, cols
    return locate


def history_rows(L: int, m: int, periods: int) -> int:
    """The node rows of :func:`history_locator`: L m + 1 for the period, L (m + 1) a past period."""
    return L * m + 1 + periods * L * (m + 1)


#: Gauss-Legendre nodes a piece of the near part that keeps at least its own length from the
#: singularity at 0 (s^-beta is analytic in the Bernstein ellipse of parameter 3 + sqrt 8 around
#: it: the rule's error is below 5.83^-24, 5e-19, relative).
Q_NEAR = 12
#: An exponential sum is steep when its fastest rate r exceeds STEEP / tau: its pieces near 0
#: are then graded (:attr:`Kernel.grading`).
STEEP = 20.0
#: How far (in the local coordinate) a whole interval's middle and three-quarter point may lie
#: from 0.5 and 0.75 on the locator's interval for its one basis matrix to be used.
WHOLE_TOL = 1e-9


@dataclass(frozen=True)
class Near:
    """The near part of a kernel: H(s) = s^-beta C on (0, delta] (a fitted kernel's exact part,
    weakly singular at 0).

    Attributes
    ----------
    delta : float
        Its length, > 0 (time units).
    beta : float
        The exponent, 0 < beta < 1.
    C : numpy.ndarray
        (n, n): the factor.
    """
    delta: float
    beta: float
    C: np.ndarray


class Kernel:
    """H(s) on (0, tau]: ``far`` (callable s (k,) -> (k, n, n)) past the near part, the near
    part s^-beta C on (0, delta] when ``near`` is given, and the lags of its known jumps inside
    (0, tau) (each a breakpoint of the delay integral's pieces, as delta is).

    Parameters
    ----------
    far : callable
        s (k,) -> H(s) (k, n, n), the kernel (past delta with a near part).
    near : Near, optional
        The near part.
    jumps : sequence of float
        Lags of jumps of H in (0, tau), sorted.
    rate : float
        The fastest decay rate of an exponential sum when it is steep on (0, tau) (0: not).
    """

    def __init__(self, far: Callable[[np.ndarray], np.ndarray], near: Near | None = None,
                 jumps: tuple[float, ...] = (), rate: float = 0.0):
        self.far, self.near, self.jumps = far, near, tuple(float(j) for j in jumps)
        self.rate = float(rate)

    @property
    def grading(self) -> float:
        """Where the graded cuts of (0, tau) start (0: none): past a near part, H (a fit of
        s^-beta) still varies on the scale of s, so the cuts are delta 2^k (k >= 1); an
        exponential sum whose fastest rate r is steep (r > STEEP / tau) is cut at 2^k / r
        (k >= 0).  Each graded piece is at least its own length from 0 and takes Q_NEAR
        Gauss-Legendre nodes."""
        if self.near is not None:
            return 2.0 * self.near.delta
        return 1.0 / self.rate if self.rate > 0 else 0.0

    def __call__(self, s: np.ndarray) -> np.ndarray:
        """H(s) (k, n, n) at the lags s (k,) (the near part at s <= delta)."""
        s = np.asarray(s, dtype=float)
        out = np.asarray(self.far(s), dtype=float)
        if self.near is not None:
            close = s <= self.near.delta
            if np.any(close):
                out = out.copy()
                out[close] = s[close, None, None] ** -self.near.beta * self.near.C
        return out

    @property
    def breaks(self) -> np.ndarray:
        """The lags where the pieces of the delay integral are cut: the jumps and delta."""
        near = [self.near.delta] if self.near is not None else []
        return np.array(sorted(set(self.jumps) | set(near)), dtype=float)


def _frozen(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays made read-only (a cached rule is shared by every caller)."""
    for a in arrays:
        a.setflags(write=False)
    return arrays


@functools.lru_cache(maxsize=64)
def _legendre(q: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [0, 1] (q nodes; computed once for each q,
    read-only)."""
    z, w = np.polynomial.legendre.leggauss(q)
    return _frozen(0.5 * (z + 1.0), 0.5 * w)  # type: ignore[return-value]


def _near_nodes(near: Near, a: np.ndarray, d: np.ndarray, q: int, n: int
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Product integration of s^-beta C P(s) on the pieces [a, a + d] of (0, delta] (P a
    polynomial): a piece that keeps its own length from 0 by Q_NEAR Gauss-Legendre nodes with the
    weight s^-beta at them; one closer (a < d) by the Gauss-Jacobi rule of s^-beta on [0, a + d]
    minus the one on [0, a] (both on the piece's polynomial, exact).  Returns the lags S (k, r),
    the weights W (k, r) and H = C at them (k, r, n, n)."""
    close = a < d
    gy, gw = gauss_jacobi(q, near.beta)
    lz, lw = _legendre(Q_NEAR)
    r = max(2 * q, Q_NEAR)
    S = np.zeros((a.size, r))
    W = np.zeros((a.size, r))
    b = a + d
    ac, bc = a[close], b[close]
    S[close, :2 * q] = np.concatenate([bc[:, None] * gy, ac[:, None] * gy], axis=1)
    W[close, :2 * q] = np.concatenate([bc[:, None] ** (1.0 - near.beta) * gw,
                                       -ac[:, None] ** (1.0 - near.beta) * gw], axis=1)
    far = ~close
    Sf = a[far, None] + d[far, None] * lz
    S[far, :Q_NEAR] = Sf
    W[far, :Q_NEAR] = d[far, None] * lw * Sf ** -near.beta
    S[W == 0] = np.where(close, 0.5 * b, a + 0.5 * d)[:, None].repeat(r, 1)[W == 0]
    H = np.broadcast_to(near.C, (a.size, r, n, n))
    return S, W, H


def delay_matrix(times: np.ndarray, tau: float, mesh_points: np.ndarray, T: float,
                 kernel: Callable[[np.ndarray], np.ndarray], locate: Locator, basis: Basis,
                 n: int, rows: int, breaks: np.ndarray | None = None,
                 pattern: np.ndarray | None = None, slope_of: np.ndarray | None = None,
                 omit: tuple[np.ndarray, np.ndarray] | None = None
                 ) -> tuple[sp.csr_matrix, np.ndarray | None]:
    """The sparse matrix G (len(times) n, rows n) with G u = (int_0^tau H(s) u(t_c - s) ds)_c.

    Parameters
    ----------
    times : numpy.ndarray
        The times t_c.
    tau : float
        The memory's length.
    mesh_points : numpy.ndarray
        The mesh points of one period (where u's pieces join), repeated every T.
    T : float
        The period.
    kernel : callable
        s (k,) -> H(s) (k, n, n); a :class:`Kernel` also brings its near part (by product
        integration) and its jumps (breakpoints).
    locate : callable
        The locator of u's node rows.
    basis : Basis
        The basis (degree m, q quadrature nodes a piece).
    n : int
        The state's dimension.
    rows : int
        The node rows of u.
    breaks : numpy.ndarray, optional
        The kernel's own breakpoints in (0, tau) (besides a Kernel's).
    pattern : numpy.ndarray of bool, optional
        (n, n): the entries of H that may be nonzero (default all).
    slope_of : numpy.ndarray, optional
        Node rows (rows, n) of u: then also (1 / T) int_0^tau s H(s) u'(t_c - s) ds (len(times),
        n), the derivative of G u in T when the mesh scales with T (an autonomous orbit).
    omit : tuple of numpy.ndarray, optional
        (jb, ja) for each time: the lags between t_c - ext[ja] and t_c - ext[jb] (ext the mesh
        crossings of :func:`crossings`, where jb < ja) left out, integrated elsewhere
        (:func:`delay_matrix_separable`).

    Returns
    -------
    tuple
        G (scipy.sparse.csr_matrix; row c n + a, column (node row) n + b) and the T derivative
        (or None).
    """
    times = np.asarray(times, dtype=float)
    near = getattr(kernel, "near", None)
    breaks, graded = _breaks(kernel, breaks, tau)
    C, a, d, whole = _pieces(times, tau, np.asarray(mesh_points[:-1], dtype=float), T, breaks,
                             omit)
    if pattern is None:
        pattern = np.ones((n, n), bool)
    ia, ib = np.nonzero(pattern)
    close = (a + d <= near.delta * (1.0 + 1e-12)) if near is not None else np.zeros(a.size, bool)
    # the graded pieces up to start 2^K: each at least its own length from 0, Q_NEAR nodes
    steep = ~close & (a + d <= graded * (1.0 + 1e-12))
    regular = ~close & ~steep
    # every piece located once, at its middle and three-quarter point (one call)
    k = a.size
    mid = times[C] - (a + 0.5 * d)
    _, z, cols = locate(np.concatenate([mid, mid + 0.25 * d]))
    z1, z2, node = z[:k], z[k:], cols[:k]
    # a whole interval of u's mesh is one of the locator's intervals only where their meshes
    # agree (not the past's fixed mesh against a period whose switches moved)
    whole &= regular & (np.abs(z1 - 0.5) <= WHOLE_TOL) & (np.abs(z2 - 0.75) <= WHOLE_TOL)
    slope = (z2 - z1) / (0.25 * d)
    groups = _nodes(kernel, near, basis, a, d, whole, regular & ~whole, steep, close, n)
    dT = np.zeros((times.size, n)) if slope_of is not None else None
    val = np.empty((k, ia.size, basis.m + 1))
    for f, S, W, H in groups:
        WH = W[:, :, None] * H[:, :, ia, ib]                          # (k, r, entries)
        if f is whole:      # t - S at the interval's Gauss nodes backwards: one B for all
            z0 = 1.0 - basis.gauss(basis.q)[0]
            val[f] = _whole_entries(WH, basis.values(z0))
            Bd = basis.derivatives(z0) if dT is not None else None
            sg = 1.0 / d[f]
        else:
            sg = slope[f]
            zg = z1[f, None] + (times[C[f], None] - S - mid[f, None]) * sg[:, None]
            B = basis.values(zg.ravel()).reshape(S.shape + (basis.m + 1,))   # (k, r, m + 1)
            val[f] = np.matmul(WH.transpose(0, 2, 1), B)              # (k, entries, m + 1)
            Bd = (basis.derivatives(zg.ravel()).reshape(B.shape) if dT is not None else None)
        if dT is not None and slope_of is not None:
            Ud = np.matmul(Bd, slope_of[node[f]]) * sg[:, None, None]    # (k, r, n)
            part = np.sum(WH * S[:, :, None] * Ud[:, :, ib], axis=1) / T  # (k, entries)
            dT += np.bincount((C[f, None] * n + ia[None, :]).ravel(), part.ravel(),
                              minlength=times.size * n).reshape(times.size, n)
    return _assemble(val, C, node, ia, ib, n, (times.size * n, rows * n)), dT


def _nodes(kernel: Any, near: Near | None, basis: Basis, a: np.ndarray, d: np.ndarray,
           *masks: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
    """The quadrature of each group of pieces (masks: whole intervals, other regular pieces,
    graded ones, the near part's; the last n): (its mask, nodes S (k, r), weights W (k, r),
    H at S (k, r, n, n)); H(far) evaluated once for all but the near part's."""
    *masks, close, n = masks
    gz, gw = basis.gauss(basis.q)
    lz, lw = _legendre(Q_NEAR)
    out = []
    for f, (zz, ww) in zip(masks, ((gz, gw), (gz, gw), (lz, lw))):
        if np.any(f):
            out.append((f, a[f, None] + d[f, None] * zz[None, :], d[f, None] * ww[None, :]))
    groups = []
    if out:
        flat = np.concatenate([S.ravel() for _, S, _ in out])
        H = np.asarray(getattr(kernel, "far", kernel)(flat)).reshape(flat.size, n, n)
        at = 0
        for f, S, W in out:
            groups.append((f, S, W, H[at:at + S.size].reshape(S.shape + (n, n))))
            at += S.size
    if np.any(close):
        groups.append((close,) + _near_nodes(near, a[close], d[close], basis.q, n))
    return groups


def _whole_entries(WH: np.ndarray, B: np.ndarray) -> np.ndarray:
    """(k, entries, m + 1): the entries sum_r WH[k, r, e] B[r, :] of pieces that share B."""
    k, r, e = WH.shape
    flat = WH.reshape(k, r) if e == 1 else np.moveaxis(WH, 2, 1).reshape(k * e, r)
    return (flat @ B).reshape(k, e, B.shape[1])


def _assemble(val: np.ndarray, C: np.ndarray, node: np.ndarray, ia: np.ndarray, ib: np.ndarray,
              n: int, shape: tuple[int, int]) -> sp.csr_matrix:
    """The sparse matrix of the pieces' entries val (k, entries, m + 1) (the pieces by time
    index C, then by their start): row C n + ia, column node n + ib, summed.  The entries go in
    by row, a row's pieces backwards (their columns then mostly ascend: little to sort)."""
    k, e, m1 = val.shape
    back = np.arange(k - 1, -1, -1)
    unit = (C[back, None] * n + ia[None, :]).ravel()                # rows of (piece, entry)
    o = np.argsort(unit, kind="stable")
    p, en = back[o // e], o % e
    idx = np.int32 if max(shape[1], k * e * m1) < 2 ** 31 - 1 else np.int64
    cols = (node[p] * n + ib[en, None]).astype(idx).ravel()
    ptr = np.zeros(shape[0] + 1, idx)
    np.cumsum(np.bincount(unit, minlength=shape[0]) * m1, out=ptr[1:])
    G = sp.csr_matrix((val[p, en].ravel(), cols, ptr), shape=shape)
    G.sum_duplicates()
    return G


def _breaks(kernel: Any, breaks: np.ndarray | None, tau: float) -> tuple[np.ndarray, float]:
    """(the kernel's breakpoints in (0, tau) with the given ones and, for a steep H near 0, the
    grading's cuts at start 2^k; the last such cut, 0 without grading)."""
    own = getattr(kernel, "breaks", np.empty(0))
    breaks = own if breaks is None else np.concatenate([np.asarray(breaks, float), own])
    graded = 0.0
    start = getattr(kernel, "grading", 0.0)
    if start > 0:                # a steep H near 0: cuts at start 2^k
        grade = start * 2.0 ** np.arange(0, 64)
        grade = grade[grade < tau * (1.0 - 1e-12)]
        graded = float(grade[-1]) if grade.size else 0.0
        breaks = np.concatenate([breaks, grade])
    return breaks, graded


def crossings(times: np.ndarray, tau: float, pts: np.ndarray, T: float
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The mesh points ``pts`` (one period's, without T) repeated every T over the memories of
    the ``times`` (sorted), and for each time the index of the first one past t - tau and of the
    first one at or past t: (ext, j0, j1)."""
    ext = _extended(pts, T, _span(times, tau, pts, T))
    j0 = np.searchsorted(ext, times - tau, side="right")
    j1 = np.searchsorted(ext, times, side="left")
    return ext, j0, j1


def _pieces(times: np.ndarray, tau: float, pts: np.ndarray, T: float, breaks: np.ndarray,
            omit: tuple[np.ndarray, np.ndarray] | None = None
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The pieces of [0, tau] on which s -> u(t_c - s) is one polynomial: (their time's index c,
    their start a, their length d, whether a piece is a whole interval of u: its ends two mesh
    crossings, neither 0, tau nor a break).  ``omit`` (jb, ja): indices into the crossings of
    :func:`crossings` for each time; where jb < ja the lags between t - ext[ja] and t - ext[jb]
    (integrated elsewhere) are left out, the crossings between them not cut."""
    ext, j0, j1 = crossings(times, tau, pts, T)
    if omit is None:
        jb = ja = j1
    else:
        jb, ja = omit
        jb = np.where(jb < ja, np.clip(jb, j0, j1), j1)
        ja = np.where(jb < j1, np.clip(ja, jb, j1), j1)
    n1 = jb - j0 + (jb < ja)                        # the crossings up to jb (with jb in a window)
    cnt = n1 + j1 - ja
    K = int(np.max(cnt)) if times.size else 0
    k = np.arange(K)[None, :]
    idx = j0[:, None] + k + np.where(k >= n1[:, None], (ja - jb - 1 + (jb >= ja))[:, None], 0)
    inside = k < cnt[:, None]
    cut = np.where(inside, times[:, None] - ext[np.clip(idx, 0, ext.size - 1)], 0.0)
    zero, end = np.zeros((times.size, 1)), np.full((times.size, 1), tau)
    if breaks.size:
        s = np.sort(np.concatenate([cut, zero, end, np.broadcast_to(breaks, (times.size,
                                                                            breaks.size))],
                                   axis=1), axis=1)
    else:       # the crossings descend in (0, tau), their padding 0: reversed, sorted
        s = np.concatenate([end, cut, zero], axis=1)[:, ::-1]
    a, d = s[:, :-1], np.diff(s, axis=1)
    keep = d > 1e-14 * max(tau, 1.0)
    if omit is not None:        # the pieces inside a window
        win = jb < ja
        lo = np.where(win, times - ext[np.minimum(ja, ext.size - 1)], np.inf)[:, None]
        hi = np.where(win, times - ext[np.minimum(jb, ext.size - 1)], -np.inf)[:, None]
        mid = a + 0.5 * d
        keep &= ~((mid > lo) & (mid < hi))
    whole = (a > 0) & (s[:, 1:] < tau)
    if breaks.size:
        whole &= ~np.isin(a, breaks) & ~np.isin(s[:, 1:], breaks)
    whole = whole[keep]
    return np.nonzero(keep)[0], a[keep], d[keep], whole


def point_matrix(times: np.ndarray, locate: Locator, basis: Basis, mesh: np.ndarray, n: int,
                 rows: int, derivative: bool = False) -> sp.csr_matrix:
    """The sparse matrix E (len(times) n, rows n) of u(t_c) (or u'(t_c), d/dt, with
    ``derivative``) from the node rows."""
    i, z, cols = locate(np.asarray(times, dtype=float))
    if derivative:
        B = basis.derivatives(z) / (mesh[i + 1] - mesh[i])[:, None]
    else:
        B = basis.values(z)
    P = len(times)
    val = np.broadcast_to(B[:, None, :], (P, n, basis.m + 1))
    r = np.broadcast_to((np.arange(P)[:, None, None] * n + np.arange(n)[None, :, None]),
                        val.shape)
    cc = cols[:, None, :] * n + np.arange(n)[None, :, None]
    return sp.csr_matrix((val.ravel(), (r.ravel(), cc.ravel())), shape=(P * n, rows * n))


class DelayPlan:
    """delay_matrix's G (and its T derivative) on a periodic orbit, for a kernel without a near
    part, jumps or grading (the pieces are cut at the mesh crossings alone), made for the
    crossings inside each time's memory and used again while they stay the same (Newton's
    iterates: the mesh moves with T and the switching times, no crossing enters or leaves a
    memory).  The pieces between two crossings keep their basis values (the Gauss nodes of their
    interval); each call takes the kernel at the lags, the end pieces of each time's memory anew
    (cut by t - tau and by t; one where no crossing lies inside it), and one sum into the kept
    sparse pattern.

    Parameters
    ----------
    times : numpy.ndarray
        The times t_c (in [0, T]).
    mesh : numpy.ndarray
        The mesh of one period, repeated every T.
    tau : float
        The memory's length.
    T : float
        The period.
    kernel : callable
        s (k,) -> the entries of H(s) in ``pattern`` (k, entries), row by row (those of a
        :class:`Kernel`'s ``far``).
    basis : Basis
        The basis (q Gauss-Legendre nodes a piece).
    n : int
        The state's dimension.
    rows : int
        The node rows of u (L m, periodic).
    pattern : numpy.ndarray of bool
        (n, n): the entries of H that may be nonzero.
    """

    def __init__(self, times: np.ndarray, mesh: np.ndarray, tau: float, T: float,
                 kernel: Callable[[np.ndarray], np.ndarray], basis: Basis, n: int, rows: int,
                 pattern: np.ndarray):
        times = np.asarray(times, dtype=float)
        L, m, P = mesh.size - 1, basis.m, times.size
        self.span = _span(times, tau, mesh[:-1], T)
        _, self.j0, self.j1 = crossings(times, tau, mesh[:-1], T)
        self.tau, self.kernel, self.basis, self.n = float(tau), kernel, basis, n
        self.ia, self.ib = np.nonzero(pattern)
        gz = basis.gauss(basis.q)[0]
        # the pieces between two crossings: intervals j0 .. j1 - 2 of each time
        inner = np.maximum(self.j1 - self.j0 - 1, 0)
        C = np.repeat(np.arange(P), inner)
        j = np.repeat(self.j0, inner) + (np.arange(C.size) - np.repeat(np.cumsum(inner) - inner,
                                                                       inner))
        self.inner = (C, j)
        self.B, self.Bd = basis.values(gz), basis.derivatives(gz)              # (q, m + 1)
        # the end pieces: the interval of t - tau (j0 - 1), and of t (j1 - 1) where it is another
        two = self.j1 > self.j0
        self.ends = (np.concatenate([np.arange(P), np.arange(P)[two]]),
                     np.concatenate([self.j0 - 1, self.j1[two] - 1]))
        self.C = np.concatenate([C, self.ends[0]])
        jj = np.concatenate([j, self.ends[1]])
        node = ((jj % L)[:, None] * m + np.arange(m + 1)[None, :]) % (L * m)
        #: The quadrature nodes of the plan (its memory: 10 bytes each with one pattern entry,
        #: 28 with four, at m = 4).
        self.nodes = self.C.size * gz.size
        # the sparse pattern: each (piece, entry, basis polynomial)'s slot in G's data; the
        # index arrays read-only (every G of the plan shares them)
        e = self.ia.size
        r = np.broadcast_to((self.C[:, None] * n + self.ia[None, :])[:, :, None],
                            (self.C.size, e, m + 1))
        c = node[:, None, :] * n + self.ib[None, :, None]
        self.shape = (P * n, rows * n)
        flat, slot = np.unique((r * self.shape[1] + c).ravel(), return_inverse=True)
        idx = np.int32 if max(self.shape[1], slot.size) < 2 ** 31 - 1 else np.int64
        self.slot = slot.astype(idx)
        self.indices = (flat % self.shape[1]).astype(idx)
        self.indptr = np.zeros(self.shape[0] + 1, idx)
        np.cumsum(np.bincount(flat // self.shape[1], minlength=self.shape[0]),
                  out=self.indptr[1:])
        for a in (self.indices, self.indptr):
            a.setflags(write=False)

    def matrix(self, times: np.ndarray, mesh: np.ndarray, T: float,
               slope_of: np.ndarray | None = None
               ) -> tuple[sp.csr_matrix, np.ndarray | None] | None:
        """delay_matrix's (G, T derivative) at these times, mesh and period; None when a
        crossing entered or left a memory (the plan does not fit: make another)."""
        times = np.asarray(times, dtype=float)
        if times.size != self.j0.size:
            return None
        ext = _extended(mesh[:-1], T, self.span)
        if not (np.array_equal(np.searchsorted(ext, times - self.tau, side="right"), self.j0)
                and np.array_equal(np.searchsorted(ext, times, side="left"), self.j1)
                and self.j0.min(initial=1) >= 1 and self.j1.max(initial=0) < ext.size):
            return None
        basis, n, ia = self.basis, self.n, self.ia
        gz, gw = basis.gauss(basis.q)
        C, j = self.inner
        lo, h = ext[j], ext[j + 1] - ext[j]
        Ce, je = self.ends
        a, b = ext[je], ext[je + 1]
        le, he = np.maximum(a, times[Ce] - self.tau), np.minimum(b, times[Ce])
        x = np.concatenate([lo[:, None] + h[:, None] * gz[None, :],
                            le[:, None] + (he - le)[:, None] * gz[None, :]])       # (k, q)
        z = ((x[C.size:] - a[:, None]) / (b - a)[:, None]).ravel()
        S = times[self.C, None] - x
        W = np.concatenate([h, he - le])[:, None] * gw[None, :]
        H = np.asarray(self.kernel(S.ravel())).reshape(S.shape + (ia.size,))
        WH = W[:, :, None] * H                                                # (k, q, entries)
        ends = (Ce.size, gz.size, basis.m + 1)
        G = self._sparse(WH, self.B, basis.values(z).reshape(ends))
        if slope_of is None:
            return G, None
        # the T derivative (1 / T) int s H(s) u'(t - s) ds: the same pattern with s H and B'
        D = self._sparse(WH * S[:, :, None], self.Bd, basis.derivatives(z).reshape(ends),
                         np.concatenate([h, b - a]))
        return G, (D @ np.asarray(slope_of, dtype=float).ravel()).reshape(times.size, n) / T

    def _sparse(self, WH: np.ndarray, B: np.ndarray, Be: np.ndarray,
                h: np.ndarray | None = None) -> sp.csr_matrix:
        """The matrix of the kept pattern with the entries sum_r WH[p, r, e] B[p, r, k] (B the
        inner pieces' shared (q, m + 1), Be the end pieces' own), each piece's over h[p]."""
        C = self.inner[0]
        k, (q, m1), e = C.size, B.shape, WH.shape[2]
        val = np.concatenate([(WH[:k].transpose(0, 2, 1).reshape(-1, q) @ B).reshape(k, e, m1),
                              np.einsum("kqe,kqm->kem", WH[k:], Be)])   # (k, entries, m + 1)
        if h is not None:
            val /= h[:, None, None]
        return sp.csr_matrix((np.bincount(self.slot, val.ravel(), minlength=self.indices.size),
                              self.indices, self.indptr), shape=self.shape)


def _span(times: np.ndarray, tau: float, pts: np.ndarray, T: float) -> tuple[int, int]:
    """The periods lo .. hi whose mesh points (``pts`` shifted by k T) cover the memories of the
    times, with one to spare at each end (:func:`crossings`)."""
    return (math.floor((times.min() - tau - pts[-1]) / T) - 1,
            math.floor((times.max() - pts[0]) / T) + 1)


def _extended(pts: np.ndarray, T: float, span: tuple[int, int]) -> np.ndarray:
    """One period's mesh points ``pts`` (without T) repeated every T over the periods of
    ``span``, sorted."""
    return (np.asarray(pts, dtype=float)[None, :]
            + T * np.arange(span[0], span[1] + 1)[:, None]).ravel()


# The far cells of an exponential sum by separated factors: delay_matrix's G for a kernel whose
# far part is an exponential sum H(s) = Re sum_j e^(lambda_j s) F_j (F_j = C_j - i D_j,
# Re lambda_j <= 0).
#
# Cut the time axis at the mesh crossings (the mesh points repeated every T) into *cells*; each
# lies inside one interval of u.  On a cell [l, l + d] whose lags t_c - sigma lie in [s0, tau],
# past every kernel break (the near part's delta, its declared jumps, the grading's start) and at
# least twice the cell's length from 0, the integral is
#
#     int H(t_c - sigma) B_k(sigma) d sigma = Re sum_j e^(lambda_j (t_c - c)) F_j M_j,k,
#     M_j,k = int_l^(l + d) e^(lambda_j (c - sigma)) B_k(sigma) d sigma,
#
# for any reference c: with c at or after the cell's end and at or before t_c both factors are
# at most 1 in modulus.  The cells are grouped in *blocks*: those far for every time (the past)
# in one, then BLOCK_CELLS cells at a time, each block its end as reference.  A time takes every
# block whose cells are all far for it (its *window*, the cells that start at or after
# t_c - tau), each by one product of its (times x terms) factors with the block's (terms x
# columns) moments; the rest of [0, tau] (the near lags, the last block not yet far, the cell cut
# by tau) keeps delay_matrix's pieces (``omit``).  M is integrated by
# Q_NEAR Gauss-Legendre nodes on the whole cell, where delay_matrix cuts it at the grading (at most
# once: the cuts double) and takes q or Q_NEAR nodes: the two differ by their quadrature errors.
# Twice its length from 0 (not once, the graded pieces' rule): a steep term e^(-r s) on the cell
# [a, a + d], a >= 2 d, keeps the rule's error bound below 4e-22 of its integral 1 / r for every
# r d (at a = d it reaches 1.1e-14, at r d = 25).

#: Cells a block of the period (after the past's block) takes: a time's direct pieces reach at
#: most that many cells past its near ones.
BLOCK_CELLS = 4
#: The far cells a time must take on average for the products to pay (fewer: delay_matrix's own
#: pieces; measured on the fractional belt's orbits of 16 and 94 intervals).
MIN_CELLS = 24
#: A block's node rows up to which its cells' columns are summed into them by a dense product.
SCATTER_DENSE = 64


def far_lag(kernel: Kernel) -> float:
    """The lag past which a cell may be integrated by the separated factors: past the near part
    (and its graded cuts' start) and the kernel's jumps (each cell also twice its own length
    from 0: :func:`windows`)."""
    near = kernel.near
    s0 = max([kernel.grading, near.delta if near is not None else 0.0]
             + [float(j) for j in kernel.jumps])
    return s0 * (1.0 + 1e-9)


def delay_matrix_separable(times: np.ndarray, tau: float, mesh_points: np.ndarray, T: float,
                           kernel: Kernel, terms: tuple, locate: Locator, basis: Basis, n: int,
                           rows: int, pattern: np.ndarray | None = None) -> sp.csr_matrix:
    """:func:`dmi.analysis.collocation.mesh.delay_matrix`'s G for a kernel whose far part is
    the exponential sum ``terms`` (a, b, C, D), its far cells by products (the comment above
    :data:`BLOCK_CELLS`).

    Parameters
    ----------
    times : numpy.ndarray
        The times t_c.
    tau : float
        The memory's length.
    mesh_points : numpy.ndarray
        The mesh points of one period (0 to T), repeated every T.
    T : float
        The period.
    kernel : Kernel
        H (:class:`~.mesh.Kernel`): its far part the exponential sum ``terms``.
    terms : tuple
        (a, b, C, D): H(s) = sum_j e^(a_j s) (C_j cos b_j s + D_j sin b_j s) past the near part.
    locate : callable
        The locator of u's node rows.
    basis : Basis
        The basis.
    n : int
        The state's dimension.
    rows : int
        The node rows of u.
    pattern : numpy.ndarray of bool, optional
        (n, n): the entries of H that may be nonzero (default all).

    Returns
    -------
    scipy.sparse.csr_matrix
        G (len(times) n, rows n), as delay_matrix's; delay_matrix's own where a rate has
        a_j > 0 (the factors would not be bounded) or no time has a far cell.
    """
    times = np.asarray(times, dtype=float)
    a, b, C, D = (np.asarray(x, dtype=float) for x in terms)
    pts = np.asarray(mesh_points, dtype=float)
    if pattern is None:
        pattern = np.ones((n, n), bool)
    got = windows(times, tau, pts, T, kernel, a)
    if got is None:
        return delay_matrix(times, tau, pts, T, kernel, locate, basis, n, rows,
                            pattern=pattern)[0]
    ext, ends, jb, ja, win = got
    G = delay_matrix(times, tau, pts, T, kernel, locate, basis, n, rows,
                     pattern=pattern, omit=(jb, ja))[0]
    return G + _far_part(times, ext, ends, jb, ja, win, (a + 1j * b, C - 1j * D), locate,
                         basis, n, rows, pattern, tau)


def windows(times: np.ndarray, tau: float, pts: np.ndarray, T: float, kernel: Kernel,
            a: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """The far cells of :func:`delay_matrix_separable` (rates' real parts ``a``): (the
    crossings ext, the blocks' ends, each time's window jb <= cell < ja, whether it has one);
    None where they would not pay (fewer than MIN_CELLS a time) or a_j > 0."""
    if times.size == 0 or np.any(a > 0):
        return None
    s0 = far_lag(kernel)
    ext, j0, j1 = crossings(times, tau, pts[:-1], T)
    # a block end e serves the times t with t - ext[e] >= s0 and every cell before it at least
    # twice its length from t: t >= ready[e - 1] (both monotone in e)
    ready = np.maximum.accumulate(ext[1:] + 2.0 * (1.0 + 1e-9) * np.diff(ext))
    ends = _block_ends(ext, ready, times, s0)
    # each time's window: the cells from its first crossing past t - tau to the last block end
    # that serves it
    at = np.minimum(np.searchsorted(ext[ends], times - s0, side="right"),
                    np.searchsorted(ready[ends - 1], times, side="right")) - 1
    ja = np.where(at >= 0, ends[np.maximum(at, 0)], -1)
    jb = np.clip(j0, 0, None)
    win = (at >= 0) & (jb < ja) & (ja < j1)
    if not np.any(win) or np.sum(np.where(win, ja - jb, 0)) < MIN_CELLS * times.size:
        return None
    return ext, ends, np.where(win, jb, j1), np.where(win, ja, j1), win


def _block_ends(ext: np.ndarray, ready: np.ndarray, times: np.ndarray, s0: float
                ) -> np.ndarray:
    """The indices into ext of the blocks' ends (their references): the last that serves
    min(t) (:func:`windows`), then every BLOCK_CELLS-th up to the last that serves max(t)."""
    def last_for(t: float) -> int:
        return min(int(np.searchsorted(ext, t - s0, side="right")),
                   int(np.searchsorted(ready, t, side="right")) + 1) - 1
    first, last = last_for(float(times.min())), last_for(float(times.max()))
    if first < 1:
        return np.empty(0, int)
    return np.arange(first, last + 1, BLOCK_CELLS)


def _far_part(times: np.ndarray, ext: np.ndarray, ends: np.ndarray, jb: np.ndarray,
              ja: np.ndarray, win: np.ndarray, lf: tuple[np.ndarray, np.ndarray],
              locate: Locator, basis: Basis, n: int, rows: int, pattern: np.ndarray,
              tau: float) -> sp.csr_matrix:
    """The window's cells (jb <= cell < ja for the times in ``win``) by the blocks' products
    (lf: the rates lambda (K,) and factors F = C - i D (K, n, n)), summed into the node rows
    (cells of several periods share a periodic locator's rows)."""
    lam, F = lf
    first = int(np.min(jb[win]))
    cells = np.arange(first, int(np.max(ja[win])))
    sig, B, node = _cells(ext, cells, locate, basis, tau)
    m1 = basis.m + 1
    ia, ib = np.nonzero(pattern)
    bounds = np.concatenate([[first], ends[ends > first]])
    refs = ext[bounds[1:]]                                  # each block's end, its reference
    last = np.searchsorted(bounds[1:], ja, side="right") - 1        # a time's last block
    use_all = np.flatnonzero(win)
    # the times' factors at their last block's reference (bounded: t - that end >= s0)
    E_last = np.exp(np.outer(times[use_all] - refs[last[use_all]], lam))
    out = np.zeros((ia.size, times.size, rows))
    for beta in range(refs.size):
        sel = last[use_all] >= beta
        use = use_all[sel]
        if use.size == 0:
            continue
        lo, hi = bounds[beta] - first, bounds[beta + 1] - first
        # e^(lambda (t - c_beta)) = e^(lambda (t - c_last)) e^(lambda (c_last - c_beta))
        step = np.exp(np.outer(refs[beta:] - refs[beta], lam))         # (later blocks, K)
        E = E_last[sel] * step[last[use] - beta]
        Er = np.concatenate([E.real, -E.imag], axis=1)                  # Re(E Y) = [Er, -Ei] Y
        Mo = np.einsum("kcr,crj->kcj", np.exp(lam[:, None, None] * (refs[beta] - sig[None, lo:hi])),
                       B[lo:hi])                                        # (K, cells, m + 1)
        early = cells[None, lo:hi] < jb[use][:, None]                   # before t - tau
        # cells of one interval of u summed, then a run of whole intervals, each
        # its own m + 1 rows (the history's past) in one slice, else by the scatter matrix
        starts = np.flatnonzero(np.r_[True, np.any(np.diff(node[lo:hi], axis=0) != 0, axis=1)])
        own = node[lo:hi][starts].ravel()
        run = bool(np.all(np.diff(own) == 1))
        extra = np.setdiff1d(np.arange(hi - lo), starts)                # a split interval's rest
        group = np.searchsorted(starts, extra, side="right") - 1
        hit, part = (None, None) if run else _scatter(node[lo:hi])
        keep = ~early.T[:, None, :]                                       # (cells, 1, times)
        for e in range(ia.size):
            Y = (F[:, ia[e], ib[e]][:, None, None] * Mo).reshape(lam.size, -1)
            # (cells, m + 1, times): the transpose, its cells' rows contiguous for reduceat
            V = (np.concatenate([Y.real, Y.imag]).T @ Er.T).reshape(hi - lo, m1, use.size)
            V *= keep
            if run:
                W = V[starts]
                if extra.size:
                    np.add.at(W, group, V[extra])
                out[e][use, own[0]:own[-1] + 1] += W.reshape(-1, use.size).T
            else:
                out[e][np.ix_(use, hit)] += (part.T @ V.reshape(-1, use.size)).T
    r, c, v = [], [], []
    for e in range(ia.size):
        i, j = np.nonzero(out[e])
        r.append(i * n + ia[e])
        c.append(j * n + ib[e])
        v.append(out[e][i, j])
    return sp.csr_matrix((np.concatenate(v), (np.concatenate(r), np.concatenate(c))),
                         shape=(times.size * n, rows * n))


def _scatter(node: np.ndarray) -> tuple[np.ndarray, Any]:
    """(the distinct node rows of cells' columns ``node`` (cells, m + 1), the 0/1 matrix from
    the cells' columns to them: dense for a few, sparse beyond SCATTER_DENSE)."""
    hit, at = np.unique(node, return_inverse=True)
    k = node.size
    if hit.size <= SCATTER_DENSE:
        P = np.zeros((k, hit.size))
        P[np.arange(k), at.ravel()] = 1.0
        return hit, P
    return hit, sp.csr_matrix((np.ones(k), (np.arange(k), at.ravel())), shape=(k, hit.size))


def _cells(ext: np.ndarray, cells: np.ndarray, locate: Locator, basis: Basis, tau: float
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells [ext[i], ext[i + 1]] (i in ``cells``): their Q_NEAR Gauss-Legendre nodes
    (cells, r), the basis at them times the weights (cells, r, m + 1; 0 on a cell shorter than
    delay_matrix's shortest piece) and their node rows (cells, m + 1)."""
    left, d = ext[cells], ext[cells + 1] - ext[cells]
    keep = d > 1e-14 * max(tau, 1.0)
    mid = left + 0.5 * d
    nc = cells.size
    _, z, cols = locate(np.concatenate([mid, mid + 0.25 * d]))
    z1, slope = z[:nc], (z[nc:] - z[:nc]) / (0.25 * d)
    lz, lw = _legendre(Q_NEAR)
    sig = left[:, None] + d[:, None] * lz[None, :]
    B = basis.values((z1[:, None] + (sig - mid[:, None]) * slope[:, None]).ravel())
    B = B.reshape(nc, Q_NEAR, -1) * (d[:, None] * lw[None, :] * keep[:, None])[:, :, None]
    return sig, B, cols[:nc]


def folded_matrix(times: np.ndarray, fold: Any, mesh_points: np.ndarray, T: float,
                  locate: Locator, basis: Basis, n: int, rows: int,
                  pattern: np.ndarray | None = None) -> sp.csr_matrix:
    """delay_matrix's G of the folded kernel H_T over [0, T] (``fold``, a
    :class:`~.fold.Fold`), its far cells by :func:`delay_matrix_separable`: H_T's near part and
    first sum over [0, T], then its second sum over (0, r) without the near lags (0, delta]
    (the tail's); the folded declared jumps stay cuts.  Where the first would not pay
    (:func:`windows`), delay_matrix's G of H_T."""
    (first, far), second = fold.sums
    H = fold.kernel
    pts = np.asarray(mesh_points, dtype=float)
    times = np.asarray(times, dtype=float)
    cuts = tuple(j for j in fold.jumps if j != fold.r)
    whole = Kernel(far, H.near, cuts, H.rate)
    got = windows(times, T, pts, T, whole, first[0])
    if got is None:
        return delay_matrix(times, T, pts, T, H, locate, basis, n, rows, pattern=pattern)[0]
    near = H.near
    if second is None or (near is not None and fold.r <= near.delta):   # H_T = whole past delta
        return delay_matrix_separable(times, T, pts, T, whole, first, locate, basis, n, rows,
                                      pattern=pattern)
    ext, ends, jb, ja, win = got
    if fold.r < np.min((times - ext[jb])[win]):       # r before every window's end
        if pattern is None:
            pattern = np.ones((n, n), bool)
        return _folded_once(times, fold, pts, T, locate, basis, n, rows, pattern, got)
    G = delay_matrix_separable(times, T, pts, T, whole, first, locate, basis, n, rows,
                               pattern=pattern)
    zero = None if near is None else Near(near.delta, near.beta, np.zeros_like(near.C))
    return G + delay_matrix_separable(times, fold.r, mesh_points, T,
                                      Kernel(second[1], zero, cuts, H.rate), second[0],
                                      locate, basis, n, rows, pattern=pattern)


def _folded_once(times: np.ndarray, fold: Any, pts: np.ndarray, T: float, locate: Locator,
                 basis: Basis, n: int, rows: int, pattern: np.ndarray, got: tuple
                 ) -> sp.csr_matrix:
    """:func:`folded_matrix` with r before the end of every time's window (``got``, the first
    sum's :func:`windows`): H_T's pieces outside the windows (its second sum where s < r with
    them), the first sum's far cells, the second's far cells that end before t - r and its
    piece of the cell cut by r."""
    (first, _), (second, far2) = fold.sums
    ext, ends, jb, ja, win = got
    G = delay_matrix(times, T, pts, T, fold.kernel, locate, basis, n, rows, pattern=pattern,
                     omit=(jb, ja))[0]
    G = G + _far_part(times, ext, ends, jb, ja, win, _rates(first), locate, basis, n, rows,
                      pattern, T)
    # the second sum where the window passes r: its cells from t - r on, the cell cut by r
    jr = np.searchsorted(ext, times - fold.r, side="right")
    cut = win & (jr <= ja)
    inner = cut & (jr < ja)
    if np.any(inner):
        G = G + _far_part(times, ext, ends, np.where(inner, jr, ja), ja, inner, _rates(second),
                          locate, basis, n, rows, pattern, T)
    if np.any(cut):
        tc = times[cut]
        _, j0, j1 = crossings(tc, fold.r, pts[:-1], T)
        part = delay_matrix(tc, fold.r, pts, T, Kernel(far2), locate, basis, n, rows,
                            pattern=pattern, omit=(j0, j1))[0]
        which = np.flatnonzero(cut)
        pick = sp.csr_matrix((np.ones(which.size * n), ((which[:, None] * n + np.arange(n))
                                                         .ravel(), np.arange(which.size * n))),
                             shape=(times.size * n, which.size * n))
        G = G + pick @ part
    return G


def _rates(terms: tuple) -> tuple[np.ndarray, np.ndarray]:
    """(lambda = a + i b, F = C - i D) of an exponential sum (a, b, C, D)."""
    a, b, C, D = (np.asarray(x, dtype=float) for x in terms)
    return a + 1j * b, C - 1j * D
