# errors["u"] of an autonomous orbit measures its shape, not its phase: the estimate (the two levels
# compared after aligning their phase) against the phase-aligned true error on three orbits (the
# circle of a rotating system with a memory in closed form; van der Pol with a distributed delay
# and its relaxation oscillation at epsilon = 10 against collocations of degree 8 on finer
# meshes), and two collocations of one orbit on different meshes within the sum of their
# estimates; the relaxation oscillation collocated from a coarse scheme orbit (Newton fails on the
# first mesh of equal intervals: a finer one graded to the scheme's speed takes over).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from dmi import analysis as da

#: Phases a period at which two orbits are compared.
PHASES = 2000


def distance(u, v, T_v: float) -> float:
    """min over the shift s of max over the phases theta of |u(theta) - v((theta + s) T_v)|
    (u: the values at the phases (PHASES, n); v: a function of time), the shift found on a grid
    of 81 shifts within 0.01 of a period and refined by a bounded scalar minimisation."""
    theta = np.arange(PHASES) / PHASES

    def gap(s: float) -> float:
        return float(np.max(np.abs(u - v((theta + s) * T_v))))
    grid = np.linspace(-0.01, 0.01, 81)
    k = int(np.argmin([gap(s) for s in grid]))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    return float(so.minimize_scalar(gap, bounds=(lo, hi), method="bounded",
                                    options={"xatol": 1e-15}).fun)


def at_phases(e) -> np.ndarray:
    return e.u_at(np.arange(PHASES) / PHASES * e.period)


def scheme_orbit(make, p: float, start, T: float, steps: int) -> da.Orbit:
    s = make(p, h=T / steps)
    s.set_history(lambda t: np.asarray(start, dtype=float))
    s.init()
    s.advance(40 * steps)
    return da.periodic_orbit(make, p, None, s, guess_period=T, steps=steps, multipliers=0)


# ---- u' = (1 - |u|^2) u + J u - int_0^2 (1/2) e^{-s} cos(2 s) u(t - s) ds: circles, closed form --
def kernel_transform(q: complex) -> complex:
    """int_0^2 (1/2) e^{-s} cos(2 s) e^{-q s} ds."""
    c = np.array([-1 + 2j - q, -1 - 2j - q])
    return complex(np.sum(0.25 * (np.exp(2 * c) - 1) / c))


def rotating(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, 2.0, h=h or 0.02)
    s.set_rhs(lambda t, u: (u @ u - p) * u + np.array([u[1], -u[0]]))
    s.set_kernel_exp([-1.0], [2.0], [0.5 * np.eye(2)])
    return s


def test_circle_estimate_bounds_the_aligned_error():
    # z = r e^{i Om t}: i Om = 1 - r^2 + i - K(i Om)
    om = so.brentq(lambda w: w - 1 + kernel_transform(1j * w).imag, 0.1, 3.0, xtol=1e-15)
    r = math.sqrt(1 - kernel_transform(1j * om).real)
    o = scheme_orbit(rotating, 1.0, [0.5, 0.0], 2 * math.pi / om * 1.01, 200)
    for L in (4, 8):
        e = da.collocate(o, intervals=L, degree=3, multipliers=0)
        start = math.atan2(*e.u_at(np.zeros(1))[0][::-1])       # the circle's phase at t = 0
        true = distance(at_phases(e), lambda t: r * np.column_stack(
            [np.cos(om * t + start), np.sin(om * t + start)]), 2 * math.pi / om)
        assert true > 1e-12                       # far above rounding: the ratio means something
        assert 1.0 <= e.errors["u"] / true <= 100.0, (L, e.errors["u"], true)


