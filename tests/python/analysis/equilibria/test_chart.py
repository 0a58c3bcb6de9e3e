# Tests of dmi.analysis.stability_chart: the traced Hopf curves of an oscillator with an
# exponential memory kernel against its D-curves, from the characteristic equation at lambda = i w
# written here; the grid against roots(); the Dask path; bad input and no process left behind.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import functools
import multiprocessing
import threading

import numpy as np
import psutil
import pytest
import scipy.optimize

import dmi
from dmi import analysis

B, TAU, THETA = 1.0, 2.0, 1.0


def oscillator(a: float, c: float, N: int = 100) -> dmi.Solver:
    """w'' + c w' + b w + a int_0^tau G(s) w(t - s) ds = 0, G(s) = exp(-s / theta) / theta, as
    u = (w, w'), u' + (-w', c w' + b w) + int H u = 0, H(s) = [[0, 0], [a G(s), 0]]."""
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], c * u[1] + B * u[0]]))
    s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [a / THETA, 0.0]]])
    return s


def G_hat(lam: complex) -> complex:
    """int_0^tau G(s) e^{-lam s} ds."""
    return (1 - np.exp(-(lam + 1 / THETA) * TAU)) / (1 + THETA * lam)


def d_curve(w: float) -> tuple[float, float]:
    """(a, c) with -w^2 + i c w + b + a G_hat(i w) = 0: a from the real part, c from the
    imaginary part."""
    g = G_hat(1j * w)
    a = (w * w - B) / g.real
    return a, -a * g.imag / w


def d_curve_gain(c: float, w_guess: float) -> tuple[float, float]:
    """The D-curve's gain a at damping c (and its frequency), near w_guess."""
    w = scipy.optimize.brentq(lambda w: d_curve(w)[1] - c, 0.8 * w_guess, 1.25 * w_guess,
                              xtol=1e-14)
    return d_curve(w)[0], w


def companion_rightmost(a: float, c: float, N: int = 100) -> complex:
    """The rightmost root of the scheme, from the eigenvalues (numpy) of the block companion
    matrix of U^{p+1} = (I - h J) U^p - h^2 sum_{l<N} H(l h) U^{p-l}, J = [[0, -1], [b, c]],
    H(s) = [[0, 0], [a G(s), 0]]: state (U^p, ..., U^{p-N+1}); lambda = log(z) / h."""
    h, n = TAU / N, 2
    J = np.array([[0.0, -1.0], [B, c]])
    M = np.zeros((n * N, n * N))
    for l in range(N):
        M[1, l * n] = -h * h * a * np.exp(-l * h / THETA) / THETA
    M[:n, :n] += np.eye(n) - h * J
    M[n:, :-n] = np.eye(n * (N - 1))
    z = np.linalg.eigvals(M).astype(complex)
    z = z[np.abs(z) > 0]
    lam = np.log(z) / h
    return complex(lam[np.argmax(lam.real)])


def broken(a: float, c: float) -> dmi.Solver:
    if a > 1.0:
        raise ArithmeticError("a broken model")
    return oscillator(a, c)


GAINS = np.linspace(0.0, 3.0, 7)
DAMPINGS = np.linspace(0.3, 0.7, 5)


@pytest.fixture(scope="module")
def charts():
    return {N: analysis.stability_chart(functools.partial(oscillator, N=N), GAINS, DAMPINGS,
                                        [0.0, 0.0], workers=2) for N in (100, 200)}


def test_traced_hopf_curve_is_the_d_curve(charts):
    errors = {}
    for N, chart in charts.items():
        hopf = [c for c in chart.curves if c.is_hopf]
        assert len(hopf) == 1 and len(hopf[0].q) == len(DAMPINGS)   # one curve, every row
        cv = hopf[0]
        assert np.array_equal(cv.q, DAMPINGS)
        got = np.array([d_curve_gain(q, w) for q, w in zip(cv.q, cv.omega)])
        errors[N] = np.max(np.abs(cv.p - got[:, 0])), np.max(np.abs(cv.omega - got[:, 1]))
        h = TAU / N   # (the explicit f of the scheme: a shift of about 5 h in a at these c)
        assert errors[N][0] < 6 * h and errors[N][1] < h, (N, errors[N])
        # the curve separates stable from unstable on the grid: Re lambda_1 changes sign across it
        for j, q in enumerate(chart.q_values):
            i = np.searchsorted(GAINS, cv.p[j])
            assert chart.re[j, i - 1] < 0 < chart.re[j, i]
    # each traced point is the scheme's own crossing (not an interpolation of the grid): the
    # rightmost root of the companion matrix changes sign within 1e-7 of it, at frequency omega
    cv = [c for c in charts[100].curves if c.is_hopf][0]
    for j in (0, len(cv.q) - 1):
        left, right = (companion_rightmost(cv.p[j] + d, cv.q[j]) for d in (-1e-7, 1e-7))
        assert left.real < 0 < right.real, (left, right)
        assert abs(abs(left.imag) - cv.omega[j]) < 1e-6
    # first order in h: halving h halves the distance to the continuous D-curve
    assert 1.8 < errors[100][0] / errors[200][0] < 2.2, errors


