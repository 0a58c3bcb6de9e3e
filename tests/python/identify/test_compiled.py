# dmi.identify.sensitivities: libdmi's loop (dmi_tangent_run, f called through its C function) against
# the Python loop, step by step, on the models of models/identify_models.py with f compiled
# (jit=True): smooth runs with exponential and callback kernels, two reversals, stick-slip, and
# stick-slip with memory; a box; which loop is taken; and Solver.c_callback, called directly.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import ctypes
import math

import numpy as np
import pytest

import dmi
from dmi.identify import sensitivities

pytest.importorskip("numba")

from models.identify_models import P_SMOOTH, oscillator, smooth_model  # noqa: E402


@pytest.fixture
def compiled_rhs(monkeypatch):
    """set_rhs compiles f (jit=True) while the fixture is active: the models of
    models/identify_models.py, as they are, with a compiled f."""
    orig = dmi.Solver.set_rhs

    def set_rhs(self, f, user=None, *, jit=False):
        orig(self, f, user, jit=True)
    monkeypatch.setattr(dmi.Solver, "set_rhs", set_rhs)


def both(make, p, steps, **kw):
    """The compiled and the Python loop on the same model; asserts which loop each took."""
    fast = sensitivities(make, p, steps, **kw)
    slow = sensitivities(make, p, steps, engine="python", **kw)
    assert (fast.engine, slow.engine) == ("compiled", "python")
    return fast, slow


def agree(fast, slow, tol=1e-12):
    assert np.array_equal(fast.u, slow.u) and np.array_equal(fast.x, slow.x)
    scale = max(1.0, float(np.abs(slow.S).max()))
    assert np.abs(fast.S - slow.S).max() <= tol * scale, np.abs(fast.S - slow.S).max() / scale
    assert np.abs(fast.dx - slow.dx).max() <= tol * max(1.0, float(np.abs(slow.dx).max()))
    assert fast.switches == slow.switches


@pytest.mark.parametrize("kernel,convolution,quadrature,h", [
    ("exp", "auto", "left", None), ("exp", "direct", "cell", None), ("exp", "auto", "left", 0.8 / 37.4),
    ("callback", "fft", "left", None)])
def test_smooth_runs_agree(compiled_rhs, kernel, convolution, quadrature, h):
    # the recursion of the exponential kernel (both rules, a short last cell) and the direct sum
    # of a callback kernel, over more than 4 N steps (the recursion is recomputed every 4 N)
    fast, slow = both(smooth_model(kernel, convolution, quadrature, h), P_SMOOTH, 200)
    assert np.abs(slow.S).max() > 0.1
    agree(fast, slow)


@pytest.mark.parametrize("T,mu,kw,kinds", [
    (6.0, 0.5, {}, {"reversal"}),                                      # two reversals
    (10.0, 1.2, {}, {"stick", "reversal"}),                            # stick-slip
    (8.0, 1.4, dict(c=0.6, a=-4.0, tau=10.0), {"stick"}),              # stick-slip with memory
])
def test_switches_agree(compiled_rhs, T, mu, kw, kinds):
    h = 1 / 500
    for jumps in (True, False):
        fast, slow = both(oscillator(h, mu, **kw), [mu, kw.get("c", 0.0)], round(T / h), jumps=jumps)
        if jumps:
            assert kinds <= {kind for _, _, kind in slow.switches}
        agree(fast, slow)


def test_box_agrees():
    def make(p):
        lo, hi = p
        s = dmi.Solver(2, 0.5, 50)
        s.set_rhs(lambda t, u: np.array([-1.0 - 0.1 * u[1], 0.5 * u[0] - 2.0 * math.cos(t)]), jit=True)
        s.set_box([lo, -10.0], [hi, 10.0])
        s.set_history(lambda t: np.array([hi - 0.01, 0.5]))
        return s
    fast, slow = both(make, [-5.0, 1.2], 120)
    # u0 is pushed against hi from the second step: dU0/dhi = 1 there, whichever loop
    assert np.abs(fast.S[2:, 0, 1] - 1.0).max() < 1e-12
    agree(fast, slow)


