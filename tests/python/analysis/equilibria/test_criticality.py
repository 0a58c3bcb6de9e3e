# The criticality of the equation's Hopf points (dmi.analysis.equilibria.normal_form): l1 in Kuznetsov's
# normalisation with its error, the crossing speed and the amplitude coefficients kappa, against
# closed forms of a rotationally symmetric oscillator with a distributed memory (its circles are
# exact), a harmonic-balance solve of an oscillator with quadratic and cubic terms and a memory,
# and roots of the characteristic equation, all written here; the derivative hook
# Solver.set_rhs_derivatives and its refusals.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from models import hopf_models
from dmi import analysis as da
from dmi.analysis.equilibria.normal_form import CriticalityWarning

# ---- z' = (mu + i W0) z + c1 |z|^2 z + c2 |z|^4 z - int_0^TAU G e^-s z(t - s) ds, z = x + i y ----
# Its circles z = r e^(i Om t) solve d(i Om) = c1 r^2 + c2 r^4 with d(lam) = lam + g(lam) - mu - i W0
# and g(lam) = G (1 - e^-(1 + lam) TAU) / (1 + lam); the Hopf point is d(i Om) = 0 at r = 0.
# Reduced to its centre manifold (q = (1, -i) / sqrt 2, p = (1, i) / (sqrt 2 d'(i Om))):
# c1 = 2 c1 / d'(i Om), l1 = Re c1 / Om, Re lambda' = Re 1 / d'(i Om),
# kappa = sqrt(Re lambda' / |Re(c1 / d')|) for both components (each moves as r cos).
W0, G, TAU = 1.0, 0.5, 2.0
C2 = 0.3 - 0.2j


def ghat(lam: complex) -> complex:
    return hopf_models.ghat(lam, G, TAU)


def dghat(lam: complex) -> complex:
    return hopf_models.dghat(lam, G, TAU)


def circle_hopf() -> tuple[float, float, complex]:
    """(Om, mu_H, d'(i Om))."""
    om = so.brentq(lambda w: w + ghat(1j * w).imag - W0, 0.1, 3.0, xtol=1e-15, rtol=1e-15)
    return om, ghat(1j * om).real, 1 + dghat(1j * om)


def circle_model(c1: complex, hook: bool, c2: complex = C2):
    """make(mu); f = -(the right-hand side) in (x, y); with hook: its exact derivatives."""
    def make(mu: float) -> dmi.Solver:
        return hopf_models.circle_solver(complex(mu, W0), c1, c2, G, TAU, 100, hook)
    return make


def newton(eq, x0) -> np.ndarray:
    """A root of eq near x0 by Newton (the Jacobian by central differences), to rounding."""
    x = np.array(x0, dtype=float)
    for _ in range(50):
        r = np.array(eq(x))
        J = np.empty((r.size, x.size))
        for j in range(x.size):
            e = np.zeros(x.size)
            e[j] = 1e-7 * max(1.0, abs(x[j]))
            J[:, j] = (np.array(eq(x + e)) - np.array(eq(x - e))) / (2 * e[j])
        dx = np.linalg.solve(J, -r)
        x += dx
        if np.max(np.abs(dx)) <= 1e-16 * max(1.0, np.max(np.abs(x))):
            break
    assert np.max(np.abs(eq(x))) <= 1e-14
    return x


def circle(c1: complex, r: float, guess: tuple[float, float]) -> tuple[float, float]:
    """(Om, mu) of the exact circle of radius r."""
    def eq(x):
        om, mu = x
        d = 1j * om + ghat(1j * om) - mu - 1j * W0 - c1 * r * r - C2 * r ** 4
        return [d.real, d.imag]
    return tuple(newton(eq, guess))


def close(got: float, want: float, rel: float) -> bool:
    return abs(got - want) <= rel * max(1.0, abs(want))


SUPER, SUB = -1.0 + 0.5j, 0.7 - 0.3j


