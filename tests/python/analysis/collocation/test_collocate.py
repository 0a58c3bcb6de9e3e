# dmi.analysis.collocate: periodic orbits of the equation against references computed here, not by
# the code under test: van der Pol with a distributed delay by a Fourier spectral solve (the delay
# integral exact on each Fourier mode) and its second multiplier by Hill's method on the same
# Fourier basis; the circles of a rotating system with a damped-cosine memory in closed form (from
# the kernel's transform at the circle's frequency); Den Hartog's dry-friction oscillator in closed
# form (models/orbit_models.py), the stick-slip orbit of u' + sigma(u) ∋ c sin t and a box's
# faces in closed form; the convergence order under mesh refinement; the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sl
import scipy.optimize as so

import dmi
from dmi import analysis as da

from models.delay_models import (AV, MU, TAU, circle_reference, forced_orbit, fourier_orbit, newton_fd,
                                 rotating, vdp_scheme_orbit)
from models.orbit_models import DenHartog, StickSlip1


# ---- van der Pol with a distributed delay (the model and its Fourier solve: models/delay_models.py)
def trig_extrema(y: np.ndarray) -> tuple[float, float]:
    """max and min of the trigonometric interpolant of the samples y (one period)."""
    N = y.size
    Y = np.fft.fft(y) / N
    k = np.fft.fftfreq(N, 1.0 / N)

    def val(x, d=0):
        return float(np.real(np.sum(Y * (2j * np.pi * k) ** d * np.exp(2j * np.pi * k * x))))
    out = []
    for j in (int(np.argmax(y)), int(np.argmin(y))):
        x = so.brentq(lambda x: val(x, 1), (j - 1) / N, (j + 1) / N, xtol=1e-15)
        out.append(val(x))
    return out[0], out[1]


def hill_multiplier(T: float, w: np.ndarray, v: np.ndarray, guess: float) -> float:
    """The real Floquet multiplier near ``guess`` by Hill's method: y = e^{lam t} p(t), p
    T-periodic on the Fourier grid of the orbit, p' + lam p = A(t) p + B int_0^tau e^{-lam s}
    p(t - s) ds (each mode exact), A = [[0, 1], [-(2 w v + 1), -(w^2 - 1)]], B = [[0, 0], [-a /
    tau, 0]]; the nonlinear eigenproblem in (p, lam) with p_w(0) = 1 by scipy's root."""
    N = w.size
    k = np.fft.fftfreq(N, 1.0 / N)
    ik = 2j * np.pi * k / T

    def res(z):
        pw, pv, lam = z[:N], z[N:2 * N], z[-1]
        PW = np.fft.fft(pw)
        dpw, dpv = np.fft.ifft(ik * PW).real, np.fft.ifft(ik * np.fft.fft(pv)).real
        q = lam + ik
        Z = np.fft.ifft(PW * np.where(np.abs(q) < 1e-14, TAU, (1 - np.exp(-q * TAU)) / q)).real
        r1 = dpw + lam * pw - pv
        r2 = dpv + lam * pv + (2 * w * v + 1) * pw + (w ** 2 - 1) * pv + AV / TAU * Z
        return np.concatenate([r1, r2, [pw[0] - 1]])

    lam0 = math.log(guess) / T
    # the start: the right singular vector of the smallest singular value of the (linear) map
    # p -> residual at lam0, scaled to p_w(0) = 1
    A = np.column_stack([res(np.concatenate([e, [lam0]]))[:2 * N] for e in np.eye(2 * N)])
    p0 = sl.svd(A)[2][-1]
    z0 = np.concatenate([p0 / p0[0], [lam0]])
    z = newton_fd(res, z0)
    assert np.max(np.abs(res(z))) < 1e-10
    return math.exp(z[-1] * T)


@pytest.fixture(scope="module")
def vdp_case():
    o = vdp_scheme_orbit()
    e = da.collocate(o, intervals=40)
    ref_T, w, v = fourier_orbit(e.period, lambda t: e.u_at(t)[:, 0])
    return o, e, ref_T, w, v


