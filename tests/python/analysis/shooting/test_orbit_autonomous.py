# dmi.analysis.periodic_orbit(period=None, guess_period=...): an autonomous stick-slip orbit of
# unknown period (models/orbit_models.py: Belt, the period from the closed-form slip and
# the stick's length): the period at order 1 in h, the stick fraction, the multipliers {1, 0}
# (the phase's and the stick's); bad input.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import warnings

import numpy as np
import pytest

import dmi
from dmi.analysis import periodic_orbit
from models.orbit_models import Belt


def test_belt_period_order1_stick_and_multipliers():
    b = Belt()
    errs, hs = [], []
    for M in (1000, 4000):
        P0 = 1.03 * b.T  # the guess's period is 3 % off
        s = b.make(0.0, h=P0 / M)
        s.init()
        s.set_window([[b.x_e, 0.0]] * 2)
        s.advance(5 * M)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a single loop: no multi-loop warning
            o = periodic_orbit(b.make, 0.0, None, s, guess_period=P0, steps=M, multipliers=2)
        assert o.steps == M and o.period == pytest.approx(M * o.h, rel=1e-14)
        errs.append(abs(o.period - b.T))
        hs.append(o.h)
        assert o.stick_fraction[1] == pytest.approx(b.t_stick / b.T, abs=0.01)
        assert np.sort(np.abs(o.multipliers)) == pytest.approx([0.0, 1.0], abs=2e-3)
        # stable: the stick forgets (multiplier 0); the phase's multiplier 1 (computed 1.0002)
        # does not count
        assert o.stable
    slope = np.log(errs[0] / errs[1]) / np.log(hs[0] / hs[1])
    assert 0.9 <= slope <= 1.1 and errs[1] < 0.01, (errs, slope)


def test_multi_loop_orbit_is_said():
    """A guess 1.6 periods long converges to the orbit of 4 loops (4 T, T in closed form) in
    M = 1000 steps: a periodic orbit, but not the one sought, and periodic_orbit says so."""
    b, M = Belt(), 1000
    P0 = 1.6 * b.T
    s = b.make(0.0, h=P0 / M)
    s.init()
    s.set_window([[b.x_e, 0.0]] * 2)
    s.advance(5 * M)
    with pytest.warns(RuntimeWarning, match="repeats 4 times in its M steps"):
        o = periodic_orbit(b.make, 0.0, None, s, guess_period=P0, steps=M, multipliers=0)
    assert o.period == pytest.approx(4 * b.T, rel=0.02)


def test_loops_counts_repeats_and_not_single_loops():
    """loops() on curves of known loop count: k turns of a closed curve in M = 1000 steps (also
    k = 3 and 7, 333.3 and 142.9 steps a loop), and single loops that a global threshold took for
    repeats (found in review): a sawtooth with a fast return, components of scales 0.01 and 5, a
    constant."""
    from dmi.analysis.shooting.autonomous import loops
    M = 1000
    s = np.arange(M + 1) / M * 2 * np.pi
    for k in (1, 2, 3, 4, 7):
        assert loops(np.column_stack([np.sin(k * s), np.cos(k * s) ** 3])) == k
    assert loops(((np.arange(M + 1) % M) / M)[:, None]) == 1
    assert loops(np.column_stack([0.01 * np.sin(s), 5 * np.sin(2 * s)])) == 1
    assert loops(np.ones((M + 1, 2))) == 1


def test_autonomous_bad_input():
    b = Belt()
    with pytest.raises(ValueError, match="needs guess_period"):
        periodic_orbit(b.make, 0.0, None, [b.x_e, 0.0])
    with pytest.raises(ValueError, match="guess_period = -1.0"):
        periodic_orbit(b.make, 0.0, None, [b.x_e, 0.0], guess_period=-1.0)

    def fixed(p):  # a model that cannot take the step
        return dmi.Solver(2, 0.01, 1)
    with pytest.raises(ValueError, match=r"make\(p, h=...\)"):
        periodic_orbit(fixed, 0.0, None, [1.0, 0.0], guess_period=6.0)
