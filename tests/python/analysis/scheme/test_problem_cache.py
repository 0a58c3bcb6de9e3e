# The one cache of a problem (dmi._cache.Cache in scheme.problem.Problem): each object built once
# per key, the least recently used dropped beyond ``keep``, a probe taken out for good.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np

import dmi
from dmi._cache import Cache
from dmi.analysis.scheme.problem import Problem


def make(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(1, 1.0, 4) if h is None else dmi.Solver(1, 1.0, h=h)
    s.set_rhs(lambda t, u: np.array([p * u[0]]))
    return s


def test_each_key_is_built_once_and_the_oldest_goes_first():
    built = []

    def factory(k):
        def f():
            built.append(k)
            return [k]
        return f

    c = Cache(2)
    a = c.cached("a", factory("a"))
    assert c.cached("a", factory("a")) is a and built == ["a"]
    c.cached("b", factory("b"))
    c.cached("a", factory("a"))          # a is now the most recent
    c.cached("c", factory("c"))          # drops b, the least recently used
    assert len(c) == 2 and built == ["a", "b", "c"]
    assert c.cached("a", factory("a")) is a
    c.cached("b", factory("b"))
    assert built == ["a", "b", "c", "b"]
    assert c.pop("b") == ["b"] and c.pop("b") is None and len(c) == 1
    # a factory's None is kept too (built once)
    calls = []
    c.cached("none", lambda: calls.append(1))
    c.cached("none", lambda: calls.append(1))
    assert calls == [1]


def test_a_problem_probes_once_and_hands_its_probe_over():
    pr = Problem(make, keep=3)
    s1 = pr.probe(0.5)
    assert pr.probe(0.5) is s1                       # read for N, h: built once
    assert pr.probe(0.5, 0.125) is not s1            # another step: another probe
    taken = pr.probe(0.5, take=True)
    assert taken is s1 and pr.probe(0.5) is not s1  # the caller owns it now
    assert pr.probe(0.5, 0.125).h == 0.125 and s1.h == 0.25