def test_vdp_period_amplitude_multiplier_against_fourier(vdp_case):
    o, e, ref_T, w, v = vdp_case
    assert e.autonomous and e.signature.switches == 0 and e.intervals == 80
    assert abs(e.period - ref_T) < 1e-10
    assert abs(o.period - ref_T) > 1e-3                    # the scheme's orbit is far from it
    wmax, wmin = trig_extrema(w)
    vmax, vmin = trig_extrema(v)
    amp = np.array([0.5 * (wmax - wmin), 0.5 * (vmax - vmin)])
    # the amplitudes (an extremum is inside an interval: h^(m+1), not the period's h^(2m))
    assert abs(e.amplitude[0] - amp[0]) < 1e-9 and abs(e.amplitude[1] - amp[1]) < 1e-7
    # the error estimates are honest: never below the true errors
    assert e.errors["period"] >= abs(e.period - ref_T)
    assert np.all(e.errors["amplitude"] >= np.abs(e.amplitude - amp))
    # trivial multiplier within 1e-8 of 1, the second one against Hill's method
    mu = e.multipliers
    assert abs(mu[0] - 1) < 1e-8
    second = mu[1]
    ref = hill_multiplier(ref_T, w, v, second.real)
    assert abs(second - ref) < 1e-8 * max(1.0, abs(ref)) + 1e-6 * abs(ref)
    assert e.errors["multipliers"][1] + 1e-12 >= abs(second - ref) or abs(second - ref) < 1e-12
    assert e.stable is True


def test_vdp_u_at_solves_the_equation(vdp_case):
    # u_at on a grid of the period against the Fourier orbit (same phase: v(0) = 0 fixes the
    # Fourier orbit's; shift the collocated one to its maximum of w)
    _, e, ref_T, w, v = vdp_case
    N = w.size
    t = np.linspace(0, e.period, 2001)
    u = e.u_at(t)
    t0 = t[np.argmax(u[:, 0])]
    t0 = so.brentq(lambda s: e.u_at(s)[1], t0 - 0.05, t0 + 0.05, xtol=1e-14)
    W = np.fft.fft(w) / N
    k = np.fft.fftfreq(N, 1.0 / N)
    th = np.linspace(0, 1, 301)
    ref = np.real(np.exp(2j * np.pi * np.outer(th, k)) @ W)
    mine = e.u_at(t0 + th * e.period)[:, 0]
    assert np.max(np.abs(mine - ref)) < 5e-7
    assert np.max(np.abs(mine - ref)) <= e.errors["u"]


def test_convergence_order_at_least_degree(vdp_case):
    # the period's error against the Fourier reference on equidistributed meshes: the observed
    # order between L = 12 and 24 (the orbits returned: 24 and 48 intervals) is at least m = 4
    o, _, ref_T, _, _ = vdp_case
    err = [abs(da.collocate(o, intervals=L, multipliers=0).period - ref_T) for L in (12, 24)]
    assert err[1] < err[0]
    assert math.log2(err[0] / err[1]) >= 4


# ---- circles of a rotating system with a damped-cosine memory ---------------------------------
def test_circle_radius_and_period_closed_form():
    r, T = circle_reference()
    s = rotating(MU, h=1.01 * T / 400)
    s.set_history(lambda t: np.array([0.5, 0.0]))
    s.init()
    s.advance(5000)
    o = da.periodic_orbit(rotating, MU, None, s, guess_period=T * 1.01, steps=400, multipliers=0)
    e = da.collocate(o, tol=1e-11)
    assert abs(e.period - T) < 1e-10
    tt = np.linspace(0, e.period, 501)
    radius = np.linalg.norm(e.u_at(tt), axis=1)
    # tol is the period's: the radius and the amplitudes are within their own estimates
    assert np.max(np.abs(radius - r)) <= e.errors["u"]
    assert np.all(np.abs(e.amplitude - r) <= e.errors["amplitude"])
    assert np.max(np.abs(radius - r)) < 1e-8 and e.errors["u"] < 1e-6   # and both small
    assert abs(e.multipliers[0] - 1) < 1e-8


# ---- Den Hartog's dry-friction oscillator: a two-segment orbit ---------------------------------
def test_den_hartog_amplitude_and_multipliers_closed_form():
    d = DenHartog()
    e = da.collocate(forced_orbit(d, 2000, 20), intervals=24)
    assert e.signature.switches == 2 and not e.autonomous
    assert abs(e.amplitude[0] - d.a) < 1e-10
    mu = np.sort_complex(e.multipliers[:2])
    ref = np.sort_complex(d.multipliers)
    assert np.max(np.abs(mu - ref)) < 1e-8
    # Den Hartog's form: mu = nu^2, nu^2 - (1 + r) cos(pi / w) nu + r = 0, r = (X w^2 - F0) /
    # (X w^2 + F0), X the amplitude
    X, w = d.a, d.w
    r = (X * w * w - d.F0) / (X * w * w + d.F0)
    nu = np.roots([1.0, -(1 + r) * np.cos(np.pi / w), r])
    assert np.max(np.abs(mu - np.sort_complex(nu ** 2))) < 1e-8
    assert np.all(np.abs(mu) < 1) and e.stable is True
    # the reversals: v = 0 at the switching times, half a period apart
    assert abs(e.switches[1] - e.switches[0] - d.T / 2) < 1e-10
    assert np.max(np.abs(e.u_at(e.switches)[:, 1])) < 1e-10