@pytest.mark.parametrize("hook", [True, False])
@pytest.mark.parametrize("c1", [SUPER, SUB])
def test_l1_kappa_and_crossing_speed_of_the_symmetric_oscillator(c1, hook):
    om, mu_h, d1 = circle_hopf()
    l1 = (2 * c1 / d1).real / om
    speed = (1 / d1).real
    kappa = math.sqrt(speed / abs((c1 / d1).real))
    hp = da.hopf(circle_model(c1, hook), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")
    rel = 1e-9 if hook else 1e-5
    assert close(hp.p, mu_h, 1e-9) and close(hp.omega, om, 1e-9)
    assert close(hp.l1, l1, rel), (hp.l1, l1)
    assert abs(hp.l1 - l1) <= hp.l1_error, (hp.l1, l1, hp.l1_error)   # the estimate holds
    assert hp.l1_error <= rel * max(1.0, abs(l1))
    assert hp.criticality == ("supercritical" if l1 < 0 else "subcritical")
    assert close(hp.crossing_speed, speed, rel)
    assert hp.kappa.shape == (2,)
    assert all(close(k, kappa, rel) for k in hp.kappa), (hp.kappa, kappa)
    # the orbit exists where d(i Om) = c1 r^2 puts mu: mu - mu_H = -r^2 Re(c1 / d') / Re(1 / d')
    assert hp.side == (-1 if (c1 / d1).real > 0 else 1)


@pytest.mark.parametrize("c1", [SUPER, SUB])
def test_kappa_against_the_exact_circles(c1):
    om, mu_h, _ = circle_hopf()
    hp = da.hopf(circle_model(c1, True), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")
    ratio = {}
    for r in (2e-3, 1e-3):
        o, mu = circle(c1, r, (om, mu_h))
        assert np.sign(mu - mu_h) == hp.side
        ratio[r] = r / math.sqrt(abs(mu - mu_h))     # each component's (max - min) / 2 is r
    kappa = (4 * ratio[1e-3] - ratio[2e-3]) / 3      # amplitude / sqrt|dmu| = kappa + O(r^2)
    assert np.all(np.abs(hp.kappa - kappa) <= 1e-9 * kappa), (hp.kappa, kappa)


def test_kappa_against_the_equations_own_orbit():
    # a consistency check against dmi's collocated orbit from hopf_orbit(of="equation")
    om, mu_h, _ = circle_hopf()
    make = circle_model(SUPER, True)
    hp = da.hopf(make, mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")
    orbit = da.hopf_orbit(make, hp, [0.0, 0.0], amplitude=0.01, of="equation")
    assert np.sign(orbit.p - hp.p) == hp.side
    got = orbit.amplitude / math.sqrt(abs(orbit.p - hp.p))
    assert np.all(np.abs(got - hp.kappa) <= 1e-3 * hp.kappa), (got, hp.kappa)


def test_a_degenerate_hopf_point_has_no_criticality():
    om, mu_h, d1 = circle_hopf()
    c1 = 0.5j * d1                                   # Re(c1 / d') = 0: l1 = 0
    with pytest.warns(CriticalityWarning, match="not decided"):
        hp = da.hopf(circle_model(c1, False), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")
    assert abs(hp.l1) <= hp.l1_error and hp.l1_error < 1e-5
    assert hp.criticality is None and hp.kappa is None and hp.side is None


def test_the_scheme_hopf_point_has_no_l1_and_the_branch_event_has_it():
    om, mu_h, d1 = circle_hopf()
    make = circle_model(SUB, False)
    hs = da.hopf(make, mu_h - 0.3, mu_h + 0.3, [0.0, 0.0])
    assert hs.l1 is None and hs.kappa is None and hs.criticality is None
    eq = da.equilibrium(make, mu_h - 0.2, [0.0, 0.0], of="equation")
    br = da.continue_equilibrium(eq, mu_h + 0.2, step=0.1)
    (ev,) = [e for e in br.events if e.kind == "hopf"]
    l1 = (2 * SUB / d1).real / om
    assert close(ev.hopf.l1, l1, 1e-5) and ev.hopf.criticality == "subcritical"


# ---- an oscillator with quadratic and cubic terms and a memory on both components -----------
# u' = g(u) - int_0^TAU2 e^(-2 s) K u(t - s) ds, g = (u1, -u0 + mu u1 + a u0^2 + b u0 u1 + c u0^3
# + e u0^2 u1); its orbits by harmonic balance, its roots by Newton on det Delta, both here.
TAU2 = 1.5
K = np.array([[0.0, 0.0], [0.5, 0.2]])
QA, QB, QC, QE = 0.8, 0.5, -0.3, -1.0


def quad_f(u: np.ndarray, mu: float) -> np.ndarray:
    """f = -g, for states u of shape (2,) or (2, m)."""
    x, y = u[0], u[1]
    return -np.array([y, -x + mu * y + QA * x * x + QB * x * y + QC * x ** 3 + QE * x * x * y])


def quad_model(mu: float) -> dmi.Solver:
    s = dmi.Solver(2, TAU2, 120)
    s.set_rhs(lambda t, u: quad_f(u, mu))
    s.set_kernel_exp([-2.0], [0.0], [K])
    return s


def quad_hhat(lam: complex) -> np.ndarray:
    return K * (1 - np.exp(-(2 + lam) * TAU2)) / (2 + lam)


def quad_delta(lam: complex, mu: float) -> np.ndarray:
    J = np.array([[0.0, -1.0], [1.0, -mu]])          # f_u at 0
    return lam * np.eye(2) + J + quad_hhat(lam)


def quad_root(mu: float, lam0: complex) -> complex:
    """The root of det Delta(lambda; mu) near lam0 (Newton, det' by a central difference)."""
    lam = lam0
    for _ in range(60):
        det = np.linalg.det(quad_delta(lam, mu))
        d = 1e-6
        dd = (np.linalg.det(quad_delta(lam + d, mu)) - np.linalg.det(quad_delta(lam - d, mu))) / (2 * d)
        step = det / dd
        lam -= step
        if abs(step) < 1e-15:
            break
    return lam


def quad_hopf() -> tuple[float, float]:
    def eq(x):
        d = np.linalg.det(quad_delta(1j * x[0], x[1]))
        return [d.real, d.imag]
    x = newton(eq, [1.0, 0.3])
    return float(x[0]), float(x[1])


def harmonic_balance(a: float, om0: float, mu0: float, q: np.ndarray, H: int = 8,
                     M: int = 64) -> tuple[float, float, np.ndarray]:
    """(Om, mu, U) of the orbit whose component 0 has first harmonic a cos(Om t): u(t) =
    U_0 + 2 Re sum_k U_k e^(i k Om t), Newton on the Fourier coefficients of the residual."""
    n = 2
    th = 2 * np.pi * np.arange(M) / M
    E = np.exp(1j * np.outer(np.arange(H + 1), th))        # (H + 1, M)

    def unpack(z):
        U = np.zeros((H + 1, n), dtype=complex)
        U[0] = z[:n]
        U[1:] = (z[n:n + n * H] + 1j * z[n + n * H:n + 2 * n * H]).reshape(H, n)
        return U, z[-2], z[-1]

    def residual(z):
        U, om, mu = unpack(z)
        u = U[0][:, None] + 2 * np.real(U[1:].T @ E[1:])    # (n, M)
        F = quad_f(u, mu) @ E.conj().T / M                  # (n, H + 1)
        R = np.array([1j * k * om * U[k] + F[:, k] + quad_hhat(1j * k * om) @ U[k]
                      for k in range(H + 1)])
        return np.concatenate([R[0].real, R[1:].real.ravel(), R[1:].imag.ravel(),
                               [U[1, 0].real - a / 2, U[1, 0].imag]])

    z = np.zeros(n + 2 * n * H + 2)
    v = a / 2 * q / q[0]
    z[n:n + n] = v.real
    z[n + n * H:n + n * H + n] = v.imag
    z[-2], z[-1] = om0, mu0
    for _ in range(40):
        r = residual(z)
        J = np.empty((r.size, z.size))
        for j in range(z.size):
            e = np.zeros(z.size)
            e[j] = 1e-7 * max(1e-3, abs(z[j]))
            J[:, j] = (residual(z + e) - residual(z - e)) / (2 * e[j])
        dz = np.linalg.solve(J, -r)
        z += dz
        if np.max(np.abs(dz)) < 1e-16:
            break
    assert np.max(np.abs(residual(z))) < 1e-14
    return unpack(z)[1], unpack(z)[2], unpack(z)[0]


def half_range(U: np.ndarray, j: int) -> float:
    """(max - min) / 2 of component j of the trigonometric polynomial, extrema refined."""
    k = np.arange(1, U.shape[0])

    def u(t):
        return U[0, j].real + 2 * np.real(np.sum(U[1:, j] * np.exp(1j * k * t)))
    grid = np.linspace(0, 2 * np.pi, 4001)
    vals = np.array([u(t) for t in grid])
    ext = []
    for sign, i in ((1, np.argmax(vals)), (-1, np.argmin(vals))):
        res = so.minimize_scalar(lambda t: -sign * u(t), bounds=(grid[i] - 0.01, grid[i] + 0.01),
                                 method="bounded", options={"xatol": 1e-12})
        ext.append(u(res.x))
    return (ext[0] - ext[1]) / 2


def test_quadratic_terms_against_harmonic_balance_and_the_roots():
    om, mu_h = quad_hopf()
    hp = da.hopf(quad_model, mu_h - 0.2, mu_h + 0.2, [0.0, 0.0], of="equation")
    assert close(hp.p, mu_h, 1e-9) and close(hp.omega, om, 1e-9)
    # the crossing speed: Re lambda(mu) of the root, a central difference (Richardson)
    lam = [quad_root(mu_h + s, 1j * om) for s in (-2e-4, -1e-4, 1e-4, 2e-4)]
    speed = ((8 * (lam[2] - lam[1]) - (lam[3] - lam[0])) / (12 * 1e-4)).real
    assert close(hp.crossing_speed, speed, 1e-9), (hp.crossing_speed, speed)
    # kappa from orbits of amplitude a and a / 2 (the ratio is kappa + O(a^2))
    _, _, Vh = np.linalg.svd(quad_delta(1j * om, mu_h))
    q = Vh[-1].conj()
    q = q / np.linalg.norm(q)
    ratio = {}
    for a in (0.02, 0.01):
        o, mu, U = harmonic_balance(a, om, mu_h, q)
        assert np.sign(mu - mu_h) == hp.side
        ratio[a] = np.array([half_range(U, j) for j in range(2)]) / math.sqrt(abs(mu - mu_h))
    kappa = (4 * ratio[0.01] - ratio[0.02]) / 3
    assert np.all(np.abs(hp.kappa - kappa) <= 1e-7 * kappa), (hp.kappa, kappa)
    # l1 from kappa: |w|^2 = Re lambda' |dmu| / (om |l1|), half range of u_j = 2 |q_j| |w|
    l1 = -hp.side * np.sign(speed) * 4 * abs(q[0]) ** 2 * abs(speed) / (om * kappa[0] ** 2)
    assert close(hp.l1, l1, 1e-7), (hp.l1, l1)     # (the quadratic terms move it by 30 %)
    assert abs(hp.l1) > 10 * hp.l1_error and hp.l1_error <= 1e-5 * abs(hp.l1)
    assert hp.criticality == ("supercritical" if l1 < 0 else "subcritical")


# ---- the derivative hook ---------------------------------------------------------------------
def test_the_hook_is_checked_and_refused_where_wrong():
    om, mu_h, _ = circle_hopf()
    good = circle_model(SUPER, True)

    def wrong(which: str):
        def make(mu):
            s = good(mu)
            fu, d2, d3 = s.rhs_derivatives
            if which == "fu":
                s.set_rhs_derivatives(lambda t, u: fu(t, u).T, d2, d3)
            elif which == "d2":
                s.set_rhs_derivatives(fu, lambda t, u, v, w: 2 * d2(t, u, v, w) + 1e-3, d3)
            else:
                s.set_rhs_derivatives(fu, d2, lambda t, u, v, w, z: -d3(t, u, v, w, z))
            return s
        return make

    for which in ("fu", "d2", "d3"):
        with pytest.raises(ValueError, match=f"derivative hook {which} "):
            da.hopf(wrong(which), mu_h - 0.3, mu_h + 0.3, [0.0, 0.0], of="equation")


def test_set_rhs_derivatives_refusals_and_forgetting():
    s = dmi.Solver(2, 1.0, 10)
    jac = (lambda t, u: np.zeros((2, 2)))
    with pytest.raises(dmi.InvalidArgument, match="set_rhs"):
        s.set_rhs_derivatives(jac)
    s.set_rhs(lambda t, u: u)
    with pytest.raises(dmi.InvalidArgument, match="not callable"):
        s.set_rhs_derivatives(3.0)
    with pytest.raises(dmi.InvalidArgument, match="without fu"):
        s.set_rhs_derivatives(None, jac)
    s.set_rhs_derivatives(jac)
    assert s.rhs_derivatives[0] is jac and s.rhs_derivatives[1] is None
    s.set_rhs(lambda t, u: 2 * u)                    # another f: its derivatives are forgotten
    assert s.rhs_derivatives is None
    s.close()
