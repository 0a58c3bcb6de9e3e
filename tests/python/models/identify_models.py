# Models of dmi.identify's tests shared by several of them: the smooth three-component model with
# memory and its parameters, the friction oscillator with memory of the event-driven reference
# (identify/test_sensitivity.py), a forcing reversed inside the step that crosses zero, and the
# Coulomb oscillator of the fits.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math

import numpy as np

import dmi


def smooth_model(kernel="exp", convolution="auto", quadrature="left", h=None):
    """n = 3: a nonlinear oscillator (u0, u1) with memory on u0, and u2 always slipping down
    under friction; parameters (k, c, mu, a0, C0, b1, D1, z0)."""
    def make(p):
        k, c, mu, a0, C0, b1, D1, z0 = p
        s = dmi.Solver(3, 0.8, 40) if h is None else dmi.Solver(3, 0.8, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], k * math.sin(u[0]) + c * u[1] * abs(u[1]) + math.cos(t),
                                         3.0 + 0.2 * u[0]]))
        s.set_friction([0.0, 0.0, mu])
        Cm = np.zeros((2, 3, 3))
        Dm = np.zeros((2, 3, 3))
        Cm[0, 1, 0], Cm[1, 1, 0], Dm[1, 1, 0] = C0, 0.5, D1
        if kernel == "exp":
            s.set_kernel_exp([a0, -0.7], [0.0, b1], Cm, Dm)
        else:
            def H(x):
                return (np.exp(a0 * x) * Cm[0] + np.exp(-0.7 * x) * (Cm[1] * np.cos(b1 * x)
                                                                     + Dm[1] * np.sin(b1 * x)))
            s.set_kernel(H)
        s.set_history(lambda t: np.array([z0 + 0.3 * t, 0.2 * math.cos(3 * t), -0.1]))
        s.set_convolution(convolution)
        s.set_quadrature(quadrature)
        return s
    return make


P_SMOOTH = [1.3, -0.2, 0.4, -1.1, 0.8, 2.0, 0.3, 0.25]


def oscillator(h, mu, k=1.0, g=2.0, om=0.8, w0=0.3, c=0.0, a=-5.0, tau=1.0):
    """The scheme of w'' + k w + mu sigma(w') + int_0^tau c e^{a s} w(t - s) ds + g cos(om t) ∋ 0,
    w = w0, w' = 0 on t <= 0; parameters (mu, c)."""
    def make(p):
        s = dmi.Solver(2, tau, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] + g * math.cos(om * t)]))
        s.set_friction([0.0, p[0]])
        C = np.zeros((1, 2, 2))
        C[0, 1, 0] = p[1]
        s.set_kernel_exp([a], [0.0], C)
        s.set_history(lambda t: np.array([w0, 0.0]))
        return s
    return make


def forcing_reversed_in_the_crossing_step(h, jit=False):
    """u' + mu sigma(u) ∋ -f, f = 3 until t = 0.055 and -3 after, u = 0.215 on t <= 0: u reaches 0
    at t = 0.05375 (speed -4, then -2 after the reversal); at h = 0.01 the step that crosses zero,
    [0.05, 0.06], also holds the jump of f, so the velocity interpolated at the crossing does not
    have the sign of a reversal; parameter (mu,)."""
    def make(p):
        s = dmi.Solver(1, 1.0, h=h)
        s.set_rhs(lambda t, u: np.array([3.0 if t < 0.055 else -3.0]), jit=jit)
        s.set_friction([p[0]])
        s.set_history(lambda t: np.array([0.215]))
        return s
    return make


def coulomb(h=0.02):
    """w'' + k w + mu sigma(w') + 2 cos 0.8t ∋ 0, w = 0.3, w' = 0 on t <= 0; p = (mu, k)."""
    def make(p):
        mu, k = p[0], p[1]
        if mu < 0:
            raise ValueError("alpha[1] must be >= 0")
        s = dmi.Solver(2, 1.0, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] + 2.0 * math.cos(0.8 * t)]))
        s.set_friction([0.0, mu])
        s.set_history(lambda t: np.array([0.3, 0.0]))
        return s
    return make
