# Two models with memory whose periodic orbits are known independently of dmi, shared by the
# collocation tests and the analysis events: van der Pol with a distributed delay and its limit
# cycle by a Fourier spectral solve (the delay integral exact on each Fourier mode); the circles of
# a rotating system with a damped-cosine memory in closed form (from the kernel's transform at the
# circle's frequency); and the scheme's orbit of a forced model of orbit_models.py.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np
import scipy.linalg as sl
import scipy.optimize as so

import dmi
from dmi import analysis as da

TAU, AV = 1.0, 0.5


# ---- van der Pol with a distributed delay -------------------------------------------------------
# w'' + (w^2 - 1) w' + w + (a / tau) int_0^tau w(t - s) ds = 0 as u = (w, v): f = (-v, (w^2 - 1) v
# + w), H = [[0, 0], [a / tau, 0]].
def vdp(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p / TAU, 0.0]]])
    return s


def vdp_scheme_orbit() -> da.Orbit:
    s = vdp(AV)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(6000)
    return da.periodic_orbit(vdp, AV, None, s, guess_period=6.0, steps=600, multipliers=0)


def newton_fd(res, z0, tol=1e-13, iters=30):
    """Newton with a forward-difference Jacobian (step 1e-7) and scipy's dense solve."""
    z = np.array(z0, dtype=float)
    for _ in range(iters):
        r = res(z)
        Jac = np.empty((r.size, z.size))
        for j in range(z.size):
            d = np.zeros(z.size)
            d[j] = 1e-7 * max(1.0, abs(z[j]))
            Jac[:, j] = (res(z + d) - r) / d[j]
        dz = sl.solve(Jac, -r)
        z = z + dz
        if np.max(np.abs(dz)) < tol * max(1.0, np.max(np.abs(z))):
            return z
    raise AssertionError("Newton did not converge")


def fourier_orbit(guess_T: float, guess_w, N: int = 192):
    """The limit cycle by a Fourier collocation on N points of one period: w' = v, v' = -(w^2 - 1)
    v - w - (a / tau) Z with Z = int_0^tau w(t - s) ds exact on each mode k (Z_k = w_k (1 -
    e^{-i k Om tau}) / (i k Om), Z_0 = tau w_0), phase v(0) = 0; scipy's root (hybr).  Returns
    (T, w, v on the grid)."""
    k = np.fft.fftfreq(N, 1.0 / N)
    th = np.arange(N) / N

    def ops(T):
        om = 2 * np.pi / T
        ik = 1j * k * om
        J = np.where(k == 0, TAU, (1 - np.exp(-ik * TAU)) / np.where(k == 0, 1, ik))
        return ik, J

    def res(z):
        w, v, T = z[:N], z[N:2 * N], z[-1]
        ik, J = ops(T)
        W, Vh = np.fft.fft(w), np.fft.fft(v)
        dw, dv = np.fft.ifft(ik * W).real, np.fft.ifft(ik * Vh).real
        Z = np.fft.ifft(J * W).real
        return np.concatenate([dw - v, dv + (w ** 2 - 1) * v + w + AV / TAU * Z, [v[0]]])

    w0 = guess_w(th * guess_T)
    w0 = np.roll(w0, -int(np.argmax(w0)))          # near v(0) = 0: start at the maximum of w
    v0 = np.fft.ifft(1j * k * 2 * np.pi / guess_T * np.fft.fft(w0)).real
    z = newton_fd(res, np.concatenate([w0, v0, [guess_T]]))
    assert np.max(np.abs(res(z))) < 1e-11
    return z[-1], z[:N], z[N:2 * N]



# ---- circles of a rotating system with a damped-cosine memory ---------------------------------
# u' = (mu - |u|^2) u + w0 J u - int_0^tau g e^{-s / th} cos(beta s) u(t - s) ds in R^2:
# z = x + i y, z = r e^{i Om t} with i Om = mu - r^2 + i w0 - K(i Om), K(q) = int_0^tau g e^{-s/th} cos(beta s)
# e^{-q s} ds in closed form.
MU, W0, G, TH, BETA, TAU_C = 1.0, 1.0, 0.5, 1.0, 2.0, 2.0


def K_hat(q: complex) -> complex:
    out = 0j
    for sb in (1, -1):
        c = -1 / TH + 1j * sb * BETA - q
        out += 0.5 * G * (np.exp(c * TAU_C) - 1) / c
    return out


def circle_reference() -> tuple[float, float]:
    Om = so.brentq(lambda W: W - W0 + K_hat(1j * W).imag, 0.1, 3.0, xtol=1e-15)
    r2 = MU - K_hat(1j * Om).real
    return math.sqrt(r2), 2 * math.pi / Om


def rotating(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU_C, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: -((p - u @ u) * u + W0 * np.array([-u[1], u[0]])))
    s.set_kernel_exp([-1 / TH], [BETA], [G * np.eye(2)])
    return s



def forced_orbit(model, M: int, periods: int, p: float = 1.0) -> da.Orbit:
    """The scheme's orbit of a forced model of orbit_models.py at M steps a period, from rest
    run ``periods`` periods."""
    make = model.make_for(M)
    s = make(p)
    s.init()
    s.advance(periods * M)
    return da.periodic_orbit(make, p, model.T, s, multipliers=0)
