# Solver.set_quadrature("cell"): the first step's delay term against dmi._transform's closed-form cell
# weights, every engine the same, the default unchanged, and the fractional relaxation
# u' + int_0^t s^-1/2 / Gamma(1/2) u(t - s) ds = 0, u(0) = 1, against u = E_{3/2}(-t^{3/2}) (mpmath series).
# Solver.set_kernel_fit: the fitted singular kernel (O(1), exact near cells) within the fit's solution bound.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes
import math

import mpmath as mp
import numpy as np
import pytest

import dmi
from dmi import _transform as tr
from dmi import kernels

A = [-1.0, 0.0]
B = [0.0, 3.0]
C = np.array([[[0.5, 1.0], [0.0, 0.0]], [[0.0, 0.0], [1.0, -0.3]]])
D = np.array([[[0.2, 0.0], [0.0, 0.0]], [[0.0, 0.4], [0.0, 0.0]]])


def history(t):
    return np.array([math.cos(5 * t), 0.5 + math.sin(t)])


def solver(method, rule, *, h=None, N=50, callback=False):
    s = dmi.Solver(2, 1.0, N) if h is None else dmi.Solver(2, 1.0, h=h)
    s.set_rhs(lambda t, u: np.array([0.3 * u[0] - u[1], u[0] + 0.1 * u[1]]))
    s.set_history(history)
    if callback:
        s.set_kernel(lambda x: tr.evaluate(x, A, B, C, D))
    else:
        s.set_kernel_exp(A, B, C, D)
    if rule is not None:
        s.set_quadrature(rule)
    s.set_convolution(method)
    s.init()
    return s


@pytest.mark.parametrize("h", [None, 0.0213])
@pytest.mark.parametrize("callback", [False, True])
def test_first_delay_term_is_the_cell_integral(h, callback):
    s = solver("direct", "cell", h=h, callback=callback)
    N, hh = s.N, s.h
    theta = (1.0 - (N - 1) * hh) / hh if h is not None else 1.0
    w = tr.cell_weights(A, B, C, D, h=hh, N=N, theta=theta)  # (N, 2, 2), tested against mpmath
    U = s.get_window()[::-1][:N]  # U^{0-l}, l < N
    s.step()
    W, _ = s.step_terms()
    assert np.allclose(W, np.einsum("lij,lj->i", w, U), rtol=1e-13, atol=1e-15)


@pytest.mark.parametrize("h", [None, 0.0213])
def test_engines_agree_and_default_unchanged(h):
    ref = solver("direct", "cell", h=h).run(300)[1]
    for m in ("fft", "recursive", "auto"):
        assert np.max(np.abs(solver(m, "cell", h=h).run(300)[1] - ref)) <= 1e-13
    assert np.max(np.abs(solver("direct", "cell", h=h, callback=True).run(300)[1] - ref)) <= 1e-13
    left = solver("direct", None, h=h).run(300)[1]
    assert np.array_equal(solver("direct", "left", h=h).run(300)[1], left)
    assert np.max(np.abs(left - ref)) > 1e-4  # another rule: the test can tell them apart


def test_bad_rule_and_after_init():
    s = dmi.Solver(1, 1.0, 10)
    with pytest.raises(dmi.InvalidArgument):
        s.set_quadrature("midpoint")
    s.init()
    with pytest.raises(dmi.Error) as e:
        s.set_quadrature("cell")
    assert e.value.code == dmi.ESTATE


def mittag_leffler_relaxation(t):
    """E_{3/2}(-t^{3/2}) by its power series in 40 digits."""
    with mp.workdps(40):
        z = -mp.mpf(t) ** 1.5
        return float(mp.nsum(lambda k: z ** k / mp.gamma(1.5 * k + 1), [0, mp.inf]))


def test_fractional_relaxation_converges():
    T = 2.0
    every = np.linspace(0, T, 11)
    ref = np.array([mittag_leffler_relaxation(t) for t in every])
    errors = []
    Ns = (50, 100, 200, 400)
    for N in Ns:
        s = dmi.Solver(1, T, N)  # memory tau = T: the whole past
        s.set_kernel(lambda x: np.array([[x ** -0.5 / math.sqrt(math.pi)]]))
        s.set_history(lambda t: np.array([1.0 if t == 0 else 0.0]))
        s.set_quadrature("cell")
        s.init()
        t, u = s.run(N)
        idx = np.rint(every / (T / N)).astype(int)
        errors.append(np.max(np.abs(u[idx, 0] - ref)))
    order = np.polyfit(np.log(np.array(Ns, float)), np.log(errors), 1)[0]
    assert -order >= 0.9, errors
    assert errors[-1] <= 5e-3


