# Verified period-doubling and torus events on a scheme's branch continued with verify=: the
# scheme of u' + c(p) u = cos(2 pi t) with h = 1/3, three steps a period, whose multiplier is
# (1 - h c)^3 = -(1 + (p - 1) / 2) exactly (a linear map): it crosses -1 at p = 1, an event
# placed there by the linear interpolation of the test function (exact here); the same points
# with error bounds larger than the multiplier's distance to the circle give no event and an
# EventWarning; with verify=False the event says it is not verified; undecided() and
# verified_tests() on hand-made multipliers.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest

import dmi
from dmi import analysis as da
from dmi.analysis.branches.events import EventWarning, orbit_events, undecided, verified_tests

H = 1.0 / 3.0


def flip(p: float) -> dmi.Solver:
    c = (1 + (1 + 0.5 * (p - 1)) ** (1 / 3)) / H      # (1 - h c)^3 = -(1 + (p - 1) / 2)
    s = dmi.Solver(1, 1.0, h=H)
    s.set_rhs(lambda t, u: np.array([c * u[0] - math.cos(2 * math.pi * t)]))
    return s


@pytest.fixture(scope="module")
def branch() -> da.Branch:
    o = da.periodic_orbit(flip, 0.5, 1.0, [0.0], multipliers=1)
    return da.continue_orbit(o, 1.5, step=0.25, multipliers=1, verify=da.Verify())


def test_verified_period_doubling_on_a_scheme_branch(branch):
    for q in branch.points:
        assert q.multipliers[0].real == pytest.approx(-(1 + 0.5 * (q.p - 1)), abs=1e-9)
    pds = [e for e in branch.events if e.kind == "period-doubling"]
    assert len(pds) == 1 and abs(pds[0].p - 1.0) < 1e-9, branch.events
    assert "verified" in pds[0].detail


def test_crossing_within_the_error_bounds_is_not_reported(branch):
    e = next(e for e in branch.events if e.kind == "period-doubling")
    a, b = branch.points[e.index - 1], branch.points[e.index]
    # the same points, their multipliers' error bounds now beyond their distance to -1
    wide = [dataclasses.replace(q, floquet=dataclasses.replace(
        q.floquet, errors=np.full(q.floquet.errors.shape, 0.5))) for q in (a, b)]
    with pytest.warns(EventWarning, match="error bound is larger than their distance"):
        got = orbit_events(wide[0], wide[1], e.index)
    assert not [g for g in got if g.kind == "period-doubling"], got
    # one side only within its bound: still not reported
    one = dataclasses.replace(b, floquet=dataclasses.replace(
        b.floquet, errors=np.full(b.floquet.errors.shape, 0.5)))
    with pytest.warns(EventWarning, match=f"at p = {b.p!r}"):
        got = orbit_events(a, one, e.index)
    assert not got
    # the true bounds: reported, without a warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventWarning)
        got = orbit_events(a, b, e.index)
    assert [g.kind for g in got] == ["period-doubling"]


def test_undecided_and_verified_tests():
    mu = np.array([-1.0 - 1e-6, 0.5 + 0.9j, 0.5 - 0.9j])
    assert undecided("period-doubling", mu, np.array([1e-9, 1e-9, 1e-9])) is None
    assert "within its error bound" in undecided("period-doubling", mu, np.array([1e-5, 0, 0]))
    assert undecided("period-doubling", mu, np.array([np.nan, 0, 0])) is not None
    r = abs(mu[1]) - 1                                  # the pair's distance to the circle
    assert undecided("torus", mu, np.array([0, abs(r) / 2, abs(r) / 2])) is None
    assert undecided("torus", mu, np.array([0, 2 * abs(r), 2 * abs(r)])) is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventWarning)
        f = verified_tests(mu, np.array([1e-9, 1e-9, 1e-9]), 0.0)
    assert f["period-doubling"] == pytest.approx(1e-6, abs=1e-15)
    assert f["torus"] == pytest.approx(r, abs=1e-15)
    with pytest.warns(EventWarning, match="does not decide a period-doubling"):
        f = verified_tests(mu, np.array([1e-5, 1e-9, 1e-9]), 0.0)
    assert f["period-doubling"] == 0.0 and f["torus"] == pytest.approx(r, abs=1e-15)
    with pytest.raises(ValueError, match="error bounds for"):
        verified_tests(mu, np.zeros(2), 0.0)
    with pytest.raises(ValueError, match="expected one of"):
        undecided("fold", mu, np.zeros(3))


