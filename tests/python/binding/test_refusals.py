# What the binding refuses or warns of instead of answering silently: a singularity exponent
# declared with set_quadrature("cell", singularity=...) is checked by init against the kernel's
# log-log slope near 0 (1/s declared 0.99 and s^-0.99 declared 0.5 refused, naming the call and
# the exponent measured, after a few kernel calls; an exponent larger than the kernel's warned
# of, the weights right); set_quadrature after init names itself and says to call it before
# init; a closure variable or global of a jit=True f rebound after init is warned of at the next
# advance / step / run, naming it, and init (or set_rhs again) takes the new value, as the
# Python callback reads it; no warning where nothing diverges (an array changed in place, a
# number rebound to the same value, a jit=True kernel, which init alone calls).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import sys
import warnings

import numpy as np
import pytest

import dmi
from models.cell_rule import first_step

# ---- the declared singularity exponent ---------------------------------------------------------


def counted(beta: float) -> tuple[list[int], object]:
    """H(s) = s^-beta (1/s for beta = 1) and the list counting its calls."""
    calls = [0]

    def H(s: float) -> np.ndarray:
        calls[0] += 1
        return np.array([[1.0 / s if beta == 1 else s ** -beta]])
    return calls, H


@pytest.mark.parametrize("beta, declared, words", [
    (1.0, 0.99, ("set_quadrature('cell', singularity=0.99)", "s^-1 ", "not integrable")),
    (1.0, 0.999, ("set_quadrature('cell', singularity=0.999)", "s^-1 ", "not integrable")),
    (0.99, 0.5, ("set_quadrature('cell', singularity=0.5)", "s^-0.99 ",
                 "set_quadrature('cell', singularity=0.99), or singularity=None")),
])
def test_kernel_steeper_than_declared_is_refused_naming_the_call(beta, declared, words):
    calls, H = counted(beta)
    with pytest.raises(dmi.InvalidArgument) as e:
        first_step(H, declared)
    assert e.value.code == dmi.EINVAL
    for w in words:
        assert w in e.value.message, e.value.message
    assert "dmi_set_kernel_singularity" not in e.value.message   # (the C call the user did not make)
    assert calls[0] <= 40          # refused from the samples near 0, before any cell's quadrature


def test_divergent_kernel_declared_within_rounding_of_its_slope_is_refused():
    # 1/s declared just below 1, as close as the slope measured near 0 (its rounding): the
    # integral diverges whatever is declared, so no finite U^1 may come out
    for declared in (0.9999995, 0.9999999999999447):
        with pytest.raises(dmi.InvalidArgument) as e:
            first_step(lambda s: np.array([[1.0 / s]]), declared)
        assert "not integrable" in e.value.message, e.value.message
    # s^-0.9999995 declared so is integrable: 1 - h int_0^1 s^-beta ds = 1 - (1/8) / (1 - beta)
    beta = 0.9999995
    got = first_step(lambda s: np.array([[s ** -beta]]), beta)
    assert got == pytest.approx(1 - 0.125 / (1 - beta), rel=1e-6)


def test_declared_larger_than_the_kernels_warns_and_integrates():
    _, H = counted(0.5)
    with pytest.warns(UserWarning, match=r"larger than needed") as w:
        got = first_step(H, 0.9)
    message = str(w[0].message)
    assert "set_quadrature('cell', singularity=0.9)" in message
    assert "set_quadrature('cell', singularity=0.5), or singularity=None" in message
    # int_0^1 s^-1/2 ds = 2, h = 1/8
    assert abs(got - 0.75) <= 1e-10 * 0.25


