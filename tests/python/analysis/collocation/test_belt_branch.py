# A belt with a truncated exponential memory, x' = y + V, y' ∈ -x + p (y + V) - g int_0^tau e^{-s}
# x(t - s) ds - alpha Sign(y) (y: the block's velocity relative to the belt), continued by
# collocation from the equation's Hopf point: up the vertical branch of pure slip (linear while
# y < 0: every amplitude an orbit at p_H), through grazing (y's maximum reaching 0) into stick-slip,
# and back from stick-slip through grazing into pure slip.  Checked against closed forms (pure
# slip: p_H, 2 pi / omega and y's amplitude omega times x's), against an event-driven integration
# written here (stick-slip: period and amplitudes to 1e-8) and against the scheme's orbits (O(h)).
#
# The event-driven integration: the memory as I(t) = int_0^tau e^{-s} x(t - s) ds, I' = x - I -
# e^{-tau} x(t - tau); DOP853 (rtol 1e-13) between events (a slip's y reaching 0: a stick, or a
# reversal when |F| > alpha; a stick's net force F reaching -alpha or alpha) and the breakpoints
# the delay carries (every switch + tau and + 2 tau, every multiple of tau: pieces at most tau
# long), x(t - tau) from the dense outputs of the earlier pieces; events located by SciPy's
# root finder on the dense output.  Started from a perturbed collocated orbit and run until two
# successive periods (stick-to-slip switch to the next) agree to 1e-12: the stick-slip orbit
# attracts (its nontrivial multiplier is about 0.015 here), so the orbit found is the equation's,
# whatever the start.  The extrema: events x' = 0 (y = -V) and y' = 0 (F = alpha sign y).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import bisect
import math
import re
import warnings

import numpy as np
import pytest
import scipy.integrate as si
import scipy.optimize as so

from dmi import analysis as da
from dmi.analysis import CollocationWarning
from models import delay_models as tc
from models.orbit_models import DenHartog
from models.truncated_belt import ALPHA, GB, TAUB, V, belt, hopf

P_UP = 0.05          # the forward branch's end, in stick-slip
MAX_STEP = 0.03      # the branches' largest step


class BeltRun:
    """The event-driven run (see the header): modes -1, +1 (slip) and 0 (stuck)."""

    def __init__(self, p: float, hist):
        self.p, self.hist = p, hist            # hist: x(t) for t <= 0
        self.starts: list[float] = []
        self.dense: list[object] = []

    def x(self, t: float) -> float:
        if t <= 0.0:
            return self.hist(t)
        k = bisect.bisect_right(self.starts, t) - 1
        return float(self.dense[k](t)[0])

    def force(self, w: np.ndarray) -> float:
        return -w[0] + self.p * (w[1] + V) - GB * w[2]

    def run(self, z0: list[float], mode: int, periods: int, T: float
            ) -> tuple[float, float, float]:
        """(period, x's amplitude, y's amplitude) of the last whole period (from a stick's
        end to the next) once two periods agree to 1e-12; AssertionError otherwise.
        ``self.modes``: the modes entered in that period; ``self.stuck_max``: the stuck
        force's largest value there (at a stick's entry or an interior maximum; None if no
        stick)."""
        e = math.exp(-TAUB)
        t, z = 0.0, np.array(z0, dtype=float)
        breaks: set[float] = set()                          # the switches' + tau, + 2 tau
        ends: list[float] = []                              # stuck -> slip switches
        switches: list[tuple[float, int]] = []               # (time, mode entered)
        xs: list[tuple[float, float]] = []
        ys: list[tuple[float, float]] = []
        fs: list[tuple[float, float]] = []                   # the stuck force's extrema
        for _ in range(100 * periods):                       # pieces at most
            if len(ends) >= periods + 1 or t >= 3 * periods * T:
                break
            stop = min([b for b in breaks if b > t + 1e-13]
                       + [(math.floor(t / TAUB + 1e-12) + 1) * TAUB])   # pieces <= tau

            def rhs(s, w, mode=mode):
                dI = w[0] - w[2] - e * self.x(s - TAUB)
                if mode == 0:
                    return [V, 0.0, dI]
                return [w[1] + V, self.force(w) - ALPHA * mode, dI]
            if mode == 0:
                def down(s, w):
                    return self.force(w) + ALPHA

                def up(s, w):
                    return self.force(w) - ALPHA

                def fext(s, w):                              # F' = -V - g I' while stuck
                    return -V - GB * (w[0] - w[2] - e * self.x(s - TAUB))
                down.terminal, down.direction = True, -1
                up.terminal, up.direction = True, 1
                events = [down, up, fext]
            else:
                def zero(s, w):
                    return w[1]

                def xext(s, w):
                    return w[1] + V

                def yext(s, w, mode=mode):
                    return self.force(w) - ALPHA * mode
                zero.terminal, zero.direction = True, -mode
                events = [zero, xext, yext]
            sol = si.solve_ivp(rhs, (t, stop), z, method="DOP853", rtol=1e-13, atol=1e-15,
                               events=events, dense_output=True)
            assert sol.status >= 0, sol.message
            self.starts.append(t)
            self.dense.append(sol.sol)
            if mode != 0:
                xs += [(s, w[0]) for s, w in zip(sol.t_events[1], sol.y_events[1])]
                ys += [(s, w[1]) for s, w in zip(sol.t_events[2], sol.y_events[2])]
            else:
                fs += [(s, self.force(w)) for s, w in zip(sol.t_events[2], sol.y_events[2])]
            if sol.status == 1:
                if mode == 0:
                    k = 0 if len(sol.t_events[0]) else 1
                    t, z = float(sol.t_events[k][0]), np.array(sol.y_events[k][0])
                    mode = -1 if k == 0 else 1
                    if mode == -1:
                        ends.append(t)
                else:
                    t, z = float(sol.t_events[0][0]), np.array(sol.y_events[0][0])
                    z[1] = 0.0
                    mode = 0 if abs(self.force(z)) <= ALPHA else -mode
                    if mode == 0:                            # the stuck force at its entry
                        fs.append((t, self.force(z)))
                switches.append((t, mode))
                breaks |= {t + TAUB, t + 2 * TAUB}
            else:
                t, z = float(sol.t[-1]), sol.y[:, -1].copy()
            if len(ends) >= 3 and abs((ends[-1] - ends[-2]) - (ends[-2] - ends[-3])) < 1e-12:
                break
        assert len(ends) >= 3, "the run did not reach stick-slip"
        gap = abs((ends[-1] - ends[-2]) - (ends[-2] - ends[-3]))
        assert gap < 1e-12, f"the run's periods still differ by {gap:.3g}"
        a, b = ends[-2], ends[-1]
        self.modes = {m for s, m in switches if a <= s < b}
        self.stuck_max = max((v for s, v in fs if a <= s < b), default=None)
        xv = [v for s, v in xs if a <= s < b]
        yv = [v for s, v in ys if a <= s < b] + [0.0]       # y = 0 while stuck
        return b - a, 0.5 * (max(xv) - min(xv)), 0.5 * (max(yv) - min(yv))


