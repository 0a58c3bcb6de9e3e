# Contact boundaries of collocated orbits with a box, and the onset of a second stick inside a
# slip, continued in (p, q) (continue_stick_curve), against values computed here without dmi:
# - a forced linear oscillator w^2 x'' + c w x' + x = F cos s in the forcing phase s = w t (period
#   2 pi whatever w), its position held by the box x <= 1 (x' + N(x) ∋ y, y = dx/ds): free, its
#   orbit is x = A cos(s - phi), A = F / sqrt((1 - w^2)^2 + (c w)^2), which first touches the face
#   hi = 1 at F = sqrt((1 - w^2)^2 + (c w)^2): the boundary in closed form; past it the orbit
#   rests on the face from its arrival until y reaches 0, the contact's times against an
#   event-driven DOP853 solve of that sweeping process (orbit_models.box_shoot);
# - a mass on a belt (speed vb) with a slow harmonic forcing, x'' + c x' + x + mu sign(x' - vb)
#   = F cos(w t), that sticks once a period: where the relative velocity's hump inside its slip
#   reaches 0 a second stick begins; the boundary F(vb) against the orbit solved here with
#   DOP853 on the slip phase and the stick phase in closed form, the hump's value and slope 0
#   among the equations (fsolve from the curve's point).
# About 40 s on an idle machine.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so
from scipy.integrate import solve_ivp

import dmi
from dmi.analysis.collocation.signature import Signature
from dmi.analysis.collocation.margins import Margin, margins
from dmi.analysis.plane.stick_curves import StickCurvePoint, continue_stick_curve

from models import orbit_models

# ---- the boxed oscillator: p = F, q = w ------------------------------------------------------
C = 0.3
W_START = 0.8


def boxed(F: float, w: float, M: int = 400) -> dmi.Solver:
    """u = (x, y), y = dx/ds: x_s + N_(-inf, 1](x) ∋ y, y_s = (F cos s - x - c w y) / w^2."""
    s = dmi.Solver(2, 2 * math.pi / M, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] + C * w * u[1] - F * math.cos(t)) / w ** 2]))
    s.set_box([-math.inf, -math.inf], [1.0, math.inf])
    return s


def contact_onset(w: float) -> float:
    """The forcing at which the free orbit's amplitude reaches the face: the closed form."""
    return math.hypot(1 - w * w, C * w)


def contact_times(F: float, w: float, guess: float) -> tuple[float, float]:
    """(s_a, s_l): the orbit of the sweeping process arrives on the face x = 1 at s_a and leaves
    it at s_l (y reaching 0), both mod 2 pi; shooting from the leaving time s_l (x = 1, y = 0)
    over one free flight to the face and the stretch on it (orbit_models.box_shoot: DOP853 with
    events), s_l by Newton."""
    def cycle(sl: float) -> tuple[float, float]:
        sa, se, _ = orbit_models.box_shoot(lambda s: F * math.cos(s), C, w, sl, [1.0, 0.0])
        return sa, se
    sl = so.newton(lambda sl: cycle(sl)[1] - sl - 2 * math.pi, guess, tol=1e-14, maxiter=50)
    sa, _ = cycle(sl)
    return sa % (2 * math.pi), sl % (2 * math.pi)


@pytest.fixture(scope="module")
def box_curve():
    br, ev = orbit_models.stick_event(lambda F: boxed(F, W_START), 0.35, 2 * math.pi, 20 * 400,
                                      24, 0.5, 0.03)
    return br, ev, continue_stick_curve(ev, boxed, W_START, 1.0, branch=br, step=0.05,
                                        at=(0.9,), multipliers=2)