def test_the_doubling_test_changes_sign_with_the_real_multipliers_below_minus_one():
    err = np.full(4, 1e-9)
    small = [0.1 + 0.2j, 0.1 - 0.2j]
    pair = verified_tests(np.array([-0.75 + 0.33j, -0.75 - 0.33j] + small), err, 0.0)
    split = verified_tests(np.array([-1.87, -0.36] + small), err, 0.0)
    both = verified_tests(np.array([-1.87, -1.2] + small), err, 0.0)
    # -prod (1 + mu) over Re mu < 0: negative before the pair meets, positive with one real
    # multiplier below -1, negative again with two
    assert pair["period-doubling"] == pytest.approx(-abs(0.25 + 0.33j) ** 2, rel=1e-14)
    assert split["period-doubling"] == pytest.approx(0.87 * 0.64, rel=1e-14)
    assert both["period-doubling"] == pytest.approx(-0.87 * 0.2, rel=1e-14)
    assert verified_tests(np.array(small), err[:2], 0.0)["period-doubling"] == -1.0
    # a complex multiplier within its bound of -1 decides nothing
    with pytest.warns(EventWarning, match="from -1, within its error bound"):
        got = verified_tests(np.array([-1 + 1e-7j, -1 - 1e-7j] + small),
                             np.array([1e-6, 1e-6, 1e-9, 1e-9]), 0.0)
    assert got["period-doubling"] == 0.0


def test_event_without_error_bounds_says_so():
    """With verify=False the Ritz multipliers have no error bound: the event is the scheme's,
    its detail says it is not verified."""
    o = da.periodic_orbit(flip, 0.5, 1.0, [0.0], multipliers=1)
    with pytest.warns(UserWarning, match="verify=False"):
        b = da.continue_orbit(o, 1.5, step=0.25, multipliers=1, verify=False)
    pds = [e for e in b.events if e.kind == "period-doubling"]
    assert len(pds) == 1 and abs(pds[0].p - 1.0) < 1e-9, b.events
    assert "not verified" in pds[0].detail


def test_an_undecided_point_between_brackets_the_event_across_it(branch):
    """A point that decides nothing of the doubling (its bounds beyond its distance to -1)
    between two that do: the event is reported between the two decided points, at the crossing
    of the linear interpolation of their test function (exact here: the multiplier is linear in
    p), with a warning at the undecided point; and without that point the same event."""
    below = [q for q in branch.points if q.p < 1 - 1e-6]
    above = [q for q in branch.points if q.p > 1 + 1e-6]
    x, z = below[-1], above[0]
    y = dataclasses.replace(z, p=0.5 * (x.p + z.p), floquet=dataclasses.replace(
        z.floquet, errors=np.full(z.floquet.errors.shape, 0.5)))
    decided: dict = {}
    with pytest.warns(EventWarning, match="sought between the points that decide it"):
        got = orbit_events(x, y, 1, decided=decided)
    assert not [g for g in got if g.kind == "period-doubling"], got
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventWarning)
        got = orbit_events(y, z, 2, decided=decided)
    pd = [g for g in got if g.kind == "period-doubling"]
    assert len(pd) == 1 and abs(pd[0].p - 1.0) < 1e-9, got
    assert f"bracketed by the points at p = {x.p!r} and {z.p!r}" in pd[0].detail
    # without the undecided point: the same event, between the same two points
    with warnings.catch_warnings():
        warnings.simplefilter("error", EventWarning)
        direct = [g for g in orbit_events(x, z, 1) if g.kind == "period-doubling"]
    assert len(direct) == 1 and abs(direct[0].p - pd[0].p) < 1e-12, direct


def test_default_branch_verifies_and_the_opt_out_has_no_verdict():
    """continue_orbit verifies by default (every point's floquet record, stable from it); with
    verify=False the Ritz multipliers stay, stable is None and a warning says so."""
    o = da.periodic_orbit(flip, 0.5, 1.0, [0.0], multipliers=1)
    b = da.continue_orbit(o, 0.8, step=0.25, multipliers=1)
    assert all(q.floquet is not None for q in b.points)
    # the exact multiplier -(1 + (p - 1) / 2) lies inside the circle below p = 1: stable
    assert all(q.stable is True for q in b.points), [q.stable for q in b.points]
    with pytest.warns(UserWarning, match="verify=False"):
        u = da.continue_orbit(o, 0.8, step=0.25, multipliers=1, verify=False)
    assert all(q.stable is None and q.floquet is None for q in u.points)
    for q in u.points:
        assert q.multipliers[0].real == pytest.approx(-(1 + 0.5 * (q.p - 1)), abs=1e-9)
    with pytest.raises(ValueError, match="verify"):
        da.continue_orbit(o, 0.8, step=0.25, multipliers=1, verify="yes")
