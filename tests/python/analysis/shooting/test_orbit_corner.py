# A corner the continuation does not pass says so: a belt with a memory and velocity-weakening
# friction (the sign graph at the static level alpha in A, the weakening -gamma v / (1 + |v|) in
# f), continued in the belt speed v_b from its Hopf point along the pure-slip orbits up to their
# grazing, where the branch ends.  Whichever route the corrector takes to fail there (its last
# points all slip and natural steps fail; or an orbit that sticks was corrected among them), the
# status names the corner, the component, and the side of p the branch could not pass to; what
# it claims of the orbits (they stick, they slip, their least velocity falls to 0) is checked by
# plain runs of the scheme from the points' states.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import dmi
import dmi.analysis as da
from dmi.analysis.branches.shooting import corner_of

K, G, ALPHA, C, GAMMA, TAU = 1.0, 0.8, 0.5, 0.6, 0.8, 1.0
CORNER = "a corner of component 1's stick pattern"
FOUND = re.compile(r"orbits that (\w+)(?: \w+)? were found at p = ([0-9., ]+), (smaller|larger) "
                   r"than the last point's p = ([0-9.]+): the other branch goes towards (\w+) p")
GRAZING = re.compile(r"least \|u_1\| over the orbit fell to ([0-9.e+-]+) \(half range "
                     r"([0-9.e+-]+)\) at the last point, reaching 0 near p = ([0-9.e+-]+)")


def belt(vb: float, h: float | None = None) -> dmi.Solver:
    # x' = v + v_b, v' + k x + c (v + v_b) - gamma v / (1 + |v|) + alpha sigma(v)
    #     + (g / tau) int_0^tau x(t - s) ds ∋ 0
    s = dmi.Solver(2, TAU, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb),
                                     K * u[0] + C * (u[1] + vb) - GAMMA * u[1] / (1 + abs(u[1]))]))
    s.set_kernel_exp([0.0], [0.0], [np.array([[0.0, 0.0], [G / TAU, 0.0]])])
    s.set_friction([0.0, ALPHA])
    return s


def plain(make, q, steps: int) -> np.ndarray:
    """One period of the scheme at the point's step from its state: the M + 1 rows."""
    s = make(q.p, h=q.period / steps)
    s.init()
    rows = q.state.reshape(-1, 2)
    s.set_window(rows[-(s.N + 1):])
    return s.run(steps)[1]


def stuck_steps(make, q, steps: int) -> int:
    """Steps of one period where v == 0 for 2 steps or more, from a plain run."""
    z = plain(make, q, steps)[1:, 1] == 0.0
    return int(np.sum(z & (np.roll(z, 1) | np.roll(z, -1))))


def way(points) -> str:
    ps = [q.p for q in points[-4:]]
    return "larger" if ps[-1] > ps[0] else "smaller"


@pytest.fixture(scope="module")
def branch():
    eq = da.equilibrium(belt, 3.0, [0.2, -3.0])
    br = da.continue_equilibrium(eq, 0.2, step=0.2)
    hopf = [e for e in br.events if e.kind == "hopf"]
    assert len(hopf) == 1
    o = da.hopf_orbit(belt, hopf[0].hopf, hopf[0].u, amplitude=0.05, steps=300, component=1)
    # the corner, not the verdicts, is under test here: the Ritz multipliers suffice
    with pytest.warns(UserWarning, match="verify=False"):
        return o, da.continue_orbit(o, 2.0, step=0.05, max_points=200, multipliers=4,
                                    verify=False)


def check_found(status: str, points, make, steps: int) -> None:
    """The orbits the status names as found on the other side are points of the list that
    stick (or slip) as it says, by plain runs, and lie on the side it says."""
    m = FOUND.search(status)
    assert m, status
    kind, ps, side, last, towards = m.groups()
    ps = [float(x) for x in ps.rstrip(", ").split(", ")]
    assert side == towards
    assert (np.mean(ps) < float(last)) == (side == "smaller")
    for p in ps:
        q = min(points, key=lambda q: abs(q.p - p))
        assert abs(q.p - p) <= 1e-6 * max(1.0, abs(p))
        assert (stuck_steps(make, q, steps) > 0) == (kind == "stick"), (p, kind)


