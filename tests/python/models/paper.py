# The paper's oscillator (4.1)-(4.3) and Examples 4.1-4.3 written again here from the paper (not
# taken from the code under test), as Python callbacks and as numba cfuncs, a solver of each
# example, and the lines of the C library's own run (binding_ref): shared by the binding's tests.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import functools
import os
import subprocess

import numpy as np
import pytest

import dmi

PI = np.pi


# ---- Examples 4.1-4.3 (b = alpha = tau = 1): forcing g, kernel H, exact w and w' --------------
def g41(t):  # (4.7): a jump at t = 2
    side = -1.0 if t < 2 else (1.0 if t > 2 else 0.0)
    return (-t + 4) * np.exp(-t) + (-t + 1) * np.exp(-t + 1) + side


def g42(t):  # (4.9): +1 before 1, -1 on ]1, 2[, +1 after 2, 0 at the switches
    base = (-t * t + 7 * t - 4) * np.exp(-t) + (-t * t + t - 2) * np.exp(-t + 1)
    if t < 1:
        return base + 1
    if t == 1 or t == 2:
        return base
    return base - 1 if t < 2 else base + 1


def g43(t):
    return 1.3 * np.cos(8 * t)


def H1(s):
    return 1.0


def H43(s):
    return np.cos(2 * PI * s) + np.cos(10 * PI * s) + np.cos(20 * PI * s)


def w41(t):  # (4.8)
    return (t - 1) * np.exp(-t)


def v41(t):
    return (2 - t) * np.exp(-t)


def w42(t):  # (4.10)
    return (t * t - t + 1) * np.exp(-t)


def v42(t):
    return (-t * t + 3 * t - 2) * np.exp(-t)


def zero(t):
    return 0.0


MODEL = {41: (g41, H1, w41, v41), 42: (g42, H1, w42, v42), 43: (g43, H43, zero, zero)}


def python_callbacks(example: int):
    """(rhs, kernel, history) of the oscillator in first-order form (4.3) as Python functions:
    u = (w, v), f = (-v, w + g(t)), kernel [[0, 0], [H, 0]], z = (w, w') exact (0 for 4.3)."""
    g, H, w, v = MODEL[example]

    def rhs(t, u):
        return np.array([-u[1], u[0] + g(t)])

    def kernel(s):
        return np.array([[0.0, 0.0], [H(s), 0.0]])

    def history(t):
        return np.array([w(t), v(t)])

    return rhs, kernel, history


@functools.cache
def numba_callbacks(example: int):
    """The same as numba cfuncs with libdmi's C signatures."""
    numba = pytest.importorskip("numba")
    g, H, w, v = (numba.njit(f) for f in MODEL[example])

    @numba.cfunc(dmi.RHS_SIGNATURE)
    def rhs(t, u, out, user):
        out[0] = -u[1]
        out[1] = u[0] + g(t)
        return 0

    @numba.cfunc(dmi.KERNEL_SIGNATURE)
    def kernel(s, out, user):
        out[2] = H(s)
        return 0

    @numba.cfunc(dmi.HISTORY_SIGNATURE)
    def history(t, out, user):
        out[0] = w(t)
        out[1] = v(t)
        return 0

    return rhs, kernel, history


def paper_solver(example: int, N: int, kind: str) -> dmi.Solver:
    """Example 4.x with h = 1/N and callbacks of the kind "python" or "numba", initialised."""
    rhs, kernel, history = (python_callbacks if kind == "python" else numba_callbacks)(example)
    s = dmi.Solver(2, 1.0, N)
    s.set_rhs(rhs)
    s.set_kernel(kernel)
    s.set_history(history)
    s.set_friction([0.0, 1.0])
    s.init()
    return s


def c_reference(scenario: str) -> list[str]:
    """The lines printed by binding_ref <scenario> (the C library's own run)."""
    prog = os.environ.get("DMI_BINDING_REF")
    if not prog:
        pytest.skip("DMI_BINDING_REF not set (ctest sets it)")
    r = subprocess.run([prog, scenario], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()
