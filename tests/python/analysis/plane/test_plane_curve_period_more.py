# Curves of forced orbits whose forcing's period changes with q (period= of the plane's curves)
# for the period doubling, the torus and the stick onset, each continued in the forcing frequency
# w with period 2 pi / w:
# - the forced damped Mathieu equation x'' + C x' + (d + E cos w t) x + GAM x^3 = FM cos w t,
#   its period doubling in (d, w): against the doubling solved in the test by shooting with
#   scipy's DOP853 (x(P) = x(0) and det(M + I) = 0, P = 2 pi / w), the other multiplier
#   -exp(-C P) (Liouville), and the same curve of the model written in the forcing's phase
#   s = w t (du/ds = f / w, period 2 pi fixed);
# - the forced van der Pol oscillator x'' + (x^2 - A) x' + x = F cos w t, its torus in (F, w):
#   the pair e^(+-i theta) on the unit circle by the integrator's monodromy, F against
#   det M = 1 solved by shooting, and the forcing's phase form's curve;
# - Den Hartog's dry-friction oscillator x'' + x + F0 sign(x') = F cos w t in time t, its stick
#   onset in (F, w) against the closed form (orbit_models.den_hartog_onset).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

import dmi

from dmi import analysis as da
from dmi.analysis.plane.orbit_curves import continue_flip_curve, continue_torus_curve
from dmi.analysis.plane.stick_curves import continue_stick_curve

try:
    from models import orbit_models
except ImportError:
    import orbit_models

C, E, FM, GAM = 0.1, 0.6, 0.2, 0.05   # the Mathieu equation's damping, e, forcing, cubic term
A = 0.2                                # the van der Pol oscillator's a
F0 = 0.3                               # Den Hartog's friction


def by_w(q: float) -> float:
    """The forcing's period at frequency q."""
    return 2 * math.pi / q


def period(p: float, q: float) -> float:
    return by_w(q)


def solver(f, w: float, phase: bool) -> dmi.Solver:
    """x'' = f(t, x, x', w) forced at frequency w in time t (period 2 pi / w), or in the forcing's
    phase s = w t (``phase``: du/ds = (du/dt) / w, period 2 pi)."""
    s = dmi.Solver(2, 1.0, h=2 * math.pi / 400 / (1.0 if phase else w))
    if phase:
        s.set_rhs(lambda t, u: -np.array([u[1], f(t / w, u[0], u[1], w)]) / w)
    else:
        s.set_rhs(lambda t, u: -np.array([u[1], f(t, u[0], u[1], w)]))
    return s


def mathieu(t: float, x: float, v: float, w: float, d: float) -> float:
    return -C * v - (d + E * math.cos(w * t)) * x - GAM * x ** 3 + FM * math.cos(w * t)


def mathieu_at(d: float, w: float):
    """The Mathieu equation at (d, w) and its Jacobian, as orbit_models.flow's rhs."""
    return lambda t, x: ([x[1], mathieu(t, x[0], x[1], w, d)],
                         [[0.0, 1.0], [-(d + E * math.cos(w * t)) - 3 * GAM * x[0] ** 2, -C]])


def vdp(t: float, x: float, v: float, w: float, F: float) -> float:
    return -(x * x - A) * v - x + F * math.cos(w * t)


def vdp_at(F: float, w: float):
    return lambda t, x: ([x[1], vdp(t, x[0], x[1], w, F)],
                         [[0.0, 1.0], [-1 - 2 * x[0] * x[1], A - x[0] ** 2]])


def make(f, phase: bool = False):
    return lambda p, w: solver(lambda t, x, v, ww: f(t, x, v, ww, p), w, phase)


def branch_event(make2, w0: float, p0: float, p1: float, u0, step: float, kind: str):
    o = da.periodic_orbit(lambda p: make2(p, w0), p0, by_w(w0), np.array(u0), steps=400,
                          multipliers=4)
    b = da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), p1, step=step)
    (e,) = [e for e in b.events if e.kind == kind]
    return b, e


def near(make2, w0: float, orbit) -> da.EquationOrbit:
    """The orbit of make2(., w0) from the state of orbit (an orbit of the same equation in the
    other time), collocated (a curve's start near its bifurcation)."""
    o = da.periodic_orbit(lambda p: make2(p, w0), orbit.p, 2 * math.pi, orbit.u_at(0.0),
                          steps=400, multipliers=4)
    return da.collocate(o, multipliers=6, intervals=40)


def on(curve, at: tuple[float, ...]) -> dict:
    got = {pt.q: pt for pt in curve.points if pt.q in at}
    assert sorted(got) == sorted(at)
    return got


# ---- the period doubling ---------------------------------------------------------------------
FLIP_AT = (1.05, 1.1)


