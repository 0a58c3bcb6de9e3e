# continue_orbit on an EquationOrbit (collocation through the one continuation driver) and
# hopf_orbit(of="equation"): the closed-form circles of u' = (mu - |u|^2) u + w0 J u - int_0^tau g
# e^{-s/th} cos(beta s) u(t - s) ds from the Hopf point (radius^2 = mu - mu_H, the period from the
# kernel's transform), van der Pol with a distributed delay for a in [0.2, 0.8] against the Fourier
# solve of models/delay_models.py at user points; and continue_orbit(verify=...) on the scheme's
# branch of a damped forced oscillator, whose multipliers are the eigenvalues of (I - h A)^M
# (the scheme steps a linear f explicitly: the paper's (3.12) with no memory and no resolvent).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dmi
from dmi import analysis as da

from models import delay_models as tc


def circle_hopf() -> tuple[float, float, float]:
    _, T = tc.circle_reference()
    om = 2 * math.pi / T
    return tc.K_hat(1j * om).real, om, T


def test_hopf_orbit_of_equation_starts_the_circles():
    muH, om, T = circle_hopf()
    e = da.hopf_orbit(tc.rotating, da.HopfPoint(p=muH, omega=om, root=1j * om), [0.0, 0.0],
                      amplitude=0.1, of="equation")
    assert isinstance(e, da.EquationOrbit) and e.autonomous
    assert abs(e.p - (muH + 0.01)) < 1e-10               # radius^2 = mu - mu_H
    assert abs(e.period - T) < 1e-10
    assert np.all(np.abs(e.amplitude - 0.1) < 1e-10)
    with pytest.raises(ValueError, match="of = 'exact'"):
        da.hopf_orbit(tc.rotating, da.HopfPoint(p=muH, omega=om, root=1j * om), [0.0, 0.0],
                      amplitude=0.1, of="exact")



def test_hopf_orbit_of_equation_with_a_singular_step_raises_shooting_error():
    # a model that ignores p: its J_p is exactly 0 and the bordered Newton step singular, which
    # hopf_orbit reports as the ShootingError its docstring names (not SuperLU's RuntimeError)
    muH, om, _ = circle_hopf()
    with pytest.raises(da.ShootingError, match="singular"):
        da.hopf_orbit(lambda p, h=None: tc.rotating(muH + 0.01, h),
                      da.HopfPoint(p=muH, omega=om, root=1j * om), [0.0, 0.0], amplitude=0.1,
                      of="equation")

def test_circle_branch_from_the_hopf_point_lands_on_p_end():
    muH, om, T = circle_hopf()
    e = da.hopf_orbit(tc.rotating, da.HopfPoint(p=muH, omega=om, root=1j * om), [0.0, 0.0],
                      amplitude=0.1, of="equation")
    b = da.continue_orbit(e, 1.0, step=0.05, multipliers=3, at=[0.6])
    assert b.status.startswith("reached p_end"), b.status
    assert b.points[-1].p == pytest.approx(1.0, abs=1e-12)
    assert any(ev.kind == "user" and ev.p == 0.6 for ev in b.events)
    assert any(abs(q.p - 0.6) <= 1e-12 for q in b.points)
    assert len(b.points) >= 4
    for q in b.points:
        assert isinstance(q, da.EquationOrbit)
        assert abs(q.period - T) < 1e-10
        assert np.all(np.abs(q.amplitude - math.sqrt(q.p - muH)) < 1e-10)
        r = np.linalg.norm(q.u_at(np.linspace(0, q.period, 301)), axis=1)
        assert np.max(np.abs(r - math.sqrt(q.p - muH))) <= q.errors["u"]   # honest estimate
        assert q.signature.describe() == ["(free, free)"]
    # the options that do not apply to a collocated branch are refused
    with pytest.raises(ValueError, match="refine"):
        da.continue_orbit(e, 1.0, step=0.05, refine=True)


@pytest.fixture(scope="module")
def vdp_start():
    return da.collocate(tc.vdp_scheme_orbit(), intervals=40, multipliers=4)


@pytest.mark.parametrize("p_end, users", [(0.8, [0.6, 0.7]), (0.2, [0.4, 0.3])])
def test_vdp_branch_at_user_points_against_fourier(vdp_start, p_end, users):
    b = da.continue_orbit(vdp_start, p_end, step=0.1, multipliers=4, at=users)
    assert b.status.startswith("reached p_end"), b.status
    assert b.points[-1].p == pytest.approx(p_end, abs=1e-12)
    checked = [q for q in b.points if any(abs(q.p - a) <= 1e-12 for a in users + [p_end])]
    assert len(checked) == len(users) + 1
    for q in checked:
        tc.AV = q.p
        try:
            ref_T, _, _ = tc.fourier_orbit(q.period, lambda t: q.u_at(t)[:, 0])
        finally:
            tc.AV = 0.5
        assert abs(q.period - ref_T) < 1e-9, (q.p, q.period, ref_T)


# ---- continue_orbit(verify=...): the scheme's branch of w'' + c w' + w = p cos t ----------------
C, MSTEPS = 0.2, 200


def damped(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, 1.0, h=2 * math.pi / MSTEPS if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], u[0] + C * u[1] - p * math.cos(t)]))
    return s


def test_continue_orbit_verify_reports_verified_stability():
    o = da.periodic_orbit(damped, 1.0, 2 * math.pi, [0.0, 0.0], multipliers=2)
    h = 2 * math.pi / MSTEPS
    A = np.array([[0.0, -1.0], [1.0, C]])                 # f(t, u) = A u - p cos t e_2
    closed = np.abs(np.linalg.eigvals(np.linalg.matrix_power(np.eye(2) - h * A, MSTEPS)))
    with warnings.catch_warnings():
        warnings.simplefilter("error", da.StabilityWarning)
        b = da.continue_orbit(o, 1.5, step=0.25, multipliers=2, verify=da.Verify())
    with pytest.warns(UserWarning, match="verify=False"):
        plain = da.continue_orbit(o, 1.5, step=0.25, multipliers=2, verify=False)
    assert b.points[-1].p == pytest.approx(1.5, abs=1e-12)
    for q in b.points:
        assert q.floquet is not None and q.stable is True
        assert np.all(np.isfinite(q.floquet.errors[:2]))
        assert np.all(np.abs(np.abs(q.multipliers[:2]) - closed) < 1e-6)
    assert all(q.floquet is None and q.stable is None for q in plain.points)