def test_which_loop():
    def make(p, jit=True, friction=True):
        s = dmi.Solver(1, 1.0, 10)
        s.set_rhs(lambda t, u: np.array([p[0] * u[0] - 1.0]), jit=jit)
        if friction:
            s.set_friction([0.5])
        else:
            s.set_resolvent(lambda lam, x: x / (1.0 + lam))
        return s
    assert sensitivities(make, [0.3], 5).engine == "compiled"
    assert sensitivities(lambda p: make(p, jit=False), [0.3], 5).engine == "python"
    assert sensitivities(lambda p: make(p, friction=False), [0.3], 5).engine == "python"
    with pytest.raises(ValueError, match="Python function"):
        sensitivities(lambda p: make(p, jit=False), [0.3], 5, engine="compiled")
    with pytest.raises(ValueError, match="resolvent"):
        sensitivities(lambda p: make(p, friction=False), [0.3], 5, engine="compiled")
    with pytest.raises(ValueError, match="engine = 'fast'"):
        sensitivities(make, [0.3], 5, engine="fast")
    # a model without f: the compiled loop, with the friction's own derivative -h sign(X) only
    no_f = sensitivities(lambda p: dmi.Solver(1, 1.0, 10), [0.3], 5)
    assert no_f.engine == "compiled" and np.all(no_f.S == 0.0)


def test_a_failing_compiled_callback_raises_through_the_python_loop():
    def make(p):
        s = dmi.Solver(1, 1.0, 10)
        # a result of the wrong shape in a perturbed model once t > 0.35 (the run at p itself
        # goes through): its compiled callback returns 2 in the compiled loop
        s.set_rhs(lambda t, u: np.array([p[0], 1.0]) if p[0] != 1.0 and t > 0.35 else np.array([p[0]]),
                  jit=True)
        return s
    with pytest.raises(dmi.Error, match="returned"):
        sensitivities(make, [1.0], 10)


def test_c_callback():
    s = dmi.Solver(2, 1.0, 10)
    assert all(s.c_callback(part) is None
               for part in ("rhs", "resolvent", "kernel", "kernel_near", "history"))
    k = 3.0
    s.set_rhs(lambda t, u: np.array([u[1], -k * u[0] + t]), jit=True)
    address, user = s.c_callback("rhs")
    fn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                          ctypes.POINTER(ctypes.c_double), ctypes.c_void_p)
    u = np.array([2.0, -1.0])
    out = np.zeros(2)
    rc = fn(address)(0.5, u.ctypes.data_as(ctypes.POINTER(ctypes.c_double)),
                     out.ctypes.data_as(ctypes.POINTER(ctypes.c_double)), user)
    assert rc == 0 and np.array_equal(out, [-1.0, -3.0 * 2.0 + 0.5])
    # a Python function goes through a trampoline: no C function to call directly
    s.set_rhs(lambda t, u: u)
    assert s.c_callback("rhs") is None and s.has("rhs")
    # built-in parts are not callbacks; a C function of the user's is given back as it is
    s.set_friction([0.0, 1.0])
    s.set_kernel_exp([-1.0], [0.0], np.ones((1, 2, 2)))
    assert s.c_callback("resolvent") is None and s.c_callback("kernel") is None
    c_rhs = fn(lambda t, u, out, user: 0)
    data = np.zeros(3)
    s.set_rhs(c_rhs, data)
    assert s.c_callback("rhs") == (ctypes.cast(c_rhs, ctypes.c_void_p).value, data.ctypes.data)
    with pytest.raises(dmi.InvalidArgument, match="part 'force'"):
        s.c_callback("force")


