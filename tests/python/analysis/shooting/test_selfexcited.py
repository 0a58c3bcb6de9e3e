# Self-excited oscillations: equilibria and their branches, the orbit born at a Hopf point, and
# autonomous continuation into stick-slip, against closed forms derived here and long plain runs;
# and the silent wrong answers refused.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.core.newton import NO_PROGRESS, newton
from models.damped_belt import ALPHA, GB, KB, VB, belt
from models.orbit_models import DenHartog

# ---- a closed-form autonomous orbit with a distributed delay ------------------------------------
# u' = (mu - |u|^2) u + w0 J u - int_0^tau g(s) u(t - s) ds in R^2, J the rotation by pi/2,
# g(s) = k e^(-a s).  In z = u_1 + i u_2: z' = (mu - |z|^2) z + i w0 z - int g(s) z(t - s) ds.
# z = r e^(i w t): i w = mu - r^2 + i w0 - G(w), G(w) = int_0^tau g(s) e^(-i w s) ds, so
# r^2 = mu - Re G(w) and w = w0 - Im G(w) (the ghat(w) = conj G(w)).  r = 0: the Hopf
# point mu_H = Re G(w) with the same w, which does not depend on mu: the period is constant along
# the branch.  In dmi's form u' + f + int H u = 0: f = -(mu - |u|^2) u - w0 J u, H = g I.
W0, KG, AG, TAU = 1.0, 0.5, 1.0, 1.0


def G(w: float) -> complex:
    z = -AG - 1j * w
    return KG * (np.exp(z * TAU) - 1) / z


OMEGA = so.brentq(lambda w: w - W0 + G(w).imag, 0.1, 3.0)
MU_H = G(OMEGA).real


def landau(mu: float, h: float | None = None, N: int = 100) -> dmi.Solver:
    s = dmi.Solver(2, TAU, N) if h is None else dmi.Solver(2, TAU, h=h)

    def f(t, u):
        g = mu - u[0] ** 2 - u[1] ** 2
        return np.array([-g * u[0] + W0 * u[1], -g * u[1] - W0 * u[0]])
    s.set_rhs(f)
    s.set_kernel_exp([-AG], [0.0], [KG * np.eye(2)])
    return s


def test_closed_form_constants():
    # the closed form itself: the linear equation's root at mu_H is i omega (independent check
    # of G by quadrature)
    from scipy.integrate import quad
    re = quad(lambda s: KG * np.exp(-AG * s) * np.cos(OMEGA * s), 0, TAU)[0]
    im = -quad(lambda s: KG * np.exp(-AG * s) * np.sin(OMEGA * s), 0, TAU)[0]
    assert G(OMEGA) == pytest.approx(complex(re, im), abs=1e-12)
    assert 0.2 < MU_H < 0.3 and 1.0 < OMEGA < 1.3


def _hopf_event(N: int) -> da.Event:
    make = (lambda mu, h=None: landau(mu, h, N))
    eq = da.equilibrium(make, 0.0, [0.02, -0.01])
    assert np.max(np.abs(eq.u)) < 1e-10 and eq.stable
    br = da.continue_equilibrium(eq, 0.6, step=0.1)
    assert br.kind == "equilibria" and br.status.startswith("reached")
    hopf = [e for e in br.events if e.kind == "hopf"]
    assert len(hopf) == 1 and not [e for e in br.events if e.kind == "fold"], br.events
    assert br.stable[0] and not br.stable[-1]
    return hopf[0]


def test_equilibrium_branch_finds_the_hopf_point_at_order_one():
    errs = []
    for N in (50, 100, 200):
        e = _hopf_event(N)
        hp = e.hopf
        assert abs(hp.root.real) < 1e-8          # located on the branch, not interpolated
        assert hp.omega == pytest.approx(hp.root.imag)
        errs.append((abs(hp.p - MU_H), abs(hp.omega - OMEGA)))
    errs = np.array(errs)
    ratios = errs[:-1] / errs[1:]
    assert np.all((ratios > 1.7) & (ratios < 2.4)), (errs, ratios)   # order 1 in h
    assert errs[-1, 0] < 5e-3


