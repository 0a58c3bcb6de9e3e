# The collocation system's exact columns of the switching times and of T against differences.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""`switch_columns`, with T's column and without (the residual's derivatives along the mesh's motion)
against Richardson's extrapolation of central differences of the residual assembled again at
moved switching times (step 1e-3 and 5e-4 of the shortest piece: their own error about 2e-10
here, 7e-9 at ten times the step, 1e-9 at a fifth), on two stick-slip orbits with a memory:

- an autonomous belt (a stick and a slip a period; T unknown; the memory's truncation at tau
  carries each switch forward, so the pieces also end at (b_k + tau) mod T, which wraps);
- a forced oscillator (three switches; f depends on t);

each periodic (Newton's system) and one period forward from its own past held (the monodromy's
system, where the past does not move).
"""
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dmi
from dmi import analysis as da
from dmi.analysis.collocation.system import (History, Layout, Terms, assemble, reference,
                                             switch_columns)
from models.memory_stickslip import FF, K, PF, belt, forced_for


def forced(p: float, h: float | None = None) -> dmi.Solver:
    """The forced oscillator at the step h."""
    return forced_for(round(PF / h) if h else 200)(p)


def orbit(name: str):
    """(layout, terms, x) of the collocated orbit (24 intervals)."""
    if name == "belt":
        make, p, u0, T, auto = belt, K, [1.0, -0.1], 6.3, True
    else:
        make, p, u0, T, auto = forced, FF, [0.0, 0.1], PF, False
    s = make(p, h=T / 200)
    s.set_history(lambda t: np.array(u0))
    s.init()
    s.advance(40 * 200)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        o = da.periodic_orbit(make, p, None if auto else PF, s, guess_period=T if auto else None,
                              steps=200, multipliers=0)
        q = da.collocate(o, intervals=24, multipliers=0)
    lay = Layout(q.degree, 2, q.signature, q.fractions, auto, q.period, tuple(q.carried))
    x = np.concatenate([q.nodes.ravel(), q.switches] + ([[q.period]] if auto else []))
    return lay, Terms(make(p)), x


@pytest.fixture(scope="module", params=["belt", "forced"])
def case(request):
    return (request.param,) + orbit(request.param)


def past(lay: Layout, terms: Terms, x: np.ndarray) -> tuple[Layout, np.ndarray, History]:
    """The period's system from the orbit's own past (T fixed: a forced layout)."""
    V, b, T = lay.split(x)
    L, m = lay.L, lay.m
    one = V[(np.arange(L)[:, None] * m + np.arange(m + 1)[None, :]) % lay.rows]
    P = max(1, math.ceil(terms.tau / T - 1e-12))
    hist = History(lay.mesh(b, T), P, np.tile(one, (P, 1, 1)).reshape(-1, lay.n))
    fixed = Layout(lay.m, lay.n, lay.signature, lay.fractions, False, T, lay.carried)
    return fixed, x[:fixed.size], hist


class CutAtPast:
    """Terms whose delay integral from a history is also cut at the history's mesh (a moved
    switch must not leave the past's breakpoint inside a quadrature piece of the differences)."""

    def __init__(self, terms: Terms):
        self._terms = terms

    def __getattr__(self, name: str):
        return getattr(self._terms, name)

    def delay(self, times, mesh, T, loc, basis, rows, history=None, extra=None, periodic=False):
        if history is not None:
            mesh = np.union1d(mesh, history.hist)
        return self._terms.delay(times, mesh, T, loc, basis, rows, history, extra,
                                 periodic=periodic)


def differences(lay, terms, x, ref, history, j: int) -> np.ndarray:
    """d residual / d x_j by Richardson on central differences (steps d, d / 2)."""
    terms = CutAtPast(terms) if history is not None else terms
    V, b, T = lay.split(x)
    d = 1e-3 * min(T, float(np.min(np.diff(lay.bounds(b, T)))))

    def central(step: float) -> np.ndarray:
        xp, xm = x.copy(), x.copy()
        xp[j] += step
        xm[j] -= step
        return (assemble(lay, terms, xp, ref, jacobian=False, history=history)[0]
                - assemble(lay, terms, xm, ref, jacobian=False, history=history)[0]) / (2 * step)
    return (4 * central(d / 2) - central(d)) / 3


def check(got: np.ndarray, want: np.ndarray) -> None:
    scale = np.max(np.abs(want))
    assert scale > 0.1
    err = np.max(np.abs(got - want))
    assert err < 2e-9 * scale, (err, scale, int(np.argmax(np.abs(got - want))))


def test_periodic_columns(case):
    """Newton's system: every switching time's column, and T's for the belt."""
    name, lay, terms, x = case
    assert lay.S == (2 if name == "belt" else 3)
    if name == "belt":
        assert lay.carried and lay.autonomous        # the carried ends (and their wraps) too
    ref = reference(lay, x) if lay.autonomous else None
    got = switch_columns(lay, terms, x, ref)
    first = lay.rows * lay.n
    for k in range(lay.S):
        check(got[:, k], differences(lay, terms, x, ref, None, first + k))
    if lay.autonomous:                 # T's column after them, from the same motions
        both = switch_columns(lay, terms, x, ref, period=True)
        assert np.array_equal(both[:, :-1], got)
        check(both[:, -1], differences(lay, terms, x, ref, None, x.size - 1))


def test_columns_from_a_fixed_past(case):
    """The monodromy's system: the past held at fixed times does not move with the switches."""
    name, lay, terms, x = case
    fixed, xf, hist = past(lay, terms, x)
    got = switch_columns(fixed, terms, xf, None, hist)
    first = fixed.rows * fixed.n
    for k in range(fixed.S):
        check(got[:, k], differences(fixed, terms, xf, None, hist, first + k))
