# dmi.analysis on the tau-diagram's friction oscillator (examples/python/orbit_tau.py, the model
# of examples/python/oscillator_tau.toml with libdmi 1.2's free step h = 4 pi / M): the continued
# period-1 branch against brute-force plain runs at the same h, the detected period doubling
# where the runs' Poincare section doubles, and the period-2 branch born there.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

from dmi.analysis import continue_orbit, period_doubled_orbit, periodic_orbit

sys.path.insert(0, str(Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).parents[4]))
                       / "examples" / "python"))
import orbit_tau  # noqa: E402  (examples/python/orbit_tau.py; a missing file must fail, not skip)
M = 2000


def section(make, tau: float, periods: int = 400, keep: int = 16) -> np.ndarray:
    """w at t = k P for the last ``keep`` of ``periods`` forcing periods of a plain run from the
    model's zero history."""
    s = make(tau)
    s.init()
    s.advance((periods - keep) * M)
    out = []
    for _ in range(keep):
        s.advance(M)
        out.append(s.state[0])
    return np.array(out)


@pytest.fixture(scope="module")
def branches():
    make = orbit_tau.model(M)
    s = make(2.2)
    s.init()
    s.advance(100 * M)
    o = periodic_orbit(make, 2.2, orbit_tau.P, s, multipliers=6)
    b = continue_orbit(o, 2.5, step=0.02, max_step=0.04, multipliers=6)
    pd = [e for e in b.events if e.kind == "period-doubling"]
    assert pd, b.events
    o2 = period_doubled_orbit(b, pd[0], multipliers=6)
    b2 = continue_orbit(o2, 2.46, step=0.02, max_step=0.04, multipliers=6, sections=2)
    return make, b, pd[0], b2


def test_stable_branch_is_the_runs_attractor(branches):
    make, b, pd, _ = branches
    stable = [q for q in b.points if q.stable and q.p < pd.p - 0.02]
    assert len(stable) >= 4
    for q in stable[:: max(1, len(stable) // 4)]:
        w = section(make, q.p)
        assert np.ptp(w) < 1e-7 and abs(w[-1] - q.section[0, 0]) < 1e-7, (q.p, w[-3:], q.section)
    assert not any(q.stable for q in b.points if q.p > pd.p + 0.01)


def test_branch_points_are_orbits_of_fresh_maps(branches):
    """Every point of both branches is a fixed point of the map built anew at its p (the
    corrector's own residual not trusted), and Newton-Picard (on the subspace of the 6 leading
    multipliers) converged at most of them."""
    from dmi.analysis.shooting.shoot import StepMap
    _, b, _, b2 = branches
    for br in (b, b2):
        for q in br.points:
            F = StepMap(br.make, q.p, br.steps, rows=br.rows)
            assert np.max(np.abs(F(q.state) - q.state)) < 1e-9, q.p
        used = [q.corrector for q in br.points[1:]]
        assert used.count("newton-picard") >= 0.7 * len(used), used


def test_period_doubling_where_the_runs_double(branches):
    make, b, pd, b2 = branches
    # the runs: period 1 just below the detected doubling, period 2 just above
    below, above = section(make, pd.p - 0.015), section(make, pd.p + 0.02)
    assert np.ptp(below) < 1e-6, below
    assert np.ptp(above) > 1e-3 and np.ptp(above[::2]) < 1e-6 and np.ptp(above[1::2]) < 1e-6
    # and the period-2 branch is that attractor
    q = min((q for q in b2.points if q.stable), key=lambda q: abs(q.p - (pd.p + 0.02)))
    w = section(make, q.p)
    assert np.sort(w[-2:]) == pytest.approx(np.sort(q.section[:, 0]), abs=1e-6), (q.p, w, q.section)
    assert 2.3 < pd.p < 2.42  # where dmi-sweep's diagram (h = tau / 1e4) splits
