# Floquet multipliers of periodic orbits that carry the stick/slip switching.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Floquet multipliers of a periodic orbit of the scheme, right at stick/slip transitions.

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
tests/python/test_analysis_orbit_oracles.py).  Multipliers of a stuck phase come out exactly
0: a perturbation that keeps the stick is wiped out.

The leading multipliers are the eigenvalues of largest modulus of that operator (a
``scipy.sparse.linalg.LinearOperator``): Rayleigh-Ritz on a block Krylov space of two blocks (a
dense matrix for small states), see :func:`floquet_multipliers`.
"""
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl
import scipy.sparse.linalg as sla

from .stepmap import StepMap

#: c in eps = c A min(M^(-1/3), FD_CAP) (see the module's docstring).
FD_FACTOR = 1.0
#: Few steps a period (M < 8000) have no switch to resolve finely; the cap keeps eps / A <= 5 %
#: there, so that the curvature error O((eps / A)^2) of a mildly nonlinear orbit stays below
#: 0.3 % (an orbit where no resolvent acts takes the small step, see :func:`fd_step`).
FD_CAP = 0.05


def fd_step(F: StepMap, x: np.ndarray, U: np.ndarray | None = None,
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


def monodromy_operator(F: StepMap, x: np.ndarray, eps: float | None = None,
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


def floquet_multipliers(F: StepMap, x: np.ndarray, count: int = 10, *,
                        eps: float | None = None, blocks: int = 2,
                        central: bool = True) -> np.ndarray:
    """The leading Floquet multipliers of a periodic orbit, right at stick/slip transitions.

    The monodromy operator by central differences with a step that moves the switches by many
    steps (:func:`fd_step`; the smooth step on an orbit with no switch to carry); its eigenvalues
    of largest modulus by Rayleigh-Ritz on ``blocks`` blocks of a block Krylov space of b =
    count + 2 vectors (states of at most 64 values: the dense matrix).  Not ARPACK's eigs: the
    difference operator is linear only up to the switches' rounding to a step (O(h / eps)), and a
    long Krylov recurrence with restarts amplifies that, while a Ritz matrix of independently
    differenced columns, few blocks deep, carries it once.

    Parameters
    ----------
    F : StepMap
        The M-step map, e.g. ``StepMap(orbit.make, orbit.p, orbit.steps, orbit.rows)``.
    x : numpy.ndarray
        Its fixed point, e.g. ``orbit.state``.
    count : int
        How many multipliers.
    eps : float, optional
        The difference step (state units), instead of :func:`fd_step`'s.
    blocks : int
        Krylov blocks (>= 2).
    central : bool
        Central differences (2 evaluations a product), else forward (1).

    Returns
    -------
    numpy.ndarray of complex, shape (count,)
        Largest |mu| first (dimensionless); below 1e-12 in modulus: 0 (a stuck phase's).

    Raises
    ------
    ValueError
        blocks < 2.
    TypeError
        An EquationOrbit (it carries its multipliers).
    """
    if getattr(F, "of", "scheme") == "equation":
        raise TypeError("floquet_multipliers: an EquationOrbit (collocate) carries its own "
                        ".multipliers; this takes a StepMap of the scheme")
    return ritz(F, x, count, blocks=blocks, eps=eps, central=central)[0]


def ritz(F: StepMap, x: np.ndarray, count: int, *, blocks: int = 2,
         start: np.ndarray | None = None, eps: float | None = None, central: bool = True
         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(multipliers, Q, Z) of :func:`floquet_multipliers`: Q (dim, k) an orthonormal basis of the
    dominant invariant subspace of the Ritz matrix (its k >= count + 2 eigenvalues of largest
    modulus; k = b, or b + 1 when a complex pair straddles the cut) and Z = A Q, so that Q' Z is
    the Ritz matrix there and Z Q' the operator's rank-k approximation on that subspace (the
    continuation's Newton-Picard corrector, see :mod:`dmi.analysis.continuation`).  ``start``:
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
