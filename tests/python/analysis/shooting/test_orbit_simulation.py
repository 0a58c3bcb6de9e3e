# dmi.analysis.periodic_orbit against plain simulation: the orbit is the attractor of a long
# run, and its multiplier is the contraction rate of the run's Poincare map, on an orbit whose
# velocity reversals make the saltation matter (models/orbit_models.py: SlipOnly1).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np

from dmi.analysis import floquet_multipliers, periodic_orbit
from dmi.analysis.shooting.shoot import StepMap
from models.orbit_models import SlipOnly1


def test_orbit_is_the_attractor_and_multiplier_the_contraction():
    m, M = SlipOnly1(), 20000
    make = m.make_for(M)
    o = periodic_orbit(make, 0.0, m.T, [0.5], multipliers=1)
    assert o.stable and np.all(o.stick_fraction == 0)
    mu = float(o.multipliers[0].real)
    s = make(0.0)
    s.init()
    s.set_window(np.full((2, 1), o.state[-1] + 0.5))
    d = []
    for _ in range(40):
        s.advance(M)
        d.append(abs(s.state[0] - o.state[-1]))
    assert d[-1] < 1e-8, d[-5:]  # the run's attractor is the orbit found by shooting
    # The Poincare map's contraction while the perturbation moves the velocity reversals by
    # many steps (d >> h |u'|; here d_0 ~ 4e-2, d_1 ~ 4e-3, h = 3e-4): the multiplier.
    assert d[0] > 1e-2 and d[1] > 2e-3
    rate = d[1] / d[0]
    assert abs(mu - rate) < 0.05 * rate, (mu, rate)
    # The exact piecewise derivative (no saltation) gives exp(-2 pi a) = 0.53: far off.  It is
    # what the run shows once the perturbation is below a step's worth of switch motion.
    wrong = floquet_multipliers(StepMap(make, 0.0, M), o.state, 1, eps=1e-9)[0].real
    assert abs(wrong - np.exp(-m.a * m.T)) < 1e-3 and abs(wrong - rate) > 0.5 * rate
    assert 1e-8 < d[14] < 1e-5 and abs(d[15] / d[14] - np.exp(-m.a * m.T)) < 0.01
