# dmi.identify through the weights libdmi uses: near cells (set_kernel_fit with delta > 0), callback
# kernels under the cell rule, and a PowerKernel's c and beta through KernelFit.refit.  The tangent
# is checked against central differences of the scheme (Richardson-extrapolated), the near cells'
# weights against closed forms, and a fractional belt is identified from noisy records.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.special import gamma

import dmi
from dmi import kernels
from dmi.identify import sensitivities

TAU, H = 4.0, 0.02
BASE = kernels.fit(kernels.PowerKernel(0.5, 1.0), TAU, tol=1e-8, relative=True, delta=H)


def fractional(p, jit=False):
    """x'' + c D^(1-beta) x + k x = cos 1.3 t, u = (x, x'), the kernel c s^-beta / Gamma(beta)
    refitted from BASE with its first cell exact; p = (k, c, beta)."""
    k, c, beta = p
    s = dmi.Solver(2, TAU, h=H)
    s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] - math.cos(1.3 * t)]), jit=jit)
    s.set_quadrature("cell")
    s.set_kernel_fit(BASE.refit(kernels.PowerKernel(beta, c / gamma(beta))), entry=(1, 1))
    s.set_history(lambda t: np.array([1.0, 0.0]))
    return s


def central(make, p, j, steps, eps):
    """dU/dp_j of the scheme by central differences at eps and 2 eps, Richardson-extrapolated
    (error O(eps^4))."""
    def diff(e):
        runs = []
        for sign in (1, -1):
            q = np.array(p, float)
            q[j] += sign * e
            s = make(q)
            s.init()
            runs.append(s.run(steps)[1])
        return (runs[0] - runs[1]) / (2 * e)
    return (4 * diff(eps) - diff(2 * eps)) / 3


def relative_error(S, ref):
    return np.abs(S - ref).max() / np.abs(ref).max()


@pytest.mark.parametrize("engine", ["python", "compiled"])
def test_tangent_through_near_cells_in_k_c_beta(engine):
    if engine == "compiled" and importlib.util.find_spec("numba") is None:
        pytest.skip("numba is not installed")
    p = np.array([1.0, 0.3, 0.5])
    steps = 300
    sens = sensitivities(lambda q: fractional(q, jit=engine == "compiled"), p, steps, engine=engine)
    assert sens.engine == engine
    for j in range(3):
        ref = central(fractional, p, j, steps, 1e-3)
        assert np.abs(ref).max() > 0.1
        assert relative_error(sens.S[:, :, j], ref) < 1e-6, j


def test_tangent_through_a_callback_kernel_under_the_cell_rule():
    # H(s) = c e^{-a s} s^-1/2 on x' (a callback, integrated by libdmi's tanh-sinh rule), and a
    # parameter of f: p = (k, c, a)
    def make(p):
        k, c, a = p
        s = dmi.Solver(2, 2.0, 50)
        s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] - math.cos(1.3 * t)]))
        s.set_quadrature("cell")
        s.set_kernel(lambda x: np.array([[0.0, 0.0], [0.0, c * math.exp(-a * x) / math.sqrt(x)]]))
        s.set_history(lambda t: np.array([1.0, 0.0]))
        return s
    p = np.array([1.0, 0.3, 0.7])
    steps = 200
    sens = sensitivities(make, p, steps)
    for j in range(3):
        ref = central(make, p, j, steps, 1e-3)
        assert np.abs(ref).max() > 1e-3
        assert relative_error(sens.S[:, :, j], ref) < 1e-6, j


def test_near_cells_weights_follow_beta_in_closed_form():
    # the first cell's weight is int_0^h c s^-beta ds = c h^(1-beta) / (1-beta) and its
    # derivative in beta -int_0^h c s^-beta log s ds; libdmi's weights and their differences
    # against these closed forms
    def first(beta, c=0.7):
        s = dmi.Solver(1, TAU, h=H)
        s.set_quadrature("cell")
        s.set_kernel_fit(BASE.refit(kernels.PowerKernel(beta, c)))
        s.init()
        G, G_near = s.kernel_weights()
        return G[0, 0, 0], G_near[:, 0, 0]
    beta, c = 0.45, 0.7
    G0, near = first(beta)
    assert G0 == pytest.approx(c * H ** (1 - beta) / (1 - beta), rel=1e-10)
    assert near[0] != 0.0 and np.all(near[1:] == 0.0)          # one near cell (delta = h)
    e = 1e-5
    d = (first(beta + e)[0] - first(beta - e)[0]) / (2 * e)
    closed = c * H ** (1 - beta) * (1 / (1 - beta) ** 2 - math.log(H) / (1 - beta))
    assert d == pytest.approx(closed, rel=1e-8)


def test_refit_keeps_the_rates_and_is_linear():
    k = kernels.PowerKernel(0.4, 0.5)
    r = BASE.refit(k)
    assert r.method == "fixed" and np.array_equal(r.a, BASE.a) and r.kernel == k
    assert r.max_error < 1e-8                     # a power law on the same rates
    r2 = BASE.refit(kernels.PowerKernel(0.4, 1.0))
    assert np.allclose(r2.C, 2 * r.C, rtol=1e-12, atol=1e-12 * np.abs(r.C).max())
    # refit_derivative: the derivative in beta against central differences of refits
    dC, _ = r.refit_derivative(lambda s: -np.log(s) * k(s))
    e = 1e-4
    fd = (BASE.refit(kernels.PowerKernel(0.4 + e, 0.5)).C
          - BASE.refit(kernels.PowerKernel(0.4 - e, 0.5)).C) / (2 * e)
    assert np.abs(dC - fd).max() < 1e-5 * np.abs(dC).max()
    with pytest.raises(ValueError, match="refit"):
        BASE.refit_derivative(lambda s: k(s))


def test_a_fit_whose_rates_move_with_a_parameter_is_refused():
    # kernels.fit inside make chooses its rates for each beta: refused, naming refit
    def make(p):
        s = dmi.Solver(1, TAU, h=H)
        s.set_rhs(lambda t, u: np.array([u[0] - math.cos(t)]))
        s.set_quadrature("cell")
        s.set_kernel_fit(kernels.fit(kernels.PowerKernel(p[0], 1.0), TAU, tol=1e-6,
                                     relative=True, delta=H))
        return s
    with pytest.raises(ValueError, match="refit"):
        sensitivities(make, [0.5], 20)


def test_fractional_belt_identified_from_noisy_records():
    # mu, c_f and beta of a stick-slip belt with a fitted s^-1/2 memory (near cells): z-scores
    # of four seeds (bench/bench_identify_fractional.py at a small size)
    sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "bench"))
    try:
        import bench_identify_fractional as bench
    finally:
        sys.path.pop(0)
    zs = bench.study(tau=5.0, T=25.0, h=0.01, every=10, sigma=0.01, seeds=4)
    rms = math.sqrt(float(np.mean(zs ** 2)))
    assert 0.5 <= rms <= 1.6, zs
    assert np.abs(zs).max() <= 3.0, zs
