# dmi.analysis.collocate on a stick-slip orbit with memory, u' + sigma(u) + int_0^tau g e^{-s}
# u(t - s) ds ∋ c sin t, against an event-driven integration written here: the memory as
# z' = g u(t) - z - g e^{-tau} u(t - tau), DOP853 between events (a slip reaching 0: a stick or a
# reversal by the net force; a stick's net force reaching +-1) and the breakpoints the delay carries
# (every switch + tau), on pieces at most tau long, u(t - tau) from the dense outputs of the earlier
# pieces; run from rest until two periods agree.  And a signature the scheme misses (Den Hartog's
# oscillator sticking for less than 2 steps) mended by collocate, against an event-driven run.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import bisect
import math

import numpy as np
import pytest
import scipy.integrate as si

import dmi
from dmi import analysis as da

C, G, TAU = 1.5, 0.3, 1.0
T = 2 * math.pi
N_RUN = 12          # periods of the run; the last whole one is compared


class EventDriven:
    """The forward run: pieces (t0, t1, mode, dense u or None (stuck: 0))."""

    def __init__(self):
        self.starts: list[float] = [-10.0]
        self.pieces: list[tuple[float, float, object]] = [(-10.0, 0.0, None)]
        self.switches: list[float] = []

    def u(self, t: float) -> float:
        k = bisect.bisect_right(self.starts, t) - 1
        t0, t1, sol = self.pieces[k]
        return 0.0 if sol is None else float(sol(t)[0])

    def run(self, t_end: float) -> None:
        t, u, z, mode = 0.0, 0.0, 0.0, 0     # from rest, stuck
        pending: list[float] = []
        e = math.exp(-TAU)
        while t < t_end:
            # the method of steps: a piece at most tau long reads u(t - tau) from earlier pieces
            stop = min([b for b in pending if b > t + 1e-13] + [t_end, t + TAU])
            if mode == 0:
                def rhs(s, y):
                    return [-y[0] - G * e * self.u(s - TAU)]

                def leave(s, y):
                    return abs(C * math.sin(s) - y[0]) - 1.0
                leave.terminal, leave.direction = True, 1
                sol = si.solve_ivp(rhs, (t, stop), [z], method="DOP853", rtol=1e-13, atol=1e-15,
                                   events=leave, dense_output=True)
                z = float(sol.y[0, -1])
                self._add(t, sol.t[-1], None)
                t = float(sol.t[-1])
                if sol.status == 1:
                    mode = 1 if C * math.sin(t) - z > 0 else -1
                    self._switch(t, pending)
            else:
                sgn = mode

                def rhs(s, y, sgn=sgn):
                    return [C * math.sin(s) - y[1] - sgn,
                            G * y[0] - y[1] - G * e * self.u(s - TAU)]

                def zero(s, y):
                    return y[0]
                zero.terminal, zero.direction = True, -sgn
                sol = si.solve_ivp(rhs, (t, stop), [u, z], method="DOP853", rtol=1e-13,
                                   atol=1e-15, events=zero, dense_output=True)
                u, z = 0.0 if sol.status == 1 else float(sol.y[0, -1]), float(sol.y[1, -1])
                self._add(t, sol.t[-1], sol.sol)
                t = float(sol.t[-1])
                if sol.status == 1:
                    F = C * math.sin(t) - z
                    mode = 0 if abs(F) <= 1 else (1 if F > 1 else -1)
                    self._switch(t, pending)

    def _add(self, t0: float, t1: float, sol: object) -> None:
        self.starts.append(t0)
        self.pieces.append((t0, t1, sol))

    def _switch(self, t: float, pending: list[float]) -> None:
        self.switches.append(t)
        pending.append(t + TAU)


def memory_model(M: int):
    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(1, TAU, h=T / M)
        s.set_rhs(lambda t, u: np.array([-C * math.sin(t)]))
        s.set_friction([1.0])
        s.set_kernel_exp([-1.0], [0.0], [[[G]]])
        return s
    return make


@pytest.fixture(scope="module")
def reference():
    ev = EventDriven()
    ev.run(N_RUN * T)
    return ev


