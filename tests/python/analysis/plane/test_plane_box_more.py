# A second contact inside a free run and a lift-off inside a stretch on the face of collocated
# orbits with a box, located on a branch and continued in (p, q) (continue_stick_curve), against
# an event-driven solve written here without dmi: the forced oscillator of test_plane_box_curves
# with two harmonics, w^2 x'' + c w x' + x = F (cos s - cos 2s / 2) in the forcing phase s = w t,
# its position held by x <= 1 (x' + N(x) ∋ y, y = dx/ds); its forcing has two humps a period:
# - F growing (w = 0.3, F near 1.09): the orbit that rests on the face once a period touches it
#   again inside its free run (x's interior maximum reaches 1, "box" run margin);
# - F falling (w = 0.3, F near 1.68): the net force y on the face stretch dips to 0 inside it
#   (y's interior minimum, the "face" margin) and the contact splits in two.
# The reference: the orbit from its lift-off s_l (x = 1, y = 0) through its free flight and its
# stretch on the face back to s_l + 2 pi by DOP853 with events (orbit_models.box_shoot), the
# touch at s* (x = 1, y = 0, or y = 0, y_s = 0 on the face) among the equations, solved by
# fsolve for (F, s_l, s*).
# About 55 s on an idle machine.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so
from scipy.integrate import solve_ivp

import dmi
from dmi.analysis.collocation.margins import Margin, MarginValues, margins
from dmi.analysis.collocation.signature import FREE, HI, Signature

from models import orbit_models

C, G, W0 = 0.3, -0.5, 0.3
TOL = dict(method="DOP853", rtol=1e-13, atol=1e-15)


def boxed(F: float, w: float, M: int = 400) -> dmi.Solver:
    """u = (x, y): x_s + N_(-inf, 1](x) ∋ y, y_s = (F (cos s + G cos 2s) - x - c w y) / w^2."""
    s = dmi.Solver(2, 2 * math.pi / M, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] + C * w * u[1]
                                             - F * (math.cos(t) + G * math.cos(2 * t))) / w ** 2]))
    s.set_box([-math.inf, -math.inf], [1.0, math.inf])
    return s


def _force(F: float):
    return lambda s: F * (math.cos(s) + G * math.cos(2 * s))


def _solved(eqs, guess: list[float]) -> np.ndarray:
    z, _, ier, msg = so.fsolve(eqs, guess, full_output=True, xtol=1e-14)
    res = max(map(abs, eqs(z)))
    assert res <= 1e-10, (ier, msg, res)   # the event times' rounding stalls fsolve near 1e-12
    return z


def second_contact(w: float, guess: list[float]) -> np.ndarray:
    """(F, s_l, s*): the orbit leaves the face at s_l, its free flight touches x = 1 at s* (y =
    0 there) and arrives on the face later; the stretch there ends at s_l + 2 pi."""
    def eqs(v):
        F, sl, ss = v
        force = _force(F)
        a = solve_ivp(lambda s, z: [z[1], (force(s) - z[0] - C * w * z[1]) / w ** 2], (sl, ss),
                      [1.0, 0.0], **TOL)
        xs, ys = a.y[:, -1]
        _, se, _ = orbit_models.box_shoot(force, C, w, ss, [xs, ys])
        return [se - sl - 2 * math.pi, xs - 1.0, ys]
    return _solved(eqs, guess)


def lift_off(w: float, guess: list[float]) -> np.ndarray:
    """(F, s_l, s*): the orbit leaves the face at s_l, arrives on it after its free flight and
    stays until s_l + 2 pi (y = 0 there), its net force y touching 0 at s* inside (y = 0, y_s =
    0 there); the stretch without events, y at s* from its dense output."""
    def eqs(v):
        F, sl, ss = v
        force = _force(F)
        _, _, b = orbit_models.box_shoot(force, C, w, sl, [1.0, 0.0], s_end=sl + 2 * math.pi)
        ys = float(b.sol(ss)[0])
        return [float(b.y[0, -1]), ys, force(ss) - 1.0 - C * w * ys]
    return _solved(eqs, guess)


def _curve(p0: float, p_end: float, step: float):
    from dmi import analysis as da
    br, ev = orbit_models.stick_event(lambda F: boxed(F, W0), p0, 2 * math.pi, 20 * 400, 32,
                                      p_end, step)
    return br, ev, da.continue_curve(ev, boxed, W0, 0.32, branch=br, step=0.01, multipliers=2)


