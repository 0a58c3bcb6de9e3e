# dmi.analysis.continue_orbit in the forcing frequency w (continue_orbit(..., period=2 pi / w)):
# M steps a period kept, the step h = 2 pi / (w M) given to the model through make(w, h=...).
# Oracle: Den Hartog's closed-form non-stick orbit of x'' + x + F0 sign(x') = F cos(w t) at
# each point's w (models/orbit_models.py), the orbit itself re-run by a plain dmi.Solver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi
from dmi.analysis import continue_orbit, periodic_orbit
from models.orbit_models import DenHartog

M = 1000
F, F0 = 1.0, 0.3
TAU = 0.05   # a delay without kernel: N = ceil(tau / h) = 6 .. 8 over the branch (rows change)
W0, W1 = 0.7, 0.9


def make(w: float, h: float | None = None) -> dmi.Solver:
    """The forced dry-friction oscillator at frequency w, step h (default 2 pi / (w M))."""
    h = 2 * math.pi / (w * M) if h is None else h
    s = dmi.Solver(2, TAU, h=h)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] - F * np.cos(w * t)]))
    s.set_friction([0.0, F0])
    return s


def plain_period(w: float, state: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t, U): one period of a plain dmi.Solver run from the shooting state's last N + 1 rows."""
    s = make(w)
    s.init()
    X = np.asarray(state).reshape(-1, 2)
    s.set_window(X[-(s.N + 1):])
    return np.arange(M + 1) * s.h, s.run(M)[1]


@pytest.fixture(scope="module")
def branch():
    dh = DenHartog(w=W0, F=F, F0=F0)
    guess = np.array(dh.exact(0.0)) + 0.2
    o = periodic_orbit(make, W0, 2 * math.pi / W0, guess, multipliers=2)
    return continue_orbit(o, W1, step=0.02, max_step=0.05, multipliers=2,
                          period=lambda w: 2 * math.pi / w)


def test_branch_in_w_is_den_hartog(branch):
    b = branch
    assert b.status.startswith("reached p_end"), b.status
    assert len(b.points) >= 5 and W1 <= b.p[-1] < W1 + 0.01
    assert np.all(np.diff(b.p) > 0)
    Ns = set()
    worst = 0.0
    for q in b.points:
        dh = DenHartog(w=q.p, F=F, F0=F0)   # raises if the orbit sticks: non-stick over the range
        h = dh.T / M
        assert q.period == pytest.approx(dh.T, rel=1e-12)
        Ns.add(make(q.p).N)
        t, U = plain_period(q.p, q.state)
        # the point is an orbit of the plain solver at its w: periodic to the Newton tolerance
        assert np.max(np.abs(U[-1] - U[0])) < 1e-8, q.p
        # amplitude: the branch's and the run's, against Den Hartog's a (20 h, as the oracle test)
        assert abs(q.amplitude[0] - dh.a) < 20 * h, (q.p, q.amplitude[0], dh.a)
        k = int(np.argmax(U[:, 0]))
        assert abs(U[k, 0] - dh.a) < 20 * h
        # phase: the maximum of x at t0 + T/2 (mod T)
        dt = (t[k] - dh.t0 - dh.T / 2 + dh.T / 2) % dh.T - dh.T / 2
        assert abs(dt) < 20 * h, (q.p, t[k], dh.t0)
        # and the whole period, to O(h a) (the scheme's numerical damping, h / 2, grows the error
        # with the amplitude a near resonance: 4.6 h a at most, a = 4.9 at w = 0.9)
        x, v = dh.exact(t)
        err = max(np.max(np.abs(U[:, 0] - x)), np.max(np.abs(U[:, 1] - v)))
        worst = max(worst, err / (h * dh.a))
        assert err < 10 * h * max(1.0, dh.a), (q.p, err, h, dh.a)
        assert np.all(q.stick_steps == 0) and q.stable
    print(f"{len(b.points)} points, N in {sorted(Ns)}, max orbit error / (h a) = {worst:.3g}")
    assert len(Ns) >= 3, Ns   # N = ceil(tau / h) changed along the branch
    # the amplitude really moves with w over the range (a fixed orbit would fail above)
    a0, a1 = DenHartog(w=W0, F=F, F0=F0).a, DenHartog(w=W1, F=F, F0=F0).a
    assert abs(a1 - a0) > 40 * 2 * math.pi / (W0 * M)


def test_period_must_match_the_orbit():
    dh = DenHartog(w=W0, F=F, F0=F0)
    o = periodic_orbit(make, W0, 2 * math.pi / W0, np.array(dh.exact(0.0)), multipliers=0)
    with pytest.raises(ValueError, match="period"):
        continue_orbit(o, W1, period=lambda w: 4 * math.pi / w)
    fixed = periodic_orbit(lambda w: make(w, h=2 * math.pi / (W0 * M)), W0, 2 * math.pi / W0,
                           np.array(dh.exact(0.0)), multipliers=0)
    with pytest.raises(ValueError, match="make\\(p, h=...\\)"):
        continue_orbit(fixed, W1, period=lambda w: 2 * math.pi / w)


def make_delay(w: float, h: float | None = None) -> dmi.Solver:
    """The same oscillator with a small distributed delay on v: + int_0^0.5 0.2 e^-s v(t - s) ds
    in the velocity equation (N = ceil(0.5 / h) = 56 .. 62 over w in [0.7, 0.77])."""
    s = dmi.Solver(2, 0.5, h=2 * math.pi / (w * M) if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] - F * np.cos(w * t)]))
    s.set_friction([0.0, F0])
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [0.0, 0.2]]])
    return s


def test_delayed_branch_in_w_is_the_runs_attractor():
    """Continued in w across changes of N, the branch's orbits are where long plain runs at
    their w (from rest) settle: to 1e-8 at the phase-0 section."""
    w0, w1 = 0.7, 0.77
    s = make_delay(w0)
    s.init()
    s.advance(60 * M)
    o = periodic_orbit(make_delay, w0, 2 * math.pi / w0, s, multipliers=2)
    b = continue_orbit(o, w1, step=0.02, max_step=0.05, multipliers=2,
                       period=lambda w: 2 * math.pi / w)
    assert b.status.startswith("reached p_end"), b.status
    Ns = [make_delay(q.p).N for q in b.points]
    assert Ns[-1] - Ns[0] >= 4, Ns
    for q in b.points[:: max(1, len(b.points) // 3)] + [b.points[-1]]:
        assert q.period == pytest.approx(2 * math.pi / q.p, rel=1e-12) and q.stable
        r = make_delay(q.p)
        r.init()
        r.advance(60 * M)
        assert np.max(np.abs(r.state - q.section[0])) < 1e-8, (q.p, r.state, q.section[0])
