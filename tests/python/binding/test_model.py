"""The model as set, read back through Solver's public accessors (what dmi.analysis and
dmi.identify read): the kinds, the built-in resolvents' closed forms, the exponential sum's
value, callbacks (Python and jit=True) called as the scheme calls them, and their failures."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import pytest

import dmi


def test_defaults_are_zero():
    s = dmi.Solver(2, 1.0, 10)
    assert (s.resolvent_kind, s.kernel_kind, s.convolution, s.quadrature) == ("", "", "auto", "left")
    assert not any(s.has(p) for p in ("rhs", "resolvent", "kernel", "kernel_near", "history"))
    assert np.array_equal(s.eval_rhs(1.0, [1.0, 2.0]), [0.0, 0.0])
    assert np.array_equal(s.eval_resolvent(0.1, [1.0, -2.0]), [1.0, -2.0])
    assert np.array_equal(s.eval_kernel(0.3), np.zeros((2, 2)))
    assert s.kernel_terms is None and s.friction is None and s.box is None and s.kernel_fit is None
    with pytest.raises(ValueError, match="part 'force'"):
        s.has("force")


def test_friction_and_box_closed_forms():
    s = dmi.Solver(2, 1.0, 10)
    s.set_friction([0.0, 1.5])
    assert s.resolvent_kind == "friction" and np.array_equal(s.friction, [0.0, 1.5])
    # soft threshold by lam alpha: 0.1 * 1.5 = 0.15
    assert np.allclose(s.eval_resolvent(0.1, [1.0, 0.1]), [1.0, 0.0], rtol=0, atol=1e-15)
    assert np.allclose(s.eval_resolvent(0.1, [1.0, -0.4]), [1.0, -0.25], rtol=0, atol=1e-15)
    s.set_box([-1.0, 0.0], [1.0, np.inf])
    assert s.resolvent_kind == "box" and s.friction is None
    lo, hi = s.box
    assert np.array_equal(lo, [-1.0, 0.0]) and np.array_equal(hi, [1.0, np.inf])
    assert np.array_equal(s.eval_resolvent(0.1, [3.0, -2.0]), [1.0, 0.0])
    s.set_resolvent(lambda lam, x: x / (1 + lam))
    assert s.resolvent_kind == "callback" and s.box is None
    assert np.allclose(s.eval_resolvent(0.25, [1.0, 2.0]), [0.8, 1.6], rtol=1e-15)
    s.set_resolvent(None)
    assert s.resolvent_kind == ""


def test_kernel_terms_and_value():
    s = dmi.Solver(2, 1.0, 10)
    C = np.array([[[1.0, 2.0], [0.0, 1.0]]])
    D = np.array([[[0.0, 0.5], [0.0, 0.0]]])
    s.set_kernel_exp([-1.0], [2.0], C, D)
    assert s.kernel_kind == "exp"
    a, b, Ct, Dt = s.kernel_terms
    assert np.array_equal(a, [-1.0]) and np.array_equal(Ct, C) and np.array_equal(Dt, D)
    x = 0.7
    want = np.exp(-x) * (np.cos(2 * x) * C[0] + np.sin(2 * x) * D[0])
    assert np.allclose(s.eval_kernel(x), want, rtol=1e-14, atol=0)
    s.set_kernel(lambda t: np.eye(2) * t)
    assert s.kernel_kind == "callback" and s.kernel_terms is None
    assert np.array_equal(s.eval_kernel(0.3), 0.3 * np.eye(2))


def test_callbacks_as_the_scheme_calls_them():
    s = dmi.Solver(2, 1.0, 10)
    s.set_rhs(lambda t, u: np.array([u[1], -u[0] + t]))
    assert s.has("rhs") and np.array_equal(s.eval_rhs(2.0, [1.0, 3.0]), [3.0, 1.0])
    s.set_rhs(lambda t, u: np.array([u[1], -u[0] + t]), jit=True)
    assert np.array_equal(s.eval_rhs(2.0, [1.0, 3.0]), [3.0, 1.0])
    s.set_history(lambda t: np.array([t, 1.0]))
    assert np.array_equal(s.eval_history(-0.5), [-0.5, 1.0])
    s.set_rhs(lambda t, u: np.array([1.0 / 0.0, 0.0]))
    with pytest.raises(ZeroDivisionError) as info:
        s.eval_rhs(0.0, [0.0, 0.0])
    assert "rhs at t = 0.0" in " ".join(info.value.__notes__)
    # the failure does not stay behind for the scheme's next call
    s.set_rhs(lambda t, u: -u)
    s.init()
    s.step()


def test_choices_and_fit_recorded():
    from dmi import kernels
    s = dmi.Solver(1, 1.0, 10)
    s.set_convolution("direct")
    s.set_quadrature("cell")
    assert (s.convolution, s.quadrature) == ("direct", "cell")
    fit = kernels.fit(lambda t: np.exp(-t), 1.0)
    s.set_kernel_fit(fit)
    got, entry = s.kernel_fit
    assert got is fit and entry == (0, 0) and s.kernel_near_delta == 0.0
    s.set_kernel_exp([-1.0], [0.0], np.ones((1, 1, 1)))
    assert s.kernel_fit is None


def test_fit_forgotten_once_its_near_cells_are_removed_or_replaced():
    # a fit with near cells, then the near cells removed or replaced: the model is no longer the
    # fit, so kernel_fit must not name it (dmi.analysis and dmi.identify read the kernel from it)
    from dmi import kernels
    fit = kernels.fit(kernels.PowerKernel(0.5), 1.0, delta=0.05)
    assert fit.delta > 0
    for near in (None, lambda s: np.array([[s ** -0.5]])):
        s = dmi.Solver(1, 1.0, 100)
        s.set_quadrature("cell")
        s.set_kernel_fit(fit)
        assert s.kernel_fit is not None and s.kernel_near_delta == fit.delta
        s.set_kernel_near(near, 0.0 if near is None else 0.1)
        assert s.kernel_fit is None
