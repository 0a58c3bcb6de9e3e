# Stick-onset boundaries of collocated orbits continued in (p, q) (continue_stick_curve), against
# values computed here without dmi:
# - Den Hartog's forced dry-friction oscillator x'' + x + F0 sign(x') = F cos(w t), written in the
#   forcing phase s = w t (period 2 pi whatever w): its non-stick orbit in closed form (Den Hartog
#   1931: on a half period x = -F0 + C1 cos(t - t0) + C2 sin(t - t0) + Q cos(w t), Q = F / (1 -
#   w^2), four conditions at the reversals), the stick onset where the net force at a reversal
#   reaches F0: |F cos(w ts) - a| = F0; the boundary F(w) by Brent's method on that, to 1e-8;
# - a rotating oscillator with a memory that slips on a belt: w = u + (0, c), in slip
#   w' = (mu + i W0) w + q |w|^2 w + C2 |w|^4 w - int_0^2 G e^-s w(t - s) ds, whose orbits are the
#   circles of radius r about w = 0, mu = mu_H - q r^2 - C2 r^4 (the Hopf point mu_H from the
#   memory's transform): the velocity u_1 touches 0 at r = c, so the stick onset is
#   mu = mu_H - q c^2 - C2 c^4; the circles' fold at fixed q, r^2 = q / (2 |C2|), meets it at
#   q = 2 |C2| c^2 (the crossing located on the curve); the small circles (r below the fold's)
#   are unstable, the large ones stable;
# - a belt with memory and velocity-weakening friction (the gallery's belt with an exponential
#   memory G e^-8s on [0, 4], its tail e^-32): the curve's points against the grazing orbit
#   solved here by shooting on the smooth slip phase with scipy's DOP853, the memory as a third
#   state z' = G x - 8 z, at three q.
# Also the map's bistable region between the Hopf and stick-onset curves, and the refusals.
# About 70 s on a loaded machine.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import importlib.util
import math
import shutil
import warnings
from pathlib import Path

import numpy as np
import pytest
import scipy.optimize as so
from scipy.integrate import solve_ivp

import dmi
from dmi import analysis as da
from dmi.analysis.continuation.branch import Event
from dmi.analysis.plane.stick_curves import StickCurvePoint, continue_stick_curve

from models import hopf_models, orbit_models

# ---- Den Hartog's oscillator in the forcing phase: p = F, q = w -----------------------------
F0 = 0.3
W_START = 0.7


def den_hartog(F: float, w: float, M: int = 400) -> dmi.Solver:
    """u = (x, dx/ds), s = w t: x_s = y, y_s = (F cos s - x - F0 sign y) / w^2."""
    s = dmi.Solver(2, 2 * math.pi / M, 1)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] - F * math.cos(t)) / w ** 2]))
    s.set_friction([0.0, F0 / w ** 2])
    return s


def den_hartog_onset(w: float) -> float:
    """The forcing F where the net force at the reversal reaches F0 (the stick onset)."""
    return orbit_models.den_hartog_onset(w, F0, 0.34, 0.9)


@pytest.fixture(scope="module")
def den_hartog_curve():
    br, ev = orbit_models.stick_event(lambda F: den_hartog(F, W_START), 1.0, 2 * math.pi,
                                      20 * 400, 24, 0.4, 0.05)
    return br, ev, continue_stick_curve(ev, den_hartog, W_START, 0.8, branch=br, step=0.05,
                                        at=(0.75,), multipliers=2)


def test_den_hartog_onset_against_its_closed_form(den_hartog_curve):
    br, ev, c = den_hartog_curve
    assert abs(ev.p - den_hartog_onset(W_START)) <= 1e-8       # the branch's event itself
    assert c.kind == "stick-onset" and c.status == "reached q_end = 0.8"
    assert c.points[-1].q == 0.8 and len(c.points) >= 4 and np.all(np.diff(c.q) > 0)
    for pt in c.points:
        assert isinstance(pt, StickCurvePoint)
        err = abs(pt.p - den_hartog_onset(pt.q))
        assert err <= 1e-8, (pt.q, err)                          # measured 5e-14
        assert pt.p_error is not None and err <= pt.p_error
        assert pt.orbit.errors["p"] == pt.p_error
        assert pt.orbit.signature.describe() == ["(free, slip +)", "(free, slip -)"]
    (u,) = [e for e in c.events if e.kind == "user"]
    assert u.q == 0.75 and c.points[u.index].q == 0.75
    assert abs(u.p - den_hartog_onset(0.75)) <= 1e-8