def _branch_error(N: int) -> tuple[float, float, da.Branch]:
    make = (lambda mu, h=None: landau(mu, h, N))
    e = _hopf_event(N)
    M = round(2 * math.pi / e.hopf.omega / (TAU / N))
    o = da.hopf_orbit(make, e.hopf, e.u, amplitude=0.1, steps=M, component=0)
    assert o.autonomous and o.amplitude[0] == pytest.approx(0.1, rel=1e-9)
    br = da.continue_orbit(o, 0.6, step=0.05, max_points=5, multipliers=4)
    assert br.kind == "autonomous" and len(br.points) == 5
    assert not br.events, br.events                  # no phase multiplier read as an event
    assert np.all(br.stable), [q.multipliers for q in br.points]
    r = br.column("amplitude")[:, 0]
    assert np.all(np.diff(r) > 0) and r[-1] > 0.3
    err_p = np.max(np.abs(br.p - (MU_H + r ** 2)))   # the branch p(r) = mu_H + r^2
    err_P = np.max(np.abs(br.column("period") - 2 * math.pi / OMEGA))
    return err_p, err_P, br


def test_hopf_orbit_and_its_continuation_match_the_closed_form_at_order_one():
    e1 = _branch_error(50)
    e2 = _branch_error(100)
    for a, b in zip(e1[:2], e2[:2]):
        assert 1.6 < a / b < 2.5, (e1[:2], e2[:2])
    assert e2[0] < 0.02 and e2[1] < 0.02


# ---- a belt with a memory that destabilises sliding ---------------------------------------------
# x' = v + v_b, v' + k x + c (v + v_b) + alpha sigma(v) + (g / tau) int_0^tau x(t - s) ds ∋ 0,
# v = x' - v_b; sliding equilibrium x = alpha / (k + g), v = -v_b; the memory makes it lose
# stability as the damping c falls.  While the orbit slips the system is linear: the branch leaves
# the Hopf point vertically up to grazing (v reaches 0), then sticks (models/damped_belt.py).
def _plain_run(c: float, h: float, M: int) -> tuple[float, float, np.ndarray]:
    """Period (upward crossings of x's mean, interpolated) and half range of v over the last
    periods of a long run from the sliding equilibrium kicked."""
    s = belt(c, h=h)
    x_eq = ALPHA / (KB + GB)
    s.set_history(lambda t: np.array([x_eq + 0.05, -VB]))
    s.init()
    _, U = s.run(80 * M)
    x = U[-20 * M:, 0]
    y = x - 0.5 * (x.max() + x.min())
    k = np.nonzero((y[:-1] < 0) & (y[1:] >= 0))[0]
    t = (k + y[k] / (y[k] - y[k + 1])) * h
    v = U[-5 * M:, 1]
    return float(np.mean(np.diff(t))), 0.5 * float(v.max() - v.min()), U


def test_belt_from_equilibrium_to_stick_slip_against_plain_runs():
    eq = da.equilibrium(belt, 1.0, [0.2, -0.2])
    assert eq.u == pytest.approx([ALPHA / (KB + GB), -VB], abs=1e-12)
    br = da.continue_equilibrium(eq, -0.5, step=0.2)
    hopf = [e for e in br.events if e.kind == "hopf"]
    assert len(hopf) == 1
    o = da.hopf_orbit(belt, hopf[0].hopf, hopf[0].u, amplitude=0.1, steps=200)
    assert abs(o.p - hopf[0].p) < 0.01 and np.max(o.stick_fraction) == 0
    b = da.continue_orbit(o, 0.0, step=0.02, max_points=16, multipliers=4)
    kinds = [e.kind for e in b.events]
    assert "fold" not in kinds, b.events     # the vertical stretch is no fold
    assert "stick-onset" in kinds, b.events
    stuck = [q for q in b.points if q.stick_steps[1] > 0]
    assert len(stuck) >= 4
    # before grazing: vertical (p constant), v's half range below v_b
    slip = [q for q in b.points if q.stick_steps[1] == 0]
    assert np.ptp([q.p for q in slip]) < 1e-6 and all(q.amplitude[1] < VB + 1e-9 for q in slip)
    # the stick onset is the vertical stretch's top: located along the branch, at its p
    onset = [e for e in b.events if e.kind == "stick-onset"][0]
    span = abs(b.points[onset.index].p - b.points[onset.index - 1].p)
    assert abs(onset.p - slip[0].p) <= span / 32, (onset, slip[0].p, span)
    for q in stuck[1::2]:
        h = q.period / b.steps
        P, A, _ = _plain_run(q.p, h, b.steps)
        assert q.stable
        assert abs(P - q.period) <= h, (q.p, P, q.period)
        assert abs(A - q.amplitude[1]) <= 1e-3 * A, (q.p, A, q.amplitude)