def test_checked_u_estimate_within_10_of_the_aligned_error():
    """check=True: errors["u"] is twice the finer level's phase-aligned difference to the orbit
    on its mesh halved: 2.1 times the closed form's aligned error on both meshes (the two
    levels' difference, without the check: 17 times)."""
    om = so.brentq(lambda w: w - 1 + kernel_transform(1j * w).imag, 0.1, 3.0, xtol=1e-15)
    r = math.sqrt(1 - kernel_transform(1j * om).real)
    o = scheme_orbit(rotating, 1.0, [0.5, 0.0], 2 * math.pi / om * 1.01, 200)
    for L in (4, 8):
        e = da.collocate(o, intervals=L, degree=3, multipliers=0, check=True)
        start = math.atan2(*e.u_at(np.zeros(1))[0][::-1])
        true = distance(at_phases(e), lambda t: r * np.column_stack(
            [np.cos(om * t + start), np.sin(om * t + start)]), 2 * math.pi / om)
        assert true > 1e-12
        assert 1.0 <= e.errors["u"] / true <= 10.0, (L, e.errors["u"], true)


# ---- van der Pol with a distributed delay: w'' + eps (w^2 - 1) w' + w + a int_0^1 w(t - s) ds = 0 --
def van_der_pol(eps: float):
    def make(p: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, 1.0, h=h or 0.01)
        s.set_rhs(lambda t, u: np.array([-u[1], eps * (u[0] ** 2 - 1) * u[1] + u[0]]))
        s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
        return s
    return make


@pytest.fixture(scope="module")
def vdp_orbit() -> da.Orbit:
    return scheme_orbit(van_der_pol(1.0), 0.5, [2.0, 0.0], 6.0, 600)


@pytest.fixture(scope="module")
def vdp_reference(vdp_orbit):
    return da.collocate(vdp_orbit, intervals=40, degree=8, multipliers=0)


@pytest.mark.parametrize("L", [10, 20])
def test_vdp_estimate_bounds_the_aligned_error(vdp_orbit, vdp_reference, L):
    e = da.collocate(vdp_orbit, intervals=L, multipliers=0)
    true = distance(at_phases(e), vdp_reference.u_at, vdp_reference.period)
    assert vdp_reference.errors["u"] < 1e-3 * true
    assert 1.0 <= e.errors["u"] / true <= 100.0, (L, e.errors["u"], true)


def test_two_meshes_differ_within_their_estimates(vdp_orbit):
    # two collocations of one orbit, on different meshes and degrees, phase-aligned
    a = da.collocate(vdp_orbit, intervals=12, multipliers=0)
    b = da.collocate(vdp_orbit, intervals=20, degree=5, multipliers=0)
    gap = distance(at_phases(a), b.u_at, b.period)
    assert gap > 1e-9
    assert gap <= a.errors["u"] + b.errors["u"]


def test_relaxation_estimate_bounds_the_aligned_error():
    o = scheme_orbit(van_der_pol(10.0), 0.5, [2.0, 0.0], 16.0, 2000)
    ref = da.collocate(o, intervals=60, degree=8, multipliers=0)
    e = da.collocate(o, intervals=40, multipliers=0)
    true = distance(at_phases(e), ref.u_at, ref.period)
    assert ref.errors["u"] < 1e-2 * true
    assert 1.0 <= e.errors["u"] / true <= 100.0, (e.errors["u"], true)


def test_relaxation_from_a_coarse_scheme_orbit():
    make = van_der_pol(10.0)
    o = scheme_orbit(make, 0.5, [2.0, 0.0], 16.0, 1000)
    ref = da.collocate(scheme_orbit(make, 0.5, [2.0, 0.0], 16.0, 2000), intervals=60, degree=8,
                       multipliers=0)
    assert abs(o.period - ref.period) > 0.5                 # the scheme's orbit is far from it
    e = da.collocate(o, degree=6, tol=1e-8, multipliers=0)
    assert e.errors["period"] <= 1e-8
    # the true error against the reference, whose own levels agree to the floor (1e-11 T)
    assert ref.errors["period"] <= 1e-11 * ref.period
    assert abs(e.period - ref.period) <= e.errors["period"]
