# One step of u' + W = 0 under the cell rule, the binding's tests of a singular kernel's exponent.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np

import dmi


def first_step(H, singularity: float | None = None) -> float:
    """U^1 of u' + W = 0 from the history 1 (tau = 1, 8 cells, the cell rule): 1 - h int_0^1 H."""
    with dmi.Solver(1, 1.0, 8) as s:
        s.set_kernel(H)
        s.set_history(lambda t: np.array([1.0]))
        s.set_quadrature("cell", singularity=singularity)
        s.init()
        s.step()
        return float(s.state[0])
