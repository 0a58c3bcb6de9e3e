# dmi.analysis.continue_orbit and its events against exact answers (models/orbit_models.py):
# a fold at p = 0 (u' = p - u^2), period doublings of the logistic scheme at p = 2 and
# p = sqrt(6) and the period-doubled branch in closed form, Den Hartog's stick onset (the
# largest forcing where the exact non-stick orbit stops existing), passed without stopping.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import pytest

import dmi
from dmi.analysis import continue_orbit, period_doubled_orbit, periodic_orbit
from models.orbit_models import DenHartog, Fold, Logistic


def test_fold_and_unstable_side():
    m = Fold()
    o = periodic_orbit(m.make, 1.0, m.M * m.h, [0.9], multipliers=2, constant=True)
    b = continue_orbit(o, -1.0, step=0.1, multipliers=2)
    folds = [e for e in b.events if e.kind == "fold"]
    assert len(folds) == 1 and abs(folds[0].p) < 0.02, b.events
    assert "left the range" in b.status
    for q in b.points:
        u = q.state[-1]
        assert u == pytest.approx(np.sign(u) * np.sqrt(q.p), abs=1e-9)
        assert q.multipliers[0].real == pytest.approx((1 - 2 * m.h * u) ** m.M, rel=1e-5)
        assert q.stable == (u > 0)
    assert any(q.state[-1] < -0.5 for q in b.points)  # it came back on the unstable side


def test_period_doubling_and_doubled_branch():
    m = Logistic()
    o = periodic_orbit(m.make, 1.5, 1.0, [0.9], multipliers=2, constant=True)
    b = continue_orbit(o, 2.5, step=0.1, multipliers=2)
    pds = [e for e in b.events if e.kind == "period-doubling"]
    assert len(pds) == 1 and pds[0].p == pytest.approx(2.0, abs=1e-6), b.events
    o2 = period_doubled_orbit(b, pds[0])
    assert o2.steps == 2 and np.sort(o2.u[:2, 0]) == pytest.approx(np.sort(m.cycle(o2.p)), abs=1e-9)
    b2 = continue_orbit(o2, 2.6, step=0.1, multipliers=2, sections=2)
    for q in b2.points:
        assert np.sort(q.section[:, 0]) == pytest.approx(np.sort(m.cycle(q.p)), abs=1e-8)
        r = 1 + q.p
        assert q.multipliers[0].real == pytest.approx(4 + 2 * r - r * r, abs=0.01)
    pd2 = [e for e in b2.events if e.kind == "period-doubling"]
    assert len(pd2) == 1 and pd2[0].p == pytest.approx(np.sqrt(6), abs=0.01), b2.events


def test_doubled_branch_started_at_its_doubling_stays_doubled():
    """The 2-cycle of the logistic scheme at p = 2.001, 1.6e-2 from the fixed point u = 1 it was
    born from, continued with a first step of 0.1: the Newton iterates from it reach u = 1 (0.13
    from the 2-cycle at p = 2.101); every point must be the closed-form 2-cycle all the same."""
    m = Logistic()
    o2 = periodic_orbit(m.make, 2.001, 2.0, m.cycle(2.001)[::-1], multipliers=2)
    assert np.ptp(o2.u[:2, 0]) > 0.03
    b2 = continue_orbit(o2, 2.3, step=0.1, multipliers=2, sections=2)
    assert len(b2.points) >= 3, b2.status
    # it ends at p_end, on the hyperplane p = 2.3 (the branch is curved: the secant's hyperplane
    # would leave it short, and one more step repeat the point)
    assert b2.p[-1] == pytest.approx(2.3, abs=1e-7) and np.all(np.diff(b2.p) > 1e-6), b2.p
    for q in b2.points:
        assert np.sort(q.section[:, 0]) == pytest.approx(np.sort(m.cycle(q.p)), abs=1e-8), q.p


