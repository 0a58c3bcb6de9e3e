# dmi.identify._saltation: how a friction component leaves a step of the scheme (the saltation test).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The test of one friction component at one step, for the Python loop of sensitivity.py (libdmi's loop,
dmi_tangent_run, has the same test in C, src/tangent.c): whether the component
reverses during the step (S_i then multiplied by the saltation factor rho = F+ / F-), starts to stick,
or neither.  Plain Python on NumPy arrays, importable without numba."""
from __future__ import annotations

import math

import numpy as np

from .._resolvent import crossing, saltation_factor

#: codes of what a component does in a step (the first element of :func:`reversal`'s result)
NONE, STICK, REVERSAL, UNPLACED = 0, 1, 2, 3


def reversal(q: int, i: int, U: np.ndarray, phi: np.ndarray, alpha: np.ndarray) -> tuple[int, float]:
    """What friction component i does in step q, and the saltation factor of a reversal.

    Parameters
    ----------
    q : int
        The step, from U^q to U^{q+1}.
    i : int
        The component.
    U : numpy.ndarray
        Shape (steps + 1, n): the states of the run.
    phi : numpy.ndarray
        Shape (steps, n): f + W at each step, (U^q - X^q) / h.
    alpha : numpy.ndarray
        Shape (n,): the friction levels.

    Returns
    -------
    tuple of (int, float)
        (REVERSAL, rho) where the component slips at U^q and reverses during the step (to the other
        sign at once, or through one step in the dead zone), rho = F+ / F- the ratio of the
        velocities just after and before the reversal (linear interpolation of phi at the reversal);
        (STICK, 0.0) where it lands in the dead zone and stays; (UNPLACED, 0.0) where it slips at U^q
        and meets zero or changes sign in the step but the velocities interpolated at the crossing do
        not have the signs of a reversal (before towards 0, after away from it), so the switching
        time cannot be placed inside the step and no saltation factor is applied; (NONE, 0.0)
        otherwise.
    """
    if U[q, i] == 0.0 or not alpha[i] > 0.0:
        return NONE, 0.0
    steps = U.shape[0] - 1
    sm = math.copysign(1.0, U[q, i])
    nxt = U[q + 1, i]
    if nxt * sm > 0.0:
        return NONE, 0.0
    if nxt == 0.0 and not (q + 2 <= steps and U[q + 2, i] * sm < 0.0):
        return STICK, 0.0
    # where the reversal falls: linear interpolation of u_i across the step
    frac = crossing(U[q, i], nxt)
    if q + 1 >= phi.shape[0]:
        ph = phi[q, i]
    else:
        ph = (1.0 - frac) * phi[q, i] + frac * phi[q + 1, i]
    rho = saltation_factor(sm, ph, alpha[i])
    if math.isnan(rho):
        return UNPLACED, 0.0
    return REVERSAL, rho
