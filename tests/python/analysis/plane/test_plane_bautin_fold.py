# The fold curve of collocated orbits started from the Bautin point of a Hopf curve
# (continue_curve of a "bautin" CurveEvent), on the rotationally symmetric oscillator with a
# distributed memory whose circles are exact:
#   z' = (mu + i W0) z + q |z|^2 z + C2 |z|^4 z - int_0^2 G e^-s z(t - s) ds,   C2 < 0.
# A circle z = r e^(i Om t) solves Om + Im g(i Om) = W0 (g the memory's transform) and
# mu = mu_H - q r^2 - C2 r^4, mu_H = Re g(i Om): the Hopf curve is mu = mu_H for every q, l1 has
# the sign of q (subcritical for q > 0), the Bautin point is (mu_H, 0), and for q > 0 the circles
# fold where d mu / d r^2 = 0: r^2 = q / (2 |C2|), mu_F(q) = mu_H - q^2 / (4 |C2|).  The model's
# exact derivatives (the hook) make the Bautin point accurate to 1e-9.  Also the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

from dmi import analysis as da
from dmi.analysis.continuation.branch import CurveEvent

try:   # the shared models' package (tests/python/models) or, before it, tests/python itself
    from models import hopf_models
except ImportError:
    import hopf_models

W0, TAU, G, C2 = 1.0, 2.0, 0.3, -1.0
QS, Q_END = -0.3, 1.0          # the Hopf curve's start (supercritical) and the fold curve's end


def make2(mu: float, q: float):
    return hopf_models.circle_solver(complex(mu, W0), q, C2, G, TAU, 100, True)


def hopf_closed_form() -> tuple[float, float]:
    """(Om, mu_H)."""
    return hopf_models.circle_hopf(W0, G, TAU)


def fold_closed_form(q: float) -> tuple[float, float]:
    """(mu_F, r) of the fold of circles at q > 0."""
    return hopf_models.circle_fold(q, C2, W0, G, TAU)


@pytest.fixture(scope="module")
def hopf_point():
    _, mu_h = hopf_closed_form()
    return da.hopf(lambda mu: make2(mu, QS), mu_h - 0.1, mu_h + 0.1, [0.0, 0.0], of="equation")


@pytest.fixture(scope="module")
def bautin(hopf_point):
    """The Bautin event of the Hopf curve from q = QS up through q = 0."""
    hc = da.continue_curve(hopf_point, make2, QS, 0.3, u_eq=[0.0, 0.0], step=0.2)
    (b,) = [e for e in hc.events if e.kind == "bautin"]
    return b


@pytest.fixture(scope="module")
def fold(bautin):
    return da.continue_curve(bautin, make2, bautin.q, Q_END, step=0.1, at=(0.5,))


def test_the_bautin_point_against_the_closed_form(bautin):
    _, mu_h = hopf_closed_form()
    assert abs(bautin.q) <= 1e-9 and abs(bautin.p - mu_h) <= 1e-9, (bautin.q, bautin.p - mu_h)


def test_the_fold_curve_from_the_bautin_point_against_the_closed_form(bautin, fold):
    om, mu_h = hopf_closed_form()
    assert fold.kind == "orbit-fold"
    assert fold.status == f"reached q_end = {Q_END}", fold.status
    assert fold.points[-1].q == Q_END and len(fold.points) >= 4
    for pt in fold.points:
        mu_f, r = fold_closed_form(pt.q)
        assert abs(pt.p - mu_f) <= 1e-9, (pt.q, pt.p - mu_f)          # measured 1.5e-13
        assert abs(pt.p - mu_f) <= pt.p_error
        assert np.all(np.abs(pt.orbit.amplitude - r) <= 1e-9)
        assert abs(pt.orbit.period - 2 * math.pi / om) <= 1e-9
    assert np.all(np.diff(fold.q) > 0)
    # the start: the bautin event first, at the Bautin point; the first point on the closed
    # form's fold a tenth of the span off it, at the closed form's distance from it
    b = fold.events[0]
    assert b.kind == "bautin" and b.index == 0 and b.hopf is bautin.hopf
    assert abs(b.q) <= 1e-9 and abs(b.p - mu_h) <= 1e-9
    first = fold.points[0]
    assert first.q == bautin.q + 0.1 * (Q_END - bautin.q)
    assert abs(math.hypot(first.p - mu_h, first.q) - math.hypot(first.q * first.q / 4, first.q)) \
        <= 1e-9
    assert [e.kind for e in fold.events] == ["bautin", "user"]
    (u,) = [e for e in fold.events if e.kind == "user"]
    assert u.q == 0.5 and abs(u.p - fold_closed_form(0.5)[0]) <= 1e-9


def test_refusals(bautin, hopf_point):
    # q_end on the supercritical side of the Bautin point: no fold of orbits there
    with pytest.raises(ValueError, match=r"it is on the other side: q_end must lie on that "):
        da.continue_curve(bautin, make2, bautin.q, -1.0)                  # bad-inputs BF01
    # a "bautin" event where l1 < 0 on both sides (the Hopf point at q = QS)
    fake = CurveEvent("bautin", hopf_point.p, QS, 0, u=np.zeros(2), hopf=hopf_point)
    with pytest.raises(ValueError, match=r"nor on the other side: no subcritical side"):
        da.continue_curve(fake, make2, QS, -0.6)                          # bad-inputs BF02
    with pytest.raises(ValueError, match=r"the bautin event has no Hopf point or equilibrium"):
        da.continue_curve(CurveEvent("bautin", 0.0, 0.0, 0), make2, 0.0, 1.0)   # BF03
    with pytest.raises(ValueError, match=r"offset = 2.0: give 0 < offset < \|q_end - q0\|"):
        da.continue_curve(bautin, make2, bautin.q, 1.0, offset=2.0)      # bad-inputs BF04