def test_den_hartog_verdict_against_the_saltation_multipliers(den_hartog_curve):
    # at the onset the acceleration after a reversal is 0: the saltation S = diag(1, 0), the
    # half period's flow a rotation by pi / w, the monodromy S R S R (the other reversal alike)
    _, _, c = den_hartog_curve
    for pt in (c.points[0], c.points[-1]):
        th = math.pi / pt.q
        R = np.array([[math.cos(th), math.sin(th)], [-math.sin(th), math.cos(th)]])
        S = np.diag([1.0, 0.0])
        inside = bool(np.max(np.abs(np.linalg.eigvals(S @ R @ S @ R))) < 1)
        assert pt.stable is inside


# ---- a rotating oscillator slipping on a belt: closed-form circles -----------------------
W0, TAU, G, C2, CB, ALPHA = 1.0, 2.0, 0.3, -1.0, 0.5, 1.0
KAPPA = -math.expm1(-TAU)
Q0 = 1.0


def rotating(mu: float, q: float) -> dmi.Solver:
    """u = w - (0, c): u' + alpha sigma(u_1) e_2 + f(u) + int G e^-s u = 0 with f chosen so that
    in slip (u_1 < 0) w follows the rotating oscillator with its memory."""
    a = complex(mu, W0)

    def rhs(t, u):
        z = complex(u[0], u[1] + CB)
        r2 = abs(z) ** 2
        v = a * z + q * r2 * z + C2 * r2 * r2 * z
        return np.array([-v.real, -v.imag + ALPHA + G * KAPPA * CB])
    s = dmi.Solver(2, TAU, 100)
    s.set_rhs(rhs)
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0], [0.0], [G * np.eye(2)])
    return s


def rotating_hopf() -> float:
    om = so.brentq(lambda w: w + hopf_models.ghat(1j * w, G, TAU).imag - W0, 0.1, 3.0,
                   xtol=1e-15, rtol=1e-15)
    return hopf_models.ghat(1j * om, G, TAU).real


@pytest.fixture(scope="module")
def rotating_curve():
    mu_h = rotating_hopf()
    make = lambda mu: rotating(mu, Q0)   # noqa: E731
    hp = da.hopf(make, mu_h - 0.2, mu_h + 0.2, [0.0, -CB], of="equation")
    o = da.hopf_orbit(make, hp, [0.0, -CB], amplitude=0.05, of="equation", multipliers=4)
    onset = mu_h - Q0 * CB ** 2 - C2 * CB ** 4
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        br = da.continue_orbit(o, onset - 0.02, step=0.03, multipliers=4, max_points=14)
    ev = [e for e in br.events if e.kind == "stick-onset"][0]
    return br, ev, continue_stick_curve(ev, rotating, Q0, 0.3, branch=br, step=0.1,
                                        at=(0.7,), multipliers=4)


def test_rotating_onset_and_the_fold_crossing_against_the_circles(rotating_curve):
    br, ev, c = rotating_curve
    mu_h = rotating_hopf()
    assert c.status == "reached q_end = 0.3" and c.points[-1].q == 0.3
    for pt in c.points:
        expected = mu_h - pt.q * CB ** 2 - C2 * CB ** 4
        assert abs(pt.p - expected) <= 1e-9, (pt.q, pt.p - expected)   # measured 7e-13
        assert err_bounded(pt, expected)
        # the small circles (below the fold's radius) unstable, the large ones stable
        r_fold = math.sqrt(pt.q / (2 * abs(C2)))
        assert pt.stable is (CB > r_fold)
    (x,) = [e for e in c.events if e.kind == "orbit-fold"]
    q_c = 2 * abs(C2) * CB ** 2
    assert abs(x.q - q_c) <= 1e-8 and abs(x.p - (mu_h - q_c * CB ** 2 - C2 * CB ** 4)) <= 1e-8
    assert "located by Newton" in x.detail
    (u,) = [e for e in c.events if e.kind == "user"]
    assert u.q == 0.7


def err_bounded(pt: StickCurvePoint, expected: float) -> bool:
    return pt.p_error is not None and abs(pt.p - expected) <= pt.p_error