def test_declared_exponent_that_fits_neither_refuses_nor_warns():
    _, H = counted(0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        got = first_step(H, 0.5)
    assert abs(got - 0.75) <= 1e-10 * 0.25


@pytest.mark.parametrize("singularity", [None, 0.5])
def test_set_quadrature_after_init_names_itself(singularity):
    with dmi.Solver(1, 1.0, 8) as s:
        s.init()
        with pytest.raises(dmi.InvalidArgument) as e:
            s.set_quadrature("cell", singularity=singularity)
        assert e.value.code == dmi.ESTATE
        assert e.value.message.startswith("set_quadrature('cell'")
        assert "before init()" in e.value.message
        assert "dmi_set_kernel_singularity" not in e.value.message
        assert s.quadrature == "left"


def test_exponent_outside_range_names_set_quadrature():
    with dmi.Solver(1, 1.0, 8) as s:
        with pytest.raises(dmi.InvalidArgument, match=r"^set_quadrature\('cell', singularity=1.5\)"
                           r": singularity = 1.5"):
            s.set_quadrature("cell", singularity=1.5)


# ---- jit=True: a closure variable or global rebound after init -----------------------------------

GAIN = 1.0


def closure_model():
    b = 1.0
    g = np.array([1.0])

    def rhs(t, u):
        return np.array([-b * g[0] * GAIN * u[0]])

    def set_b(value):
        nonlocal b
        b = value
    return rhs, set_b, g


def started(rhs, jit: bool) -> dmi.Solver:
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    s.set_rhs(rhs, jit=jit)
    s.init()
    return s


def run_with_change(jit: bool, change) -> tuple[float, list[str]]:
    """5 steps, change(), 5 more (advance), then run(3) and step(): the state and the warnings."""
    rhs, set_b, g = closure_model()
    s = started(rhs, jit)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        s.advance(5)
        change(set_b, g)
        s.advance(5)
        s.run(3)
        s.step()
    return float(s.state[0]), [str(x.message) for x in w]


def test_closure_rebound_after_init_is_warned_once_naming_it():
    pytest.importorskip("numba")
    python, none = run_with_change(False, lambda set_b, g: set_b(2.0))
    compiled, told = run_with_change(True, lambda set_b, g: set_b(2.0))
    assert none == []
    assert compiled != python     # the compiled code kept b = 1: what the warning is for
    assert len(told) == 1, told
    assert "closure variable 'b'" in told[0] and "since init()" in told[0]
    assert "init() takes the new value" in told[0]


def test_both_jit_callbacks_are_watched_each_warned_once():
    # a jit=True f and a jit=True resolvent: a variable of either rebound is named at the next
    # step, each once; the first warned stays quiet while the other is still watched
    pytest.importorskip("numba")
    rhs, set_b, g = closure_model()
    level = 0.5

    def resolvent(h, x):      # the friction's resolvent of level `level`, written out
        lam = h * level
        return np.array([x[0] - lam if x[0] > lam else (x[0] + lam if x[0] < -lam else 0.0)])

    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([1.0]))
    s.set_rhs(rhs, jit=True)
    s.set_resolvent(resolvent, jit=True)
    s.init()
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        s.step()
        set_b(2.0)
        s.step()
        s.step()
        level = 0.25
        s.step()
        s.step()
    told = [str(x.message) for x in w]
    assert len(told) == 2, told
    assert "closure variable 'b'" in told[0] and "rhs" in told[0]
    assert "closure variable 'level'" in told[1] and "resolvent" in told[1]


def test_init_or_set_rhs_again_takes_the_new_value():
    pytest.importorskip("numba")
    python, _ = run_with_change(False, lambda set_b, g: set_b(2.0))
    rhs, set_b, g = closure_model()
    s = started(rhs, True)
    s.advance(5)
    set_b(2.0)
    with pytest.warns(UserWarning, match="'b'"):
        s.advance(0)
    s.set_rhs(rhs, jit=True)      # the new value from the next step
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        s.advance(5)
        s.run(3)
        s.step()
    assert float(s.state[0]) == pytest.approx(python, rel=1e-14)
    s.init()                      # the new value from t = 0: as the Python callback with b = 2
    s.advance(10)
    assert float(s.state[0]) == pytest.approx(1.02 ** 10, rel=1e-14)


def test_global_rebound_after_init_is_warned_naming_it():
    pytest.importorskip("numba")
    global GAIN
    try:
        def change(set_b, g):
            global GAIN
            GAIN = 3.0
        _, told = run_with_change(True, change)
    finally:
        GAIN = 1.0
    assert len(told) == 1 and "global 'GAIN'" in told[0], told


def test_type_change_says_to_set_the_callback_again():
    pytest.importorskip("numba")
    _, told = run_with_change(True, lambda set_b, g: set_b(2))   # an int where a float was
    assert len(told) == 1 and "set_rhs(..., jit=True) again" in told[0], told


@pytest.mark.parametrize("change", [
    lambda set_b, g: g.__setitem__(0, 2.0),    # in place: the compiled code reads it too
    lambda set_b, g: set_b(float("1.0")),      # another object, the same value
])
def test_no_warning_where_both_paths_agree(change):
    pytest.importorskip("numba")
    python, none = run_with_change(False, change)
    compiled, told = run_with_change(True, change)
    assert told == [] and none == []
    assert compiled == pytest.approx(python, rel=1e-14)


def kernel_model():
    c = 1.0

    def H(s):
        return np.array([[c * np.exp(-s)]])

    def set_c(value):
        nonlocal c
        c = value
    return H, set_c


def test_jit_kernel_rebound_after_init_is_not_warned_of():
    """The kernel is called by init alone: a later rebinding changes neither path."""
    pytest.importorskip("numba")
    states = []
    for jit in (False, True):
        H, set_c = kernel_model()
        with dmi.Solver(1, 1.0, 20) as s:
            s.set_kernel(H, jit=jit)
            s.set_history(lambda t: np.array([1.0]))
            s.init()
            s.advance(5)
            set_c(5.0)
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                s.advance(30)
            states.append(float(s.state[0]))
    assert states[1] == pytest.approx(states[0], rel=1e-14)


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