# ---- no silent wrong answers --------------------------------------------------------------------
def test_autonomous_shooting_onto_the_equilibrium_is_refused():
    make = (lambda mu, h=None: landau(mu, h, 50))
    P = 2 * math.pi / OMEGA
    s = landau(0.1, h=P / 100, N=50)   # mu below mu_H: the equilibrium attracts
    s.set_history(lambda t: np.array([1e-11 * np.cos(OMEGA * t), 1e-11 * np.sin(OMEGA * t)]))
    s.init()
    with pytest.raises(da.ShootingError, match="equilibrium, not an orbit"):
        da.periodic_orbit(make, 0.1, guess=s.get_window(), guess_period=P, steps=100)


def test_a_period_that_is_not_the_models_is_refused():
    def make(p):   # u' + u = cos t: the map over 3 pi (1.5 periods) contracts to a fixed point
        s = dmi.Solver(1, 2 * math.pi / 400, 1)
        s.set_rhs(lambda t, u: np.array([u[0] - np.cos(t)]))
        return s
    o = da.periodic_orbit(make, 0.0, 2 * math.pi, [0.0], multipliers=0)   # the true period
    assert o.amplitude[0] > 0.5
    with pytest.raises(ValueError, match="not a period of the model"):
        da.periodic_orbit(make, 0.0, 3 * math.pi, [0.0], multipliers=2)


def test_newton_gives_up_without_progress_and_lists_every_residual():
    def F(x):   # x + 1 + sin(3 x) / 2 has no fixed point; I - DF is rarely singular
        return x + 1 + 0.5 * np.sin(3 * x)
    with pytest.raises(da.ShootingError, match="no progress") as e:
        newton(F, np.array([0.3]), max_iter=50)
    res = e.value.residuals
    best = int(np.argmin(res))
    assert len(res) == best + 1 + NO_PROGRESS            # stopped right after 3 iterations
    assert len(res) < 50
    assert all(f"{r:.2g}" in str(e.value) for r in res)  # every residual listed


def test_forced_guess_of_the_wrong_shape_names_n():
    dh = DenHartog()
    with pytest.raises(ValueError, match=r"n = 2: give n = 2 values.*N \+ 1 = 2 <= k"):
        da.periodic_orbit(dh.make_for(400), 1.0, dh.T, np.zeros((3, 3)))


def test_nan_from_the_rhs_names_the_call_and_p():
    def make(p):
        s = dmi.Solver(1, 0.01, 1)
        s.set_rhs(lambda t, u: np.array([np.nan if u[0] > 0.3 else -np.cos(t)]))
        return s
    with pytest.raises(da.ShootingError, match=r"p = 2\.0.*f\(.*nan"):
        da.periodic_orbit(make, 2.0, 6.28, [0.0])


def test_make_failing_is_the_models_exception_with_a_note():
    def make(p, h=None):
        if p > 1:
            raise KeyError("p too large")
        return landau(p, h, 50)
    with pytest.raises(KeyError) as e:
        da.equilibrium(make, 2.0, [0.0, 0.0])
    assert any("make(p = 2.0)" in n for n in e.value.__notes__)
    eq = da.equilibrium(make, 0.0, [0.0, 0.0])
    br = da.continue_equilibrium(eq, 1.5, step=0.3)   # stops where make refuses, no raise
    assert br.p[-1] <= 1.0 and "failed" in br.status


def test_an_equilibrium_guess_off_by_7e_9_is_corrected():
    # the continuous equation's equilibrium of the belt is the scheme's too (the kernel's
    # integral: tau g / tau); one moved by 7e-9 is corrected, and a rough guess converges
    eq = da.equilibrium(belt, 0.5, [0.28 + 7e-9, -0.3])
    assert eq.u == pytest.approx([ALPHA / (KB + GB), -VB], abs=1e-13)
    assert eq.residual <= 1e-10 and eq.roots.size and eq.stable


