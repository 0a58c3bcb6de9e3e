# The monodromy operator of a collocated orbit applied to vectors, and its leading multipliers by
# a Krylov method (ARPACK), for long memories whose past makes the dense matrix large.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The monodromy operator of :mod:`dmi.analysis.collocation.floquet` without its dense matrix;
private to the package.

The operator is :func:`dmi.analysis.collocation.floquet.monodromy`'s: the state is the past over
[-tau, 0] on the orbit's mesh shifted back; one period forward moves the past's intervals that
stay in [-tau, 0] by one period (a copy) and fills the newest period from the linearised
collocation system of the period from that past (a sparse solve, the switching times' saltation
included).  Its matrix has (intervals within tau) (m + 1) n rows: on a memory of many periods,
thousands, and its dense eigenvalues cost minutes.  Here the operator is applied to vectors (one
sparse product with the past's columns, one solve with the factored period block, the copies),
and ARPACK's implicitly restarted Arnoldi method finds the leading multipliers from those
products; each is checked by its residual |M v - mu v| against the largest multiplier (or 1).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

#: The monodromy matrices up to this size are decomposed densely (LAPACK); larger ones by ARPACK.
DENSE_MAX = 1200
#: ARPACK's relative tolerance on the Ritz values.
ARNOLDI_TOL = 1e-13
#: A multiplier is accepted when |M v - mu v| <= RESIDUAL_TOL max(1, the largest |mu|) |v|.
RESIDUAL_TOL = 1e-9


@dataclass
class Monodromy:
    """The monodromy operator of an orbit as the pieces its products need.

    ``lu`` factors the Jacobian's columns of the period (nodes, switching times); ``B`` holds
    its columns of the state (the past's nodes that meet [-tau, 0]); ``dst``/``src`` copy the
    state's entries that stay in the past; ``new``, ``rows`` place the newest period's node
    values; ``slope`` (len(new),) is u*' at them, ``left``/``right`` the nodes' motion with the
    ends of their pieces and ``wl``/``wr`` the switch each end moves with (S: none)."""
    lu: sla.SuperLU
    B: sp.csc_matrix
    nc: int
    dim: int
    dst: np.ndarray
    src: np.ndarray
    new: np.ndarray
    rows: np.ndarray
    slope: np.ndarray
    left: np.ndarray
    right: np.ndarray
    wl: np.ndarray
    wr: np.ndarray

    def apply(self, v: np.ndarray) -> np.ndarray:
        """M v for v (dim,) or (dim, k), real or complex."""
        v = np.asarray(v)
        flat = v.ndim == 1
        V = v[:, None] if flat else v
        out = np.zeros(V.shape, dtype=np.result_type(V.dtype, float))
        out[self.dst] = V[self.src]
        rhs = self.B @ V
        if np.iscomplexobj(rhs):
            Z = -(self.lu.solve(np.ascontiguousarray(rhs.real))
                  + 1j * self.lu.solve(np.ascontiguousarray(rhs.imag)))
        else:
            Z = -self.lu.solve(np.ascontiguousarray(rhs))
        Z = Z.reshape(Z.shape[0], -1)
        db = np.vstack([Z[self.nc:], np.zeros((1, Z.shape[1]))])    # the last row: no switch
        move = self.left[:, None] * db[self.wl] + self.right[:, None] * db[self.wr]
        out[self.new] = Z[self.rows] - self.slope[:, None] * move
        return out[:, 0] if flat else out


def leading_pairs(op: Monodromy, count: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The ``count`` multipliers of largest modulus by ARPACK (largest first) and their
    eigenvectors (columns), each checked by its residual; None where ARPACK does not converge or
    a residual is too large (the caller then decomposes the dense matrix)."""
    got = _arnoldi(op, count)
    return None if got is None else (got[0][:count], got[1][:, :count])


def nearest(op: Monodromy, near: complex, count: int = 10
            ) -> tuple[complex, np.ndarray] | None:
    """The multiplier nearest ``near`` and its eigenvector, among the ``count`` leading ones by
    ARPACK, where that is the nearest of all: its distance to ``near`` at most |near| minus the
    modulus of the last one found (every other multiplier is smaller); None otherwise."""
    got = _arnoldi(op, count)
    if got is None:
        return None
    mu, Y = got
    j = int(np.argmin(np.abs(mu - near)))
    if not abs(mu[j] - near) <= abs(near) - abs(mu[-1]):
        return None
    return complex(mu[j]), Y[:, j]


def _arnoldi(op: Monodromy, count: int) -> tuple[np.ndarray, np.ndarray] | None:
    """count + 2 leading multipliers and their eigenvectors by ARPACK (largest first), each
    checked by its residual; None where that fails."""
    k = min(count + 2, op.dim - 2)
    if k < 1:
        return None
    A = sla.LinearOperator((op.dim, op.dim), matvec=op.apply, dtype=float)
    ncv = min(op.dim, max(2 * k + 1, k + 40))
    v0 = np.random.default_rng(12345).standard_normal(op.dim)
    try:
        mu, Y = sla.eigs(A, k=k, which="LM", tol=ARNOLDI_TOL, ncv=ncv, v0=v0,
                         maxiter=50 * op.dim)
    except sla.ArpackError:
        return None
    scale = max(float(np.max(np.abs(mu), initial=0.0)), 1.0)
    R = op.apply(Y) - Y * mu[None, :]
    res = np.linalg.norm(R, axis=0) / np.maximum(np.linalg.norm(Y, axis=0), 1e-300)
    if not np.all(res <= RESIDUAL_TOL * scale):
        return None
    order = np.lexsort((-mu.imag, -np.abs(mu)))         # largest first; a pair: Im > 0 first
    return mu[order], Y[:, order]
