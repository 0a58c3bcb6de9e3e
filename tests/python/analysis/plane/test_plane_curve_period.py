# Curves of forced orbits whose forcing's period changes with q (period= of the plane's orbit
# curves): the hardening Duffing oscillator x'' + c x' + x + x^3 = F cos(w t), its resonance's
# fold in F continued in the forcing frequency w (period 2 pi / w), against the fold solved in
# the test by shooting with scipy's DOP853 (x(P) = x(0) and det(M - I) = 0, M the monodromy
# matrix, P = 2 pi / w), and against the same curve of the model written in the forcing's phase
# s = w t (dx/ds = f / w, period 2 pi fixed).  Also the refusals of period=.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi

from dmi import analysis as da
from dmi.analysis.plane.orbit_curves import continue_flip_curve, continue_orbit_curve

try:
    from models import orbit_models
except ImportError:
    import orbit_models

C = 0.1                       # the damping
W0 = 1.4                      # the start's forcing frequency
AT = (1.45, 1.5)              # the frequencies checked


def duffing_w(F: float, w: float):
    """The oscillator forced at frequency w, in time t (period 2 pi / w)."""
    s = dmi.Solver(2, 1.0, h=2 * math.pi / w / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -C * u[1] - u[0] - u[0] ** 3 + F * math.cos(w * t)]))
    return s


def duffing_phase(F: float, w: float):
    """The same oscillator in the forcing's phase s = w t (period 2 pi): du/ds = (du/dt) / w."""
    s = dmi.Solver(2, 1.0, h=2 * math.pi / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -C * u[1] - u[0] - u[0] ** 3 + F * math.cos(t)])
              / w)
    return s


def shooting_fold(w: float, guess: np.ndarray) -> float:
    """F at the fold at frequency w, by shooting with scipy's DOP853."""
    return orbit_models.duffing_fold(C, w, guess)


def fold_start(make2, period: float):
    """The branch in F at w = W0 and its fold event."""
    o = da.periodic_orbit(lambda F: make2(F, W0), 0.3, period, np.array([1.5, 0.0]), steps=400,
                          multipliers=4)
    b = da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), 0.0, step=0.02)
    (f,) = [e for e in b.events if e.kind == "fold"]
    return f, b


@pytest.fixture(scope="module")
def start():
    return fold_start(duffing_w, 2 * math.pi / W0)


def test_a_fold_curve_in_the_forcing_frequency(start):
    f, b = start
    c = continue_orbit_curve(f, duffing_w, W0, AT[-1], branch=b, step=0.02, at=AT,
                             period=lambda p, q: 2 * math.pi / q)
    assert c.status == f"reached q_end = {AT[-1]}" and c.points[-1].q == AT[-1]
    on = {pt.q: pt for pt in c.points if pt.q in AT}
    assert sorted(on) == list(AT)
    fp, bp = fold_start(duffing_phase, 2 * math.pi)
    cp = continue_orbit_curve(fp, duffing_phase, W0, AT[-1], branch=bp, step=0.02, at=AT)
    phase = {pt.q: pt for pt in cp.points if pt.q in AT}
    assert sorted(phase) == list(AT)
    for w in (c.points[0].q,) + AT:
        pt = on.get(w, c.points[0])
        assert not pt.orbit.autonomous
        assert abs(pt.orbit.period - 2 * math.pi / w) <= 1e-12 * pt.orbit.period
        ref = shooting_fold(w, np.concatenate([pt.orbit.u_at(0.0), [pt.p]]))
        assert abs(pt.p - ref) <= 1e-8, (w, pt.p - ref)
        assert abs(pt.p - ref) <= pt.p_error
        if w in phase:   # the same fold in the forcing's phase (u(s) = x(s / w))
            assert abs(phase[w].p - pt.p) <= 1e-8, (w, phase[w].p - pt.p)
            assert np.allclose(phase[w].orbit.u_at(0.0), pt.orbit.u_at(0.0), atol=1e-7)
    # the period changed along the curve: the fixed period's curve differs
    assert abs(c.points[-1].orbit.period - 2 * math.pi / W0) > 0.1


def vdp(mu: float, h: float = 0.02):
    s = dmi.Solver(2, 1.0, h=h)
    s.set_rhs(lambda t, u: -np.array([u[1], mu * (1 - u[0] ** 2) * u[1] - u[0]]))
    return s


def test_period_refusals(start):
    f, b = start
    with pytest.raises(ValueError, match=r"period= disagree"):   # bad-inputs CP01
        continue_orbit_curve(f, duffing_w, W0, 1.5, branch=b, period=lambda p, q: 6.0 / q)
    with pytest.raises(ValueError, match=r"= nan: a forced orbit's period must be finite"):
        continue_orbit_curve(f, duffing_w, W0, 1.5, branch=b,   # bad-inputs CP02
                             period=lambda p, q: math.nan)
    with pytest.raises(ValueError, match=r"= -1.0: a forced orbit's period must be finite"):
        da.continue_curve(f, duffing_w, W0, 1.5, branch=b, period=lambda p, q: -1.0)
    o = da.periodic_orbit(vdp, 1.0, None, np.array([2.0, 0.0]), guess_period=6.6, steps=300,
                          multipliers=4)
    eo = da.collocate(o, multipliers=4, intervals=20)
    assert eo.autonomous
    with pytest.raises(ValueError, match=r"continue_flip_curve: period = .*autonomous"):
        continue_flip_curve(eo, lambda p, q: vdp(p), 1.0, 2.0,   # bad-inputs CP03
                            period=lambda p, q: eo.period)