def check_grazing(status: str, points, make, steps: int) -> None:
    """The grazing the status reads off slipping points: the last two points do not stick in
    plain runs (v = 0 at one step is the grazing itself, reached at the last point where the
    corrector stopped within rounding of it), their least |v| falls, and the zero extrapolated
    from the plain runs' least |v| is the status's, at or beyond the last point on the side the
    branch went."""
    m = GRAZING.search(status)
    assert m, status
    least, half, at = (float(x) for x in m.groups())
    a, b = points[-2], points[-1]
    va, vb = (np.abs(plain(make, q, steps)[:, 1]) for q in (a, b))
    assert stuck_steps(make, a, steps) == stuck_steps(make, b, steps) == 0
    assert va.min() > vb.min() >= 0.0      # neither sticks, the least |v| falls
    assert least <= 0.05 * half
    # the status reads the orbits' samples to 3 digits (a relative rounding of up to 5e-3):
    # at most a little above the plain run's
    assert vb.min() * (1 - 5e-3) <= least <= vb.min() + 0.2 * (va.min() - vb.min()), \
        (least, vb.min())
    ours = b.p + vb.min() * (b.p - a.p) / (va.min() - vb.min())
    assert abs(at - ours) <= 0.2 * abs(b.p - a.p), (at, ours)
    # the status's p has 8 digits: at the last point (least |v| = 0 there) within them
    ahead = (at - b.p) * (1 if way(points) == "larger" else -1)
    assert ahead > (0.0 if least > 0 else -1e-7 * max(1.0, abs(b.p))), (at, b.p, least)


def test_a_corner_not_passed_is_named_with_the_side(branch):
    o, b = branch
    if b.status.startswith("reached p_end"):     # the corner was passed: it must stick beyond
        assert any(q.stick_steps[1] > 0 for q in b.points)
        return
    assert b.status.startswith("the branch ended at " + CORNER), b.status
    m = re.search(r"which it could not pass towards (larger|smaller) p", b.status)
    assert m and m.group(1) == way(b.points), b.status
    if FOUND.search(b.status):
        check_found(b.status, b.points, o.make, b.steps)
    else:
        check_grazing(b.status, b.points, o.make, b.steps)
    assert b.points[-1].stick_steps[1] == 0 or stuck_steps(o.make, b.points[-1], b.steps) > 0


def test_both_routes_give_the_one_sentence(branch):
    o, b = branch
    alpha = np.array([0.0, ALPHA])
    slips = []
    for q in b.points:               # the pure-slip orbits up to the first that sticks
        if q.stick_steps[1]:
            break
        slips.append(q)
    assert len(slips) >= 6
    # the route where every last point slips: a grazing ahead, read from the velocities
    said = corner_of(slips, alpha)
    assert said.startswith("the branch ended at " + CORNER), said
    assert f"could not pass towards {way(slips)} p" in said
    check_grazing(said, slips, o.make, b.steps)
    # the route where an orbit that sticks was corrected among the last points: the branch's
    # own when it has one, else the last slipping point with a stick phase laid on it (a
    # constructed input, not a claim: its plain run is not asked for)
    stuck = [q for q in b.points if q.stick_steps[1]]
    other = stuck[0] if stuck else dataclasses.replace(
        slips[-1], p=slips[-2].p, stick_steps=np.array([0, 3]), stick_phases=np.array([0, 1]))
    pts = slips[-3:] + [other] + ([slips[-1]] if not stuck else [])
    said = corner_of(pts, alpha)
    assert said.startswith("the branch ended at " + CORNER), said
    assert f"could not pass towards {way(pts)} p" in said
    assert FOUND.search(said), said
    if stuck:
        check_found(said, pts, o.make, b.steps)
    # far from the corner (the first points, their velocities far from 0) no corner is named,
    # nor without friction
    assert corner_of(slips[:4], alpha) == ""
    assert corner_of(slips, None) == ""
    assert corner_of(slips, np.zeros(2)) == ""
