# Two solvers in two threads run in parallel: the GIL is released inside
# libdmi.  Each solver's right-hand side is meet_rhs (meet.c), a C function
# that on its first call waits (bounded) until the other solver's has been
# called too: both can meet only if both threads are inside libdmi at once.
# No timing is asserted; the control shows that solvers stepped one after the
# other do not meet (so the test can fail).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import ctypes
import threading

import pytest

import dmi


class Meet(ctypes.Structure):  # meet_data of meet.c
    _fields_ = [("arrived", ctypes.POINTER(ctypes.c_int)), ("limit", ctypes.c_double),
                ("calls", ctypes.c_int), ("met", ctypes.c_int)]


def solvers(testlib, limit: float):
    arrived = ctypes.c_int(0)
    meets = [Meet(ctypes.pointer(arrived), limit, 0, 0) for _ in range(2)]
    out = []
    for m in meets:
        s = dmi.Solver(2, 1.0, 100)
        s.set_rhs(dmi.RhsFn(("meet_rhs", testlib)), m)
        s.set_kernel_exp([-1.0], [0.0], [[[0, 0], [1, 0]]])
        s.set_friction([0.0, 1.0])
        s.init()
        out.append(s)
    return out, meets, arrived


@pytest.mark.parametrize("call", ["advance", "run"])
def test_two_solvers_in_two_threads_meet_inside_libdmi(testlib, call):
    (a, b), meets, arrived = solvers(testlib, 30.0)
    errors = []

    def work(s):
        try:
            s.advance(5) if call == "advance" else s.run(5)
        except BaseException as e:  # reported below
            errors.append(e)
    threads = [threading.Thread(target=work, args=(s,)) for s in (a, b)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert not errors
    assert arrived.value == 2 and [m.calls for m in meets] == [5, 5]
    assert [m.met for m in meets] == [1, 1], "the two threads were never inside libdmi together"
    assert a.step_index == b.step_index == 5


def test_control_one_after_the_other_never_meet(testlib):
    (a, b), meets, arrived = solvers(testlib, 0.05)
    a.advance(5)
    b.advance(5)
    assert arrived.value == 2 and [m.met for m in meets] == [0, 1]