# ---- stick-slip: u' + sigma(u) ∋ c sin t ------------------------------------------------------
def test_stick_slip_closed_form():
    d = StickSlip1()
    e = da.collocate(forced_orbit(d, 2000, 5), intervals=48)
    assert e.signature.describe() == ["(slip -)", "(stuck)", "(slip +)", "(stuck)"]
    ref = np.array([d.t2 - np.pi, d.t1, d.t2, np.pi + d.t1])
    assert np.max(np.abs(e.switches - ref)) < 1e-10
    t = np.linspace(0, 2 * np.pi, 3001)
    assert np.max(np.abs(e.u_at(t)[:, 0] - d.exact(t))) < 1e-10
    assert np.all(e.multipliers == 0)            # a stuck segment wipes a perturbation out


# ---- the refusals -------------------------------------------------------------------------------
def test_user_resolvent_refused_naming_refine_orbit():
    d = StickSlip1()
    o_make = d.make_for(200)

    def make(p: float) -> dmi.Solver:
        s = o_make(p)
        s.set_resolvent(lambda lam, x: np.sign(x) * np.maximum(np.abs(x) - lam, 0.0))
        return s
    s = make(1.0)
    s.init()
    s.advance(1000)
    o = da.periodic_orbit(make, 1.0, d.T, s, multipliers=0)
    with pytest.raises(ValueError, match="refine_orbit"):
        da.collocate(o)


def test_equation_orbit_refused_by_refine_and_floquet():
    o = forced_orbit(StickSlip1(), 400, 5)
    e = da.collocate(o, intervals=8, multipliers=0)
    with pytest.raises(TypeError, match="Orbit of the scheme"):
        da.refine_orbit(e)
    with pytest.raises(TypeError, match="StepMap of the scheme"):
        da.floquet_multipliers(e, np.zeros(1))
    with pytest.raises(TypeError, match="Orbit of the scheme"):
        da.collocate(e)
    with pytest.raises(ValueError, match="degree"):
        da.collocate(o, degree=1)


def test_eval_rhs_many_is_eval_rhs_at_each_point():
    s = dmi.Solver(2, 1.0, 10)
    s.set_rhs(lambda t, u: np.array([u[1] * t, -u[0] ** 3]))
    rng = np.random.default_rng(1)
    t, U = rng.normal(size=5), rng.normal(size=(5, 2))
    many = s.eval_rhs_many(t, U)
    assert np.array_equal(many, np.array([s.eval_rhs(t[c], U[c]) for c in range(5)]))
    assert np.array_equal(many[:, 1], -U[:, 0] ** 3)
    with pytest.raises(ValueError, match=r"\(5, 2\)"):
        s.eval_rhs_many(t, U[:, :1])
    s.set_rhs(lambda t, u: np.array([1.0 / 0.0, 0.0]))
    with pytest.raises(ZeroDivisionError) as info:
        s.eval_rhs_many(t, U)
    assert "rhs at t = " in " ".join(info.value.__notes__)


# ---- a box: u' + N_[-1, 1](u) ∋ c sin(t + phi) ------------------------------------------------
def test_box_faces_closed_form():
    # free: u' = c sin(t + phi); held on a face while the force pushes into it.  With s = t + phi:
    # on hi from its arrival until sin s = 0 (s = pi), then u = 1 - c (1 + cos s) down to -1 at
    # cos s = (2 - c) / c, on lo until s = 2 pi, then u = -1 + c (1 - cos s) up to 1 at
    # cos s = (c - 2) / c
    c, phi, M = 1.5, 1.0, 2000
    T = 2 * math.pi

    def make(p: float) -> dmi.Solver:
        s = dmi.Solver(1, T / M, 1)
        s.set_rhs(lambda t, u: np.array([-c * math.sin(t + phi)]))
        s.set_box([-1.0], [1.0])
        return s
    s = make(1.0)
    s.init()
    s.advance(5 * M)
    o = da.periodic_orbit(make, 1.0, T, s, multipliers=0)
    e = da.collocate(o, intervals=24, multipliers=2)
    s_ref = np.array([math.acos((c - 2) / c), math.pi, 2 * math.pi - math.acos((2 - c) / c),
                      2 * math.pi])
    ref = np.sort(np.mod(s_ref - phi, T))
    assert np.max(np.abs(np.sort(e.switches) - ref)) < 1e-10
    assert sorted(e.signature.describe()) == sorted(["(free)", "(on hi)", "(free)", "(on lo)"])
    assert np.all(e.multipliers == 0)               # a face wipes a perturbation out
