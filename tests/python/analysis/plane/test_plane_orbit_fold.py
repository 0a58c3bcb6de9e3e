# The fold of collocated orbits continued in (p, q) (continue_orbit_curve) on the rotationally
# symmetric oscillator with a distributed memory whose circles are exact:
#   z' = (mu + i W0) z + q |z|^2 z + C2 |z|^4 z - int_0^2 G e^-s z(t - s) ds,   C2 < 0 < q.
# A circle z = r e^(i Om t) solves Om + Im g(i Om) = W0 (g the memory's transform: Om does not
# depend on r, mu or q) and mu = mu_H - q r^2 - C2 r^4, mu_H = Re g(i Om); in mu it folds where
# d mu / d r^2 = 0: r^2 = q / (2 |C2|), mu_F(q) = mu_H - q^2 / (4 |C2|).  The fold curve ends on
# the Hopf curve mu = mu_H at the Bautin point q = 0 (r -> 0).  The multipliers of a circle other
# than its two at 1 come from the rotating frame's characteristic matrix (derived here):
#   D(lam) = [[lam - A + g(lam + i Om), -B], [-B, lam - conj(A) + g(lam - i Om)]],
#   A = mu + i (W0 - Om) + 2 q r^2 + 3 C2 r^4,  B = q r^2 + 2 C2 r^4,
# and the verdict is checked by counting the zeros of det D with Re lam > 0 (argument principle).
# A forced orbit too: the hardening Duffing oscillator x'' + c x' + x + x^3 = F cos(1.4 t), its
# resonance's fold in F continued in c, against the fold solved in the test by shooting with
# scipy's integrator (x(P) = x(0) and det(M - I) = 0, M the monodromy matrix), and against
# harmonic balance.  Also the refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest

import dmi

from dmi import analysis as da
from dmi.analysis.continuation.branch import Event
from dmi.analysis.plane.orbit_curves import OrbitCurvePoint, continue_orbit_curve

try:   # the shared models' package (tests/python/models) or, before it, tests/python itself
    from models import hopf_models, orbit_models
except ImportError:
    import hopf_models
    import orbit_models

W0, TAU, G, C2 = 1.0, 2.0, 0.3, -1.0
Q0 = 1.0


def make2(mu: float, q: float):
    return hopf_models.circle_solver(complex(mu, W0), q, C2, G, TAU, 100, False)


def hopf_closed_form() -> tuple[float, float]:
    """(Om, mu_H)."""
    return hopf_models.circle_hopf(W0, G, TAU)


def fold_closed_form(q: float) -> tuple[float, float]:
    """(mu_F, r) of the fold of circles at q > 0."""
    return hopf_models.circle_fold(q, C2, W0, G, TAU)


def unstable_roots(mu: float, q: float, r: float, delta: float = 1e-3, R: float = 40.0) -> int:
    """The zeros of det D with delta <= Re lam <= R, |Im lam| <= R (det D ~ lam^2 beyond)."""
    om, _ = hopf_closed_form()
    A = complex(mu, W0 - om) + 2 * q * r ** 2 + 3 * C2 * r ** 4
    B = q * r ** 2 + 2 * C2 * r ** 4

    def det(lam: np.ndarray) -> np.ndarray:
        d11 = lam - A + hopf_models.ghat(lam + 1j * om, G, TAU)
        d22 = lam - np.conj(A) + hopf_models.ghat(lam - 1j * om, G, TAU)
        return d11 * d22 - B * B

    k = 20000
    corners = [complex(delta, -R), complex(R, -R), complex(R, R), complex(delta, R)]
    path = np.concatenate([np.linspace(a, b, k, endpoint=False)
                           for a, b in zip(corners, corners[1:] + corners[:1])])
    phase = np.unwrap(np.angle(det(np.append(path, path[0]))))
    return int(round((phase[-1] - phase[0]) / (2 * math.pi)))


