# Errors of the Python binding: invalid arguments raise dmi.InvalidArgument (a
# dmi.Error and a ValueError) and leave the solver bitwise as it was; library
# failures raise dmi.Error with the DMI_E* code and libdmi's message; an
# exception raised in a Python callback comes out of step/advance/run/init as
# that same object with its traceback, the solver where it was before the
# failing step, and a retry gives the clean run's result; a callback returning
# the wrong shape or NaN gives a clear error, the solver unchanged.  "Where it
# was" is checked on the saved state's bytes and by stepping on beside a twin
# solver that never saw the failure.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes
import math
import traceback

import numpy as np
import pytest
from models.paper import numba_callbacks, paper_solver, python_callbacks

import dmi

N = 50


def model(example=43):
    """Example 4.3 at h = 1/50 with Python callbacks, initialised, and 20 steps taken."""
    s = paper_solver(example, N, "python")
    s.advance(20)
    return s


def same(a: dmi.Solver, b: dmi.Solver, steps: int = 30) -> bool:
    """Bitwise the same state now and after stepping both on."""
    if a.save_state() != b.save_state():
        return False
    ta, Ua = a.run(steps)
    tb, Ub = b.run(steps)
    return np.array_equal(ta, tb) and np.array_equal(Ua, Ub) and a.save_state() == b.save_state()


@pytest.mark.parametrize("args, word", [((0, 1.0, 10), "n"), ((2, float("nan"), 10), "tau"),
                                        ((2, -1.0, 10), "tau"), ((2, float("inf"), 10), "tau"),
                                        ((2, 1.0, 0), "N"), ((2.5, 1.0, 10), "n"),
                                        ((2, "one", 10), "tau")])
def test_bad_constructor(args, word):
    with pytest.raises(dmi.InvalidArgument) as e:
        dmi.Solver(*args)
    assert isinstance(e.value, ValueError) and isinstance(e.value, dmi.Error)
    assert e.value.code == dmi.EINVAL and str(e.value).startswith(word)


BAD_CALLS = {
    "friction negative": (lambda s: s.set_friction([0.0, -1.0]), dmi.EINVAL, "alpha[1]"),
    "friction NaN": (lambda s: s.set_friction([math.nan, 1.0]), dmi.EINVAL, "alpha[0]"),
    "friction shape": (lambda s: s.set_friction([1.0, 1.0, 1.0]), dmi.EINVAL, "shape (3,)"),
    "friction not numbers": (lambda s: s.set_friction(["a", "b"]), dmi.EINVAL, "alpha"),
    "box lo > hi": (lambda s: s.set_box([0, 1], [0, 0]), dmi.EINVAL, "lo[1] = 1 > hi[1] = 0"),
    "box NaN": (lambda s: s.set_box([math.nan, 0], [1, 1]), dmi.EINVAL, "NaN"),
    "box shape": (lambda s: s.set_box(np.zeros((2, 1)), np.ones(2)), dmi.EINVAL, "lo has shape"),
    "kernel after init": (lambda s: s.set_kernel(lambda x: np.zeros((2, 2))), dmi.ESTATE, "dmi_init"),
    "history after init": (lambda s: s.set_history(lambda t: np.zeros(2)), dmi.ESTATE, "dmi_init"),
    "kernel_exp after init": (lambda s: s.set_kernel_exp([0.0], [1.0], np.ones((1, 2, 2))),
                              dmi.ESTATE, "dmi_init"),
    "kernel_exp C shape": (lambda s: s.set_kernel_exp([0.0], [1.0], np.ones((2, 2))), dmi.EINVAL,
                           "C has shape (2, 2); expected (1, 2, 2)"),
    "kernel_exp no term": (lambda s: s.set_kernel_exp([], [], np.ones((0, 2, 2))), dmi.EINVAL, "K >= 1"),
    "convolution name": (lambda s: s.set_convolution("fast"), dmi.EINVAL, "'fast'"),
    "recursive, callback kernel": (lambda s: s.set_convolution("recursive"), dmi.EINVAL,
                                   "DMI_CONV_RECURSIVE"),
    "rhs not callable": (lambda s: s.set_rhs(3.0), dmi.EINVAL, "neither callable"),
    "user pointer, Python rhs": (lambda s: s.set_rhs(lambda t, u: u, user=1), dmi.EINVAL, "closure"),
    "advance negative": (lambda s: s.advance(-1), dmi.EINVAL, "steps = -1"),
    "run stride 0": (lambda s: s.run(5, 0), dmi.EINVAL, "stride = 0"),
    "past beyond N": (lambda s: s.past(N + 1), dmi.EINVAL, "lag = 51 > N = 50"),
    "load garbage": (lambda s: s.load_state(b"garbage"), dmi.EINVAL, "dmi_state_load"),
    "window shape": (lambda s: s.set_window(np.zeros((N, 2))), dmi.EINVAL,
                     "U has shape (50, 2); expected (51, 2)"),
    "window NaN": (lambda s: s.set_window(np.where(np.arange(102).reshape(51, 2) == 9, np.nan, 0.0)),
                   dmi.EINVAL, "row 4 = U^{p-46}, component 1) is not finite"),
}