def test_memory_stick_slip_against_event_driven_run(reference):
    ev = reference
    # the run has settled: the switches of the last two periods agree
    sw = np.array(ev.switches)
    k = N_RUN - 2
    last = sw[(sw > k * T) & (sw < (k + 1) * T)] - k * T
    before = sw[(sw > (k - 1) * T) & (sw < k * T)] - (k - 1) * T
    assert last.size == before.size == 4 and np.max(np.abs(last - before)) < 1e-11
    M = 2000
    make = memory_model(M)
    s = make(1.0)
    s.init()
    s.advance(10 * M)
    o = da.periodic_orbit(make, 1.0, T, s, multipliers=0)
    e = da.collocate(o, intervals=48)
    assert [d.split()[0] for d in e.signature.describe()].count("(stuck)") == 2
    assert e.carried == (TAU,)                  # the memory carries each switch by tau
    assert np.max(np.abs(np.sort(e.switches) - np.sort(last))) < 1e-10
    t = np.linspace(0.0, T, 1001)
    ref = np.array([ev.u(k * T + x) for x in t])
    err = np.max(np.abs(e.u_at(t)[:, 0] - ref))
    assert err < 1e-9
    assert e.errors["u"] >= err
    # every inequality holds on the result (collocate checks them); a stuck phase: |mu| < 1
    assert np.all(np.abs(e.multipliers) < 1) and e.stable is True
    # convergence with the carried breakpoints in the mesh: the switching times to 1e-10 already
    # at 12 intervals (the orbit returned: about 30), and u's largest error falls at an order
    # >= 3.5 from 12 to 48 (measured 4.1: the sup norm over adapted, not nested, meshes)
    c = da.collocate(o, intervals=12, multipliers=0)
    assert np.max(np.abs(np.sort(c.switches) - np.sort(last))) < 1e-10
    err_c = np.max(np.abs(c.u_at(t)[:, 0] - ref))
    assert math.log(err_c / err) / math.log(e.intervals / c.intervals) >= 3.5


# ---- a signature the scheme misses, mended: Den Hartog's oscillator sticking briefly -----------
def den_hartog_switches(d, p: float, periods: int) -> np.ndarray:
    """The switching times of x'' + x + F0 sigma(x') ∋ p F cos(w t) over the last whole period of
    an event-driven run from rest (slip: v = 0 ends it, a stick where |p F cos(w t) - x| <= F0;
    stuck: |p F cos(w t) - x| reaching F0 ends it), DOP853."""
    t, x, v, mode, out = 0.0, 0.0, 0.0, 0, []
    t_end = periods * d.T

    def force(s, x):
        return p * d.F * math.cos(d.w * s) - x
    while t < t_end:
        if mode == 0:
            def leave(s, y, x=x):
                return abs(force(s, x)) - d.F0
            leave.terminal, leave.direction = True, 1
            sol = si.solve_ivp(lambda s, y: [0.0], (t, t_end), [0.0], events=leave, rtol=1e-13,
                               atol=1e-15, method="DOP853")
            t = float(sol.t[-1])
            if sol.status == 1:
                mode = 1 if force(t, x) > 0 else -1
                out.append(t)
        else:
            sgn = mode

            def rhs(s, y, sgn=sgn):
                return [y[1], force(s, y[0]) - sgn * d.F0]

            def zero(s, y):
                return y[1]
            zero.terminal, zero.direction = True, -sgn
            sol = si.solve_ivp(rhs, (t, t_end), [x, v], events=zero, rtol=1e-13, atol=1e-15,
                               method="DOP853")
            t, x, v = float(sol.t[-1]), float(sol.y[0, -1]), 0.0
            if sol.status == 1:
                F = force(t, x)
                mode = 0 if abs(F) <= d.F0 else (1 if F > 0 else -1)
                out.append(t)
    sw = np.array(out)
    k = periods - 2
    return sw[(sw > k * d.T) & (sw < (k + 1) * d.T)] - k * d.T


def test_missed_sticks_are_mended_against_event_driven_run():
    from models.orbit_models import DenHartog
    from models.delay_models import forced_orbit
    d = DenHartog()
    o = forced_orbit(d, 60, 20, 0.40)             # 60 steps a period: the sticks are < 2 steps
    assert np.all(o.stick_fraction == 0)          # the scheme's mask sees no stick
    e = da.collocate(o, intervals=24, multipliers=2)
    assert [r.split(", ")[1] for r in e.signature.describe()] == ["slip +)", "stuck)", "slip -)",
                                                                  "stuck)"]
    ref = den_hartog_switches(d, 0.40, 30)
    assert ref.size == 4 and np.max(np.abs(np.sort(e.switches) - np.sort(ref))) < 1e-9
    assert np.max(np.abs(e.multipliers[1:])) < 1e-12  # the stuck segments wipe one direction out
