# Analysis events that are real: van der Pol with a distributed delay on its trivial equilibrium
# (no Hopf point in a in (-2, 0.5], a real root through 0 at a = -1 where w = const is a whole
# line of equilibria: a branch point), the landing on p_end, and messages that name the cause.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi.analysis as da

from models.delay_models import TAU, vdp   # van der Pol with a distributed delay


def characteristic(lam: complex, a: float) -> complex:
    """The equation's characteristic function at w = 0: lam^2 - lam + 1 + a (1 - e^-lam) / lam."""
    return lam * lam - lam + 1 - a * np.expm1(-lam * TAU) / (lam * TAU)


def test_equation_roots_match_the_closed_form_around_the_branch_point():
    # the rightmost roots of the equation at w = 0 against the closed-form characteristic function:
    # two real roots > 0 at a = -0.95 (the unstable pair of a = -0.85 has met on the real axis),
    # a complex pair with Re > 0 at a = -0.85, and a root through 0 at a = -1 (the branch point)
    from scipy.optimize import brentq
    x = np.linspace(1e-4, 3, 30001)
    for a in (-0.95, -0.85, -1.05):
        r = da.roots(vdp, a, [0.0, 0.0], count=4, of="equation")
        assert np.all(np.isfinite(r)), r
        for z in r:                                   # every reported root is one of Delta
            assert abs(characteristic(complex(z), a)) <= 1e-8 * max(1.0, abs(z) ** 2), (a, z)
        g = characteristic(x, a).real
        real = [brentq(lambda y: characteristic(y, a).real, x[i], x[i + 1], xtol=1e-14)
                for i in np.flatnonzero(np.diff(np.sign(g)))]
        code = sorted(z.real for z in r if abs(z.imag) <= 1e-9 and z.real > 0)
        assert len(code) == len(real), (a, r, real)
        assert np.allclose(code, sorted(real), atol=1e-8), (a, code, real)
        if a == -0.85:
            assert not real and r[0].real > 0 and abs(r[0].imag) > 1e-3, r
    r = da.roots(vdp, -1.0, [0.0, 0.0], count=4, of="equation")
    assert np.min(np.abs(r)) <= 1e-8, r                # the root through 0 at a = -1


@pytest.mark.parametrize("of", ["scheme", "equation"])
def test_vdp_trivial_branch_has_a_branch_point_and_no_hopf(of):
    e = da.equilibrium(vdp, 0.5, [0.0, 0.0], of=of)
    br = da.continue_equilibrium(e, -2.0, step=0.1, at=[-0.95, -0.9, -0.85, -1.2])
    assert br.status.startswith("reached p_end"), br.status
    assert abs(br.p[-1] + 2.0) <= 1e-12                          # landed on p_end
    assert not [x for x in br.events if x.kind == "hopf"], br.events
    bp = [x for x in br.events if x.kind == "branch-point"]
    assert len(bp) == 1, br.events
    assert abs(bp[0].p + 1.0) <= 1e-8, bp[0].p
    assert "two-dimensional" in bp[0].detail
    assert all(np.max(np.abs(q.u)) <= 1e-12 for q in br.points)   # stayed on w = 0
    # the unstable count: two roots in Re > 0 before a = -1, one after (a real root crossed 0)
    user = {x.p: br.points[x.index] for x in br.events if x.kind == "user"}
    assert sorted(user) == [-1.2, -0.95, -0.9, -0.85]
    before = [user[-0.95], user[-0.9], user[-0.85]]
    after = [user[-1.2]]
    for q in before:
        assert np.sum(q.roots.real > 0) == 2 and q.stable is False
    for q in after:
        assert np.sum(q.roots.real > 0) == 1


def test_hopf_orbit_refuses_a_non_hopf_event():
    e = da.equilibrium(vdp, 0.5, [0.0, 0.0])
    br = da.continue_equilibrium(e, -1.5, step=0.2)
    bp = [x for x in br.events if x.kind == "branch-point"][0]
    with pytest.raises(ValueError, match="branch-point.*not a Hopf"):
        da.hopf_orbit(vdp, bp, bp.u, amplitude=0.1, steps=100)
    # a HopfPoint whose root is off the imaginary axis (where a pair meets on the real axis)
    fake = da.HopfPoint(p=-0.913, omega=0.02, root=complex(0.31, 0.02))
    with pytest.raises(ValueError, match="not on the imaginary axis"):
        da.hopf_orbit(vdp, fake, [0.0, 0.0], amplitude=0.1, steps=100)


def test_hopf_orbit_amplitude_message_is_in_state_units():
    hp = da.HopfPoint(p=0.0, omega=1.0, root=1j)
    with pytest.raises(ValueError, match="state units") as ex:
        da.hopf_orbit(vdp, hp, [0.0, 0.0], amplitude=0, steps=100)
    assert "time units" not in str(ex.value)


def test_equilibrium_at_a_nan_parameter_names_p_and_the_call():
    with pytest.raises(ValueError, match=r"equilibrium\(make, p = nan"):
        da.equilibrium(vdp, math.nan, [0.0, 0.0])
