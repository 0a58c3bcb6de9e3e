# jit=True fails where the Python callback fails and computes with the same values: a raise, a
# division by zero and an index out of range give the plain callback's exception or libdmi error
# (the solver unchanged); a function writing into u changes only its copy; a function whose file was edited after import is refused, not compiled
# from the edited file; globals and closure values are those at init(), also after set_rhs is
# called again; a kernel returning a vector is told it must return an n x n array; eval_rhs_many
# raises the function's exception; a built-in resolvent or kernel set after a jit=True one runs
# alone; eval_rhs names a result of another shape as the step does.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import importlib.util
import os
import sys

import numpy as np
import pytest

import dmi


def decay(rhs, jit: bool, steps: int = 20, history: float = 1.0) -> dmi.Solver:
    """u' = f(t, u) on n = 1 from U^0 = history, h = 0.01; the solver after init."""
    s = dmi.Solver(1, 1.0, 100)
    s.set_history(lambda t: np.array([history]))
    s.set_rhs(rhs, jit=jit)
    s.init()
    return s


# ---- failures ----------------------------------------------------------------------------------

def raising(t, u):
    if t > 0.045:
        raise ValueError("the state left the model's range")
    return np.array([u[0]])


def test_raise_fails_the_step_with_the_exception():
    for jit in (False, True):             # the plain callback, then the compiled one: the same
        s = decay(raising, jit)
        s.advance(5)                      # t = 0.05 after this: f is called at t_p = 0.04 last
        before = s.get_window()
        with pytest.raises(ValueError) as e:
            s.step()                      # f(0.05, U): raises
        assert e.value.args == ("the state left the model's range",)
        assert s.step_index == 5 and np.array_equal(s.get_window(), before)   # rolled back
        with pytest.raises(ValueError, match="left the model's range"):
            s.eval_rhs(0.05, [1.0])
        assert s.eval_rhs(0.0, [2.0])[0] == 2.0


def history_raising(t):
    if t < -0.5:
        raise KeyError("no record before -0.5")
    return np.array([1.0])


def test_history_raising_fails_init_with_its_exception():
    for jit in (False, True):
        s = dmi.Solver(1, 1.0, 10)
        s.set_history(history_raising, jit=jit)
        with pytest.raises(KeyError) as e:
            s.init()
        assert e.value.args == ("no record before -0.5",)


def test_division_by_zero_is_the_plain_callbacks_nonfinite_error():
    errors = []
    for jit in (False, True):
        s = decay(lambda t, u: np.array([1.0 / u[0]]), jit, history=0.0)
        with np.errstate(divide="ignore"), pytest.raises(dmi.Error) as e:
            s.step()
        errors.append((e.value.code, str(e.value)))
        assert s.step_index == 0
    assert errors[0][0] == dmi.ENONFINITE and "= inf" in errors[0][1]
    assert errors[1] == errors[0]


def test_index_out_of_range_is_an_index_error():
    for jit in (False, True):
        s = dmi.Solver(2, 1.0, 10)
        s.set_rhs(lambda t, u: np.array([-u[5], -u[1]]), jit=jit)
        s.init()
        with pytest.raises(IndexError):
            s.step()
        assert s.step_index == 0 and np.array_equal(s.state, [0.0, 0.0])


def test_eval_rhs_many_raises_the_exception():
    for jit in (False, True):             # the plain callback, then the compiled one: the same
        s = dmi.Solver(1, 1.0, 100)
        s.set_rhs(raising, jit=jit)
        with pytest.raises(ValueError) as e:
            s.eval_rhs_many([0.0, 0.05], [[1.0], [2.0]])   # raising at the second point
        assert e.value.args == ("the state left the model's range",)
        assert "0.05" in " ".join(e.value.__notes__)
        assert np.array_equal(s.eval_rhs_many([0.0], [[2.0]]), [[2.0]])


def test_result_of_another_shape_is_named_by_eval_rhs_as_by_the_step():
    s = dmi.Solver(2, 1.0, 10)
    s.set_rhs(lambda t, u: np.array([u[0], u[1], 0.0]), jit=True)   # 3 values for n = 2
    s.init()
    for call in (s.step, lambda: s.eval_rhs(0.0, [1.0, 2.0]),
                 lambda: s.eval_rhs_many([0.0], [[1.0, 2.0]])):
        with pytest.raises(dmi.Error, match=r"returned 2 .*does not have libdmi's shape"):
            call()


