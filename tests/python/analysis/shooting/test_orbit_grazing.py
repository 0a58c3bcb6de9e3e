# dmi.analysis.continue_orbit across a pure grazing: the number of stick phases of a component
# changes while it sticks on both sides.  u' + sigma(u) ∋ 0.2 + sin t - p sin 3t
# (orbit_models.BumpStick): one stick phase a period for p <= p* = 0.2 (closed form: the
# forcing's minimum -0.8 - p reaches the friction 1 at t = 3 pi / 2), two above (a short
# negative slip splits it).  Oracles: p* and the slip phases in closed form, and plain
# dmi.Solver runs from rest for the stick pattern at every point.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

from dmi.analysis import continue_orbit, periodic_orbit
from models.orbit_models import BumpStick

M = 400   # 4 | M: t = 3 pi / 2 is a step, where the scheme's stick breaks at p* exactly
P0, P1 = 0.1, 0.3


def plain_stick(make, p: float) -> tuple[int, int]:
    """(stuck steps, stick phases) of one period of a plain run from rest (after 3 periods:
    a stick forgets the past), stuck = U == 0 for 2 steps or more, on the period's circle."""
    s = make(p)
    s.init()
    s.advance(3 * M)
    z = s.run(M)[1][1:, 0] == 0.0
    stuck = z & (np.roll(z, 1) | np.roll(z, -1))
    return int(stuck.sum()), int(np.sum(stuck & ~np.roll(stuck, 1)))


def test_grazing_split_of_a_stick_phase():
    m = BumpStick()
    make = m.make_for(M)
    h = 2 * math.pi / M
    o = periodic_orbit(make, P0, 2 * math.pi, [0.0], multipliers=2)
    b = continue_orbit(o, P1, step=0.03, multipliers=2)
    assert b.status.startswith("reached p_end"), b.status
    # exactly one event: a grazing of component 0 (no stick-onset: it sticks all along)
    assert len(b.events) == 1, b.events
    e = b.events[0]
    assert e.kind == "grazing" and e.component == 0, e
    pa, pb = b.points[e.index - 1].p, b.points[e.index].p
    assert pa < m.p_star < pb, (pa, pb)
    # located by 6 bisections: the midpoint of the final bracket, |pb - pa| / 2^6 wide, which
    # holds p* (no O(h) here: the scheme's p* is the continuous one, F's minimum being on a step)
    assert abs(e.p - m.p_star) <= (pb - pa) / 2 ** 7 + 1e-12, (e.p, m.p_star, pb - pa)
    phases = b.column("stick_phases")[:, 0]
    steps = b.column("stick_steps")[:, 0]
    assert np.any(b.p < m.p_star - 0.02) and np.any(b.p > m.p_star + 0.02), b.p
    for q, ph, st in zip(b.points, phases, steps):
        T, ph_exact = m.stick_time(q.p)
        assert ph == ph_exact == (1 if q.p < m.p_star else 2), (q.p, ph, ph_exact)
        assert abs(st * h - T) < 2 * h, (q.p, st, T / h)   # stuck time: closed form to O(h)
        assert (st, ph) == plain_stick(make, q.p), q.p