# ---- the belt with memory and velocity-weakening friction: shooting on the slip phase ------
K, LAM, TAU_B = 1.0, 8.0, 4.0
G_B = 0.5 * LAM
MU_S, MU_D, V_S = 0.5, 0.3, 0.3
C_START = 0.3


def weakening(v: float) -> float:
    return -math.copysign((MU_S - MU_D) * -math.expm1(-abs(v) / V_S), v)


def belt(vb: float, c: float) -> dmi.Solver:
    """u = (x, y), y = x' - vb: x'' + c x' + k x + int G e^-8s x(t - s) ds + F(x' - vb) = 0."""
    s = dmi.Solver(2, TAU_B, 80)
    s.set_rhs(lambda t, u: np.array([-(u[1] + vb),
                                     K * u[0] + c * (u[1] + vb) + weakening(u[1])]))
    s.set_friction([0.0, MU_S])
    s.set_kernel_exp([-LAM], [0.0], [[[0.0, 0.0], [G_B, 0.0]]])
    return s


def slip_phase(c: float, vb: float):
    """(x, y, z)' in slip (y < 0), z the memory."""
    def f(t, s):
        x, y, z = s
        return [y + vb, -K * x - c * (y + vb) - (MU_S - MU_D) * -math.expm1(y / V_S) + MU_S - z,
                G_B * x - LAM * z]
    return f


def grazing_orbit(c: float, guess: list[float]) -> tuple[float, float, float]:
    """(z0, T, vb) of the slipping orbit through y = 0 with y' = 0 (x0 from y' = 0), periodic."""
    def run(v):
        z0, T, vb = v
        s0 = [(MU_S - c * vb - z0) / K, 0.0, z0]
        sol = solve_ivp(slip_phase(c, vb), (0.0, T), s0, method="DOP853", rtol=1e-12,
                        atol=1e-14, dense_output=True)
        return np.array(s0), sol
    v, _, ier, msg = so.fsolve(lambda v: run(v)[1].y[:, -1] - run(v)[0], guess,
                               full_output=True, xtol=1e-13)
    s0, sol = run(v)
    # converged, or stalled at the integration's rounding (its steps below xtol's reach)
    assert ier == 1 or np.max(np.abs(sol.y[:, -1] - s0)) <= 1e-14, msg
    y = sol.sol(np.linspace(0.0, v[1], 4001))[1]
    assert y.max() <= 1e-12                       # slips throughout, touching 0 at the start
    return tuple(v)


@pytest.fixture(scope="module")
def belt_curve():
    make = lambda vb: belt(vb, C_START)   # noqa: E731
    x_rest = (MU_D + (MU_S - MU_D) * math.exp(-1.6 / V_S)) / (K + G_B * -math.expm1(
        -LAM * TAU_B) / LAM)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rest = da.continue_equilibrium(da.equilibrium(make, 1.6, [x_rest, -1.6],
                                                      of="equation"), 0.2, step=0.2)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    o = da.hopf_orbit(make, h.hopf, h.u, amplitude=0.05, of="equation", multipliers=4)
    br = da.continue_orbit(o, 0.6, step=0.05, max_points=12, multipliers=4)
    ev = [e for e in br.events if e.kind == "stick-onset"][0]
    return continue_stick_curve(ev, belt, C_START, 0.4, branch=br, step=0.03,
                                at=(0.33, 0.37), multipliers=4)


def test_belt_onset_against_shooting_on_the_slip_phase(belt_curve):
    c = belt_curve
    assert c.status == "reached q_end = 0.4"
    checked = [pt for pt in c.points if pt.q in (0.33, 0.37, 0.4)]
    assert len(checked) == 3
    for pt in checked:
        # the seed from the curve's point; the answer is the shooting's
        x_star = pt.orbit.u_at(np.array([pt.t_star]))[0]
        z0 = MU_S - pt.q * pt.p - K * x_star[0]
        _, T, vb = grazing_orbit(pt.q, [z0, pt.orbit.period, pt.p])
        assert abs(pt.p - vb) <= 1e-7, (pt.q, pt.p - vb)          # measured 2e-9 .. 3e-9
        assert abs(pt.p - vb) <= pt.p_error
        assert abs(pt.orbit.period - T) <= 1e-7
        assert pt.orbit.signature.describe() == ["(free, slip -)"]


