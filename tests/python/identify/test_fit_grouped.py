# Perturbed models shared by parameters that move disjoint parts of the model (dmi.identify._grouped,
# used by estimate's Jacobians): on a friction oscillator with a two-term memory whose parameters
# enter f, the friction, the kernel's rates and coefficients and the history, the grouped models
# give the sensitivities of one model per parameter and the plain tangent of central differences of
# plain runs; a plan that no longer holds (a parameter moving another part, or the structure) falls
# back to one model per parameter; estimate's point and covariance equal those without groups; a
# make failing at a grouped point is named and leaves the fit's problem usable; the polish's stop
# rule against a geometric sequence's closed-form rest.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dmi
from dmi.identify import FitOptions, Record, _grouped, estimate
from dmi.identify.fitting import _check_record, _converged, _Problem
from dmi.identify.sensitivity import _build, _sensitivities_of

P0 = np.array([1.0, 0.6, 0.8, -0.7, 0.5, -2.0, 1.0])   # k, mu, c1, a1, c2, a2, w0
TAU = 1.0
STEPS = 120


def oscillator(branch: str = "", fail: list | None = None):
    """make(p): w'' + k w + mu sigma(w') + int_0^tau (c1 e^{a1 s} + c2 e^{a2 s}) w'(t - s) ds
    = 0.9 cos 1.3 t, w = w0 cos t on [-tau, 0] (u = (w, w'), N = 50, Python callbacks).  branch
    "friction": above c1 = 0.9, c1 moves the friction too; "terms": above it, a third kernel term.
    fail: [x]: make raises where k differs from x[0] (the models at perturbed k)."""
    def make(p):
        k, mu, c1, a1, c2, a2, w0 = p
        if fail and fail[0] is not None and k != fail[0][0]:
            raise RuntimeError("no model at this k")

        def rhs(t, u):
            return np.array([-u[1], k * u[0] - 0.9 * math.cos(1.3 * t)])

        def history(t):
            return np.array([w0 * math.cos(t), -w0 * math.sin(t)])
        s = dmi.Solver(2, TAU, 50)
        s.set_rhs(rhs)
        s.set_friction([0.0, mu + (c1 - 0.9 if branch == "friction" and c1 > 0.9 else 0.0)])
        K = 3 if branch == "terms" and c1 > 0.9 else 2
        C = np.zeros((K, 2, 2))
        C[0, 1, 1], C[1, 1, 1] = c1, c2
        s.set_kernel_exp([a1, a2, -1.0][:K], np.zeros(K), C)
        s.set_history(history)
        return s
    return make


def plain(make, p, steps):
    s = make(p)
    s.init()
    return s.run(steps)[1]


def test_grouped_models_give_the_sensitivities_of_one_model_per_parameter():
    make = oscillator()
    plan = _grouped.plan(_build(make, P0))
    assert plan is not None
    group_of = {j: g for g, members in enumerate(plan.groups) for j in members}
    # k (f) and mu (friction) are read by the loop from their own models: never in one group
    assert group_of[0] != group_of[1]
    assert len(plan.groups) + len(plan.own) < len(P0)
    q = P0 * 1.03
    grouped = _grouped.build(make, q, plan)
    assert grouped is not None
    for jumps in (True, False):
        Sg = _sensitivities_of(grouped, q, STEPS, jumps=jumps).S
        Sf = _sensitivities_of(_build(make, q), q, STEPS, jumps=jumps).S
        assert np.max(np.abs(Sg - Sf)) <= 1e-12 * max(1.0, float(np.max(np.abs(Sf))))
    # the plain tangent from the grouped models against central differences of plain runs
    S = _sensitivities_of(grouped, q, STEPS, jumps=False).S
    worst = 0.0
    for j in range(len(q)):
        eps = 1e-7 * max(1.0, abs(q[j]))
        up, down = q.copy(), q.copy()
        up[j] += eps
        down[j] -= eps
        D = (plain(make, up, STEPS) - plain(make, down, STEPS)) / (up[j] - down[j])
        worst = max(worst, float(np.max(np.abs(S[:, :, j] - D) / (1 + np.abs(D)))))
    assert worst < 1e-5, worst


def problem(make) -> _Problem:
    t = np.linspace(0.05, STEPS * TAU / 50, 40)
    y = plain(make, P0, STEPS)[1::3, 0][:40]
    return _Problem([make], P0.copy(), np.ones(len(P0), bool), [_check_record(Record(t, y), 0, 2)],
                    None)