def _face_switches(sig) -> tuple[int, int]:
    """(k_a, k_l) of an orbit that rests on the face once a period: it arrives on the face at
    b_(k_a) and leaves it at b_(k_l) (piece k mod S of the signature starts at b_k)."""
    modes = np.asarray(sig.modes)[:, 0]
    S = modes.size
    on = [k for k in range(1, S + 1) if modes[k % S] == HI]
    assert len(on) == 1, modes
    return on[0], on[0] % S + 1


def _pieces(sig) -> set[tuple[int, ...]]:
    """The signature's pieces' modes, whatever their order."""
    return {tuple(int(v) for v in row) for row in np.asarray(sig.modes)}


def _check_branch(br, ev, p_end: float) -> None:
    """The branch reached p_end from orbits that rest on the face once a period (a free piece
    and one on the face) to orbits with two contacts (four switches), its event on x."""
    assert br.status == f"reached p_end = {p_end}" and ev.component == 0
    sig = br.points[0].signature
    assert sig.switches == 2 and _pieces(sig) == {(FREE, FREE), (HI, FREE)}
    assert br.points[-1].signature.switches == 4


def _check(c, oracle):
    assert c.kind == "stick-onset" and c.status == "reached q_end = 0.32"
    assert len(c.points) >= 3 and np.all(np.diff(c.q) > 0)
    errs = []
    for pt in c.points:
        sl = float(pt.orbit.switches[_face_switches(pt.orbit.signature)[1] - 1])
        ss = sl + (pt.t_star - sl) % (2 * math.pi)
        F, sl_ref, ss_ref = oracle(pt.q, [pt.p, sl, ss])
        errs.append((pt.q, pt.p - F, sl - sl_ref, ss - ss_ref))
    for q, dF, dsl, dss in errs:
        # measured: F within 3e-9, s_l within 4e-9, s* within 2e-7 (a flat extremum)
        assert abs(dF) <= 1e-8 and abs(dsl) <= 1e-7 and abs(dss) <= 1e-5, (q, dF, dsl, dss)


@pytest.fixture(scope="module")
def contact_curve():
    return _curve(1.04, 1.12, 0.01)


@pytest.fixture(scope="module")
def lift_curve():
    return _curve(1.8, 1.6, 0.02)


def test_a_second_contact_inside_the_free_run(contact_curve):
    br, ev, c = contact_curve
    _check_branch(br, ev, 1.12)
    assert abs(ev.p - c.points[0].p) <= 1e-10     # the curve starts at the branch's event
    _check(c, second_contact)
    lay, terms, x = _layout(c.points[0])
    got = margins(lay, terms, Signature(np.asarray(br.points[-1].signature.modes)))
    # both candidates, in any order: the face stretch from the arrival and the free run from
    # the lift-off, the one held (x's interior maximum on it at the face: 0 at the curve)
    ka, kl = _face_switches(c.points[0].orbit.signature)
    assert len(got) == 2 and set(got) == {Margin("face", 0, 1, ka), Margin("box", 0, 1, kl)}
    held = MarginValues(lay, Margin("box", 0, 1, kl)).least(terms, x)[0]
    assert abs(held) <= 1e-8, held


def test_a_lift_off_inside_the_face_stretch(lift_curve):
    br, ev, c = lift_curve
    _check_branch(br, ev, 1.6)
    _check(c, lift_off)
    lay, terms, x = _layout(c.points[0])
    got = [m for m in margins(lay, terms, Signature(np.asarray(br.points[-1].signature.modes)))
           if m.kind == "face"]
    # the stretch on the hi face from the arrival, held: its net force's interior minimum 0
    ka, _ = _face_switches(c.points[0].orbit.signature)
    assert got == [Margin("face", 0, 1, ka)]
    held = MarginValues(lay, got[0]).least(terms, x)[0]
    assert abs(held) <= 1e-8, held


def _layout(pt):
    from dmi.analysis.collocation.system import Terms
    from dmi.analysis.plane.stick_curves import _layout_of
    from dmi.analysis.scheme.stepmap import build
    lay, x = _layout_of(pt.orbit)
    return lay, Terms(build(pt.orbit.make, pt.p), ()), x
