# jit=True of Solver.set_rhs, set_resolvent, set_kernel and set_history: plain Python functions
# compiled by numba into libdmi's C callbacks.  The compiled callbacks give the Python callbacks'
# results (Example 4.3 with a kernel and a history callback; the two-mass chain of the Python
# examples, its rhs closing over a parameter array, with a resolvent written in Python); a
# closure's values are read at run time, not frozen; make(p) called 1000 times compiles once and
# each p keeps its own value (against the scheme's closed form); numba's refusal names the
# line; bad results and bad calls are refused; a chart on a process pool and on Dask works with
# a jit=True model.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import functools
import inspect
import math

import numpy as np
import pytest

import dmi
from dmi import _jit, analysis

# ---- Example 4.3: u = (w, v), f = (-v, w + 1.3 cos 8t), friction on v, H in entry (1, 0) -------

def ex43_rhs(t, u):
    return np.array([-u[1], u[0] + 1.3 * math.cos(8.0 * t)])


def ex43_kernel(s):
    H = np.zeros((2, 2))
    H[1, 0] = math.cos(2 * math.pi * s) + math.cos(10 * math.pi * s) + math.cos(20 * math.pi * s)
    return H


def ex43_history(t):
    return np.array([0.1 * t, 0.2 + 0.05 * math.sin(3.0 * t)])


def ex43(jit: bool, N: int = 500, steps: int = 2000) -> np.ndarray:
    s = dmi.Solver(2, 1.0, N)
    s.set_rhs(ex43_rhs, jit=jit)
    s.set_kernel(ex43_kernel, jit=jit)
    s.set_history(ex43_history, jit=jit)
    s.set_friction([0.0, 1.0])
    s.init()
    _, U = s.run(steps)
    s.close()
    return U


def test_example_43_equals_the_python_callbacks():
    py, jit = ex43(False), ex43(True)
    assert np.max(np.abs(py)) > 0.1  # the run moves
    assert np.max(np.abs(jit - py)) <= 1e-13 * np.max(np.abs(py))


# ---- the two-mass chain (python/examples/two_mass_chain.py's model) ----------------------------

K1, K2, M1, M2, MU, FORCE, OMEGA = 1.0, 0.8, 1.0, 0.5, (0.12, 0.1), 0.3, 1.2
G, THETA, TAU = (0.4, 0.2), (0.1, 0.5), 2.0


def chain_rhs(p):
    """f(t, u) closing over the parameter array p = (k1, k2, m1, m2, force, omega)."""
    def rhs(t, u):
        k1, k2, m1, m2, force, omega = p[0], p[1], p[2], p[3], p[4], p[5]
        return np.array([-u[2], -u[3], ((k1 + k2) * u[0] - k2 * u[1]) / m1,
                         (-k2 * u[0] + k2 * u[1] - force * np.cos(omega * t)) / m2])
    return rhs


def chain_friction(mu):
    """The friction's resolvent written in Python: soft thresholding of x by lam mu."""
    def r(lam, x):
        out = x.copy()
        for i in range(x.shape[0]):
            a = lam * mu[i]
            out[i] = x[i] - a if x[i] > a else x[i] + a if x[i] < -a else 0.0
        return out
    return r


def chain(jit: bool, p: np.ndarray, change: np.ndarray | None = None) -> np.ndarray:
    """The chain from rest over 3000 steps of h = 2 / 1000; with change, p becomes it after
    1500 steps (the callbacks are not set again)."""
    s = dmi.Solver(4, TAU, 1000)
    s.set_rhs(chain_rhs(p), jit=jit)
    s.set_resolvent(chain_friction(np.array([0.0, 0.0, MU[0] / M1, MU[1] / M2])), jit=jit)
    a = -1.0 / np.array(THETA)
    C = np.zeros((2, 4, 4))
    for k, g in enumerate(G):
        C[k, 2:, :2] = g * np.array([[K1 + K2, -K2], [-K2, K2]]) / np.array([[M1], [M2]])
    s.set_kernel_exp(a, np.zeros(2), C)
    s.init()
    _, U1 = s.run(1500)
    if change is not None:
        p[:] = change
    _, U2 = s.run(1500)
    s.close()
    return np.vstack([U1, U2[1:]])