@pytest.mark.parametrize("name", BAD_CALLS)
def test_invalid_call_leaves_solver_unchanged(name):
    call, code, text = BAD_CALLS[name]
    s, twin = model(), model()
    with pytest.raises(dmi.InvalidArgument) as e:
        call(s)
    assert isinstance(e.value, ValueError) and e.value.code == code
    assert text in str(e.value), str(e.value)
    assert same(s, twin)


def test_load_state_of_another_solver_refused():
    s, twin = model(), model()
    other = dmi.Solver(2, 1.0, N + 1)
    other.init()
    with pytest.raises(dmi.InvalidArgument, match="dmi_state_load"):
        s.load_state(other.save_state())
    assert same(s, twin)


def test_calls_before_init():
    s = dmi.Solver(2, 1.0, N)
    for call in (s.step, lambda: s.advance(1), lambda: s.run(1), lambda: s.state,
                 lambda: s.step_index, s.save_state):
        with pytest.raises(dmi.InvalidArgument) as e:
            call()
        assert e.value.code == dmi.ESTATE
    s.init()
    with pytest.raises(dmi.InvalidArgument, match="no step taken") as e:
        s.step_terms()
    assert s.time == 0.0 and s.step_index == 0


def test_library_error_is_not_value_error():
    """A NaN from the right-hand side: DMI_ENONFINITE with libdmi's message; solver unchanged."""
    s, twin = model(), model()
    rhs = python_callbacks(43)[0]
    s.set_rhs(lambda t, u: np.array([math.nan, 0.0]))
    with pytest.raises(dmi.Error) as e:
        s.step()
    assert not isinstance(e.value, ValueError)
    assert e.value.code == dmi.ENONFINITE and "dmi_step: f(0.40000000000000002, U)[0] = nan" in str(e.value)
    s.set_rhs(rhs)
    assert same(s, twin)


@pytest.mark.parametrize("value, text", [(np.zeros(3), "shape (3,); libdmi needs shape (2,)"),
                                         (np.zeros((2, 1)), "shape (2, 1)"), (None, "shape ()"),
                                         ("ab", "returned str, not an array of floats")])
def test_rhs_wrong_result(value, text):
    s, twin = model(), model()
    rhs = python_callbacks(43)[0]
    s.set_rhs(lambda t, u: value)
    with pytest.raises(dmi.InvalidArgument) as e:
        s.advance(5)
    assert e.value.code == dmi.ECALLBACK and text in str(e.value), str(e.value)
    s.set_rhs(rhs)
    assert same(s, twin)


def test_kernel_wrong_shape_at_init():
    s = dmi.Solver(2, 1.0, N)
    s.set_kernel(lambda x: np.zeros(2))
    with pytest.raises(dmi.InvalidArgument, match=r"kernel callback returned an array of shape \(2,\); "
                       r"libdmi needs shape \(2, 2\)"):
        s.init()
    with pytest.raises(dmi.InvalidArgument):  # still uninitialised
        s.step()


class Boom(Exception):
    pass


def failing(f, at_call: int, raised: list):
    """f, but its at_call-th call raises a new Boom (kept in raised) while raised has one slot."""
    calls = [0]

    def wrapped(*args):
        calls[0] += 1
        if calls[0] == at_call and not raised:
            raised.append(Boom(f"call {at_call}"))
            raise raised[0]
        return f(*args)
    return wrapped


def frames(e: BaseException) -> list[str]:
    return [fr.name for fr in traceback.extract_tb(e.__traceback__)]


@pytest.mark.parametrize("how", ["step", "advance", "run"])
def test_exception_in_rhs(how):
    """The same exception object, its traceback down to the callback; the solver at the failing
    step's start, bitwise; a retry finishes as a clean run."""
    clean = model()
    t_clean, U_clean = clean.run(40)
    s, raised = model(), []
    rhs = failing(python_callbacks(43)[0], 15, raised)
    s.set_rhs(rhs)
    steps_before = 0
    with pytest.raises(Boom) as e:
        if how == "step":
            for steps_before in range(40):
                s.step()
        elif how == "advance":
            s.advance(40)
        else:
            s.run(40, stride=3)
    assert e.value is raised[0]
    assert "wrapped" in frames(e.value)
    assert s.step_index == 20 + 14
    twin = model()
    twin.advance(14)
    assert twin.save_state() == s.save_state()
    if how == "run":
        t_part, U_part = e.value.partial
        assert np.array_equal(t_part, t_clean[0:15:3]) and np.array_equal(U_part, U_clean[0:15:3])
    s.advance(40 - 14)  # the retry: the callback no longer fails
    clean_state = U_clean[-1]
    assert np.array_equal(s.state, clean_state) and s.step_index == 60