# ---- a forced pure-slip orbit near stick onset, and a forced branch through it -----------------
# The belt with memory forced: v' + ... = F cos(w t).  While v < 0 throughout (pure slip) the
# friction force is the constant -alpha and the system is linear: the M-step map's multipliers
# are exactly z^M = exp(lambda P) for the scheme's roots lambda of the unforced equilibrium
# (dmi.analysis.roots), and the response's amplitude is proportional to F, so that stick onset
# (max v = 0) is at F_on = v_b F_1 / A_1 from one orbit at a small F_1.
CF, WF, MF = 0.6, 1.3, 400
PF = 2 * math.pi / WF


def forced_belt(F: float) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=PF / MF)
    s.set_rhs(lambda t, u: np.array([-(u[1] + VB),
                                     KB * u[0] + CF * (u[1] + VB) - F * np.cos(WF * t)]))
    s.set_kernel_exp([0.0], [0.0], [np.array([[0.0, 0.0], [GB / TAU, 0.0]])])
    s.set_friction([0.0, ALPHA])
    return s


U_EQ = [ALPHA / (KB + GB), -VB]


@pytest.fixture(scope="module")
def onset() -> tuple[float, np.ndarray]:
    o = da.periodic_orbit(forced_belt, 0.01, PF, U_EQ, multipliers=0)
    assert o.u[:, 1].mean() == pytest.approx(-VB, abs=1e-3) and np.max(o.stick_fraction) == 0
    lam = da.roots(forced_belt, 0.0, U_EQ, 8)
    mu = np.exp(lam * PF)
    return 0.01 * VB / o.amplitude[1], mu[np.argsort(-np.abs(mu))]


def _close(got: np.ndarray, want: np.ndarray, rel: float) -> bool:
    """The leading multipliers agree (each of want's two largest has one of got within rel)."""
    return all(np.min(np.abs(got - w)) <= rel * abs(w) for w in want[:2])


def test_pure_slip_multipliers_near_stick_onset_are_exp_lambda_P(onset):
    F_on, mu = onset
    o = da.periodic_orbit(forced_belt, 0.995 * F_on, PF, U_EQ, multipliers=6)
    assert np.max(o.stick_fraction) == 0 and -0.01 * VB < o.u[:, 1].max() < 0   # just below
    assert _close(o.multipliers, mu, 1e-6), (o.multipliers, mu[:2])   # (the issue asks 0.5 %)


def test_forced_branch_passes_stick_onset_both_ways(onset):
    F_on, mu = onset
    for a, b in ((0.9, 1.6), (1.6, 0.8)):
        o = da.periodic_orbit(forced_belt, a * F_on, PF, U_EQ, multipliers=6)
        br = da.continue_orbit(o, b * F_on, step=0.05 * F_on, max_points=40)
        assert br.status.startswith("reached"), br.status
        kinds = [e.kind for e in br.events]
        assert kinds == ["stick-onset"], br.events
        assert abs(br.events[0].p / F_on - 1) < 2e-3, br.events
        for q in br.points:
            if q.p < 0.999 * F_on:
                # pure slip: the branch's multipliers are exp(lambda P) (the linear response)
                assert q.stick_steps[1] == 0 and _close(q.multipliers, mu, 1e-3), \
                    (q.p / F_on, q.multipliers, mu[:2])
            elif q.p > 1.01 * F_on:
                assert q.stick_steps[1] > 0


def test_a_guess_period_too_long_says_so():
    make = (lambda mu, h=None: landau(mu, h, 50))
    P = 2 * math.pi / OMEGA
    s = landau(0.4, h=1.6 * P / 200, N=50)   # on the orbit (r^2 ~ mu - mu_H), 1.6 periods long
    s.set_history(lambda t: np.array([0.36 * np.cos(OMEGA * t), 0.36 * np.sin(OMEGA * t)]))
    s.init()
    s.advance(1000)
    with pytest.raises(da.ShootingError, match="guess period is too long") as e:
        da.periodic_orbit(make, 0.4, guess=s, guess_period=1.6 * P, steps=200)
    assert "rows = " not in str(e.value)