def reference(q: da.EquationOrbit, p: float | None = None) -> tuple[float, float, float]:
    """The event-driven run's (period, amplitudes) at p (default q's) from q's orbit shifted
    by 1e-3 in x."""
    return _run(q, q.p if p is None else p)[0]


def _run(q: da.EquationOrbit, p: float) -> tuple[tuple[float, float, float], BeltRun]:
    T = q.period

    def hist(t: float) -> float:
        return float(q.u_at(np.array([t % T]))[0, 0]) + 1e-3
    I0 = si.quad(lambda s: math.exp(-s) * hist(-s), 0.0, TAUB, epsabs=1e-14, limit=200)[0]
    y0 = float(q.u_at(np.array([0.0]))[0, 1])
    run = BeltRun(p, hist)
    return run.run([hist(0.0), min(y0, 0.0), I0], -1 if y0 < 0 else 0, 40, T), run


def is_slip(q: da.EquationOrbit) -> bool:
    return q.signature.describe() == ["(free, slip -)"]


def is_stick_slip(q: da.EquationOrbit) -> bool:
    return q.signature.describe() == ["(free, slip -)", "(free, stuck)"]


@pytest.fixture(scope="module")
def branches() -> tuple[da.Branch, da.Branch]:
    om, pH, xe = hopf()
    with warnings.catch_warnings(record=True) as caught:   # the vertical branch: no verified
        warnings.simplefilter("always")                   # stability, no estimate (warned of)
        e = da.hopf_orbit(belt, da.HopfPoint(p=pH, omega=om, root=1j * om), [xe, -V],
                          amplitude=0.45, of="equation")
        up = da.continue_orbit(e, P_UP, step=0.02, min_step=1e-3, max_step=MAX_STEP,
                               multipliers=2, max_points=30)
        down = da.continue_orbit(up.points[-1], pH - 0.1, step=0.02, min_step=1e-3,
                                 max_step=MAX_STEP, multipliers=2, max_points=17)
    WARNED[:] = [str(w.message) for w in caught if issubclass(w.category, CollocationWarning)]
    return up, down


#: The CollocationWarnings the branches gave.
WARNED: list[str] = []


