# dmi.identify._near: the near cells' part of the tangent's delay sum, written once.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The near cells' part of the delay sum of the tangent, sum_{l<m} D_l S^{q-l}, with D_l the part of
the weights that libdmi's near cells add to the exponential sum's (``Solver.kernel_weights``).  The
Python loop of sensitivity.py calls :func:`near_sum` (libdmi's loop adds the near cells with the
solver's own engine); :func:`near_kernel_part` gives the kernel parameters' part of them to both.
(Plain NumPy.)"""
from __future__ import annotations

import numpy as np


def near_sum(D: np.ndarray, Sall: np.ndarray, q: int, N: int, acc: np.ndarray) -> None:
    """acc += sum_{l<m} D[l] @ S^{q-l}, where D is (m, n, n), Sall[q + N] = S^q is (n, P) and acc
    is (n, P)."""
    for l in range(D.shape[0]):
        acc += D[l] @ Sall[q + N - l]


def near_kernel_part(dD: np.ndarray, Uext: np.ndarray, N: int, steps: int) -> np.ndarray:
    """out[q, :, j] = sum_{l<m} dD[j, l] @ U^{q-l} for q = 0 .. steps - 1 (steps, n, P), where dD is
    (P, m, n, n), the near parts' derivatives in p_j, and Uext[k] = U^{k-N+1}."""
    P, m, n = dD.shape[0], dD.shape[1], Uext.shape[1]
    out = np.zeros((steps, n, P))
    for l in range(m):
        rows = Uext[N - 1 - l:N - 1 - l + steps]                      # U^{q-l}, q = 0 .. steps - 1
        out += np.einsum("jik,qk->qij", dD[:, l], rows)
    return out