@pytest.fixture(scope="module")
def branch():
    """The circles at q = Q0 from the Hopf point down through their fold."""
    _, mu_h = hopf_closed_form()
    make = lambda mu: make2(mu, Q0)   # noqa: E731
    rest = da.continue_equilibrium(da.equilibrium(make, mu_h - 0.6, [0.0, 0.0], of="equation"),
                                   mu_h + 0.3, step=0.1)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    orbit = da.hopf_orbit(make, h.hopf, h.u, amplitude=0.01, of="equation")
    return da.continue_orbit(orbit, mu_h - 0.6, step=0.02)


@pytest.fixture(scope="module")
def fold(branch):
    (f,) = [e for e in branch.events if e.kind == "fold"]
    return f


@pytest.fixture(scope="module")
def up(branch, fold):
    return continue_orbit_curve(fold, make2, Q0, 1.6, branch=branch, step=0.1, at=(1.3,))


def test_the_fold_curve_against_the_closed_form(up):
    om, _ = hopf_closed_form()
    assert up.kind == "orbit-fold"
    assert up.status == "reached q_end = 1.6"
    assert up.points[-1].q == 1.6 and len(up.points) >= 4
    worst = 0.0
    for pt in up.points:
        assert isinstance(pt, OrbitCurvePoint) and isinstance(pt.orbit, da.EquationOrbit)
        mu_f, r = fold_closed_form(pt.q)
        worst = max(worst, abs(pt.p - mu_f))
        assert abs(pt.p - mu_f) <= 1e-9                       # measured 1.6e-13
        assert abs(pt.p - mu_f) <= pt.p_error                 # the estimate bounds the error
        assert pt.orbit.errors["p"] == pt.p_error
        assert np.all(np.abs(pt.orbit.amplitude - r) <= 1e-9)
        assert abs(pt.orbit.period - 2 * math.pi / om) <= 1e-9
        assert pt.orbit.p == pt.p and pt.orbit.stable is None  # a multiplier at 1: no verdict
    assert np.all(np.diff(up.q) > 0)
    # the user point on q = 1.3 exactly, with its point
    (e,) = [e for e in up.events if e.kind == "user"]
    assert e.q == 1.3 and up.points[e.index].q == 1.3
    assert abs(e.p - fold_closed_form(1.3)[0]) <= 1e-9


def test_a_points_orbit_is_the_model_at_its_q(up):
    pt = up.points[-1]
    # the orbit is a circle of the model at q = 1.6: continued at that q it stays one
    s = pt.orbit.make(pt.p)
    try:
        assert s.n == 2
    finally:
        s.close()
    mu_f, r = fold_closed_form(1.6)
    z = pt.orbit.u_at(np.linspace(0.0, pt.orbit.period, 50))
    assert np.all(np.abs(np.hypot(z[:, 0], z[:, 1]) - r) <= 1e-8)


def test_the_verdict_on_the_other_multipliers_against_the_characteristic_matrix(up):
    # the count itself: the small circle at mu_H - 0.1, q = 1 (r^4 - r^2 + 0.1 = 0) is a saddle
    _, mu_h = hopf_closed_form()
    assert unstable_roots(mu_h - 0.1, 1.0, math.sqrt((1 - math.sqrt(0.6)) / 2)) == 1
    assert unstable_roots(mu_h - 0.1, 1.0, math.sqrt((1 + math.sqrt(0.6)) / 2)) == 0
    for pt in (up.points[0], up.points[-1]):
        mu_f, r = fold_closed_form(pt.q)
        expected = unstable_roots(mu_f, pt.q, r) == 0
        assert pt.stable is expected


def test_the_curve_ends_at_the_bautin_point(branch, fold):
    _, mu_h = hopf_closed_form()
    down = continue_orbit_curve(fold, make2, Q0, -0.5, branch=branch, step=0.1)
    assert down.status.startswith("reached a Bautin point near (p, q) = ")
    (b,) = [e for e in down.events if e.kind == "bautin"]
    assert abs(b.q) <= 1e-6 and abs(b.p - mu_h) <= 1e-9       # measured 2e-10 and 1.6e-13
    assert all(pt.q > 0 for pt in down.points) and np.all(np.diff(down.q) < 0)
    for pt in down.points:
        assert abs(pt.p - fold_closed_form(pt.q)[0]) <= 1e-9