def test_two_mass_chain_equals_the_python_callbacks():
    p = np.array([K1, K2, M1, M2, FORCE, OMEGA])
    py, jit = chain(False, p.copy()), chain(True, p.copy())
    assert np.mean(py[1:, 2] == 0) > 0.05  # mass 1 sticks at times: the resolvent acts
    assert np.max(np.abs(jit - py)) <= 1e-13 * np.max(np.abs(py))


def test_closure_array_is_read_at_run_time():
    """The parameter array changed in place halfway: the compiled rhs sees the new force, as
    the Python one does (a frozen copy would keep the old one)."""
    p = np.array([K1, K2, M1, M2, FORCE, OMEGA])
    new = np.array([K1, K2, M1, M2, 3 * FORCE, OMEGA])
    py, jit = chain(False, p.copy(), new), chain(True, p.copy(), new)
    same = chain(True, p.copy())
    assert np.max(np.abs(jit - py)) <= 1e-13 * np.max(np.abs(py))
    assert np.max(np.abs(jit[-1] - same[-1])) > 1e-3  # the change matters


# ---- make(p): compiled once, each p its own ----------------------------------------------------

def make(b: float):
    return lambda t, u: np.array([b * u[0]])


def test_make_in_a_loop_compiles_once_and_keeps_each_p():
    """u' + b u = 0 from U^0 = 1: the scheme's U^k = (1 - h b)^k exactly (f is explicit)."""
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    s.set_rhs(make(0.5), jit=True)  # compiled here, or earlier in this process
    before = _jit.compilations()
    bs = np.linspace(-2.0, 3.0, 1000)
    for b in bs:
        s.set_rhs(make(b), jit=True)
    assert _jit.compilations() == before  # 1000 closures, no compilation
    for b in (bs[0], bs[317], bs[-1]):
        s.set_rhs(make(b), jit=True)
        s.init()
        s.advance(50)
        assert s.state[0] == pytest.approx((1 - s.h * b) ** 50, rel=1e-13)
    s.set_rhs(make(2), jit=True)  # an int closure: a new type, one compilation more
    assert _jit.compilations() == before + 1
    s.close()


def test_compilation_count_sees_a_new_function():
    before = _jit.compilations()
    s = dmi.Solver(1, 1.0, 10)
    s.set_rhs(lambda t, u: np.array([0.25 * u[0] + 1.0]), jit=True)
    assert _jit.compilations() == before + 1
    s.close()



def test_code_analysis_is_shared_but_closure_values_are_read_per_call(monkeypatch):
    """The bytecode analysis is kept per code object (one entry for 200 closures of one lambda);
    the closure's values are still read at each set_rhs and init: a cell rebound between two
    init() calls gives the scheme's closed form with the new value, not the cached one's."""
    def damped(b: float):
        def f(t, u):
            return np.array([b * u[0]])

        def rebind(v: float) -> None:
            nonlocal b
            b = v
        return f, rebind
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    read = []                    # the code objects whose bytecode is read
    real = _jit._loaded_globals
    monkeypatch.setattr(_jit, "_loaded_globals", lambda code: read.append(code) or real(code))
    fns = [damped(b) for b in np.linspace(0.1, 2.0, 200)]
    for f, _ in fns:
        s.set_rhs(f, jit=True)
    f, rebind = fns[0]
    assert read.count(f.__code__) == 1
    s.set_rhs(f, jit=True)
    s.init()
    s.advance(40)
    assert s.state[0] == pytest.approx((1 - s.h * 0.1) ** 40, rel=1e-13)
    rebind(1.7)
    s.init()
    s.advance(40)
    assert s.state[0] == pytest.approx((1 - s.h * 1.7) ** 40, rel=1e-13)
    s.close()