def test_hopf_takes_the_equilibrium_tolerance():
    make = (lambda mu: landau(mu, None, 50))
    u = [1e-8, 0.0]   # one step moves it by about h 1e-8 = 2e-10 (state units)
    with pytest.raises(ValueError, match="not an equilibrium"):
        da.hopf(make, 0.1, 0.4, u, tol=1e-11)
    hp = da.hopf(make, 0.1, 0.4, u, tol=1e-8)
    assert hp.p == pytest.approx(_hopf_event(50).p, rel=1e-8)


def test_plot_branch_draws_equilibria_and_amplitudes_with_labelled_axes():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    make = (lambda mu, h=None: landau(mu, h, 50))
    eb = da.continue_equilibrium(da.equilibrium(make, 0.0, [0.0, 0.0]), 0.5, step=0.1)
    e = [q for q in eb.events if q.kind == "hopf"][0]
    ob = da.continue_orbit(da.hopf_orbit(make, e.hopf, e.u, amplitude=0.1, steps=277,
                                         component=0), 0.5, step=0.05, max_points=3)
    fig, (a1, a2) = plt.subplots(1, 2)
    da.plot_branch(eb, a1, component=1)
    da.plot_branch(ob, a2, component=0, p_label="mu")
    ys = np.concatenate([ln.get_ydata() for ln in a1.lines if len(ln.get_ydata()) > 1])
    assert np.allclose(np.unique(ys), np.unique([q.u[1] for q in eb.points]))
    star = [ln for ln in a1.lines if ln.get_marker() == "*"]
    assert len(star) == 1 and star[0].get_xdata()[0] == e.p
    ys = np.concatenate([ln.get_ydata() for ln in a2.lines if len(ln.get_ydata()) > 1])
    assert np.allclose(np.sort(np.unique(ys)), np.sort(ob.column("amplitude")[:, 0]))
    assert a1.get_xlabel() == "parameter p" and "equilibrium" in a1.get_ylabel()
    assert a2.get_xlabel() == "mu" and "amplitude" in a2.get_ylabel()
    plt.close(fig)


def test_branch_points_keep_a_thinned_period():
    make = (lambda mu, h=None: landau(mu, h, 50))
    e = _hopf_event(50)
    o = da.hopf_orbit(make, e.hopf, e.u, amplitude=0.1, steps=600, component=0)
    br = da.continue_orbit(o, 0.5, step=0.05, max_points=2, multipliers=0)
    for q in br.points:
        assert q.u.shape == (200, 2) and q.t[0] == 0 and q.t[-1] == pytest.approx(q.period)
        r = np.hypot(q.u[:, 0], q.u[:, 1])             # a circle of the amplitude's radius
        assert np.allclose(r, q.amplitude[0], rtol=2e-3)


def test_belt_from_stick_slip_back_through_grazing_onto_the_vertical_branch():
    # the other direction: from a stick-slip orbit, c growing, through grazing onto the vertical
    # stretch at the Hopf point's c, amplitude falling
    M, P = 200, 4.98
    s = belt(0.33, h=P / M)
    s.set_history(lambda t: np.array([ALPHA / (KB + GB) + 0.05, -VB]))
    s.init()
    s.advance(round(80 / s.h))
    o = da.periodic_orbit(belt, 0.33, guess=s, guess_period=P, steps=M, multipliers=4)
    assert o.stick_fraction[1] > 0
    b = da.continue_orbit(o, 0.5, step=0.02, max_points=12, multipliers=4)
    kinds = [e.kind for e in b.events]
    assert kinds == ["stick-onset"], b.events
    slip = [q for q in b.points if q.stick_steps[1] == 0]
    assert len(slip) >= 4, [(q.p, q.stick_steps) for q in b.points]
    amp = [q.amplitude[1] for q in slip]
    assert np.ptp([q.p for q in slip[1:]]) < 1e-6 and np.all(np.diff(amp) < 0), (amp, slip)
    hp = da.hopf(lambda c: belt(c, h=P / M), 0.3, 0.45, [ALPHA / (KB + GB), -VB])
    assert abs(slip[-1].p - hp.p) < 1e-3, (slip[-1].p, hp.p)   # the vertical stretch's c