def test_a_flip_curve_in_the_forcing_frequency():
    # at w = 1 the model in time and in the forcing's phase coincide: one branch starts both
    b, e = branch_event(make(mathieu), 1.0, 0.7, 0.4, [-0.65, 0.0], 0.02, "period-doubling")
    c = continue_flip_curve(e, make(mathieu), 1.0, FLIP_AT[-1], branch=b, step=0.05, at=FLIP_AT,
                            period=period)
    assert c.status == f"reached q_end = {FLIP_AT[-1]}"
    cp = continue_flip_curve(e, make(mathieu, True), 1.0, FLIP_AT[-1], branch=b, step=0.05,
                             at=FLIP_AT)
    phase = on(cp, FLIP_AT)
    for w, pt in [(1.0, c.points[0])] + sorted(on(c, FLIP_AT).items()):
        P = by_w(w)
        assert not pt.orbit.autonomous and abs(pt.orbit.period - P) <= 1e-12 * P
        x0, d = orbit_models.forced_bifurcation(
            lambda dd: mathieu_at(dd, w), P, np.append(pt.orbit.u_at(0.0), pt.p),
            lambda M: np.linalg.det(M + np.eye(2)))
        assert abs(pt.p - d) <= 1e-9 and abs(pt.p - d) <= pt.p_error, (w, pt.p - d)
        assert np.max(np.abs(x0 - pt.orbit.u_at(0.0))) <= 1e-8
        mu = np.linalg.eigvals(orbit_models.flow(mathieu_at(d, w), 2, P, x0)[1])
        mu = mu[np.argsort(np.abs(mu + 1))]
        assert abs(mu[0] + 1) <= 1e-9
        assert abs(mu[1] + math.exp(-C * P)) <= 1e-9     # Liouville: mu_1 mu_2 = exp(-C P)
        assert np.min(np.abs(pt.orbit.multipliers - mu[1])) <= 1e-8
        assert pt.stable is True
        if w in phase:   # the same doubling in the forcing's phase
            assert abs(phase[w].p - pt.p) <= 1e-9, (w, phase[w].p - pt.p)
            assert np.allclose(phase[w].orbit.u_at(0.0), pt.orbit.u_at(0.0), atol=1e-8)
    # the period changed along the curve: not the fixed period's curve
    assert abs(c.points[-1].orbit.period - by_w(1.0)) > 0.5


# ---- the torus -------------------------------------------------------------------------------
TORUS_AT = (1.55, 1.6)


def test_a_torus_curve_in_the_forcing_frequency():
    b, e = branch_event(make(vdp), 1.5, 1.0, 0.6, [-1.0, 0.0], 0.05, "torus")
    c = continue_torus_curve(e, make(vdp), 1.5, TORUS_AT[-1], branch=b, step=0.05, at=TORUS_AT,
                             period=period)
    assert c.status == f"reached q_end = {TORUS_AT[-1]}"
    start = near(make(vdp, True), 1.5, b.points[e.index])
    cp = continue_torus_curve(start, make(vdp, True), 1.5, TORUS_AT[-1], step=0.05, at=TORUS_AT)
    phase = on(cp, TORUS_AT)
    for w, pt in [(1.5, c.points[0])] + sorted(on(c, TORUS_AT).items()):
        P = by_w(w)
        assert not pt.orbit.autonomous and abs(pt.orbit.period - P) <= 1e-12 * P
        x0, M = orbit_models.flow(vdp_at(pt.p, w), 2, P, pt.orbit.u_at(0.0))
        assert np.max(np.abs(x0 - pt.orbit.u_at(0.0))) <= 1e-8
        mu = np.linalg.eigvals(M)
        assert abs(mu[0].imag) > 0.1                              # a complex pair
        assert np.all(np.abs(np.abs(mu) - 1) <= 1e-9)
        assert abs(abs(np.angle(mu[0])) - pt.theta) <= 1e-9
        assert abs(abs(np.angle(mu[0])) - pt.theta) <= pt.theta_error
        _, F = orbit_models.forced_bifurcation(lambda FF: vdp_at(FF, w), P,
                                               np.append(x0, pt.p),
                                               lambda M: np.linalg.det(M) - 1)
        assert abs(pt.p - F) <= 1e-9 and abs(pt.p - F) <= pt.p_error, (w, pt.p - F)
        if w in phase:
            assert abs(phase[w].p - pt.p) <= 1e-9, (w, phase[w].p - pt.p)
            assert abs(phase[w].theta - pt.theta) <= 1e-9
            assert np.allclose(phase[w].orbit.u_at(0.0), pt.orbit.u_at(0.0), atol=1e-8)
    assert c.points[-1].theta - c.points[0].theta > 0.2   # the pair turned with w


# ---- the stick onset -------------------------------------------------------------------------
def den_hartog(F: float, w: float, M: int = 400) -> dmi.Solver:
    """u = (x, x') in time t, h = (2 pi / w) / M."""
    s = dmi.Solver(2, by_w(w) / M, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] - F * math.cos(w * t)]))
    s.set_friction([0.0, F0])
    return s


def test_a_stick_onset_curve_in_the_forcing_frequency():
    make1 = lambda F: den_hartog(F, 0.7)   # noqa: E731
    s = make1(0.5)
    s.init()
    s.advance(8000)
    o = da.periodic_orbit(make1, 0.5, by_w(0.7), s, multipliers=0)
    br = da.continue_orbit(da.collocate(o, intervals=24, multipliers=2), 0.38, step=0.02,
                           multipliers=2)
    (ev,) = [x for x in br.events if x.kind == "stick-onset"]
    c = continue_stick_curve(ev, den_hartog, 0.7, 0.8, branch=br, step=0.05, at=(0.75,),
                             multipliers=2, period=period)
    assert c.status == "reached q_end = 0.8" and len(c.points) >= 3
    for pt in c.points:
        assert abs(pt.orbit.period - by_w(pt.q)) <= 1e-12 * by_w(pt.q)
        err = abs(pt.p - orbit_models.den_hartog_onset(pt.q, F0, 0.34, 0.9))
        assert err <= 1e-10 and err <= pt.p_error, (pt.q, err)
        assert pt.orbit.signature.describe() == ["(free, slip +)", "(free, slip -)"]
        assert pt.side == -1
