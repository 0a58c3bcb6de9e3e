# A stick-slip orbit with a weakly singular memory (the fractional belt of tests/python/models/
# fractional_belt.py, tau = 15, about two and a half periods): past a switch where a derivative
# of the solution jumps (its second at a slip onset), the convolution with s^-1/2 makes it behave
# as a fractional power of t - t_s, which the equidistribution of u^(m+1) does not see; the
# interval after that switch carries almost all of the period's error.  The refinement finds that interval by the dual-weighted residual (adapt.contributions)
# and grades the mesh towards the switch (adapt.graded).  Checked against independent solves: the
# shares against the re-solved period of the mesh with one end graded and with everything else
# halved; the refined period against a reference on a mesh with every switch graded deeply (its
# own convergence shown by two finer such meshes).  The grading's cuts, the hot ends and the
# halving of a round's hottest intervals (adapt.repaired) by hand.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import warnings
from types import SimpleNamespace

import numpy as np
import pytest

from dmi import analysis as da
from dmi.analysis.collocation import adapt
from dmi.analysis.collocation.system import reference as phase_reference, solve

from models import fractional_belt as fb

TAU = 15.0


@pytest.fixture(scope="module")
def orbit() -> da.Orbit:
    make, _ = fb.model(TAU)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return fb.stick_slip_orbit(make)


@pytest.fixture(scope="module")
def collocated(orbit):
    """The orbit on 2 x 12 intervals: (its layout, terms, x, phase reference)."""
    e = da.collocate(orbit, intervals=12, multipliers=0)
    disc, x = da.CollocationDiscretisation.of(e, estimate=False)
    return disc.lay, disc.terms(e.p), x, phase_reference(disc.lay, x)


def period_on(collocated, fractions) -> float:
    lay, terms, x, ref = collocated
    new = lay.with_fractions(fractions)
    return float(solve(new, terms, adapt.transfer(lay, x, new), ref)[0][-1])


@pytest.fixture(scope="module")
def reference_period(collocated) -> tuple[float, float]:
    """The period on the mesh halved with every piece's start graded 12 times (the
    reference), and its uncertainty: its difference to that mesh halved again and to every
    start graded 16 times."""
    lay = collocated[0]
    starts = {(j, 0): 12 for j in range(len(lay.fractions))}
    fine = adapt.halved(lay.fractions)
    T = period_on(collocated, adapt.graded(fine, starts))
    finer = period_on(collocated, adapt.graded(adapt.halved(fine), starts))
    deeper = period_on(collocated, adapt.graded(fine, {k: 16 for k in starts}))
    return T, max(abs(finer - T), abs(deeper - T))


def test_the_shares_locate_the_error(collocated):
    lay, terms, x, ref = collocated
    f = adapt.Solved(lay, x)
    f.check = adapt.checked(f, terms, ref)
    assert f.check is not None
    dT = f.check.T - f.T
    eta = adapt.contributions(f, terms, ref)
    assert eta is not None and eta.shape == (lay.L,)
    assert abs(eta.sum() - dT) <= 0.02 * abs(dT)          # first order: the shares sum to it
    hot = adapt.hot_ends(lay, eta)
    assert len(hot) == 1
    j, side, share = hot[0]
    assert abs(share) >= 0.9 * abs(dT)                    # one interval, almost all of it
    # independent solves: that end graded once takes its share away ...
    once = period_on(collocated, adapt.graded(lay.fractions, {(j, side): 1}))
    assert abs((once - f.T) - share) <= 0.25 * abs(share)
    # ... and every other interval halved moves the period by a tenth of the difference at most
    fr = lay.fractions
    hot_mid = 0.5 * (fr[j][0] + fr[j][1]) if side == 0 else 0.5 * (fr[j][-2] + fr[j][-1])
    others = adapt.halved(fr)
    others[j] = others[j][np.abs(others[j] - hot_mid) > 1e-15]
    assert abs(period_on(collocated, others) - f.T) <= 0.1 * abs(dT)


def test_reference_converged(reference_period):
    # within a quarter of the rounding floor a checked estimate claims (1.3e-13 measured, 2e-14
    # relative): the refinement's estimate at that floor still bounds its true error
    T, uncertainty = reference_period
    assert uncertainty <= 0.25 * adapt.CHECKED_FLOOR * T


