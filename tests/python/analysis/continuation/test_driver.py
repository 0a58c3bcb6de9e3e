# The one continuation driver (dmi.analysis.continuation.driver) on discretisations written here: the S-curve
# x^3 - 3x = p (two folds at p = +-2, x = -+1), a transcritical crossing x (p - x) = 0 (a branch
# point at p = 0), each curve's points known in closed form.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import pickle
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.sparse
import scipy.sparse.linalg as sla

from dmi.analysis.continuation.driver import (ContinuationOptions, Discretisation, HasEvents,
                                               Predictor, continuation)
from dmi.analysis.core.newton import (Converge, NewtonOptions, Search, ShootingError,
                                      newton_loop)


class SCurve:
    """x^3 - 3 x - p = 0 with a dense, sparse or operator Jacobian."""

    def __init__(self, form: str = "dense"):
        self.form = form

    def residual(self, x, p):
        return np.array([x[0] ** 3 - 3 * x[0] - p])

    def jacobian(self, x, p):
        d = np.array([[3 * x[0] ** 2 - 3]])
        if self.form == "sparse":
            d = scipy.sparse.csc_matrix(d)
        elif self.form == "operator":
            d = sla.aslinearoperator(d)
        return d, np.array([-1.0])

    def point(self, x, p):
        return SimpleNamespace(p=p, x=float(x[0]), stable=None, dpds=0.0)


def cubic_roots(p):
    return np.sort(np.roots([1, 0, -3, -p]).real[np.abs(np.roots([1, 0, -3, -p]).imag) < 1e-9])


@pytest.mark.parametrize("form", ["dense", "sparse", "operator"])
def test_folds_passed_user_points_hit_and_p_end_landed_exactly(form):
    x0 = -3.0
    b = continuation(SCurve(form), [x0], x0 ** 3 - 3 * x0, 10.0, step=0.3, max_points=400,
                     at=[0.0, 5.0], predictor="secant" if form == "operator" else "tangent")
    assert b.status.startswith("reached p_end"), b.status
    last = b.points[-1]
    assert last.p == 10.0 or abs(last.p - 10.0) <= 1e-12
    assert abs(last.x - cubic_roots(10.0)[-1]) <= 1e-10
    for q in b.points:                                  # every point on the curve
        assert abs(q.x ** 3 - 3 * q.x - q.p) <= 1e-9
    folds = sorted(e.p for e in b.events if e.kind == "fold")
    assert len(folds) == 2, b.events
    tol = 1e-9 if form != "operator" else 1e-2        # the secant's fold: a parabola's vertex
    assert abs(folds[0] + 2) <= tol and abs(folds[1] - 2) <= tol, folds
    user = [e for e in b.events if e.kind == "user"]
    # p = 0 is met three times (x = -sqrt 3, 0, sqrt 3), p = 5 once
    assert sorted(e.p for e in user) == [0.0, 0.0, 0.0, 5.0]
    xs = sorted(b.points[e.index].x for e in user if e.p == 0.0)
    assert np.allclose(xs, [-math.sqrt(3), 0.0, math.sqrt(3)], atol=1e-10)
    for e in user:
        assert abs(b.points[e.index].p - e.p) <= 1e-12
    assert not [e for e in b.events if e.kind == "branch-point"]


def test_landing_whatever_the_tangent():
    # p_end just below a fold's vertex: the tangent is nearly vertical where the branch meets it
    x0 = -3.0
    for p_end in (1.99, 1.9999):
        b = continuation(SCurve(), [x0], x0 ** 3 - 3 * x0, p_end, step=0.3, max_points=100)
        assert b.status.startswith("reached p_end"), b.status
        assert abs(b.points[-1].p - p_end) <= 1e-12
        assert abs(b.points[-1].x - cubic_roots(p_end)[0]) <= 1e-9
        assert abs(b.points[-1].dpds) < 0.5


class Transcritical:
    """x (p - x) = 0: the branches x = 0 and x = p cross at p = 0."""
    def residual(self, x, p):
        return np.array([x[0] * (p - x[0])])

    def jacobian(self, x, p):
        return np.array([[p - 2 * x[0]]]), np.array([x[0]])

    def point(self, x, p):
        return SimpleNamespace(p=p, x=float(x[0]), stable=p - 2 * x[0] < 0)


