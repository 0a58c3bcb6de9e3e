"""Solver.set_quadrature("cell", singularity=...) (dmi_set_kernel_singularity, libdmi 1.4): a weakly
singular kernel s^-alpha integrated to 1e-10 relative with the exponent given or estimated, and
what the cell rule refuses (an exponent outside [0, 1), a kernel that is not integrable at 0).
One step from the history 1 with f = 0, A = 0: U^1 = 1 - h int_0^tau H(s) ds in closed form."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import pytest

import dmi
from models.cell_rule import first_step as one_step


@pytest.mark.parametrize("alpha", [0.5, 0.9, 0.99])
@pytest.mark.parametrize("given", [False, True])
def test_power_kernel_to_1e10(alpha, given):
    exact = 1.0 - 0.125 / (1.0 - alpha)            # int_0^1 s^-alpha ds = 1 / (1 - alpha)
    got = one_step(lambda s: np.array([[s ** -alpha]]), alpha if given else None)
    assert abs(got - exact) <= 1e-10 * abs(0.125 / (1.0 - alpha))


@pytest.mark.parametrize("bad", [1.0, -0.1, 1.5])
def test_exponent_outside_refused(bad):
    with dmi.Solver(1, 1.0, 8) as s:
        with pytest.raises(dmi.InvalidArgument):
            s.set_quadrature("cell", singularity=bad)
        assert s.quadrature == "left"


def test_not_integrable_refused_at_init():
    with dmi.Solver(1, 1.0, 8) as s:
        s.set_kernel(lambda x: np.array([[1.0 / x]]))
        s.set_quadrature("cell")
        with pytest.raises(dmi.InvalidArgument, match="cell 0"):
            s.init()
