# The rotationally symmetric oscillator with a distributed memory, for the Hopf criticality and
# Hopf-curve tests, with its memory's transform and the model's exact derivatives derived here
# from the equation, not from the code under test:
#   z' = a z + c1 |z|^2 z + c2 |z|^4 z - int_0^tau G e^-s z(t - s) ds,   z = x + i y,
# written as u' + f(u) + int H u = 0 in (x, y), H = G e^-s I.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import numpy as np
import scipy.optimize as so

import dmi


def ghat(lam: complex, G: float, tau: float) -> complex:
    """int_0^tau G e^-s e^(-lam s) ds."""
    return G * (1 - np.exp(-(1 + lam) * tau)) / (1 + lam)


def dghat(lam: complex, G: float, tau: float) -> complex:
    """d ghat / d lam."""
    e = np.exp(-(1 + lam) * tau)
    return G * (tau * e * (1 + lam) - (1 - e)) / (1 + lam) ** 2


def circle_solver(a: complex, c1: complex, c2: complex, G: float, tau: float, N: int,
                  hook: bool) -> dmi.Solver:
    """The oscillator's solver (f = -(the right-hand side) in (x, y)); with hook its exact
    derivatives fu, d2, d3 (Solver.set_rhs_derivatives)."""
    def g(z: complex) -> complex:
        r2 = abs(z) ** 2
        return a * z + c1 * r2 * z + c2 * r2 * r2 * z

    s = dmi.Solver(2, tau, N)
    s.set_rhs(lambda t, u: -np.array([g(complex(*u)).real, g(complex(*u)).imag]))
    s.set_kernel_exp([-1.0], [0.0], [G * np.eye(2)])
    if hook:
        # g = a z + c1 z^2 zb + c2 z^3 zb^2: derivatives of each monomial z^m zb^l in the
        # complex directions A_i (zb: their conjugates)
        def fu(t, u):
            z = complex(*u)
            r2 = abs(z) ** 2
            dz = a + 2 * c1 * r2 + 3 * c2 * r2 * r2       # dg/dz
            dzb = c1 * z * z + 2 * c2 * r2 * z * z         # dg/dzb
            cols = [dz + dzb, 1j * dz - 1j * dzb]          # along dx and dy
            return -np.array([[c.real for c in cols], [c.imag for c in cols]])

        def d2(t, u, v, w):
            z, A, B = complex(*u), complex(*v), complex(*w)
            zb, Ab, Bb = z.conjugate(), A.conjugate(), B.conjugate()
            r = c1 * (2 * A * B * zb + 2 * z * (A * Bb + B * Ab))
            r += c2 * (6 * z * A * B * zb ** 2 + 6 * z * z * zb * (A * Bb + B * Ab)
                       + 2 * z ** 3 * Ab * Bb)
            return -np.array([r.real, r.imag])

        def d3(t, u, v, w, x):
            z = complex(*u)
            zb = z.conjugate()
            A = [complex(*v), complex(*w), complex(*x)]
            Ab = [e.conjugate() for e in A]
            trip = ((0, 1, 2), (0, 2, 1), (1, 2, 0))
            r = c1 * 2 * sum(A[i] * A[j] * Ab[k] for i, j, k in trip)
            r += c2 * (6 * A[0] * A[1] * A[2] * zb ** 2
                       + sum(12 * z * zb * A[i] * A[j] * Ab[k] for i, j, k in trip)
                       + sum(6 * z * z * A[k] * Ab[i] * Ab[j] for i, j, k in trip))
            return -np.array([r.real, r.imag])

        s.set_rhs_derivatives(fu, d2, d3)
    return s


def circle_hopf(w0: float, G: float, tau: float) -> tuple[float, float]:
    """(Om, mu_H) of the circle oscillator (circle_solver) with rotation w0: the frequency
    where Om + Im ghat(i Om) = w0, and mu_H = Re ghat(i Om)."""
    om = so.brentq(lambda w: w + ghat(1j * w, G, tau).imag - w0, 0.1, 3.0,
                   xtol=1e-15, rtol=1e-15)
    return om, ghat(1j * om, G, tau).real


def circle_fold(q: float, c2: float, w0: float, G: float, tau: float) -> tuple[float, float]:
    """(mu_F, r) of the fold of its circles at q > 0 (cubic coefficient q, quintic c2 < 0)."""
    _, mu_h = circle_hopf(w0, G, tau)
    return mu_h - q * q / (4 * abs(c2)), float(np.sqrt(q / (2 * abs(c2))))