def test_a_plan_that_no_longer_holds_falls_back_to_one_model_per_parameter():
    make = oscillator("friction")
    x = P0.copy()
    x[2] = 0.95                        # c1 now moves the friction as well as its kernel term
    pr = problem(make)
    pr.linearised(P0)                  # the plan: learned where c1 moves its term only
    plan = _grouped.plan(_build(make, P0))
    assert _grouped.build(make, x, plan) is None
    J = pr.jacobian(x)
    ref = problem(make)
    ref.grouped = False
    assert np.max(np.abs(J - ref.jacobian(x))) <= 1e-12 * np.max(np.abs(J))


def test_a_structure_changed_at_a_grouped_point_is_refused_by_name():
    # at c1 = 0.9 the model at c1 + delta has a third kernel term, the model at c1 not
    pr = problem(oscillator("terms"))
    pr.linearised(P0)
    x = P0.copy()
    x[2] = 0.9
    with pytest.raises(ValueError, match="parameter 2 changes the number of kernel terms"):
        pr.jacobian(x)


def test_a_make_failing_at_a_grouped_point_is_named_and_leaves_the_problem_usable():
    fail: list = [None]
    make = oscillator(fail=fail)
    pr = problem(make)
    pr.linearised(P0)
    x = P0 * 1.01
    fail[0] = x
    with pytest.raises(ValueError, match=r"make\(p \+ delta e_0 \+ delta e_2 .* raised RuntimeError: "
                                         "no model at this k"):
        pr.jacobian(x)
    fail[0] = None
    ref = problem(oscillator())
    ref.grouped = False
    J = pr.jacobian(x)
    assert np.max(np.abs(J - ref.jacobian(x))) <= 1e-12 * np.max(np.abs(J))


def test_the_estimate_with_grouped_models_equals_the_one_without():
    # k, mu, c1, c2, w0 free (the rates fixed): groups {k, c1, c2, w0} and {mu}
    make = oscillator()
    t = np.linspace(0.05, 8.0, 100)
    rng = np.random.default_rng(5)
    y = plain(make, P0, 401)[np.round(t * 50).astype(int), 0] + 1e-3 * rng.standard_normal(100)
    start = P0 * (1 + np.array([0.05, -0.05, 0.05, 0.05, -0.05, 0.05, 0.03]))
    free = [0, 1, 2, 4, 6]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        est = estimate(make, start, Record(t, y), free=free)
        ref = estimate(make, start, Record(t, y), free=free,
                       options=FitOptions(group_models=False))
    assert est.success and ref.success
    assert est.njev == ref.njev and est.nfev == ref.nfev
    assert np.max(np.abs(est.p - ref.p) / np.abs(ref.p)) <= 1e-10
    assert np.max(np.abs(est.cov - ref.cov)) <= 1e-8 * np.max(np.abs(ref.cov))


def test_the_polish_stops_where_a_geometric_rest_is_below_the_tolerance():
    # drops 4e-6 then 1e-6 (rate 1/4): the rest of the geometric sequence is 1e-6 (1/4) / (3/4)
    rest = 1e-6 / 3
    assert _converged(1e-6, 4e-6, rest * 1.01)
    assert not _converged(1e-6, 4e-6, rest * 0.99)
    assert not _converged(3e-6, 4e-6, 1.0)             # shrinking by less than half: no estimate
    assert not _converged(1e-6, math.inf, 1.0)         # one drop only


def test_group_models_must_be_a_bool():
    make = oscillator()
    t = np.linspace(0.05, 2.0, 10)
    with pytest.raises(TypeError, match=r"FitOptions.group_models = 'no': expected True or False"):
        estimate(make, P0, Record(t, np.zeros(10)), options=FitOptions(group_models="no"))


def test_residuals_from_a_jacobian_that_fails_come_from_a_plain_run():
    # the fit asks for the residuals from a Jacobian's run; where that Jacobian fails (make at a
    # perturbed point), the residuals come from a plain run, and the Jacobian asked for next raises
    fail: list = [None]
    make = oscillator(fail=fail)
    pr = problem(make)
    pr.linearised(P0)
    x = P0 * 1.01
    fail[0] = x
    pr.speculate = True
    r = pr.residuals(x)
    assert pr.nfev == 1 and pr.njev == 1                 # a plain run; no Jacobian at x
    fail[0] = None
    ref = problem(oscillator())
    assert np.max(np.abs(r - ref.residuals(x))) == 0.0
    fail[0] = x
    with pytest.raises(ValueError, match=r"make\(p \+ delta e_0 .* raised RuntimeError"):
        pr.jacobian(x)
    # where the Jacobian's run works, the residuals are its own (no plain run), a plain run's bits
    fail[0] = None
    y = P0 * 0.99
    pr.asked = True
    r = pr.residuals(y)
    assert pr.nfev == 1 and pr.njev == 2
    assert np.max(np.abs(r - ref.residuals(y))) == 0.0
