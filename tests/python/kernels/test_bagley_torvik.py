# The Bagley-Torvik oscillator without friction, w'' + c D^{1/2} w + k w = 0, w(0) = w0, w'(0) = 0,
# D^{1/2} the Caputo derivative: as u = (w, v), u' + f(u) + int_0^tau H(s) u(t - s) ds = 0 with
# f = (-v, k w), H = [[0, 0], [0, c s^-1/2 / Gamma(1/2)]], v = 0 on the history and tau >= the run,
# so that the delay integral is c (s^-1/2 / Gamma(1/2) * w')(t), the Caputo term.  Its Laplace
# transform (below) inverted by mpmath's Talbot method is the reference; the scheme with exact cell
# weights converges to it at order >= 0.9, with the exact kernel (DIRECT) and with the fitted kernel
# in O(1) (the recursion, the near cells exact).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math

import mpmath as mp
import numpy as np
import pytest

import dmi
from dmi import kernels

CD, K, W0 = 0.5, 1.0, 1.0      # c, k, w(0)
TAU = 4.0                      # the memory = the run's length
TIMES = [1.0, 2.0, 3.0, 4.0]   # the grid points compared (multiples of every h below)
NS = [40, 80, 160, 320, 640]   # h = tau / N


def laplace(s):
    """W(s) = L[w](s).  L[w''] = s^2 W - s w0 - w'(0), L[D^{1/2} w] = s^{1/2} W - s^{-1/2} w0
    (the Caputo derivative's initial term), w'(0) = 0: (s^2 + c s^{1/2} + k) W = w0 (s + c s^{-1/2})."""
    return W0 * (s + CD / mp.sqrt(s)) / (s * s + CD * mp.sqrt(s) + K)


@pytest.fixture(scope="module")
def reference():
    mp.mp.dps = 30
    talbot = [float(mp.invertlaplace(laplace, t, method="talbot")) for t in TIMES]
    # the oracle against a second inversion (de Hoog's), and the initial data by the initial value
    # theorem: w(0) = lim s W(s) = w0, w'(0) = lim s (s W(s) - w0) = 0
    hoog = [float(mp.invertlaplace(laplace, t, method="dehoog")) for t in TIMES]
    assert np.max(np.abs(np.subtract(talbot, hoog))) < 1e-9, (talbot, hoog)
    big = mp.mpf(10) ** 20
    assert abs(big * laplace(big) - W0) < 1e-12 and abs(big * (big * laplace(big) - W0)) < 1e-6
    return np.array(talbot)


def kernel(s):
    out = np.zeros((2, 2))
    out[1, 1] = CD / math.sqrt(math.pi * s)
    return out


def run(N, fit=None):
    """w at TIMES by the scheme with exact cell weights: the exact kernel by DIRECT, or the fit."""
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], K * u[0]]))
    s.set_history(lambda t: np.array([W0, 0.0]))
    s.set_quadrature("cell")
    if fit is None:
        s.set_kernel(kernel)
        s.set_convolution("direct")
    else:
        s.set_kernel_fit(fit, entry=(1, 1))
        s.set_convolution("recursive")
    s.init()
    t, U = s.run(N)
    q = N // 4  # TIMES[i] = t_{(i + 1) q}
    assert np.allclose(t[q::q], TIMES, rtol=0, atol=1e-12)
    return U[q::q, 0]


@pytest.mark.parametrize("path", ["exact", "fitted"])
def test_converges_to_the_inverse_laplace_transform(reference, path):
    fit = None
    if path == "fitted":  # one fit on [h_min, tau] serves every coarser h (more near cells)
        fit = kernels.fit(kernels.PowerKernel(0.5, CD / math.sqrt(math.pi)), TAU, tol=1e-10,
                          relative=True, delta=TAU / NS[-1])
        assert fit.kernel is not None and np.all(fit.a <= 0)
    errors = []
    for N in NS:
        errors.append(np.max(np.abs(run(N, fit) - reference)))
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert errors[-1] < 1e-2, errors
    assert np.all(orders >= 0.9), (errors, orders)
