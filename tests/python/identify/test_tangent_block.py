# dmi.identify's compiled tangent (dmi_tangent_run) where its delay sum runs all parameters' columns
# of S as one recursion (an exponential kernel, N up to 4096) and where it runs one engine per
# column (N beyond), each against the Python loop; and grouped perturbed models whose history
# libdmi samples from the group's model (no init of it) against one model per parameter, where the
# group's model may take the base model's place (its friction the base model's) and where it may
# not (its history then from its init).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi.identify import _grouped, sensitivities
from dmi.identify.sensitivity import _build, _sensitivities_of

pytest.importorskip("numba")


def memory_model(N: int, tau: float):
    """make(p), p = (k, c1, a1, c2, a2, w0): w'' + k w + int_0^tau (c1 e^{a1 s} + c2 e^{a2 s})
    w'(t - s) ds = cos t, w = w0 cos t on [-tau, 0], f and the history compiled; N cells."""
    def make(p):
        k, c1, a1, c2, a2, w0 = p

        def rhs(t, u):
            return np.array([-u[1], k * u[0] - math.cos(t)])

        def history(t):
            return np.array([w0 * math.cos(t), -w0 * math.sin(t)])
        s = dmi.Solver(2, tau, N)
        s.set_rhs(rhs, jit=True)
        C = np.zeros((2, 2, 2))
        C[0, 1, 1], C[1, 1, 1] = c1, c2
        s.set_kernel_exp([a1, a2], [0.0, 0.3], C)
        s.set_history(history, jit=True)
        return s
    return make


P_MEMORY = [1.3, 0.4, -0.8, 0.3, -2.0, 0.7]


@pytest.mark.parametrize("N,tau,steps", [(40, 0.5, 300), (4100, 4.1, 250)])
def test_compiled_delay_sum_agrees_with_the_python_loop(N, tau, steps):
    # N = 40: the block recursion of all columns, restarted every 4 N = 160 steps; N = 4100: one
    # engine per column.  The Python loop computes its own recursion (Z of each term, the
    # weights e^{lam l h}), so both are checked against an independent sum
    make = memory_model(N, tau)
    fast = sensitivities(make, P_MEMORY, steps)
    slow = sensitivities(make, P_MEMORY, steps, engine="python")
    assert (fast.engine, slow.engine) == ("compiled", "python")
    assert np.array_equal(fast.u, slow.u)
    scale = max(1.0, float(np.abs(slow.S).max()))
    assert np.abs(slow.S[:, :, 1:5]).max() > 1e-3          # the kernel's parameters move U
    assert np.abs(fast.S - slow.S).max() <= 1e-12 * scale, np.abs(fast.S - slow.S).max() / scale
    assert np.abs(fast.dx - slow.dx).max() <= 1e-12 * max(1.0, float(np.abs(slow.dx).max()))


def friction_model(order: tuple):
    """make(p) of the parameters (k, mu, c1, a1, c2, a2, w0) listed in the order ``order`` (the
    plan groups them in that order): w'' + k w + mu sigma(w') + memory = 0.9 cos 1.3 t, w = w0 cos t
    on [-1, 0], N = 50, f and the history compiled."""
    def make(q):
        p = dict(zip(order, q))
        k, mu, c1, a1, c2, a2, w0 = (p[x] for x in ("k", "mu", "c1", "a1", "c2", "a2", "w0"))

        def rhs(t, u):
            return np.array([-u[1], k * u[0] - 0.9 * math.cos(1.3 * t)])

        def history(t):
            return np.array([w0 * math.cos(t), -w0 * math.sin(t)])
        s = dmi.Solver(2, 1.0, 50)
        s.set_rhs(rhs, jit=True)
        s.set_friction([0.0, mu])
        C = np.zeros((2, 2, 2))
        C[0, 1, 1], C[1, 1, 1] = c1, c2
        s.set_kernel_exp([a1, a2], np.zeros(2), C)
        s.set_history(history, jit=True)
        return s
    return make


VALUES = {"k": 1.0, "mu": 0.6, "c1": 0.8, "a1": -0.7, "c2": 0.5, "a2": -2.0, "w0": 1.0}


@pytest.mark.parametrize("order,inits", [
    (("k", "mu", "c1", "a1", "c2", "a2", "w0"), 1),     # w0 with k: libdmi samples its history
    (("mu", "w0", "k", "c1", "a1", "c2", "a2"), 2)])    # w0 with mu: the group's model's init
def test_grouped_history_agrees_with_one_model_per_parameter(monkeypatch, order, inits):
    make = friction_model(order)
    p = np.array([VALUES[x] for x in order])
    plan = _grouped.plan(_build(make, p))
    assert plan is not None
    w0 = order.index("w0")
    group = next(g for g in plan.groups if w0 in g)
    assert len(group) > 1 and plan.history[plan.groups.index(group)] == w0
    q = p * 1.03
    grouped = _grouped.build(make, q, plan)
    full = _build(make, q)
    counted = []
    orig = dmi.Solver.init

    def counting(self):
        counted.append(self)
        return orig(self)
    for jumps in (True, False):
        Sf = _sensitivities_of(full, q, 150, jumps=jumps)
        monkeypatch.setattr(dmi.Solver, "init", counting)
        counted.clear()
        Sg = _sensitivities_of(grouped, q, 150, jumps=jumps)
        monkeypatch.setattr(dmi.Solver, "init", orig)
        assert (Sg.engine, Sf.engine) == ("compiled", "compiled")
        assert len(counted) == inits
        assert np.array_equal(Sg.S[0], Sf.S[0])           # the history's S, w0's column (cos, -sin)
        assert np.abs(Sg.S[0, :, w0] - [math.cos(0.0), 0.0]).max() < 1e-7
        scale = max(1.0, float(np.abs(Sf.S).max()))
        assert np.abs(Sg.S - Sf.S).max() <= 1e-12 * scale, np.abs(Sg.S - Sf.S).max() / scale