def test_grid_is_the_rightmost_root(charts):
    # the oracle: the companion matrix's eigenvalues (numpy), not dmi.analysis.roots
    chart = charts[100]
    for j, i in [(0, 0), (2, 3), (4, 6), (1, 5)]:
        lam = companion_rightmost(GAINS[i], DAMPINGS[j])
        assert chart.re[j, i] == pytest.approx(lam.real, abs=1e-9)
        assert abs(chart.im[j, i]) == pytest.approx(abs(lam.imag), abs=1e-9)
        # the verified verdict (oscillator: n N = 200 values, the scheme's second eigen-solve)
        # says what the oracle says wherever the oracle's root is off the axis
        if abs(lam.real) > 1e-6:
            assert chart.verdict[j, i] is bool(lam.real < 0), chart.reason[j, i]
    # stable is the verdict True; a decided cell's verdict agrees with the sign of its root
    assert np.array_equal(chart.stable, chart.verdict == True)   # noqa: E712
    decided = ~chart.undecided
    assert np.array_equal(chart.stable[decided], (chart.re < 0)[decided])
    assert decided.all(), chart.reason[chart.undecided]   # no root near the axis on this grid


def test_one_start_per_chain_of_sign_changes():
    from dmi.analysis.equilibria.chart import _brackets
    re = np.ones((8, 12))
    re[:, :2] = -1                       # a vertical boundary between columns 1 and 2
    for j in range(6):                   # a diagonal one, one column further left each row
        re[j, 11 - j:] = -1
    starts = _brackets(re)
    assert len(starts) == 2
    assert sorted(i for _, i in starts)[0] == 1


def test_figure(charts, tmp_path):
    import matplotlib
    matplotlib.use("Agg")
    ax = analysis.plot_stability_chart(charts[100], p_label="delay gain a (1/s²)",
                                       q_label="damping c (1/s)")
    assert ax.get_xlabel() == "delay gain a (1/s²)" and ax.get_ylabel() == "damping c (1/s)"
    assert len(ax.lines) == len(charts[100].curves)
    ax.figure.savefig(tmp_path / "chart.png")
    assert (tmp_path / "chart.png").stat().st_size > 1000


def test_dask_client_gives_the_same_chart(charts):
    import distributed   # (scripts/requirements.txt: installed by scripts/deps.sh, no skip)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        chart = analysis.stability_chart(functools.partial(oscillator, N=100), GAINS, DAMPINGS,
                                         [0.0, 0.0], client=client, trace=False)
    assert np.array_equal(chart.re, charts[100].re) and chart.curves == []


def test_bad_input_and_no_process_left():
    me = psutil.Process()
    before = {t.ident for t in threading.enumerate()}
    children = set(me.children(recursive=True))   # (a resource tracker of an earlier test)
    with pytest.raises(ArithmeticError, match="broken"):
        analysis.stability_chart(broken, GAINS, DAMPINGS[:2], [0.0, 0.0], workers=2)
    with pytest.raises(TypeError, match="pickle"):
        analysis.stability_chart(lambda a, c: oscillator(a, c), GAINS, DAMPINGS, [0.0, 0.0])
    with pytest.raises(ValueError, match="p_values"):
        analysis.stability_chart(oscillator, [1.0], DAMPINGS, [0.0, 0.0])
    with pytest.raises(ValueError, match="not an equilibrium"):
        analysis.stability_chart(oscillator, GAINS[:2], DAMPINGS[:1], [1.0, 0.0], workers=1)
    assert multiprocessing.active_children() == [] and set(me.children(recursive=True)) <= children
    assert {t.ident for t in threading.enumerate()} <= before
