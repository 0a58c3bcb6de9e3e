# dmi.analysis.period_doubled_orbit on a branch continued in the forcing frequency w
# (continue_orbit(..., period=2 pi / w)), and the doubled branch continued with period 2 (2 pi / w).
# Oracle: the scheme of x'' + d x' + (1 + b cos w t) x + x^3 = 0 (orbit_models.ParametricDuffing)
# in numpy (its period map and exact derivative: the rest's multipliers, the doubling frequency w*
# by brentq, the two-cycle by Newton), and a long plain dmi.Solver run onto the doubled orbit.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

from dmi.analysis import continue_orbit, period_doubled_orbit, periodic_orbit
from models.orbit_models import ParametricDuffing

W0, W1 = 1.70, 1.86


def period(w: float) -> float:
    return 2 * math.pi / w


@pytest.fixture(scope="module")
def model():
    return ParametricDuffing()


@pytest.fixture(scope="module")
def branch(model):
    o = periodic_orbit(model.make, W0, period(W0), [0.0, 0.0], multipliers=2)
    return continue_orbit(o, W1, step=0.02, multipliers=2, period=period)


def test_numpy_oracle_is_the_scheme(model):
    """The numpy period map is dmi's scheme: one period of a plain run from a nonzero state."""
    w, x = 1.81, np.array([0.3, -0.2])
    s = model.make(w)
    s.init()
    s.set_window(np.array([x, x]))
    U = s.run(model.M)[1]
    assert np.max(np.abs(U[-1] - model.run(x, w)[0])) < 1e-12


def test_doubling_in_w_and_the_doubled_orbit(model, branch):
    ws = model.doubling()
    b = branch
    assert b.status.startswith("reached p_end"), b.status
    for q in b.points:   # the rest, at each w's own step 2 pi / (w M)
        assert q.period == pytest.approx(period(q.p), rel=1e-12)
        assert np.max(np.abs(q.state)) < 1e-12
        mu = model.rest_multipliers(q.p)
        assert np.sort_complex(q.multipliers) == pytest.approx(np.sort_complex(mu), abs=1e-6)
    pds = [e for e in b.events if e.kind == "period-doubling"]
    assert len(pds) == 1 and len(b.events) == 1, b.events
    e = pds[0]
    a, c = b.points[e.index - 1].p, b.points[e.index].p
    assert a < ws < c and a <= e.p <= c, (a, ws, c, e)   # between the two points around w*
    # interpolated on 1 + min Re mu (at a the multiplier is half of a complex pair)
    assert abs(e.p - ws) < 0.25 * (c - a), (a, ws, c, e)

    o2 = period_doubled_orbit(b, e, multipliers=2)
    assert o2.steps == 2 * model.M and o2.period == pytest.approx(2 * period(o2.p), rel=1e-12)
    assert o2.p > ws   # the unstable side of the rest, where the doubled orbit lives
    x0, x1 = o2.u[0], o2.u[model.M]
    assert np.max(np.abs(x0 - x1)) > 0.05   # not the M-periodic rest
    y0, y1, mu2 = model.two_cycle(o2.p, x0)
    assert np.max(np.abs(x0 - y0)) < 1e-9 and np.max(np.abs(x1 - y1)) < 1e-9, (x0, y0, x1, y1)
    assert np.sort_complex(o2.multipliers) == pytest.approx(np.sort_complex(mu2), abs=2e-3)
    assert o2.stable

    # a long plain run at o2.p from near the rest settles on the doubled orbit (either phase)
    s = model.make(o2.p)
    s.init()
    s.set_window(np.array([[0.0, 0.01], [0.0, 0.01]]))
    s.advance(400 * model.M)
    d = min(np.max(np.abs(s.state - x0)), np.max(np.abs(s.state - x1)))
    assert d < 1e-8, (s.state, x0, x1)

    # the doubled branch in w: period 2 (2 pi / w), two sections a point
    b2 = continue_orbit(o2, o2.p + 0.03, step=0.01, multipliers=2, sections=2,
                        period=lambda w: 2 * period(w))
    assert b2.status.startswith("reached p_end"), b2.status
    assert len(b2.points) >= 4 and not b2.events, b2.events
    amp = []
    for q in b2.points:
        assert q.period == pytest.approx(2 * period(q.p), rel=1e-12)
        y0, y1, mu2 = model.two_cycle(q.p, q.section[0])
        assert np.max(np.abs(q.section - np.array([y0, y1]))) < 1e-9, (q.p, q.section, y0, y1)
        assert np.sort_complex(q.multipliers) == pytest.approx(np.sort_complex(mu2), abs=2e-3)
        assert q.stable
        amp.append(q.amplitude[0])
    assert np.all(np.diff(amp) > 0)   # it grows from the rest, away from w*
