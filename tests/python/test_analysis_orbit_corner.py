# A corner the continuation does not pass says so: a belt with a memory and velocity-weakening
# friction (the sign graph at the static level alpha in A, the weakening -gamma v / (1 + |v|) in
# f), continued in the belt speed v_b from its Hopf point along the pure-slip orbits up to their
# grazing, where the branch ends; the status names the corner, and where the orbits that stick
# were found and so which way the other branch goes.  The claim that they stick is checked by a
# plain run of the scheme from the point's state.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import re

import numpy as np

import dmi
import dmi.analysis as da

K, G, ALPHA, C, GAMMA, TAU = 1.0, 0.8, 0.5, 0.6, 0.8, 1.0


def belt(vb: float, h: float | None = None) -> dmi.Solver:
    # x' = v + v_b, v' + k x + c (v + v_b) - gamma v / (1 + |v|) + alpha sigma(v)
    #     + (g / tau) int_0^tau x(t - s) ds ∋ 0
    s = dmi.Solver(2, TAU, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb),
                                     K * u[0] + C * (u[1] + vb) - GAMMA * u[1] / (1 + abs(u[1]))]))
    s.set_kernel_exp([0.0], [0.0], [np.array([[0.0, 0.0], [G / TAU, 0.0]])])
    s.set_friction([0.0, ALPHA])
    return s


def stuck_steps(make, q, steps: int) -> int:
    """Steps of one period where v == 0 for 2 steps or more, from a plain run of the scheme at the
    point's step from its state."""
    s = make(q.p, h=q.period / steps)
    s.init()
    rows = q.state.reshape(-1, 2)
    s.set_window(rows[-(s.N + 1):])
    z = s.run(steps)[1][1:, 1] == 0.0
    return int(np.sum(z & (np.roll(z, 1) | np.roll(z, -1))))


def test_a_corner_not_passed_is_named_with_the_other_side():
    eq = da.equilibrium(belt, 3.0, [0.2, -3.0])
    br = da.continue_equilibrium(eq, 0.2, step=0.2)
    hopf = [e for e in br.events if e.kind == "hopf"]
    assert len(hopf) == 1
    o = da.hopf_orbit(belt, hopf[0].hopf, hopf[0].u, amplitude=0.05, steps=300, component=1)
    b = da.continue_orbit(o, 2.0, step=0.05, max_points=200, multipliers=4)
    if b.status.startswith("reached p_end"):     # the corner was passed: it must stick beyond
        assert any(q.stick_steps[1] > 0 for q in b.points)
        return
    assert "a corner of component 1's stick pattern" in b.status, b.status
    m = re.search(r"orbits that (\w+)(?: \w+)? were found at p = ([0-9., ]+), (smaller|larger) than "
                  r"the last point's p = ([0-9.]+): the other branch goes towards (\w+) p",
                  b.status)
    assert m, b.status
    kind, ps, side, last, towards = m.groups()
    ps = [float(x) for x in ps.rstrip(", ").split(", ")]
    assert side == towards
    assert (np.mean(ps) < float(last)) == (side == "smaller")
    for p in ps:                  # each named orbit is a point of the branch that sticks
        q = min(b.points, key=lambda q: abs(q.p - p))
        assert abs(q.p - p) <= 1e-6 * max(1.0, abs(p))
        stuck = stuck_steps(o.make, q, b.steps)
        assert (stuck > 0) == (kind == "stick"), (p, stuck)
    assert b.points[-1].stick_steps[1] == 0 and stuck_steps(o.make, b.points[-1], b.steps) == 0