def test_branch_point_located_and_the_branch_kept():
    b = continuation(Transcritical(), [0.0], -1.0, 1.0, step=0.15)
    assert b.status.startswith("reached p_end") and b.points[-1].p == 1.0
    bp = [e for e in b.events if e.kind == "branch-point"]
    assert len(bp) == 1 and abs(bp[0].p) <= 1e-10, b.events
    assert all(q.x == 0.0 for q in b.points)           # stayed on x = 0
    assert not [e for e in b.events if e.kind == "fold"]


class Circle:
    """x^2 + p^2 = 1 with an event function x (its zeros at p = +-1, the folds)."""
    def residual(self, x, p):
        return np.array([x[0] ** 2 + p ** 2 - 1])

    def jacobian(self, x, p):
        return np.array([[2 * x[0]]]), np.array([2 * p])

    def point(self, x, p):
        return SimpleNamespace(p=p, x=float(x[0]), stable=True, dpds=0.0)

    def event_functions(self, x, p, point):
        return {"crossing": float(x[0] - 0.5)}


def test_event_function_located_by_brent_and_fold_out_of_range_stops():
    b = continuation(Circle(), [-1.0], 0.0, 0.5, step=0.1, max_points=200)
    # from x = -1 (p = 0) towards p = 0.5: p grows to the fold p = 1 at x = 0 ... but p_end = 0.5
    # comes first, at x = -sqrt(0.75)
    assert b.status.startswith("reached p_end") and b.points[-1].p == 0.5
    assert abs(b.points[-1].x + math.sqrt(0.75)) <= 1e-10
    b = continuation(Circle(), [-0.9], math.sqrt(1 - 0.81), 0.99, step=0.05, max_points=400,
                     at=[])
    ev = [e for e in b.events if e.kind == "crossing"]
    # from x = -0.9 the p = 0.99 is met at x = -sqrt(1 - 0.99^2) < 0.5: no crossing
    assert not ev and b.points[-1].p == 0.99


def test_bad_input_is_named():
    with pytest.raises(ValueError, match="p_end"):
        continuation(SCurve(), [0.0], 0.0, 0.0)
    with pytest.raises(ValueError, match="step"):
        continuation(SCurve(), [0.0], 0.0, 1.0, step=-1)
    with pytest.raises(ValueError, match="non-finite"):
        continuation(SCurve(), [math.nan], 0.0, 1.0)


class NoJacobian:
    """A discretisation that forgot its Jacobian."""
    def residual(self, x, p):
        return np.array([x[0] - p])

    def point(self, x, p):
        return SimpleNamespace(p=p)


def test_a_discretisation_without_a_required_method_is_a_type_error_naming_it():
    with pytest.raises(TypeError, match="NoJacobian lacks jacobian"):   # bad-inputs DC01
        continuation(NoJacobian(), [0.0], 0.0, 1.0)
    assert isinstance(SCurve(), Discretisation) and not isinstance(NoJacobian(), Discretisation)
    assert isinstance(Circle(), HasEvents) and not isinstance(SCurve(), HasEvents)


def test_options_are_values_and_the_keywords_map_onto_them():
    x0 = -3.0
    o = ContinuationOptions(step=0.3, max_points=400, at=(5.0, 0.0))
    assert o.at == (0.0, 5.0) and o.predictor is Predictor.TANGENT
    b = continuation(SCurve(), [x0], x0 ** 3 - 3 * x0, 10.0, o)
    k = continuation(SCurve(), [x0], x0 ** 3 - 3 * x0, 10.0, step=0.3, max_points=400,
                     at=[0.0, 5.0])
    assert [q.p for q in b.points] == [q.p for q in k.points]
    folds = sorted(e.p for e in b.events if e.kind == "fold")
    assert len(folds) == 2 and abs(folds[0] + 2) <= 1e-9 and abs(folds[1] - 2) <= 1e-9
    # a keyword replaces the options' field
    s = continuation(SCurve(), [x0], x0 ** 3 - 3 * x0, 10.0, o, predictor="secant")
    assert s.status.startswith("reached p_end") and abs(s.points[-1].x - cubic_roots(10.0)[-1]) \
        <= 1e-10
    with pytest.raises(TypeError, match="no field stepsize"):   # bad-inputs DC02
        continuation(SCurve(), [x0], x0 ** 3 - 3 * x0, 10.0, stepsize=0.1)
    with pytest.raises(ValueError, match="predictor"):   # bad-inputs DC03
        ContinuationOptions(predictor="chord")
    with pytest.raises(ValueError, match="converge"):
        NewtonOptions(converge="energy")
    with pytest.raises(TypeError, match="no field damping"):   # bad-inputs DC04
        NewtonOptions().but(damping=0.5)
    assert NewtonOptions(converge="both", search="descent") == NewtonOptions(
        converge=Converge.BOTH, search=Search.DESCENT)


