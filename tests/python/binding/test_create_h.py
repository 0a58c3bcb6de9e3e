# Solver(n, tau, h=...) (dmi_create_h, libdmi 1.2): a step that need not divide tau.  The delay
# term of a step is checked against the quadrature of include/dmi.h computed here with NumPy from
# the window; h = tau / N gives Solver(n, tau, N) bitwise; the errors of the new argument.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi

A = np.array([-0.5, 0.0])
B = np.array([0.0, 2.0])
C = np.array([[[0.0, 0.0], [1.0, 0.0]], [[0.0, 0.3], [0.5, 0.0]]])


def H(s: float) -> np.ndarray:
    """The kernel of set_kernel_exp(A, B, C), written out."""
    return sum(math.exp(A[k] * s) * math.cos(B[k] * s) * C[k] for k in range(2))


def model(tau: float, method: str = "auto", kernel: str = "exp", **size) -> dmi.Solver:
    s = dmi.Solver(2, tau, **size)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] + math.cos(3 * t)]))
    s.set_friction([0.0, 0.4])
    if kernel == "exp":
        s.set_kernel_exp(A, B, C)
    else:
        s.set_kernel(H)
    s.set_history(lambda t: np.array([math.cos(t), -math.sin(t)]))
    s.set_convolution(method)
    s.init()
    return s


def test_sizes():
    s = dmi.Solver(2, 1.0, h=1 / 40.37)
    assert (s.N, s.h, s.tau) == (41, 1 / 40.37, 1.0)
    assert repr(s) == f"dmi.Solver(n=2, tau=1.0, h={1 / 40.37!r})"
    assert dmi.Solver(2, 1.0, h=1 / 41).N == 41
    assert dmi.Solver(2, 0.5, h=2.0).N == 1          # h > tau: one cell, weight tau
    assert dmi.Solver(2, 1.0, 7).N == 7 and dmi.Solver(2, 1.0, N=7).h == 1 / 7


@pytest.mark.parametrize("tau, N", [(1.0, 3), (0.7, 10), (3.3, 49), (1.0, 383)])
@pytest.mark.parametrize("method", ["direct", "fft", "recursive", "auto"])
def test_h_tau_over_N_is_dmi_create(tau, N, method):
    a = model(tau, method, N=N)
    b = model(tau, method, h=tau / N)
    assert b.N == N
    a.advance(5 * N + 3)
    b.advance(5 * N + 3)
    assert a.save_state() == b.save_state()
    assert np.array_equal(a.get_window(), b.get_window())


@pytest.mark.parametrize("tau, h", [(1.0, 1 / 40.37), (2.0, 0.3), (0.6, 1.5)])
@pytest.mark.parametrize("kernel", ["exp", "callback"])
def test_step_is_the_quadrature(tau, h, kernel):
    """W^p = h sum_{l<N-1} H(l h) U^{p-l} + (tau - (N-1) h) H((N-1) h) U^{p-N+1}."""
    s = model(tau, "direct", kernel, h=h)
    N = s.N
    assert N == math.ceil(tau / h)
    weights = np.full(N, h)
    weights[-1] = tau - (N - 1) * h
    assert 0 < weights[-1] < h
    samples = np.array([H(l * h) for l in range(N)])
    for _ in range(3 * N + 5):
        U = s.get_window()                     # rows U^{p-N} .. U^p
        s.step()
        W, _ = s.step_terms()
        expected = sum(weights[l] * samples[l] @ U[N - l] for l in range(N))
        assert np.allclose(W, expected, rtol=1e-13, atol=1e-15), (W, expected)


def test_methods_agree():
    runs = {m: model(1.0, m, h=1 / 300.61) for m in ("direct", "fft", "recursive")}
    for s in runs.values():
        s.advance(1500)
    u = {m: s.state for m, s in runs.items()}
    assert np.max(np.abs(u["fft"] - u["direct"])) <= 1e-12
    assert np.max(np.abs(u["recursive"] - u["direct"])) <= 1e-12
    assert np.max(np.abs(u["direct"])) > 1e-2


def test_state_records_h():
    a, same, other = (model(1.0, h=h) for h in (1 / 40.37, 1 / 40.37, 1 / 40.5))
    plain = model(1.0, N=41)
    a.advance(60)
    same.load_state(a.save_state())
    assert same.save_state() == a.save_state()
    for b in (other, plain):
        before = b.save_state()
        with pytest.raises(dmi.InvalidArgument, match="h = "):
            b.load_state(a.save_state())
        assert b.save_state() == before


@pytest.mark.parametrize("size, message", [
    ({}, "exactly one of N and h"),
    ({"N": 10, "h": 0.1}, "exactly one of N and h"),
    ({"h": 0.0}, "h = 0.0: must be finite and > 0"),
    ({"h": -1.0}, "must be finite and > 0"),
    ({"h": float("nan")}, "must be finite and > 0"),
    ({"h": float("inf")}, "must be finite and > 0"),
    ({"h": "x"}, "is not a number"),
    ({"h": 1e-310}, "dmi_create_h"),             # subnormal: the library refuses it
])
def test_bad_h(size, message):
    with pytest.raises(dmi.InvalidArgument, match=message):
        dmi.Solver(2, 1.0, **size)


def test_too_many_cells():
    with pytest.raises(dmi.Error, match="dmi_create_h") as e:
        dmi.Solver(2, 1.0, h=1e-300)
    assert e.value.code == dmi.ENOMEM