def jit_history_model(h=None):
    """A friction oscillator with memory whose compiled history carries parameters; tau = 0.8 with
    h = 0.8 / 37.4 leaves a short last delay cell (the window's oldest sample at -tau, not -N h);
    parameters (k, mu, w0, v0, c)."""
    def make(p):
        k, mu, w0, v0, c = p
        s = dmi.Solver(2, 0.8, 40) if h is None else dmi.Solver(2, 0.8, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] + 2.0 * math.cos(0.8 * t)]), jit=True)
        s.set_friction([0.0, mu])
        C = np.zeros((1, 2, 2))
        C[0, 1, 0] = c
        s.set_kernel_exp([-2.0], [0.0], C)
        s.set_history(lambda t: np.array([w0 + v0 * t + 0.3 * t * t, v0 + 0.6 * t]), jit=True)
        return s
    return make


@pytest.mark.parametrize("h", [None, 0.8 / 37.4])
def test_compiled_history_is_sampled_without_init(monkeypatch, h):
    # the perturbed models' windows come from their compiled history callbacks, called as init
    # calls them; the Python loop inits every model: both give the same S, through reversals
    make = jit_history_model(h)
    p = [1.0, 0.5, 0.3, 0.2, 0.6]
    slow = sensitivities(make, p, 300, engine="python")
    inits = []
    orig = dmi.Solver.init

    def counted(self):
        inits.append(self)
        return orig(self)
    monkeypatch.setattr(dmi.Solver, "init", counted)
    fast = sensitivities(make, p, 300)
    assert fast.engine == "compiled" and len(inits) == 1          # the base model's init only
    assert "reversal" in {kind for _, _, kind in slow.switches}
    # the history's columns: dU^0/dw0 = (1, 0), dU^0/dv0 = (0, 1)
    assert np.array_equal(fast.S[0, :, 2:4], np.eye(2))
    agree(fast, slow)


def test_same_callback():
    # Solver.same_callback: the same function with the same data, for the three kinds of callback;
    # what it cannot be sure of counts as different
    def solvers(make_rhs, jit=False, values=(1.0, 1.0)):
        out = []
        for v in values:
            s = dmi.Solver(2, 1.0, 10)
            s.set_rhs(make_rhs(v), jit=jit)
            out.append(s)
        return out

    def scalar(k):
        return lambda t, u: np.array([-u[1], k * u[0]])

    def vector(k):
        a = np.array([k, 2.0])
        return lambda t, u: np.array([-u[1], a[0] * u[0]])

    def nested(k):
        def g(x):
            return k * x
        return lambda t, u: np.array([-u[1], g(u[0])])
    for jit in (False, True):
        for maker in (scalar, vector, nested if not jit else scalar):
            a, b = solvers(maker, jit, (1.5, 1.5))
            assert a.same_callback(b, "rhs") and b.same_callback(a, "rhs"), (jit, maker)
            a, b = solvers(maker, jit, (1.5, 1.5 + 2.0 ** -40))
            assert not a.same_callback(b, "rhs"), (jit, maker)
        a, b = solvers(scalar, jit, (0.0, -0.0))        # numbers compared bit for bit
        assert not a.same_callback(b, "rhs")
    # a Python f against the same f compiled; a part absent in both, in one
    (a,), (b,) = solvers(scalar, False, (1.0,)), solvers(scalar, True, (1.0,))
    assert not a.same_callback(b, "rhs")
    assert a.same_callback(b, "history")
    b.set_history(lambda t: np.zeros(2))
    assert not a.same_callback(b, "history") and not b.same_callback(a, "history")
    # C functions: the same address and user pointer
    fn = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.POINTER(ctypes.c_double),
                          ctypes.POINTER(ctypes.c_double), ctypes.c_void_p)
    c_rhs = fn(lambda t, u, out, user: 0)
    data, other = np.zeros(3), np.zeros(3)
    a.set_rhs(c_rhs, data)
    b.set_rhs(c_rhs, data)
    assert a.same_callback(b, "rhs")
    b.set_rhs(c_rhs, other)
    assert not a.same_callback(b, "rhs")
    with pytest.raises(dmi.InvalidArgument, match="part 'force'"):
        a.same_callback(b, "force")
    with pytest.raises(TypeError, match="expected a dmi.Solver"):
        a.same_callback("solver", "rhs")