def test_the_branch_reports_the_first_contact_and_mends_onto_the_face(box_curve):
    br, ev, _ = box_curve
    assert br.status == "reached p_end = 0.5"
    assert ev.component == 0 and "located at" in ev.detail
    assert abs(ev.p - contact_onset(W_START)) <= 1e-8             # measured 7e-12
    assert br.points[0].signature.describe() == ["(free, free)"]
    last = br.points[-1]
    assert last.p == 0.5
    assert sorted(last.signature.describe()) == ["(free, free)", "(on hi, free)"]
    # the contact's arrival and leaving times against the sweeping process's shooting
    modes = np.asarray(last.signature.modes)
    on = [k for k in (1, 2) if modes[k % 2, 0] != 0]    # b_k enters the face segment
    s_in, s_out = float(last.switches[on[0] - 1]), float(last.switches[on[0] % 2])
    sa, sl = contact_times(0.5, W_START, s_out)
    assert abs(s_in - sa) <= 1e-8 and abs(s_out - sl) <= 1e-8, (s_in - sa, s_out - sl)


def test_the_box_boundary_against_its_closed_form(box_curve):
    _, _, c = box_curve
    assert c.kind == "stick-onset" and c.status == "reached q_end = 1.0"
    assert c.points[-1].q == 1.0 and len(c.points) >= 4 and np.all(np.diff(c.q) > 0)
    for pt in c.points:
        assert isinstance(pt, StickCurvePoint)
        err = abs(pt.p - contact_onset(pt.q))
        assert err <= 1e-8, (pt.q, err)                          # measured 2e-11
        assert pt.p_error is not None and err <= pt.p_error
        assert pt.orbit.signature.describe() == ["(free, free)"]
        # the touch where the free orbit's maximum lies: x = A cos(s - phi) peaks at s = phi
        phi = math.atan2(C * pt.q, 1 - pt.q ** 2)
        assert abs((pt.t_star - phi + math.pi) % (2 * math.pi) - math.pi) <= 1e-6
        assert pt.side == 1                      # the contact at larger forcing
        assert pt.stable is True                 # a damped linear orbit
    (u,) = [e for e in c.events if e.kind == "user"]
    assert u.q == 0.9 and abs(u.p - contact_onset(0.9)) <= 1e-8


def test_the_box_margin_names_the_face():
    from dmi.analysis.collocation.signature import FREE, HI
    from dmi.analysis.collocation.system import Layout, Terms
    from dmi.analysis.scheme.stepmap import build
    lay = Layout(4, 2, Signature(np.array([[FREE, FREE]])), [], False, 2 * math.pi, ())
    lay = lay.with_fractions([np.linspace(0.0, 1.0, 9)])
    terms = Terms(build(lambda F: boxed(F, W_START), 0.4), ())
    other = Signature(np.array([[FREE, FREE], [HI, FREE]]))
    assert margins(lay, terms, other) == [Margin("box", 0, 1)]
    assert "hi face" in Margin("box", 0, 1).describe()


# ---- the forced mass on a belt: p = F, q = vb ------------------------------------------------
W, CB, MU = 0.3, 0.05, 1.0
T = 2 * math.pi / W
VB_START = 0.3


def belt(F: float, vb: float, M: int = 2000) -> dmi.Solver:
    """u = (x, v), v = x' - vb: x' = v + vb, v' + mu sigma(v) = -x - c (v + vb) + F cos(w t)."""
    s = dmi.Solver(2, T / M, 1)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb),
                                     u[0] + CB * (u[1] + vb) - F * math.cos(W * t)]))
    s.set_friction([0.0, MU])
    return s