def test_newton_loop_takes_a_convergence_test():
    # x^2 = 2 from 1: the caller's test stops once x^2 is within 1e-14 of 2 (Newton's
    # residual); it sees every residual and may stop the loop
    seen = []

    def near(z, r, res):
        seen.append(len(res))
        return abs(z[0] ** 2 - 2) <= 1e-14

    z, res = newton_loop(lambda z: (np.array([z[0] ** 2 - 2]), None),
                         lambda z, r, s: (lambda r: -r / (2 * z)), np.array([1.0]),
                         NewtonOptions(converge=near, max_iter=20), what="sqrt 2")
    assert abs(z[0] - math.sqrt(2)) <= 1e-15 and seen == list(range(1, len(res) + 1))

    def slow(z, r, res):
        if len(res) > 2:
            raise OverflowError("too slow")
        return False
    with pytest.raises(OverflowError, match="too slow"):
        newton_loop(lambda z: (np.array([z[0] ** 2 - 2]), None),
                    lambda z, r, s: (lambda r: -r / (2 * z)), np.array([1.0]),
                    NewtonOptions(converge=slow), what="sqrt 2")


class Refusing(SCurve):
    """The S-curve whose points with x > 0 are refused (``accept`` raises): a mend that fails."""
    def accept(self, x, p, step):
        if x[0] > 0:
            raise ShootingError(f"x = {x[0]} > 0 refused", [])
        return x, p


def test_accept_refuses_points_and_the_branch_ends_before_them():
    x0 = -3.0
    b = continuation(Refusing(), [x0], x0 ** 3 - 3 * x0, 10.0, step=0.3, max_points=400)
    # from x = -3 (p = -18) towards p = 10: x grows past the fold at x = -1 (p = 2), p falls
    # back, x reaches 0 at p = 0: no point with x > 0, the step fell to its smallest just
    # before x = 0
    assert b.status.startswith("corrector failed at the smallest step"), b.status
    assert "refused" in b.status
    assert all(q.x <= 0 for q in b.points) and b.points[-1].x > -0.01


class Holed:
    """x = p, whose residual refuses 1 < p < 1.2 (a model that fails there); ``recover`` gives
    the exact point on the hyperplane where Newton failed."""
    def __init__(self):
        self.recovered = 0

    def residual(self, x, p):
        if 1.0 < p < 1.2:
            raise ValueError(f"p = {p} in the hole")
        return np.array([x[0] - p])

    def jacobian(self, x, p):
        return np.array([[1.0]]), np.array([-1.0])

    def point(self, x, p):
        return SimpleNamespace(p=p, x=float(x[0]))

    def recover(self, x, p, row, target, step, error):
        self.recovered += 1
        s = target / (row[0] + row[1])       # x = p on row . (x, p) = target
        return np.array([s]), s


def test_recover_gives_the_point_where_the_corrector_fails():
    d = Holed()
    b = continuation(d, [0.0], 0.0, 2.0, step=0.05, max_points=400)
    assert b.status.startswith("reached p_end") and b.points[-1].p == 2.0
    assert d.recovered > 0 and any(1.0 < q.p < 1.2 for q in b.points)
    assert all(abs(q.x - q.p) <= 1e-12 for q in b.points)


def test_continue_orbit_of_something_else_is_a_type_error():
    from dmi.analysis import continue_orbit
    with pytest.raises(TypeError, match="orbit is a dict: give an Orbit"):   # bad-inputs DC05
        continue_orbit({"p": 0.0}, 1.0)


def test_a_folds_parabola_after_the_unknowns_changed():
    # the points before a fold of another size (a signature changed) are left out; the vertex of
    # p(s) = 1 - s^2 through three points of the new size, and with one of them only, its own p
    from dmi.analysis.continuation.driver import _parabola
    curve = SimpleNamespace(norm=lambda v: float(np.linalg.norm(v)))
    old = [np.array([0.0, 0.0, 5.0]), np.array([1.0, 1.0, 6.0])]
    new = [np.array([s, 1.0 - s * s]) for s in (-0.5, 0.1, 0.6)]
    assert _parabola(curve, old + new) == pytest.approx(1.0, abs=0.02)
    assert _parabola(curve, old + new[-1:]) == pytest.approx(1.0 - 0.36, abs=1e-15)
