# A collocated branch of a forced orbit with switches whose switching time crosses t = 0 (= T):
# the forced van der Pol oscillator with a small dry friction and a cosine forcing,
#     x'' + (x^2 - Q) x' + x + AL sigma(x') ∋ p cos(W t),
# whose T-orbit reverses its velocity twice a period without sticking; as p grows from 0.85 one
# reversal moves from t = 0.028 down through t = 0 near p = 0.961 and re-enters the period at
# T (the phase origin is the forcing's).  The branch must pass there (the signature rotated, the
# same segments around the circle), not stop at a "grazing" corner; both ways in p.
# Against an event-driven integration written here: DOP853 (rtol 1e-13) between the velocity's
# zeros, located by its event finder (each a reversal: the net force there exceeds AL, asserted;
# no stick), the T-orbit by Newton on the period map from the section t = T/4 (away from both
# reversals), its reversal times and states compared with the branch's to 1e-8.
# Also the corner's reading of a true grazing (a slipping velocity that touches 0 without
# crossing it) against the closed form of a damped first-order slip orbit.  About 30 s.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dmi
from dmi import analysis as da
from dmi.analysis.branches.collocated import EquationBranch

from models import orbit_models

W, AL, Q = 1.5, 0.02, 0.2            # the forcing's frequency, the dry friction, the damping
T = 2 * math.pi / W
T0 = T / 4                           # the reference's section: far from both reversals
P_LO, P_HI = 0.9, 1.02               # the branch's range: the reversal crosses t = 0 inside
AT = (0.955, 0.97)                   # user points just before and after the crossing (p 0.961)


def vdp(p: float, h: float | None = None) -> dmi.Solver:
    """u = (x, x'): u' + A(u) + f(t, u) ∋ 0, f = (-x', (x^2 - Q) x' + x - p cos(W t)),
    A = (0, AL sigma(x'))."""
    s = dmi.Solver(2, T / 400 if h is None else h, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - Q) * u[1] + u[0] - p * math.cos(W * t)]))
    s.set_friction([0.0, AL])
    return s


# ---- the independent event-driven integration -------------------------------------------------
def flow(p: float, x0: np.ndarray, t0: float, t1: float, at: np.ndarray | None = None
         ) -> tuple[np.ndarray, list, np.ndarray | None]:
    """The state at t1 from x0 = (x, x') at t0 (x' != 0), the reversals' times, and the states at
    the times ``at`` (ascending, in [t0, t1])."""
    t, x = t0, np.array(x0, dtype=float)
    mode = 1.0 if x[1] > 0 else -1.0
    seen: list[float] = []
    want = [] if at is None else list(at)
    got = []
    while t < t1:
        def rhs(s, y, mode=mode):
            return [y[1], -(y[0] ** 2 - Q) * y[1] - y[0] + p * math.cos(W * s) - AL * mode]

        def zero(s, y):
            return y[1]
        zero.terminal, zero.direction = True, -mode
        sol = solve_ivp(rhs, (t, t1), x, method="DOP853", rtol=1e-13, atol=1e-14,
                        events=zero, dense_output=bool(want))
        end = float(sol.t[-1])
        while want and want[0] <= end:
            got.append(sol.sol(want.pop(0)))
        t, x = end, sol.y[:, -1].copy()
        if sol.status == 1:                 # x' = 0: a reversal where the net force exceeds AL
            x[1] = 0.0
            F = -x[0] + p * math.cos(W * t)
            assert abs(F) > AL, f"a stick at t = {t} (net force {F}): not this test's orbit"
            mode = math.copysign(1.0, F)
            seen.append(t)
    return x, seen, (np.array(got) if at is not None else None)


def reference(p: float, guess: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the state at T0, the reversal times in [0, T) ascending) of the T-orbit at p near
    guess, by Newton on the period map from t = T0."""
    z = orbit_models.map_fixed_point(lambda y: flow(p, y, T0, T0 + T)[0], guess, 1e-6)[0]
    _, seen, _ = flow(p, z, T0, T0 + T)
    return z, np.sort(np.mod(seen, T))


# ---- the branches -----------------------------------------------------------------------------
@pytest.fixture(scope="module")
def start() -> da.EquationOrbit:
    scheme = da.periodic_orbit(vdp, P_LO, T, [-1.0, 0.0], multipliers=2)
    return da.collocate(scheme, multipliers=2, intervals=40)


@pytest.fixture(scope="module")
def up(start) -> da.Branch:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", da.CollocationWarning)
        return da.continue_orbit(start, P_HI, step=0.03, multipliers=2, at=AT)


@pytest.fixture(scope="module")
def down(up) -> da.Branch:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", da.CollocationWarning)
        return da.continue_orbit(up.points[-1], P_LO, step=0.03, multipliers=2)


def check_against_reference(pt: da.EquationOrbit) -> None:
    """The point's switching times and its states at 7 times against the reference (1e-8;
    Newton on the period map starts from the point's state at T0)."""
    z, times = reference(pt.p, pt.u_at(T0))
    assert times.size == 2 and pt.switches.size == 2, (times, pt.switches)
    assert np.max(np.abs(np.sort(pt.switches) - times)) < 1e-8, (pt.p, pt.switches - times)
    at = T0 + np.linspace(0.0, T, 8)[:-1]
    _, _, ref = flow(pt.p, z, T0, T0 + T, at)
    err = float(np.max(np.abs(pt.u_at(at) - ref)))
    assert err < 1e-8, (pt.p, err)