def test_exception_in_resolvent():
    clean, s, raised = model(), model(), []

    def soft_threshold(lam, x):  # the friction's resolvent, alpha = (0, 1)
        return np.array([x[0], np.sign(x[1]) * max(abs(x[1]) - lam, 0.0)])
    clean.set_resolvent(soft_threshold)
    s.set_resolvent(failing(soft_threshold, 3, raised))
    before = s.save_state()
    s.advance(2)
    with pytest.raises(Boom) as e:
        s.advance(5)
    assert e.value is raised[0] and s.step_index == 22
    clean.advance(2)
    assert s.save_state() == clean.save_state() != before
    assert same(s, clean)


@pytest.mark.parametrize("which", ["kernel", "history"])
def test_exception_at_init(which):
    rhs, kernel, history = python_callbacks(42)
    raised = []
    s = dmi.Solver(2, 1.0, N)
    s.set_kernel(failing(kernel, 7, raised) if which == "kernel" else kernel)
    s.set_history(failing(history, 7, raised) if which == "history" else history)
    with pytest.raises(Boom) as e:
        s.init()
    assert e.value is raised[0]
    with pytest.raises(dmi.InvalidArgument):  # still uninitialised
        s.state
    s.init()  # the retry
    assert np.array_equal(s.past(N), history(-1.0))


def test_callback_calling_its_own_solver():
    s = model()
    s.set_rhs(lambda t, u: s.state)
    with pytest.raises(dmi.InvalidArgument, match="in use") as e:
        s.step()
    assert e.value.code == dmi.ESTATE


def test_c_function_with_another_signature_refused():
    numba = pytest.importorskip("numba")
    _, kernel, _ = numba_callbacks(43)
    s, twin = model(), model()
    with pytest.raises(dmi.InvalidArgument, match=r"signature int \(double, double \*, double \*, void \*\)"):
        s.set_rhs(kernel)
    proto = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_double, ctypes.c_void_p, ctypes.c_void_p,
                             ctypes.c_void_p)
    with pytest.raises(dmi.InvalidArgument, match="ctypes function"):
        s.set_rhs(proto(lambda t, u, out, user: 0.0))
    scipy = pytest.importorskip("scipy")
    with pytest.raises(dmi.InvalidArgument, match="LowLevelCallable"):
        s.set_rhs(scipy.LowLevelCallable(kernel.ctypes))
    assert same(s, twin)


def test_user_array_kept_alive_and_checked():
    """A NumPy array as the user pointer: its data reaches the C function, the solver keeps it
    alive (no other reference here), and a non-contiguous one is refused."""
    numba = pytest.importorskip("numba")
    import gc

    sig = numba.types.intc(numba.types.float64, numba.types.CPointer(numba.types.float64),
                           numba.types.CPointer(numba.types.float64),
                           numba.types.CPointer(numba.types.float64))

    @numba.cfunc(sig)
    def growth(t, u, out, user):  # f = -c u: U^{p+1} = (1 + c h) U^p
        out[0] = -user[0] * u[0]
        return 0
    s = dmi.Solver(1, 1.0, 4)
    s.set_history(lambda t: np.ones(1))
    with pytest.raises(dmi.InvalidArgument, match="C-contiguous"):
        s.set_rhs(growth, np.array([[3.0, 9.0], [9.0, 9.0]])[:, 0])
    s.set_rhs(growth, np.array([2.0]))
    gc.collect()
    s.init()
    _, U = s.run(3)
    assert U[:, 0].tolist() == [1.0, 1.5, 2.25, 3.375]  # h = 1/4, c = 2: factor 1.5, exact


def test_window_round_trip():
    """get_window's rows are past(N - k); a window set into a solver at the same step makes it
    step on bitwise as the solver it came from (libdmi 1.2)."""
    s, other = model(), paper_solver(43, N, "python")
    other.advance(20)
    other.set_window(np.zeros((N + 1, 2)))        # elsewhere now
    U = s.get_window()
    assert U.shape == (N + 1, 2)
    assert all(np.array_equal(U[k], s.past(N - k)) for k in range(N + 1))
    assert not np.array_equal(other.get_window(), U)
    other.set_window(U)
    t1, U1 = s.run(40)
    t2, U2 = other.run(40)
    assert np.array_equal(t1, t2) and np.array_equal(U1, U2)


@pytest.mark.parametrize("stride", [1, 3])
def test_run_terms_records_each_steps_argument(stride):
    """run_terms's X rows are step_terms()'s X after the step into each recorded row (Example 4.3,
    friction: X differs from U on every slip step), its t and U are run's; a failing step keeps
    the rows before it, as run does."""
    a, b = model(), model()
    t, U, X = a.run_terms(40, stride)
    Xs, rows = [], []
    for k in range(1, 41):
        b.step()
        if k % stride == 0 or k == 40:
            Xs.append(b.step_terms()[1])
            rows.append(b.state)
    assert X.shape == (len(U) - 1, 2) and np.array_equal(X, np.array(Xs))
    assert np.array_equal(U[1:], np.array(rows)) and not np.array_equal(X, U[1:])
    assert a.save_state() == b.save_state()
    s, raised = model(), []
    s.set_rhs(failing(python_callbacks(43)[0], 15, raised))
    with pytest.raises(Boom):
        s.run_terms(40, stride)
    assert s.step_index == 20 + 14