def test_builtin_part_after_a_jit_callback_runs_alone():
    # a jit=True resolvent replaced by set_friction, a jit=True kernel by set_kernel_exp: init
    # and the steps are those of a solver given only the built-in parts
    runs = []
    for replaced in (True, False):
        s = dmi.Solver(1, 1.0, 10)
        s.set_rhs(lambda t, u: np.array([1.0 - u[0]]))
        if replaced:
            s.set_resolvent(lambda lam, x: x / (1.0 + lam), jit=True)
            s.set_kernel(lambda x: np.array([[np.exp(-x)]]), jit=True)
        s.set_friction([0.3])
        s.set_kernel_exp([-2.0], [0.0], [[[0.5]]])
        s.init()
        s.advance(30)
        runs.append(s.get_window())
    assert np.array_equal(runs[0], runs[1])


def test_kernel_returning_a_vector_is_told_the_shape():
    s = dmi.Solver(2, 1.0, 10)
    with pytest.raises(dmi.InvalidArgument, match="the kernel must return an n x n array"):
        s.set_kernel(lambda x: np.array([np.exp(-x), 0.0]), jit=True)


def overwriting(t, u):
    v = u[0]
    u[0] = 0.0            # writes into its argument: the Python callback's is a copy
    return np.array([0.1 * v])


def test_writing_into_u_changes_nothing_else():
    runs = []
    for jit in (False, True):
        s = decay(overwriting, jit)
        s.advance(5)
        runs.append(s.state[0])
    assert runs[0] == pytest.approx(0.999 ** 5, rel=1e-14) and runs[1] == runs[0]


# ---- the function object, not the file ----------------------------------------------------------

MODULE = """import numpy as np


def rhs(t, u):
    return np.array([{rate} * u[0]])
"""


def test_edited_file_is_refused_not_compiled(tmp_path):
    path = tmp_path / "edited_model.py"
    path.write_text(MODULE.format(rate="1.0"))
    spec = importlib.util.spec_from_file_location("edited_model", path)
    model = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(model)
    path.write_text(MODULE.format(rate="25.0"))   # edited, not reloaded (another size: seen)
    st = os.stat(path)
    os.utime(path, ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))
    py = decay(model.rhs, False)
    py.advance(10)
    assert py.state[0] == pytest.approx(0.99 ** 10, rel=1e-14)   # the object's rate, 1
    s = dmi.Solver(1, 1.0, 100)
    with pytest.raises(dmi.InvalidArgument, match="no longer matches the function object"):
        s.set_rhs(model.rhs, jit=True)


# ---- values at init() --------------------------------------------------------------------------

GAIN = 1.0


def global_rhs(t, u):
    return np.array([GAIN * u[0]])


def test_global_changed_is_seen_at_set_rhs_and_at_init():
    global GAIN
    try:
        for gain, reset in ((1.0, False), (3.0, True), (2.0, False)):
            GAIN = gain
            runs = []
            for jit in (False, True):
                s = dmi.Solver(1, 1.0, 100)
                s.set_history(lambda t: np.array([1.0]))
                if reset:
                    s.set_rhs(global_rhs, jit=jit)   # (set again after a change)
                else:
                    GAIN = -1.0
                    s.set_rhs(global_rhs, jit=jit)
                    GAIN = gain                      # changed between set_rhs and init
                s.init()
                s.advance(10)
                runs.append(s.state[0])
            assert runs[0] == pytest.approx((1 - 0.01 * gain) ** 10, rel=1e-14)
            assert runs[1] == runs[0]
    finally:
        GAIN = 1.0


def closure_model():
    b = 1.0

    def rhs(t, u):
        return np.array([b * u[0]])

    def set_b(value):
        nonlocal b
        b = value
    return rhs, set_b


def test_closure_value_is_the_one_at_init():
    runs = []
    for jit in (False, True):
        rhs, set_b = closure_model()
        s = dmi.Solver(1, 1.0, 100)
        s.set_history(lambda t: np.array([1.0]))
        s.set_rhs(rhs, jit=jit)
        set_b(4.0)
        s.init()
        s.advance(10)
        runs.append(s.state[0])
    assert runs[0] == pytest.approx(0.96 ** 10, rel=1e-14) and runs[1] == runs[0]
    rhs, set_b = closure_model()
    s = dmi.Solver(1, 1.0, 100)
    s.set_rhs(rhs, jit=True)
    set_b(4)   # an int now: the compiled code does not fit
    with pytest.raises(dmi.InvalidArgument, match="'b' changed its type"):
        s.init()


if __name__ == "__main__":
    sys.exit(pytest.main([__file__, "-q"]))