def test_points_without_a_verdict_say_why(branches):
    # a point of the vertical branch is not isolated at fixed p (its amplitude's error is about
    # the amplitude, a second multiplier at 1): its stable None comes with a warning naming its
    # p, none for a point with a verdict
    for q in branches[0].points + branches[1].points:
        said = [w for w in WARNED if w.startswith(f"p = {q.p!r}: ")]
        assert bool(said) == (q.stable is None), (q.p, q.stable, said)


def test_the_stick_slip_orbits_trivial_multiplier_is_one(branches):
    # an autonomous orbit's derivative is a Floquet solution of multiplier 1 exactly, with the
    # memory and the switches (the monodromy reads the past on its own mesh while the period's
    # switching times move)
    slips = [q for q in branches[0].points + branches[1].points if is_stick_slip(q)]
    assert slips
    for q in slips:
        j = int(np.argmin(np.abs(q.multipliers - 1)))
        assert abs(q.multipliers[j] - 1) <= 1e-8, (q.p, q.multipliers[j])


def corner(points: list[da.EquationOrbit], before, after) -> int:
    """The index of the first point of kind ``after``; every point before it of kind
    ``before``."""
    k = next(i for i, q in enumerate(points) if after(q))
    assert k > 0 and all(before(q) for q in points[:k]), [q.signature.describe()
                                                          for q in points]
    return k


def check_slip(q: da.EquationOrbit, om: float, pH: float) -> None:
    """A pure-slip point: the linear orbit at p_H, period 2 pi / omega, y = x' - V so y's
    amplitude is omega times x's, below grazing; not isolated at fixed p, so no verdict."""
    assert abs(q.p - pH) < 1e-9 and q.stable is None
    assert abs(q.period - 2 * math.pi / om) < 1e-9
    assert abs(q.amplitude[1] - om * q.amplitude[0]) < 1e-9
    assert q.amplitude[1] < V


def check_against_run(q: da.EquationOrbit) -> None:
    T, ax, ay = reference(q)
    assert abs(q.period - T) < 1e-8, (q.p, q.period - T)
    assert abs(q.amplitude[0] - ax) < 1e-8, (q.p, q.amplitude[0] - ax)
    assert abs(q.amplitude[1] - ay) < 1e-8, (q.p, q.amplitude[1] - ay)


def check_corner(a: da.EquationOrbit, b: da.EquationOrbit) -> None:
    """One family across the corner: y's amplitude V at grazing lies between the two points,
    which are within two of the branch's largest steps in p, period and amplitude."""
    assert (a.amplitude[1] - V) * (b.amplitude[1] - V) < 0
    assert abs(a.p - b.p) < 2 * MAX_STEP
    assert abs(a.period - b.period) < 2 * MAX_STEP
    assert np.max(np.abs(a.amplitude - b.amplitude)) < 2 * MAX_STEP