# ---- refusals ----------------------------------------------------------------------------
def test_refusals(den_hartog_curve):
    br, ev, _ = den_hartog_curve
    with pytest.raises(ValueError, match="give a 'stick-onset' or 'grazing' event"):   # SC01
        continue_stick_curve(br.points[0], den_hartog, W_START, 0.8, branch=br)
    with pytest.raises(ValueError, match="needs branch="):   # bad-inputs SC02
        continue_stick_curve(ev, den_hartog, W_START, 0.8)
    with pytest.raises(ValueError, match="not one of branch.events"):   # SC03
        continue_stick_curve(Event("stick-onset", ev.p, ev.index, 1, ev.detail), den_hartog,
                             W_START, 0.8, branch=br)
    with pytest.raises(ValueError, match="two different finite values"):   # SC04
        continue_stick_curve(ev, den_hartog, W_START, W_START, branch=br)
    with pytest.raises(ValueError, match="step = -1"):   # bad-inputs SC05
        continue_stick_curve(ev, den_hartog, W_START, 0.8, branch=br, step=-1)
    # a model that is not the branch's at q0: no boundary at the event's p
    with pytest.raises(ValueError, match="no boundary of make2"):   # bad-inputs SC06
        continue_stick_curve(ev, lambda F, w: den_hartog(F + 0.05, w), W_START, 0.8,
                             branch=br)


def test_the_side_where_the_orbits_stick(den_hartog_curve, rotating_curve):
    # Den Hartog: the orbits stick at smaller forcing; the circles on the belt at smaller mu
    # while the small (unstable) circles grow as mu falls, at larger mu past the fold crossing
    # (the large circles grow with mu)
    assert all(pt.side == -1 for pt in den_hartog_curve[2].points)
    for pt in rotating_curve[2].points:
        assert pt.side == (-1 if CB < math.sqrt(pt.q / (2 * abs(C2))) else 1)


def test_the_map_draws_the_curve_and_the_bistable_region(rotating_curve, tmp_path):
    # the Hopf curve mu = mu_H (subcritical for q > 0: c1 = q) and the stick-onset curve, whose
    # circles are unstable for q > 1/2: the bistable region lies between them there
    import matplotlib.pyplot as plt
    _, _, c = rotating_curve
    mu_h = rotating_hopf()
    hp = da.hopf(lambda mu: rotating(mu, Q0), mu_h - 0.2, mu_h + 0.2, [0.0, -CB], of="equation")
    h = da.continue_curve(hp, rotating, Q0, 0.3, u_eq=[0.0, -CB])
    assert all(pt.criticality == "subcritical" for pt in h.points)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ax = da.plot_curves([h, c], p_label="mu", q_label="q", html=tmp_path / "map.html")
    (line,) = [ln for ln in ax.get_lines() if ln.get_color() == "#d94801"]
    assert np.array_equal(line.get_xdata(), c.p)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert {"stick-onset curve", "bistable (from the curves)",
            "codimension-two point"} <= set(labels)
    from dmi.analysis.plane.style import curve_regions
    (bi,) = [(p, q) for name, p, q in curve_regions([h, c]) if name == "bistable"]
    p, q = bi
    k = p.size // 2
    assert abs(q.min() - 0.5) <= 0.2 and q.max() == 1.0
    # one side on the Hopf curve, the other on the stick onset's closed form (interpolated)
    assert np.all(np.abs(p[:k] - mu_h) <= 1e-8)
    on = np.abs(p[k:] - (mu_h - q[k:] * CB ** 2 - C2 * CB ** 4))
    assert np.max(on) <= 2e-3
    text = (tmp_path / "map.html").read_text()
    assert '"curve_regions"' in text
    plt.close("all")
    # hovering the page in headless Chromium (where installed): inside the bistable polygon
    if importlib.util.find_spec("websocket") is None or shutil.which("chromium") is None:
        return
    path = Path(__file__).resolve().parents[3] / "docs" / "browser_check.py"
    spec = importlib.util.spec_from_file_location("browser_check", path)
    bc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bc)
    b = bc.Browser()
    try:
        b.open((tmp_path / "map.html").as_uri())
        assert b.eval(bc.BOKEH_READY_JS) is not None, "BokehJS did not draw the page"
        q = 0.8
        inside = 0.5 * (mu_h + mu_h - q * CB ** 2 - C2 * CB ** 4)
        hover = bc.hover_text(b, "diagram", inside, q)
        assert "bistable (from the curves)" in hover, hover
    finally:
        b.close()