# ---- errors ------------------------------------------------------------------------------------

def refused(t, u):
    x = u[0] + 1.0
    return np.array([x.no_such_attribute, 0.0])  # numba refuses this line


def test_numba_refusal_names_the_line():
    s = dmi.Solver(2, 1.0, 10)
    lines, first = inspect.getsourcelines(refused)
    line = first + next(i for i, x in enumerate(lines) if "no_such_attribute" in x)
    with pytest.raises(dmi.InvalidArgument) as e:
        s.set_rhs(refused, jit=True)
    text = str(e.value)
    assert f"{__file__}, line {line}:" in text and "no_such_attribute" in text
    assert "numba cannot compile refused" in text
    s.set_rhs(ex43_rhs)  # the solver is usable: the former callback was kept
    s.close()


def test_unknown_name_is_located():
    s = dmi.Solver(1, 1.0, 10)
    line = inspect.currentframe().f_lineno + 1
    f = lambda t, u: np.array([no_such_function(u[0])])  # noqa: E731, F821
    with pytest.raises(dmi.InvalidArgument, match=rf"line {line}: f = lambda"):
        s.set_rhs(f, jit=True)
    s.close()


def test_bad_results_and_calls():
    s = dmi.Solver(2, 1.0, 10)
    s.set_rhs(lambda t, u: np.array([1.0, 2.0, 3.0]), jit=True)
    s.init()
    with pytest.raises(dmi.Error, match=r"rhs callback returned 2 .*shape"):
        s.step()
    assert s.step_index == 0
    with pytest.raises(dmi.InvalidArgument, match="takes no user pointer"):
        s.set_rhs(ex43_rhs, np.zeros(2), jit=True)
    with pytest.raises(dmi.InvalidArgument, match="compiles a Python function"):
        s.set_rhs(np.sin, jit=True)
    table = {"k": 1.0}
    with pytest.raises(dmi.InvalidArgument, match="the closure's table is a dict"):
        s.set_rhs(lambda t, u: np.array([table["k"], 0.0]), jit=True)
    with pytest.raises(dmi.InvalidArgument, match="function of 2 argument"):
        s.set_rhs(lambda t: np.zeros(2), jit=True)
    s.close()


# ---- a chart on a process pool and on Dask -----------------------------------------------------

def oscillator(a: float, c: float, jit: bool = True, N: int = 60) -> dmi.Solver:
    """test_analysis_chart's oscillator with its rhs compiled (jit=True) or in Python."""
    s = dmi.Solver(2, 2.0, N)
    s.set_rhs(lambda t, u: np.array([-u[1], c * u[1] + u[0]]), jit=jit)
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [a, 0.0]]])
    return s


GAINS, DAMPINGS = np.linspace(0.0, 3.0, 4), np.array([0.3, 0.6])


@pytest.fixture(scope="module")
def python_chart():
    return analysis.stability_chart(functools.partial(oscillator, jit=False), GAINS, DAMPINGS,
                                    [0.0, 0.0], workers=1, trace=False)


def test_chart_on_a_process_pool(python_chart):
    chart = analysis.stability_chart(oscillator, GAINS, DAMPINGS, [0.0, 0.0], workers=2,
                                     trace=False)
    assert np.max(np.abs(chart.re - python_chart.re)) <= 1e-9
    assert np.max(np.abs(chart.im - python_chart.im)) <= 1e-9


def test_chart_on_dask(python_chart):
    import distributed   # (scripts/requirements.txt: installed by scripts/deps.sh, no skip)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        chart = analysis.stability_chart(oscillator, GAINS, DAMPINGS, [0.0, 0.0], client=client,
                                         trace=False)
    assert np.max(np.abs(chart.re - python_chart.re)) <= 1e-9