def test_branch_from_hopf_passes_grazing_into_stick_slip(branches):
    up, _ = branches
    om, pH, _ = hopf()
    assert up.status == f"reached p_end = {P_UP!r}", up.status
    assert abs(up.points[-1].p - P_UP) < 1e-12
    pts = up.points
    k = corner(pts, is_slip, is_stick_slip)
    assert all(is_stick_slip(q) for q in pts[k:])
    for q in pts[:k]:
        check_slip(q, om, pH)
    check_corner(pts[k - 1], pts[k])
    assert [ev.kind for ev in up.events] == ["stick-onset"]
    for q in (pts[k], pts[(k + len(pts)) // 2], pts[-1]):
        assert q.p > pH and q.stable is True
        check_against_run(q)


def test_branch_back_from_stick_slip_through_grazing_into_pure_slip(branches):
    _, down = branches
    om, pH, _ = hopf()
    pts = down.points
    k = corner(pts, is_stick_slip, is_slip)
    assert k + 2 < len(pts)
    for q in pts[k:]:
        check_slip(q, om, pH)
    check_corner(pts[k - 1], pts[k])
    amp = [q.amplitude[1] for q in pts[k:k + 3]]
    assert amp[0] > amp[1] > amp[2]                         # on down the vertical branch
    assert pts[k - 1].p - pH < 1e-3                         # the last stick-slip point: near it
    for q in (pts[k - 2], pts[k - 4]):
        check_against_run(q)


def test_stick_slip_point_agrees_with_the_scheme_at_order_h(branches):
    up, _ = branches
    q = up.points[-1]
    assert is_stick_slip(q)
    gaps = []
    for M in (300, 600, 1200):
        s = belt(q.p, h=q.period / M)
        s.set_history(lambda t: q.u_at(np.array([t % q.period]))[0])
        s.init()
        s.advance(2 * M)
        o = da.periodic_orbit(belt, q.p, None, s, guess_period=q.period, steps=M, multipliers=0)
        gaps.append(max(abs(o.period - q.period), float(np.max(np.abs(o.amplitude
                                                                       - q.amplitude)))))
    assert gaps[0] > gaps[1] > gaps[2]
    assert 1.6 < gaps[0] / gaps[1] < 2.5 and 1.6 < gaps[1] / gaps[2] < 2.5, gaps


def located(ev: da.Event) -> bool:
    return "; located at p = " in ev.detail


def test_stick_onset_and_grazing_located_on_the_belt_branch(branches):
    # the stick onset of the way up: at grazing, on the vertical branch, so at p_H
    up, _ = branches
    om, pH, _ = hopf()
    (ev,) = up.events
    assert ev.kind == "stick-onset" and located(ev) and abs(ev.p - pH) < 1e-9, ev
    # further up, the stuck force reaches +alpha and a slip + segment appears (grazing): its p
    # bracketed to 1e-6 by the event-driven run (no slip + just below, slip + just above)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        more = da.continue_orbit(up.points[-1], 0.12, step=0.02, min_step=1e-3,
                                 max_step=MAX_STEP, multipliers=2, max_points=12)
    assert more.status == "reached p_end = 0.12", more.status
    (ev,) = [e for e in more.events if e.kind == "grazing"]
    assert located(ev), ev
    q = min(more.points, key=lambda q: abs(q.p - ev.p))
    # the run's margin alpha - max F on the stuck stretch (its entry's here) at p* - k d (k = 1,
    # 2, 3; no slip + there), extrapolated to 0 by the parabola through them
    d = 1e-4
    runs = [_run(q, ev.p - k * d)[1] for k in (1, 2, 3)]
    assert all(1 not in r.modes and r.stuck_max is not None for r in runs)
    c = np.polyfit([-d, -2 * d, -3 * d], [ALPHA - r.stuck_max for r in runs], 2)
    roots = np.roots(c)
    dp = roots[np.argmin(np.abs(roots))].real
    assert abs(dp) < 1e-6, dp


def den_hartog_stick_margin(p: float) -> float:
    """|F p cos(w t_s) - a| - F0 at the reversal t_s of Den Hartog's closed form at the forcing
    F p; -1 where the closed form does not hold (it sticks, or x' changes sign in a half)."""
    try:
        d = DenHartog(F=p)
    except RuntimeError:
        return -1.0
    return abs(d.F * math.cos(d.w * (d.t0 + d.T / 2)) - d.a) - d.F0


def test_den_hartog_branch_lands_before_its_stick_onset_and_locates_it():
    d = DenHartog()
    e = da.collocate(tc.forced_orbit(d, 2000, 20), intervals=24, multipliers=2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        b = da.continue_orbit(e, 0.42, step=0.05, multipliers=2, max_points=40)
        assert b.status == "reached p_end = 0.42", b.status
        q = b.points[-1]
        assert abs(q.p - 0.42) < 1e-12 and q.signature.switches == 2
        assert not [ev for ev in b.events if ev.kind == "stick-onset"]
        ref = DenHartog(F=0.42)                        # the closed form: no stick at 0.42
        assert abs(q.amplitude[0] - ref.a) < 1e-9
        c = da.continue_orbit(q, 0.40, step=0.01, multipliers=2, max_points=10)
    assert c.status == "reached p_end = 0.4", c.status
    onset = so.brentq(den_hartog_stick_margin, 0.412, 0.42, xtol=1e-14)
    assert 0 < den_hartog_stick_margin(onset + 1e-9) < 1e-6   # the margin itself reaches 0
    # the sticks at both reversals, one mend each (the symmetric orbit sticks at both at the
    # onset): one of them located there; the other's branch (one stick) may end at that same
    # onset, so that it cannot be bracketed: then reported as not located, at the middle of its
    # two points, within their step of the onset (which mend comes first is the route taken)
    evs = [ev for ev in c.events if ev.kind == "stick-onset"]
    assert len(evs) == 2, c.events
    assert any(located(ev) for ev in evs), evs
    for ev in evs:
        if located(ev):
            assert abs(ev.p - onset) < 1e-8, (ev, onset)
            continue
        assert "; not located (placed at the middle): " in ev.detail, ev
        pa, pb = (float(x) for x in re.search(r"between p = (\S+) and (\S+);", ev.detail).groups())
        assert ev.p == pytest.approx(0.5 * (pa + pb), abs=1e-15), ev
        assert abs(ev.p - onset) <= abs(pb - pa) + 1e-8, (ev, onset)
