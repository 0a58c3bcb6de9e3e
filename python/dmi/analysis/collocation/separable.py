# The delay integral's matrix of an exponential-sum kernel over the far lags as products of
# separated factors (one matrix product instead of an exponential a lag and term).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The delay integral of :func:`dmi.analysis.collocation.mesh.delay_matrix` for a kernel whose
far part is an exponential sum H(s) = Re sum_j e^(lambda_j s) F_j (F_j = C_j - i D_j,
Re lambda_j <= 0); private to the package.

Cut the time axis at the mesh crossings (the mesh points repeated every T) into *cells*; each
lies inside one interval of u.  On a cell [l, l + d] whose lags t_c - sigma lie in [s0, tau],
past every kernel break (the near part's delta, its declared jumps, the grading's start) and at
least the cell's length from 0, the integral is

    int H(t_c - sigma) B_k(sigma) d sigma = Re sum_j e^(lambda_j (t_c - c)) F_j M_j,k,
    M_j,k = int_l^(l + d) e^(lambda_j (c - sigma)) B_k(sigma) d sigma,

for any reference c: with c at or after the cell's end and at or before t_c both factors are
at most 1 in modulus.  The cells are grouped in *blocks*: those that end at or before
min(t) - s0 (every time's memory, the past) in one, then BLOCK_CELLS cells at a time, each block
its end as reference.  A time takes every block that ends at or before t_c - s0 (its *window*,
the cells that start at or after t_c - tau), each by one product of its (times x terms) factors
with the block's (terms x columns) moments; the rest of [0, tau] (the near lags, the last block
not yet ended, the cell cut by tau) keeps delay_matrix's pieces (``omit``).  M is integrated by
Q_NEAR Gauss-Legendre nodes on the whole cell (a cell at least its own length from 0: the
graded pieces' rule), where delay_matrix cuts it at the grading and takes q or Q_NEAR nodes: the
two differ by their quadrature errors.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .fold import Fold, exp_sum
from .mesh import Basis, Kernel, Locator, Near, Q_NEAR, _legendre, crossings, delay_matrix

#: Cells a block of the period (after the past's block) takes: the direct pieces of a time end
#: at most that many cells (and s0) behind it.
BLOCK_CELLS = 4


def far_lag(kernel: object, pts: np.ndarray, T: float) -> float:
    """s0: the lag from which a cell is integrated by the separated factors, past the near part
    (and its graded cuts' start), the kernel's jumps and the longest cell of the mesh ``pts``
    (one period, 0 to T)."""
    near = getattr(kernel, "near", None)
    jumps = getattr(kernel, "jumps", ())
    s0 = max([float(np.max(np.diff(pts))), getattr(kernel, "grading", 0.0),
              near.delta if near is not None else 0.0] + [float(j) for j in jumps])
    return s0 * (1.0 + 1e-9)


def delay_matrix_separable(times: np.ndarray, tau: float, mesh_points: np.ndarray, T: float,
                           kernel: object, terms: tuple, locate: Locator, basis: Basis, n: int,
                           rows: int, pattern: np.ndarray | None = None) -> sp.csr_matrix:
    """:func:`dmi.analysis.collocation.mesh.delay_matrix`'s G for a kernel whose far part is
    the exponential sum ``terms`` (a, b, C, D) (see the module), the far cells by products.

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
    if times.size == 0 or np.any(a > 0):
        return delay_matrix(times, tau, pts, T, kernel, locate, basis, n, rows,  # type: ignore
                            pattern=pattern)[0]
    s0 = far_lag(kernel, pts, T)
    ext, j0, j1 = crossings(times, tau, pts[:-1], T)
    ends = _block_ends(ext, times, s0)
    # each time's window: the cells from its first crossing past t - tau to the last block end
    # at or before t - s0
    at = np.searchsorted(ext[ends], times - s0, side="right") - 1
    ja = np.where(at >= 0, ends[np.maximum(at, 0)], -1)
    jb = np.clip(j0, 0, None)
    win = (at >= 0) & (jb < ja) & (ja < j1)
    if not np.any(win):
        return delay_matrix(times, tau, pts, T, kernel, locate, basis, n, rows,  # type: ignore
                            pattern=pattern)[0]
    jb, ja = np.where(win, jb, j1), np.where(win, ja, j1)
    G = delay_matrix(times, tau, pts, T, kernel, locate, basis, n, rows,  # type: ignore
                     pattern=pattern, omit=(jb, ja))[0]
    return G + _far_part(times, ext, ends, jb, ja, win, (a + 1j * b, C - 1j * D), locate,
                         basis, n, rows, pattern, tau)


def _block_ends(ext: np.ndarray, times: np.ndarray, s0: float) -> np.ndarray:
    """The indices into ext of the blocks' ends (their references): the last crossing at or
    before min(t) - s0, then every BLOCK_CELLS-th up to max(t) - s0."""
    first = int(np.searchsorted(ext, times.min() - s0, side="right")) - 1
    last = int(np.searchsorted(ext, times.max() - s0, side="right")) - 1
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
        hit = np.unique(node[lo:hi])                                   # the block's node rows
        part = sp.csr_matrix((np.ones((hi - lo) * m1), (np.arange((hi - lo) * m1),
                              np.searchsorted(hit, node[lo:hi]).ravel())),
                             shape=((hi - lo) * m1, hit.size))
        where = np.ix_(use, hit)
        for e in range(ia.size):
            Y = (F[:, ia[e], ib[e]][:, None, None] * Mo).reshape(lam.size, -1)
            V = (Er @ np.concatenate([Y.real, Y.imag])).reshape(use.size, hi - lo, m1)
            V[early] = 0.0
            out[e][where] += (part.T @ V.reshape(use.size, -1).T).T
    G = sp.csr_matrix((times.size * n, rows * n))
    for e in range(ia.size):
        unit = sp.csr_matrix(([1.0], ([ia[e]], [ib[e]])), shape=(n, n))
        G = G + sp.kron(sp.csr_matrix(out[e]), unit, format="csr")
    return G


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


def folded_matrix(times: np.ndarray, fold: Fold, mesh_points: np.ndarray, T: float,
                  locate: Locator, basis: Basis, n: int, rows: int,
                  pattern: np.ndarray | None = None) -> sp.csr_matrix:
    """delay_matrix's G of the folded kernel H_T over [0, T] (``fold``, :mod:`~.fold`), its
    far cells by :func:`delay_matrix_separable`: H_T's near part and first sum over [0, T],
    then its second sum over (0, r) without the near lags (0, delta] (the tail's); the folded
    declared jumps stay cuts."""
    first, second = fold.sums
    H = fold.kernel
    cuts = tuple(j for j in fold.jumps if j != fold.r)

    def kernel(terms: tuple, near: Near | None) -> Kernel:
        return Kernel(lambda s: exp_sum(s, *terms), near, cuts, H.rate)
    G = delay_matrix_separable(times, T, mesh_points, T, kernel(first, H.near), first, locate,
                               basis, n, rows, pattern=pattern)
    near = H.near
    if second is not None and (near is None or fold.r > near.delta):
        zero = None if near is None else Near(near.delta, near.beta, np.zeros_like(near.C))
        G = G + delay_matrix_separable(times, fold.r, mesh_points, T,
                                       kernel(second, zero), second, locate, basis, n, rows,
                                       pattern=pattern)
    return G