def second_stick(vb: float, guess: list[float]) -> tuple[float, float, float, float]:
    """(F, t_u, t_s, t_h): the orbit that sticks from t_s to t_u + T and slips (v < 0) from t_u
    to t_s, its velocity's hump at t_h reaching 0 with slope 0; the slip by DOP853, the stick in
    closed form (x = x_s + vb (t - t_s)), the slip's start where the net force -x - c vb +
    F cos(w t) reaches -mu: x_u = mu - c vb + F cos(w t_u)."""
    def slip(F):
        return lambda t, z: [z[1] + vb, -z[0] - CB * (z[1] + vb) + F * math.cos(W * t) + MU]

    def run(z):
        F, tu, ts, th = z
        xu = MU - CB * vb + F * math.cos(W * tu)
        sol = solve_ivp(slip(F), (tu, ts), [xu, 0.0], method="DOP853", rtol=1e-13,
                        atol=1e-15, dense_output=True)
        return xu, sol

    def eqs(z):
        F, tu, ts, th = z
        xu, sol = run(z)
        xs, vs = sol.y[:, -1]
        xh, vh = sol.sol(th)
        return [vs, xs + vb * (tu + T - ts) - xu, vh,
                -xh - CB * (vh + vb) + F * math.cos(W * th) + MU]
    z, _, ier, msg = so.fsolve(eqs, guess, full_output=True, xtol=1e-14)
    assert ier in (1, 3) and max(map(abs, eqs(z))) <= 1e-11, msg   # 3: at rounding's floor
    F, tu, ts, th = z
    _, sol = run(z)
    v = sol.sol(np.linspace(tu, ts, 4001))[1]
    assert v.max() <= 1e-10 and v[1:-1].max() > v[1]   # slips throughout, the hump touching 0
    assert tu < th < ts
    # the stick phase's net force stays inside [-mu, mu] until t_u + T
    t = np.linspace(ts, tu + T, 2001)
    net = -(sol.y[0, -1] + vb * (t - ts)) - CB * vb + F * np.cos(W * t)
    assert np.all(np.abs(net[:-1]) <= MU + 1e-12)
    return F, tu, ts, th


@pytest.fixture(scope="module")
def belt_curve():
    br, ev = orbit_models.stick_event(lambda F: belt(F, VB_START), 1.1, T, 40 * 2000, 40, 1.2,
                                      0.02)
    return br, ev, continue_stick_curve(ev, belt, VB_START, 0.34, branch=br, step=0.02,
                                        at=(0.32,), multipliers=2)


def test_the_second_stick_inside_a_slip_against_shooting(belt_curve):
    br, ev, c = belt_curve
    assert br.points[0].signature.describe() == ["(free, slip -)", "(free, stuck)"]
    assert br.points[-1].signature.switches == 4           # two sticks a period past the onset
    assert "located at" in ev.detail and ev.component == 1
    assert c.status == "reached q_end = 0.34"
    checked = [pt for pt in c.points if pt.q in (VB_START, 0.32, 0.34)]
    assert len(checked) == 3
    for pt in checked:
        # the seed from the curve's point; the answer is the shooting's
        assert pt.orbit.signature.describe() == ["(free, slip -)", "(free, stuck)"]
        ts, tu = float(pt.orbit.switches[0]), float(pt.orbit.switches[1]) - T
        th = tu + (pt.t_star - tu) % T
        F, _, ts_ref, _ = second_stick(pt.q, [pt.p, tu, ts, th])
        assert abs(pt.p - F) <= 1e-8, (pt.q, pt.p - F)
        assert abs(pt.p - F) <= pt.p_error
        assert abs(ts - ts_ref) <= 1e-7
        assert pt.side == 1                       # the second stick at larger forcing
    (u,) = [e for e in c.events if e.kind == "user"]
    assert u.q == 0.32
    # the margin held: the least interior minimum of -v on the slip run that starts at b_2
    lay_margin = [m for m in margins(*_layout(c.points[0]), Signature(np.asarray(
        br.points[-1].signature.modes))) if m.kind == "slip"]
    assert lay_margin == [Margin("slip", 1, -1, 2)]
    assert "inside the run from b_2" in lay_margin[0].describe()


def _layout(pt: StickCurvePoint):
    from dmi.analysis.collocation.system import Terms
    from dmi.analysis.plane.stick_curves import _layout_of
    from dmi.analysis.scheme.stepmap import build
    lay, _ = _layout_of(pt.orbit)
    return lay, Terms(build(pt.orbit.make, pt.p), ())