def test_a_start_from_an_orbit_near_the_fold(branch, fold):
    near = branch.points[fold.index]            # the first orbit past the fold
    assert abs(near.p - fold.p) > 1e-6
    c = continue_orbit_curve(near, make2, Q0, 1.2, step=0.1)
    assert c.status == "reached q_end = 1.2"
    for pt in c.points:
        assert abs(pt.p - fold_closed_form(pt.q)[0]) <= 1e-9


def test_refusals(branch, fold):
    with pytest.raises(ValueError, match=r"a fold event needs branch="):   # bad-inputs OC01
        continue_orbit_curve(fold, make2, Q0, 1.5)
    with pytest.raises(ValueError, match=r"give a 'fold' event of a branch of "):   # OC02
        continue_orbit_curve(Event("torus", fold.p, fold.index), make2, Q0, 1.5, branch=branch)
    with pytest.raises(ValueError, match=r"not one of branch.events"):   # bad-inputs OC03
        continue_orbit_curve(Event("fold", fold.p, fold.index), make2, Q0, 1.5, branch=branch)
    with pytest.raises(ValueError, match=r"give two different finite values"):   # OC04
        continue_orbit_curve(fold, make2, Q0, Q0, branch=branch)
    with pytest.raises(ValueError, match=r"step = -0.1: must be finite and > 0"):   # OC05
        continue_orbit_curve(fold, make2, Q0, 1.5, branch=branch, step=-0.1)
    # make2 at q0 is not the branch's model: the fold is elsewhere
    with pytest.raises(ValueError, match=r"make2\(\., q0 = 1.2\)"):   # bad-inputs OC06
        continue_orbit_curve(fold, make2, 1.2, 1.5, branch=branch)


DW = 1.4                      # the Duffing oscillator's forcing frequency
DP = 2 * math.pi / DW


def duffing2(F: float, c: float):
    s = dmi.Solver(2, 1.0, h=DP / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -c * u[1] - u[0] - u[0] ** 3 + F * math.cos(DW * t)]))
    return s


def duffing_fold(c: float, guess: np.ndarray) -> float:
    """F at the fold at damping c (forcing frequency DW), by shooting with scipy's DOP853."""
    return orbit_models.duffing_fold(c, DW, guess)


def harmonic_balance_fold(c: float) -> float:
    """The smaller F where x = a cos(W t - phi) folds: F^2 = s ((K + k s)^2 + c^2 W^2), s = a^2,
    K = 1 - W^2, k = 3/4, d F^2 / d s = 0 at the larger root s."""
    K, k = 1 - DW ** 2, 0.75
    s = (-4 * k * K + math.sqrt(16 * k * k * K * K - 12 * k * k * (K * K + c * c * DW * DW))) \
        / (6 * k * k)
    return math.sqrt(s * ((K + k * s) ** 2 + c * c * DW * DW))


def test_a_forced_orbits_fold_curve_against_shooting():
    make = lambda F: duffing2(F, 0.1)   # noqa: E731
    o = da.periodic_orbit(make, 0.3, DP, np.array([1.5, 0.0]), steps=400, multipliers=4)
    b = da.continue_orbit(da.collocate(o, multipliers=6, intervals=40), 0.0, step=0.02)
    (f,) = [e for e in b.events if e.kind == "fold"]
    c = continue_orbit_curve(f, duffing2, 0.1, 0.2, branch=b, step=0.02)
    assert c.status == "reached q_end = 0.2" and c.points[-1].q == 0.2
    for pt in (c.points[0], c.points[len(c.points) // 2], c.points[-1]):
        assert not pt.orbit.autonomous and pt.orbit.period == DP
        ref = duffing_fold(pt.q, np.concatenate([pt.orbit.u_at(0.0), [pt.p]]))
        assert abs(pt.p - ref) <= 1e-8                      # measured 2e-14
        assert abs(pt.p - ref) <= pt.p_error
        assert abs(pt.p - harmonic_balance_fold(pt.q)) <= 0.01 * pt.p