def wrapped(a: da.EquationOrbit, b: da.EquationOrbit) -> bool:
    """b's signature is a's with the other segment holding t = 0."""
    return (not np.array_equal(a.signature.modes, b.signature.modes)
            and np.array_equal(np.roll(a.signature.modes, 1, axis=0), b.signature.modes))


def test_reference_reversal_crosses_t0(start, up):
    """The reference's reversal near 0 lies inside (0, T) just after t = 0 at P_LO and just
    before T at P_HI: the branch's range holds the crossing."""
    _, lo = reference(P_LO, start.u_at(T0))
    _, hi = reference(P_HI, up.points[-1].u_at(T0))
    assert 0 < lo[0] < 0.05 and T - 0.05 < hi[1] < T, (lo, hi)


def test_branch_passes_a_switch_crossing_t0(up):
    """The branch reaches p_end; its signature turns once (the same two segments, the other
    holding t = 0), between the user points on either side of the crossing, and no event is
    reported for it; every point before and after the turn agrees with the reference."""
    assert up.status == f"reached p_end = {P_HI!r}", up.status
    pts = up.points
    turns = [k for k in range(1, len(pts)) if wrapped(pts[k - 1], pts[k])]
    assert len(turns) == 1, [pt.signature.describe() for pt in pts]
    assert not [e for e in up.events if e.kind in ("grazing", "stick-onset")], up.events
    k = turns[0]
    assert pts[k - 1].switches[0] < 0.05 and pts[k].switches[-1] > T - 0.05
    assert [pt.p for pt in pts[k - 1:k + 1]] == list(AT)   # landed on either side of it
    for pt in pts:
        check_against_reference(pt)


def test_branch_back_through_the_crossing(down):
    """Back down in p the other switch (now next to T) crosses t = T into t = 0+: the branch
    reaches p_end and its points after the turn agree with the reference."""
    assert down.status == f"reached p_end = {P_LO!r}", down.status
    pts = down.points
    turns = [k for k in range(1, len(pts)) if wrapped(pts[k - 1], pts[k])]
    assert len(turns) == 1, [pt.signature.describe() for pt in pts]
    for pt in pts[turns[0]:]:
        check_against_reference(pt)


# ---- the corner's grazing ---------------------------------------------------------------------
K, C, AG = 1.0, math.sqrt(2.0), 0.5     # u' + K u + AG sigma(u) ∋ A + C sin t
LEAST = 0.005                          # the closed form's least u: (A - AG) / K - C / sqrt(1 + K^2)


def slip(p: float, h: float | None = None) -> dmi.Solver:
    """A first-order slip orbit: f = K u - A - C sin t with A = AG + K (LEAST + C / sqrt(1 +
    K^2)) p (p = 1: u > 0 throughout, u = c0 + C / sqrt(1 + K^2) sin(t - atan(1 / K)), least
    LEAST, half range 1)."""
    A = AG + K * (LEAST + C / math.sqrt(1 + K * K)) * p
    s = dmi.Solver(1, 2 * math.pi / 400 if h is None else h, 1)
    s.set_rhs(lambda t, u: np.array([K * u[0] - A - C * math.sin(t)]))
    s.set_friction([AG])
    return s


def test_corner_reads_a_true_grazing_and_not_a_reversal(up):
    """The corner's sentence on an orbit that slips throughout and touches u = 0 (least u
    LEAST = 0.005 of the half range 1, closed form) names the grazing with that least velocity
    (to the sentence's 3 digits); on the branch's orbit whose reversal lies 0.003 after t = 0
    (its velocity crosses 0 twice a period, touching it nowhere) it names no grazing."""
    scheme = da.periodic_orbit(slip, 1.0, 2 * math.pi, [1.0], multipliers=1)
    o = da.collocate(scheme, multipliers=1, intervals=24)
    assert o.signature.switches == 0 and abs(o.amplitude[0] - 1.0) < 1e-8, o.amplitude
    said = EquationBranch.of(o)[0].corner([o])
    assert "its velocity comes within 0.005 of 0 (half range 1): a grazing" in said, said
    near = min(up.points, key=lambda pt: pt.switches[0])
    assert 0 < near.switches[0] < 0.005, near.switches
    said = EquationBranch.of(near)[0].corner([near])
    assert "grazing" not in said, said
