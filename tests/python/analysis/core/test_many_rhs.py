# f at many points in one call (dmi.analysis.core.model.ManyRhs): the stacked call where the
# model's function takes stacked states, the per-point loop where it does not, and the same
# values either way (the expected values from the model's formula evaluated point by point here).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi.analysis.core.model import ManyRhs


def points() -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 3.0, 7)
    U = np.column_stack([np.cos(t) + 2.0, np.sin(3 * t) - 0.5])
    return t, U


def by_hand(t: np.ndarray, U: np.ndarray) -> np.ndarray:
    """van der Pol's f with a forcing, point by point with math (not the model's code)."""
    return np.array([[-v, (u * u - 1.0) * v + u + math.sin(s)] for s, (u, v) in zip(t, U)])


def solver(f) -> dmi.Solver:
    s = dmi.Solver(2, 1.0, h=0.01)
    s.set_rhs(f)
    return s


def test_stacked_call_is_used_and_agrees() -> None:
    calls = []

    def f(t, u):
        calls.append(np.shape(u))
        return np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0] + np.sin(t)])
    many = ManyRhs(solver(f))
    t, U = points()
    for _ in range(2):
        out = many(t, U)
        assert np.allclose(out, by_hand(t, U), rtol=1e-14, atol=1e-14)
    assert many.f is not None                       # still stacked after its checks
    assert (2, t.size) in calls                     # one call on all the points


@pytest.mark.parametrize("kind", ["raises", "wrong values", "wrong shape"])
def test_a_function_that_does_not_stack_falls_back(kind: str) -> None:
    def f(t, u):
        if kind == "raises":
            return np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0] + math.sin(t)])
        if kind == "wrong values":                  # np.max over all the points when stacked
            return np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0] + np.sin(t)
                             + 0.0 * np.max(u) + (np.size(u) > 2) * 1e-6])
        return np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0] + np.sin(t)]).ravel()
    many = ManyRhs(solver(f))
    t, U = points()
    out = many(t, U)
    assert many.f is None                           # not tried again
    assert np.allclose(out, by_hand(t, U), rtol=1e-14, atol=1e-14)
    assert {"raises": "raised", "wrong values": "disagrees", "wrong shape": "shape"}[kind] \
        in many.why                                 # and says why


def test_a_nan_where_the_model_gives_nan_keeps_the_stacked_call() -> None:
    # sqrt of a negative u[0]: NaN point by point and stacked alike (a Newton trial outside the
    # model's domain), so the two agree and the stacked call stays
    def f(t, u):
        return np.array([-u[1], np.sqrt(u[0]) * u[1]])
    many = ManyRhs(solver(f))
    t, U = points()
    U[3, 0] = -1.0
    with np.errstate(invalid="ignore"):
        out = many(t, U)
    assert many.f is not None and many.why == ""
    assert np.isnan(out[3, 1]) and np.all(np.isfinite(np.delete(out, 3, axis=0)))


def test_later_calls_check_points_that_move() -> None:
    # a function wrong at one point only from its second call on: the fixed checks (first,
    # middle, last) miss it, the moving ones find it within the calls of a collocation solve
    state = {"calls": 0}

    def f(t, u):
        state["calls"] += 1
        out = np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0] + np.sin(t)])
        if state["calls"] > 1 and np.ndim(u) == 2:
            out[1, 2] += 1.0
        return out
    many = ManyRhs(solver(f))
    t, U = points()
    many(t, U)                                     # checked at every point: right
    for _ in range(20):
        if many.f is None:
            break
        many(t, U)
    assert many.f is None and "disagrees" in many.why
