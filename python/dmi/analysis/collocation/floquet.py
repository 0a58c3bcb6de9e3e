# Floquet multipliers of a collocated orbit: the discretised monodromy operator of the linearised
# equation over one period, with the switches' saltation.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Multipliers of :mod:`dmi.analysis.collocation.collocate`'s orbits; private to the package.

As DDE-BIFTOOL does: the state is the past over [-tau, 0] as a piecewise polynomial on the
orbit's own mesh shifted back (each interval its own m + 1 nodes, so a perturbation may jump at a
switch); one period forward is the collocation system of the period from that past (u(0) =
phi(0-), the collocation, the switching conditions with their times unknown), linearised at the
orbit; the image is the new past over [T - tau, T].  The monodromy matrix (the intervals that meet
[-tau, 0]) is decomposed densely up to DENSE_MAX rows; beyond (a memory of many periods) the
operator's products give the leading multipliers by ARPACK (:mod:`dmi.analysis.collocation.krylov`).

A switching time's variation moves the nodes of the pieces it bounds: the perturbation at a
fixed time is the node value's minus u*' (one-sided, inside the node's interval) times the node's
motion.  That is the saltation of Barton (2008) in the collocation's terms: linearising the
switching condition with the switching time as an unknown gives it (a stuck piece's component
is held, so its perturbation is wiped out: the zero multipliers it should give).  The system's
columns of the switching times are exact, the past held at fixed times
(:func:`dmi.analysis.collocation.system.full_jacobian` with the history,
:func:`dmi.analysis.collocation.system.switch_columns`).
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .krylov import DENSE_MAX, Monodromy, leading_pairs, nearest
from .system import History, Layout, Terms, full_jacobian
from ..core.blas import _one_blas_thread

#: Products of :func:`on_halved`'s subspace iteration at most.
RITZ_ROUNDS = 4
#: A Ritz pair of :func:`on_halved` is accepted when |M y - theta y| <= RITZ_TOL max(1, the
#: largest |theta|) |y|.
RITZ_TOL = 1e-12


def monodromy(lay: Layout, terms: Terms, x: np.ndarray) -> np.ndarray:
    """The monodromy matrix on the past's nodes over the intervals that meet [-tau, 0]."""
    m, n, L = lay.m, lay.n, lay.L
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    P = max(1, math.ceil(terms.tau / T - 1e-12))
    i = np.arange(L)
    k = np.arange(m + 1)
    cols = (i[:, None] * m + k[None, :]) % lay.rows
    one = V[cols]                                          # (L, m + 1, n)
    phi = np.tile(one, (P, 1, 1)).reshape(-1, n)
    J = full_jacobian(lay, terms, x, None, history=History(mesh, P, phi))[1]
    nc = (lay.rows + 1) * n
    nh = P * L * (m + 1) * n
    Jcur = sp.hstack([J[:, :nc], J[:, nc + nh:]], format="csc")
    # the past's intervals g (oldest first) that meet (-tau, 0]
    g = np.arange(P * L)
    per = P - g // L
    end = mesh[g % L + 1] - per * T
    state = g[end > -terms.tau + 1e-14 * T]
    if state.size == 0 or state[-1] != P * L - 1:
        state = np.append(state, P * L - 1)
    scol = (state[:, None, None] * (m + 1) * n + k[None, :, None] * n
            + np.arange(n)[None, None, :]).ravel()
    lu = sla.splu(Jcur, permc_spec="NATURAL")     # the columns' own order (Newton's LU on a
    #                                               graded mesh takes COLAMD's: not measured here)
    Z = -lu.solve(J[:, nc + scol].toarray())   # d(nodes, b) / d(state)
    dV, db = Z[:nc].reshape(lay.rows + 1, n, -1), Z[nc:]
    # the image: interval g + L of the past, or interval g + L - P L of the period
    h = np.diff(mesh)
    dz = lay.basis.derivatives(lay.basis.nodes)             # (m + 1 nodes, m + 1 basis)
    left, right = lay.node_motion()
    piece = lay.piece_of_interval()
    who = lay.ends(b, T)[1]                                 # the switch each piece end moves with
    where = {int(gg): j for j, gg in enumerate(state)}
    dim = scol.size
    M = np.zeros((dim, dim))
    for j, gg in enumerate(state):
        out = slice(j * (m + 1) * n, (j + 1) * (m + 1) * n)
        ng = int(gg) + L
        if ng < P * L:
            src = where[ng]
            M[out, src * (m + 1) * n:(src + 1) * (m + 1) * n] = np.eye((m + 1) * n)
            continue
        iv = ng - P * L
        rows = dV[iv * m + k]                               # (m + 1, n, dim)
        slope = dz @ one[iv] / h[iv]                        # u*' inside interval iv at its nodes
        move = np.zeros((m + 1, dim))                       # d t_node / d state
        pc = piece[iv]
        if who[pc] >= 0:
            move += left[iv][:, None] * db[who[pc]][None, :]
        if who[pc + 1] >= 0:
            move += right[iv][:, None] * db[who[pc + 1]][None, :]
        M[out] = (rows - slope[:, :, None] * move[:, None, :]).reshape((m + 1) * n, dim)
    return M


def state_intervals(lay: Layout, terms: Terms, mesh: np.ndarray, T: float, P: int) -> np.ndarray:
    """The past's intervals (oldest first, of P periods behind 0) that meet (-tau, 0]: the
    state of the monodromy operator (the newest always)."""
    L = lay.L
    g = np.arange(P * L)
    end = mesh[g % L + 1] - (P - g // L) * T
    state = g[end > -terms.tau + 1e-14 * T]
    if state.size == 0 or state[-1] != P * L - 1:
        state = np.append(state, P * L - 1)
    return state


def operator(lay: Layout, terms: Terms, x: np.ndarray) -> Monodromy:
    """The monodromy operator of the orbit x: :func:`monodromy`'s matrix as the pieces of its
    products (:class:`dmi.analysis.collocation.krylov.Monodromy`), without the dense matrix."""
    m, n, L = lay.m, lay.n, lay.L
    V, b, T = lay.split(x)
    mesh = lay.mesh(b, T)
    P = max(1, math.ceil(terms.tau / T - 1e-12))
    k = np.arange(m + 1)
    one = V[(np.arange(L)[:, None] * m + k[None, :]) % lay.rows]       # (L, m + 1, n)
    J = full_jacobian(lay, terms, x, None,
                      history=History(mesh, P, np.tile(one, (P, 1, 1)).reshape(-1, n)))[1]
    nc = (lay.rows + 1) * n
    nh = P * L * (m + 1) * n
    state = state_intervals(lay, terms, mesh, T, P)
    block = (m + 1) * n
    inner = (k[:, None] * n + np.arange(n)[None, :]).ravel()         # a block's entries
    scol = (state[:, None] * block + inner[None, :]).ravel()
    lu = sla.splu(sp.hstack([J[:, :nc], J[:, nc + nh:]], format="csc"))
    where = {int(g): j for j, g in enumerate(state)}
    nxt = state + L
    shift = nxt < P * L
    jd = np.flatnonzero(shift)
    js = np.array([where[int(g)] for g in nxt[shift]], dtype=int)
    dst = (jd[:, None] * block + inner[None, :]).ravel()
    src = (js[:, None] * block + inner[None, :]).ravel()
    jn = np.flatnonzero(~shift)
    iv = nxt[~shift] - P * L                                          # the period's intervals
    new = (jn[:, None] * block + inner[None, :]).ravel()
    rows = ((iv[:, None, None] * m + k[None, :, None]) * n
            + np.arange(n)[None, None, :]).ravel()
    h = np.diff(mesh)
    dz = lay.basis.derivatives(lay.basis.nodes)                        # (m + 1, m + 1)
    slope = (np.einsum("ij,ljn->lin", dz, one[iv]) / h[iv][:, None, None]).ravel()
    left, right = lay.node_motion()
    piece = lay.piece_of_interval()[iv]
    who = lay.ends(b, T)[1]
    S = lay.S

    def spread(a: np.ndarray) -> np.ndarray:                          # (k, m + 1) -> entries
        return np.repeat(a[:, :, None], n, axis=2).ravel()
    wl = spread(np.broadcast_to(np.where(who[piece] >= 0, who[piece], S)[:, None], (iv.size,
                                                                                    m + 1)))
    wr = spread(np.broadcast_to(np.where(who[piece + 1] >= 0, who[piece + 1], S)[:, None],
                                (iv.size, m + 1)))
    return Monodromy(lu, J[:, nc + scol], nc, scol.size, dst, src, new, rows, slope,
                     spread(left[iv]), spread(right[iv]), wl.astype(int), wr.astype(int))


def multipliers(lay: Layout, terms: Terms, x: np.ndarray, count: int = 10) -> np.ndarray:
    """The ``count`` multipliers of largest modulus (largest first; below 1e-12: 0): the dense
    monodromy matrix's eigenvalues up to ``DENSE_MAX`` rows, beyond by ARPACK on the operator
    (:mod:`dmi.analysis.collocation.krylov`; the dense matrix where ARPACK's are not verified)."""
    return pairs(lay, terms, x, count, False)[0]


def pairs(lay: Layout, terms: Terms, x: np.ndarray, count: int = 10, vectors: bool = True
          ) -> tuple[np.ndarray, np.ndarray | None]:
    """:func:`multipliers` and, with ``vectors``, their eigenvectors on the monodromy's state
    (columns, the same order; None where there are none)."""
    op = operator(lay, terms, x)
    V = None
    with _one_blas_thread():          # small dense problems: BLAS threads only contend
        got = leading_pairs(op, count) if op.dim > DENSE_MAX else None
        if got is not None:
            mu, V = got
        elif vectors:
            mu, V = sl.eig(op.apply(np.eye(op.dim)))
        else:
            mu = sl.eigvals(op.apply(np.eye(op.dim)))
    order = np.argsort(-np.abs(mu), kind="stable")[:count]
    mu = mu[order]
    return np.where(np.abs(mu) < 1e-12, 0.0, mu), (None if V is None else V[:, order])


def on_halved(fine: Layout, x: np.ndarray, coarse: Layout, xc: np.ndarray, terms: Terms,
              mu: np.ndarray, V: np.ndarray) -> np.ndarray | None:
    """The multipliers of the orbit x on ``fine``, the ``coarse`` layout's mesh halved, near
    ``mu``, those of the coarse orbit xc (V: their eigenvectors, :func:`pairs`): subspace
    iteration on fine's monodromy operator from V prolonged (exactly: each interval of ``fine``
    is half of one of ``coarse``, its polynomial the coarse one's there), with two more
    directions than mu, and the Rayleigh-Ritz values of the subspace, up to RITZ_ROUNDS
    products (M Q, Q orthonormal: the operator's products are its only cost); the same
    number as mu, largest first, below 1e-12: 0.  None where a Ritz pair of a nonzero
    multiplier keeps a residual |M y - theta y| above RITZ_TOL (relative to max(1, |theta|)
    and |y|; the caller then decomposes the monodromy, :func:`multipliers`): a slow
    convergence (moduli close to the next ones'), or V not of the coarse operator; None too,
    without building fine's operator, where its state (twice V's rows) exceeds DENSE_MAX: there
    :func:`multipliers` takes ARPACK's on it, and subspace iteration from V converges slowly
    (a ring of multipliers near one modulus)."""
    if 2 * V.shape[0] > DENSE_MAX:
        return None
    op = operator(fine, terms, x)
    k = min(mu.size + 2, V.shape[1], op.dim)
    P = prolongation(coarse, xc, fine, x, terms)
    if k < mu.size or P is None or P.shape != (op.dim, V.shape[0]):
        return None
    Y = P @ V[:, :k]
    with _one_blas_thread():
        for _ in range(RITZ_ROUNDS):
            Q = np.linalg.qr(Y)[0]
            Y = op.apply(Q)
            theta, W = np.linalg.eig(Q.conj().T @ Y)
            order = np.argsort(-np.abs(theta), kind="stable")[:mu.size]
            theta, W = theta[order], W[:, order]
            Z = Q @ W
            res = (np.linalg.norm(Y @ W - Z * theta[None, :], axis=0)
                   / np.maximum(np.linalg.norm(Z, axis=0), 1e-300))
            big = np.abs(theta) >= 1e-12
            if np.all(res[big] <= RITZ_TOL * max(1.0, float(np.max(np.abs(theta))))):
                return np.where(big, theta, 0.0)
    return None


def prolongation(coarse: Layout, xc: np.ndarray, fine: Layout, x: np.ndarray, terms: Terms
                 ) -> sp.csr_matrix | None:
    """The matrix taking a state of the monodromy of the orbit xc on ``coarse`` (its past's node
    values) to the one of the orbit x on ``fine`` (the coarse mesh halved): each fine interval's
    nodes the coarse polynomial's values there; None where a fine state interval's parent is not
    in the coarse state (their periods span another number of periods of the past)."""
    m, n = coarse.m, coarse.n
    _, bc, Tc = coarse.split(xc)
    _, b, T = fine.split(x)
    P = max(1, math.ceil(terms.tau / T - 1e-12))
    if P != max(1, math.ceil(terms.tau / Tc - 1e-12)):
        return None
    rows = state_intervals(fine, terms, fine.mesh(b, T), T, P)
    cols = {int(g): j for j, g in enumerate(state_intervals(coarse, terms, coarse.mesh(bc, Tc),
                                                            Tc, P))}
    z = np.arange(m + 1) / m
    halves = (np.kron(coarse.basis.values(0.5 * z), np.eye(n)),
              np.kron(coarse.basis.values(0.5 + 0.5 * z), np.eye(n)))
    parent = []
    for g in rows:
        period, k = divmod(int(g), fine.L)
        i = cols.get(period * coarse.L + k // 2)
        if i is None:
            return None
        parent.append((i, k % 2))
    blocks = np.empty((len(rows), len(cols)), dtype=object)   # (a list of one-block lists
    for j, (i, half) in enumerate(parent):                     # would become a 4-D array)
        blocks[j, i] = halves[half]
    return sp.bmat(blocks, format="csr", dtype=float) if len(rows) else None


def eigenfunction(lay: Layout, terms: Terms, x: np.ndarray, near: complex = -1.0
                  ) -> tuple[complex, np.ndarray]:
    """The Floquet eigenfunction of the multiplier nearest ``near`` over one period, as node
    values on the orbit's own mesh (for :func:`dmi.analysis.period_doubled_orbit`).

    The eigenvector of :func:`monodromy` is the past over [-tau, 0]; the linearised collocation
    system of the period from that past (the same system :func:`monodromy` solves) gives the
    perturbation at the period's nodes, the eigenfunction v on [0, T) (v(t + T) = mu v(t)).  On
    an orbit with switches these are the node values' perturbations (the nodes move with the
    switches; the saltation is left out).

    Parameters
    ----------
    lay : Layout
        The orbit's layout.
    terms : Terms
        The model's terms at the orbit's p.
    x : numpy.ndarray
        The orbit's unknowns.
    near : complex
        The multiplier wanted (-1: a period doubling's).

    Returns
    -------
    tuple
        (mu, V): the multiplier nearest ``near`` and the eigenfunction's values (L m, n) at the
        node times (:func:`dmi.analysis.collocation.system.node_times`), complex, largest
        |value| 1.

    Raises
    ------
    ValueError
        The eigenfunction vanishes on the period (a multiplier 0).
    """
    op = operator(lay, terms, x)
    with _one_blas_thread():
        pair = nearest(op, near) if op.dim > DENSE_MAX else None
        if pair is None:
            mu, Y = sl.eig(op.apply(np.eye(op.dim)))
            j = int(np.argmin(np.abs(mu - near)))
            pair = (complex(mu[j]), Y[:, j])
    rhs = op.B @ pair[1]
    re, im = np.ascontiguousarray(rhs.real), np.ascontiguousarray(rhs.imag)
    dV = -(op.lu.solve(re) + 1j * op.lu.solve(im))
    out = dV[:lay.rows * lay.n].reshape(lay.rows, lay.n)
    big = float(np.max(np.abs(out)))
    if not big > 0:
        raise ValueError(f"the eigenfunction of the multiplier {pair[0]:.6g} vanishes on the "
                         "period: no direction to follow")
    return pair[0], out / out.flat[int(np.argmax(np.abs(out)))]