def _den_hartog_valid(p: float) -> bool:
    try:
        d = DenHartog(F=p)
    except RuntimeError:
        return False
    return abs(d.F * np.cos(d.w * (d.t0 + d.T / 2)) - d.a) > d.F0


def test_stick_onset_located_and_passed():
    lo, hi = 0.40, 0.45  # bisection of the exact orbit's existence: the stick onset p*
    assert _den_hartog_valid(hi) and not _den_hartog_valid(lo)
    while hi - lo > 1e-6:
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if _den_hartog_valid(mid) else (mid, hi)
    d, M = DenHartog(), 2000
    x, v = d.exact(0.0)
    o = periodic_orbit(d.make_for(M), 0.6, d.T, [0.6 * x, 0.6 * v], multipliers=2)
    b = continue_orbit(o, 0.35, step=0.05, multipliers=2)
    assert b.status.startswith("reached p_end"), b.status
    onsets = [e for e in b.events if e.kind == "stick-onset"]
    assert len(onsets) == 1 and onsets[0].component == 1, b.events
    assert abs(onsets[0].p - hi) < 2 * d.T / M, (onsets[0].p, hi)  # O(h)
    steps = b.column("stick_steps")[:, 1]
    assert np.all(steps[b.p > hi + 0.01] == 0) and np.all(steps[b.p < hi - 0.01] > 0)
    # the margin: on the non-stick side Den Hartog's net force beyond friction at the velocity
    # reversal, |F cos(w t_r) - x(t_r)| - F0 at x(t_r) = a (F = p), to O(h) wherever the steps
    # fall about the reversal; below 0 where it sticks
    for q in b.points:
        if q.p > hi + 0.01:     # the exact orbit exists (no stick) with an O(h) margin
            assert q.stick_steps[1] == 0
            e = DenHartog(F=q.p)
            exact = abs(e.F * np.cos(e.w * (e.t0 + e.T / 2)) - e.a) - e.F0
            assert abs(q.margin[1] - exact) < 2 * d.T / M, (q.p, q.margin, exact)
        elif q.stick_steps[1]:
            assert q.margin[1] < 0, (q.p, q.margin)
    # the corrector: Newton-Picard on the previous point's basis (here the dense Jacobian)
    assert [q.corrector for q in b.points[1:]].count("newton-picard") >= len(b.points) - 2
    assert np.all(b.column("stick_steps")[:, 0] == 0)
    # the points past the kink are orbits: the map's residual at each
    from dmi.analysis.shooting.shoot import StepMap
    for q in b.points[-3:]:
        F = StepMap(d.make_for(M), q.p, M, rows=b.rows)
        assert np.max(np.abs(F(q.state) - q.state)) < 1e-9


def test_torus_where_a_complex_pair_leaves_the_unit_circle():
    """u' = [[p, -1], [1, p]] u, h = 0.1, M = 10: the orbit u = 0 has the multipliers
    (1 + h (p +- i))^M, of modulus 1 at p* = (sqrt(1 - h^2) - 1) / h."""
    h, M = 0.1, 10

    def make(p):
        s = dmi.Solver(2, h, h=h)
        s.set_rhs(lambda t, u: np.array([-p * u[0] + u[1], -u[0] - p * u[1]]))
        return s
    o = periodic_orbit(make, -0.3, M * h, [0.0, 0.0], multipliers=2, constant=True)
    b = continue_orbit(o, 0.3, step=0.05, multipliers=2)
    tori = [e for e in b.events if e.kind == "torus"]
    pstar = (np.sqrt(1 - h * h) - 1) / h
    assert len(tori) == 1 and abs(tori[0].p - pstar) < 5e-3, (b.events, pstar)
    assert not [e for e in b.events if e.kind in ("period-doubling", "fold")]
    for q in b.points:
        mu = (1 + h * (q.p + 1j)) ** M
        assert np.sort_complex(q.multipliers) == pytest.approx(np.sort_complex([mu, mu.conjugate()]),
                                                               abs=1e-6)
        assert q.stable == (q.p < pstar)
