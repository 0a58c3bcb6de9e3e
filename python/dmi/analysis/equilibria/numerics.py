# Small numerical tools of the equilibria room: forward-difference Jacobians, null vectors and the
# signed mean of test functions.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The numerical tools that several modules of :mod:`dmi.analysis.equilibria` share, each written
once: :func:`forward_jacobian` (the columns of a Jacobian by forward differences),
:func:`null_vectors` (the right and left null vectors of a matrix from its singular value
decomposition) and :func:`signed_mean` (the form of the test functions of events).

What it may import: numpy only (it sits at the bottom of the room: nothing here reads a model)."""
from __future__ import annotations

import math
from collections.abc import Callable, Iterable

import numpy as np

#: Relative step of :func:`forward_jacobian`: the step of column j is FORWARD_STEP max(1, |y_j|).
FORWARD_STEP = 1e-7


def forward_jacobian(g: Callable[[np.ndarray], np.ndarray], y: np.ndarray, g0: np.ndarray,
                     columns: Iterable[int] | None = None) -> np.ndarray:
    """The Jacobian of g at y by forward differences, step FORWARD_STEP max(1, |y_j|), with
    g0 = g(y) given; only the ``columns`` listed (default all), the others 0."""
    y = np.asarray(y, dtype=float)
    J = np.zeros((np.size(g0), y.size))
    for j in range(y.size) if columns is None else columns:
        d = FORWARD_STEP * max(1.0, abs(y[j]))
        e = y.copy()
        e[j] += d
        J[:, j] = (g(e) - g0) / d
    return J


def null_vectors(M: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, p, s): the unit right null vector q (M q ~ 0), the unit left null row p (p M ~ 0),
    both the smallest singular value's, and the singular values s (largest first)."""
    U, s, Vh = np.linalg.svd(M)
    q = Vh[-1].conj()
    return q / np.linalg.norm(q), U[:, -1].conj(), s


def signed_mean(values: Iterable[float]) -> float:
    """sign(prod values) times the geometric mean of |values|; NaN for none, 0 with a zero
    (the test functions' form: the sign of a product, a size that does not under- or
    overflow)."""
    f = np.array(list(values), dtype=float)
    if f.size == 0:
        return math.nan
    if np.any(f == 0):
        return 0.0
    return float(np.prod(np.sign(f))) * float(np.exp(np.mean(np.log(np.abs(f)))))


__all__ = ["FORWARD_STEP", "forward_jacobian", "null_vectors", "signed_mean"]