def relaxation(N, T, *, fit=None, method="auto"):
    """u' + int_0^t s^-1/2 / Gamma(1/2) u(t - s) ds = 0, u(0) = 1, tau = T: the cell rule with the exact
    kernel (fit None) or the fitted sum and exact near cells."""
    c = 1 / math.sqrt(math.pi)
    s = dmi.Solver(1, T, N)
    s.set_history(lambda t: np.array([1.0 if t == 0 else 0.0]))
    s.set_quadrature("cell")
    if fit is None:
        s.set_kernel(lambda x: np.array([[c * x ** -0.5]]))
    else:
        s.set_kernel_fit(fit)
    s.set_convolution(method)
    s.init()
    return s.run(N)[1][:, 0]


@pytest.mark.parametrize("N", [200, 1000])
def test_fitted_singular_kernel_within_the_solution_bound(N):
    T = 2.0
    h = T / N
    f = kernels.fit(kernels.PowerKernel(0.5, 1 / math.sqrt(math.pi)), T, tol=1e-8, relative=True, delta=h)
    exact = relaxation(N, T)
    fitted = relaxation(N, T, fit=f)  # AUTO: the recursion and the near cell
    assert np.max(np.abs(relaxation(N, T, fit=f, method="direct") - fitted)) <= 1e-13
    bound = f.solution_bound(T, 0.0, float(np.max(np.abs(fitted))), h=h)
    assert bound < 1e-7  # informative at T = 2
    assert np.max(np.abs(fitted - exact)) <= bound


def test_set_kernel_fit_entries():
    f = kernels.fit(lambda x: np.exp(-x) * np.cos(3 * x), 1.0, tol=1e-10)
    s = dmi.Solver(2, 1.0, 20)
    with pytest.raises(dmi.InvalidArgument):
        s.set_kernel_fit(f)  # a scalar fit needs an entry when n = 2
    with pytest.raises(dmi.InvalidArgument):
        s.set_kernel_fit(f, entry=(2, 0))
    s.set_kernel_fit(f, entry=(1, 0))
    s.set_history(lambda t: np.array([1.0, 1.0]))
    s.set_quadrature("cell")
    s.init()
    s.step()
    W, _ = s.step_terms()
    # entry (1, 0) alone: W = (0, int_0^1 e^{-s} cos 3s ds) with the constant history
    ref = (1 - math.exp(-1) * (math.cos(3) - 3 * math.sin(3))) / 10
    assert W[0] == 0 and W[1] == pytest.approx(ref, rel=1e-9)
    singular = kernels.fit(lambda x: x ** -0.5, 1.0, tol=1e-6, relative=True, delta=0.1)
    with pytest.raises(dmi.InvalidArgument, match="near"):
        dmi.Solver(1, 1.0, 20).set_kernel_fit(singular)  # no exact kernel for the near cells


def test_set_kernel_fit_refused_near_kernel_leaves_the_kernel():
    # the near cells are set first: a near kernel refused (a C kernel for one entry of an n = 2
    # solver) leaves the solver's former kernel, whose run is then bitwise a fresh solver's
    singular = kernels.fit(lambda x: x ** -0.5, 1.0, tol=1e-6, relative=True, delta=0.1)
    C_kernel = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_double, ctypes.c_void_p,
                                ctypes.c_void_p)(lambda s, out, user: 0)

    def fresh() -> dmi.Solver:
        s = dmi.Solver(2, 1.0, 20)
        s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [0.5, 0.0]]])
        s.set_history(lambda t: np.array([1.0, 0.5]))
        return s
    s = fresh()
    with pytest.raises(dmi.InvalidArgument, match="Python function"):
        s.set_kernel_fit(singular, entry=(1, 0), near=C_kernel)
    ref = fresh()
    for x in (s, ref):
        x.init()
        x.advance(30)
    assert np.array_equal(s.get_window(), ref.get_window())