def test_refinement_grades_the_switch(orbit, reference_period):
    T_ref, uncertainty = reference_period
    calls = []
    real = adapt.regraded

    def spy(lay, eta, tol, ends):
        out = real(lay, eta, tol, ends)
        calls.append(dict(ends))
        return out
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(adapt, "regraded", spy)
        e = da.collocate(orbit, tol=1e-10, multipliers=0)
    true = abs(e.period - T_ref)
    assert true + uncertainty <= e.errors["period"] <= 1e-10
    assert any(calls[-1].values())                        # an end graded
    # without grading: 59 intervals in five rounds (each check on twice as many)
    assert e.intervals <= 40


def test_graded_cuts_each_end_by_halves():
    fr = [np.array([0.0, 0.5, 1.0]), np.array([0.0, 0.25, 0.5, 1.0])]
    g = adapt.graded(fr, {(0, 0): 2, (1, 1): 3})
    assert np.array_equal(g[0], [0.0, 0.125, 0.25, 0.5, 1.0])
    assert np.array_equal(g[1], [0.0, 0.25, 0.5, 0.75, 0.875, 0.9375, 1.0])
    assert np.array_equal(fr[0], [0.0, 0.5, 1.0])         # the fractions given are kept


def test_hot_ends_are_the_pieces_ends_only():
    lay = SimpleNamespace(signature=SimpleNamespace(switches=2),
                          fractions=[np.linspace(0, 1, 4), np.linspace(0, 1, 3)])
    # intervals 0 1 2 | 3 4: the start of piece 0, the end of piece 1, an inner interval
    assert adapt.hot_ends(lay, np.array([-6.0, 1, 1, 1, 1])) == [(0, 0, -6.0)]
    assert adapt.hot_ends(lay, np.array([1.0, 1, 1, 1, 6])) == [(1, 1, 6.0)]
    assert adapt.hot_ends(lay, np.array([1.0, 6, 1, 1, 1])) == []     # inside a piece
    assert adapt.hot_ends(lay, np.array([1.0, 1, 1, 1, 3])) == []     # under HOT_SHARE
    smooth = SimpleNamespace(signature=SimpleNamespace(switches=0),
                             fractions=[np.linspace(0, 1, 6)])
    assert adapt.hot_ends(smooth, np.array([9.0, 1, 1, 1, 1])) == []   # no switch, no end


def test_repaired_halves_the_fewest_hottest_intervals():
    lay = SimpleNamespace(m=4, L=8, fractions=[np.linspace(0, 1, 5), np.linspace(0, 1, 5)])
    # sum |eta| = 1e-8 (the estimate 2e-8); intervals 2 and 5 carry 90 % of it.  Halving k of
    # the hottest leaves 2 (1e-8 - (their sum) (1 - 2^-5)): interval 2 alone 1.03e-8, with 5
    # 2.56e-9, with a third 2.17e-9, a fourth 1.79e-9
    eta = np.array([1e-10, 1e-10, 5e-9, 2e-10, 2e-10, -4e-9, 2e-10, 2e-10])
    d = 2 * abs(eta.sum())                                  # the round's estimate, 1.84e-8

    def repair(tol, d=d, grow=100):
        return adapt.repaired(lay, eta, tol * adapt.MARGIN, d, grow)
    out = repair(3e-9)
    assert out is not None
    assert np.array_equal(out[0], [0.0, 0.25, 0.5, 0.625, 0.75, 1.0])
    assert np.array_equal(out[1], [0.0, 0.25, 0.375, 0.5, 0.75, 1.0])
    assert repair(2e-9) is None                             # four: over L / 4 = 2
    assert repair(3e-9, grow=9) is None                     # 10 intervals where 9 would do
    assert repair(3e-9, grow=10) is not None
    assert repair(3e-9, d=4 * d) is None                    # the shares say a quarter of d
    # spread: 1e-9 each; k halved leave 2 (8e-9 - k 1e-9 (31 / 32)): 1.41e-8, 1.21e-8, 1.02e-8
    eta = np.full(8, 1e-9)
    d = 1.6e-8
    assert repair(1.1e-8, d=d) is None                      # three needed
    two = repair(1.25e-8, d=d)
    assert two is not None and sum(len(f) - 5 for f in two) == 2
