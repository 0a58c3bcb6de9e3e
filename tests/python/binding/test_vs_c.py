# The binding against the C library's own results (binding_ref.c, run as a
# program): the box operator, the exponential kernel, method switching and
# save/load on the paper's oscillator at N = 500.  With the C callbacks of
# examples/paper.c handed over as ctypes function pointers or as a
# scipy.LowLevelCallable, the trajectories and the saved bytes must be bitwise
# the C program's; with a numba cfunc right-hand side, within 1e-13.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes
import math

import numpy as np
import pytest
from models.paper import c_reference, numba_callbacks

import dmi

N = 500
EXP43 = dict(a=[0.0, 0.0, 0.0], b=[2 * math.pi, 10 * math.pi, 20 * math.pi],
             C=[[[0, 0], [1, 0]]] * 3)  # Example 4.3's kernel, each term in the entry (1, 0)


class PaperExample(ctypes.Structure):  # paper_example of examples/paper.h
    _fields_ = [("example", ctypes.c_int)]


def rows(lines: list[str]) -> np.ndarray:
    """The "p w v" lines as an array."""
    return np.array([[float(x) for x in line.split()] for line in lines])


def solver(testlib, rhs: str, exp_kernel: bool) -> dmi.Solver:
    """Example 4.3 at h = 1/500 as binding_ref.c's make(): the rhs given as "ctypes" (paper_rhs),
    "lowlevel" (paper_rhs as a scipy.LowLevelCallable) or "numba"; the kernel and history as
    ctypes pointers to paper_kernel and paper_history; friction alpha = (0, 1)."""
    ex = PaperExample(43)
    s = dmi.Solver(2, 1.0, N)
    c_rhs = dmi.RhsFn(("paper_rhs", testlib))
    if rhs == "ctypes":
        s.set_rhs(c_rhs, ex)
    elif rhs == "lowlevel":
        scipy = pytest.importorskip("scipy")
        s.set_rhs(scipy.LowLevelCallable(c_rhs, ctypes.cast(ctypes.pointer(ex), ctypes.c_void_p)))
    else:
        s.set_rhs(numba_callbacks(43)[0])
    s.set_kernel(dmi.KernelFn(("paper_kernel", testlib)), ex)
    s.set_history(dmi.HistoryFn(("paper_history", testlib)), ex)
    s.set_friction([0.0, 1.0])
    if exp_kernel:
        s.set_kernel_exp(**EXP43)
        s.set_convolution("recursive")
    return s


def recorded(s: dmi.Solver, steps: int) -> np.ndarray:
    """Rows (p, w, v) after every 50th of the next steps, as binding_ref prints them."""
    p0 = s.step_index
    t, U = s.run(steps, stride=50)
    p = p0 + np.arange(len(t)) * 50
    assert np.array_equal(t, p * (1.0 / N))
    return np.column_stack([p, U])[1:]


def check(got: np.ndarray, want: np.ndarray, rhs: str) -> None:
    assert got.shape == want.shape and len(want) >= 5
    assert np.array_equal(got[:, 0], want[:, 0])
    dev = np.abs(got - want).max()
    print(f"rhs {rhs}: max deviation from the C program {dev:.3e} over {len(want)} rows")
    assert np.abs(want[:, 1:]).max() > 1e-3  # not two zero solutions
    if rhs == "numba":
        assert dev <= 1e-13
    else:
        assert np.array_equal(got, want)


RHS = ["ctypes", "lowlevel", "numba"]


@pytest.mark.parametrize("rhs", RHS)
def test_box(testlib, rhs):
    want = rows(c_reference("box"))
    s = solver(testlib, rhs, False)
    s.set_box([-0.01, -0.05], [0.01, 0.05])
    s.init()
    got = recorded(s, 3000)
    check(got, want, rhs)
    assert np.abs(got[:, 1]).max() <= 0.01 and (np.abs(got[:, 2]) == 0.05).sum() >= 10  # v at the box


@pytest.mark.parametrize("rhs", RHS)
def test_exponential_kernel(testlib, rhs):
    want = rows(c_reference("exp"))
    s = solver(testlib, rhs, True)
    s.init()
    check(recorded(s, 3000), want, rhs)


@pytest.mark.parametrize("rhs", RHS)
def test_method_switching(testlib, rhs):
    want = rows(c_reference("switch"))
    s = solver(testlib, rhs, True)
    s.init()
    got = []
    for method in ["direct", "fft", "recursive", "auto", "direct", "recursive"]:
        s.set_convolution(method)
        got.append(recorded(s, 250))
    check(np.concatenate(got), want, rhs)


@pytest.mark.parametrize("rhs", ["ctypes", "numba"])
def test_save_load(testlib, rhs):
    lines = c_reference("save")
    k = next(i for i, line in enumerate(lines) if line.startswith("state "))
    c_state = bytes.fromhex(lines[k].split()[1])
    j = lines.index("loaded")
    s = solver(testlib, rhs, True)
    s.init()
    s.advance(700)
    saved = s.save_state()
    if rhs == "ctypes":
        assert saved == c_state  # the same bytes as the C program's solver
    check(recorded(s, 300), rows(lines[k + 1:j]), rhs)
    t = solver(testlib, rhs, True)
    t.init()
    t.load_state(c_state)
    assert t.step_index == 700
    check(recorded(t, 300), rows(lines[j + 1:]), rhs)
