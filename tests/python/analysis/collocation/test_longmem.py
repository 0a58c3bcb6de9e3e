# Collocation on a long memory: the leading Floquet multipliers by ARPACK on the monodromy operator
# (dmi.analysis.collocation.krylov) against the dense monodromy matrix and against an independent
# computation: van der Pol with a three-term exponential memory of six periods, whose exponential
# terms are ODE states of their own (z_k' = w - a_k z_k; the memory's truncation at tau is below
# 1e-13), its monodromy integrated with scipy's DOP853; the Floquet eigenfunction by ARPACK against
# the dense matrix's; and hopf_orbit(of="equation") started at the amplitude's predicted parameter
# against the closed-form circles and the start at p_H.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import math
import warnings

import numpy as np
import pytest
import scipy.linalg as sl

import dmi
from dmi import analysis as da
from dmi.analysis.collocation import floquet, krylov

from models import delay_models as tc
from models.orbit_models import limit_cycle

RATES = np.array([0.8, 1.6, 3.2])          # the memory's decay rates
WEIGHTS = np.array([0.05, 0.05, 0.05])     # and weights: v' gets -sum_k w_k int e^-a_k s w(t - s)
TAU = 40.0                                 # about 6.5 periods; e^(-0.8 tau) ~ 1e-14
P = 0.15                                   # van der Pol's damping


def vdp_memory(p: float, h: float | None = None) -> dmi.Solver:
    """w' = v, v' = -p (w^2 - 1) v - w - sum_k c_k int_0^tau e^(-a_k s) w(t - s) ds."""
    s = dmi.Solver(2, TAU, h=0.02 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], p * (u[0] ** 2 - 1) * u[1] + u[0]]))
    C = np.zeros((RATES.size, 2, 2))
    C[:, 1, 0] = WEIGHTS
    s.set_kernel_exp(-RATES, np.zeros(RATES.size), C)
    return s


def ode(t: float, y: np.ndarray) -> np.ndarray:
    """The same model with its memory's terms as states z_k = int_0^inf e^(-a_k s) w(t - s) ds."""
    w, v, z = y[0], y[1], y[2:]
    return np.concatenate([[v, -P * (w * w - 1) * v - w - WEIGHTS @ z], w - RATES * z])


def ode_jacobian(y: np.ndarray) -> np.ndarray:
    w, v = y[0], y[1]
    J = np.zeros((5, 5))
    J[0, 1] = 1.0
    J[1, 0], J[1, 1], J[1, 2:] = -2 * P * w * v - 1, -P * (w * w - 1), -WEIGHTS
    J[2:, 0] = 1.0
    J[2:, 2:] = -np.diag(RATES)
    return J


@pytest.fixture(scope="module")
def reference() -> tuple[float, np.ndarray]:
    """The ODE's period and multipliers (largest first): the limit cycle reached from (2, 0),
    its period between two upward crossings of w = 0, the variational equations over it."""
    return limit_cycle(ode, ode_jacobian, [2.0, 0, 0, 0, 0], 5)


@pytest.fixture(scope="module")
def scheme_orbit(reference) -> da.Orbit:
    T, _ = reference
    steps = 400
    s = vdp_memory(P, h=T / steps)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(40 * steps)
    return da.periodic_orbit(vdp_memory, P, None, s, guess_period=T, steps=steps,
                             multipliers=0)


def operator_of(orbit: da.EquationOrbit):
    disc, x = da.CollocationDiscretisation.of(orbit, estimate=False)
    return disc.lay, disc.terms(orbit.p), x


def test_operator_is_the_dense_monodromy(scheme_orbit):
    e = da.collocate(scheme_orbit, intervals=4, multipliers=0)
    lay, terms, x = operator_of(e)
    M = floquet.monodromy(lay, terms, x)                  # the dense matrix, as before
    op = floquet.operator(lay, terms, x)
    assert op.dim == M.shape[0] > 300                     # the past of six periods
    v = np.random.default_rng(3).standard_normal((op.dim, 3))
    scale = np.max(np.abs(M @ v))
    assert np.max(np.abs(op.apply(v) - M @ v)) <= 1e-12 * scale
    w = v[:, 0] + 1j * v[:, 1]
    assert np.max(np.abs(op.apply(w) - M @ w)) <= 1e-12 * scale


def test_arpack_leading_multipliers_against_dense_and_ode(scheme_orbit, reference, monkeypatch):
    T, mu_ode = reference
    monkeypatch.setattr(floquet, "DENSE_MAX", 200)        # collocate takes ARPACK's
    e = da.collocate(scheme_orbit, intervals=6, multipliers=2)
    lay, terms, x = operator_of(e)
    op = floquet.operator(lay, terms, x)
    assert op.dim > 600
    dense = sl.eigvals(floquet.monodromy(lay, terms, x))
    dense = dense[np.argsort(-np.abs(dense))][:2]
    arnoldi = krylov.leading_pairs(op, 2)
    assert arnoldi is not None
    assert np.max(np.abs(arnoldi[0] - dense)) <= 1e-9
    assert np.max(np.abs(e.multipliers[:2] - dense)) <= 1e-9
    # against the ODE: the trivial multiplier and the orbit's own, to the estimated errors
    assert abs(e.period - T) <= e.errors["period"]
    assert np.all(np.abs(e.multipliers[:2] - mu_ode[:2]) <= e.errors["multipliers"][:2])
    assert abs(mu_ode[1] - 0.3065) < 1e-3                 # well apart from the memory's ring


def test_dense_and_arpack_paths_of_collocate_agree(scheme_orbit, monkeypatch):
    e = da.collocate(scheme_orbit, intervals=4, multipliers=2)
    lay, terms, x = operator_of(e)
    assert floquet.operator(lay, terms, x).dim <= krylov.DENSE_MAX     # the dense path
    monkeypatch.setattr(floquet, "DENSE_MAX", 50)
    found = []
    monkeypatch.setattr(floquet, "leading_pairs",
                        lambda op, count: found.append(krylov.leading_pairs(op, count))
                        or found[-1])
    a = da.collocate(scheme_orbit, intervals=4, multipliers=2)        # ARPACK's
    assert found and all(f is not None for f in found)                # (not the dense fallback)
    assert np.max(np.abs(a.multipliers - e.multipliers)) <= 1e-9
    assert a.period == e.period


def test_hopf_orbit_starts_at_the_predicted_parameter():
    # u' = (mu - |u|^2) u + w0 J u - memory: circles of radius sqrt(mu - mu_H), kappa = (1, 1)
    _, T = tc.circle_reference()
    muH = tc.K_hat(2j * math.pi / T).real
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hp = da.hopf(tc.rotating, muH - 0.1, muH + 0.1, [0.0, 0.0], of="equation")
    assert hp.kappa is not None and np.allclose(hp.kappa, 1.0, atol=1e-5)
    a = 0.1
    start = da.equilibria.normal_form.predicted_parameter(hp, a)
    assert abs(start - (muH + a * a)) < 1e-4 and abs(start - hp.p) > 1e-3
    e = da.hopf_orbit(tc.rotating, hp, [0.0, 0.0], amplitude=a, of="equation")
    assert abs(e.p - (muH + a * a)) < 1e-10
    assert abs(e.period - T) < 1e-10
    old = da.hopf_orbit(tc.rotating, dataclasses.replace(hp, kappa=None), [0.0, 0.0],
                        amplitude=a, of="equation")        # started at p_H, as before
    assert abs(e.p - old.p) < 1e-11 and abs(e.period - old.period) < 1e-11


def test_eigenfunction_by_arpack_is_the_dense_one(scheme_orbit, reference, monkeypatch):
    _, mu_ode = reference
    e = da.collocate(scheme_orbit, intervals=4, multipliers=0)
    lay, terms, x = operator_of(e)
    mu, V = floquet.eigenfunction(lay, terms, x, near=0.3)           # the dense matrix's
    monkeypatch.setattr(floquet, "DENSE_MAX", 50)
    found = []
    monkeypatch.setattr(floquet, "nearest",
                        lambda op, near: found.append(krylov.nearest(op, near)) or found[-1])
    mu_a, V_a = floquet.eigenfunction(lay, terms, x, near=0.3)       # ARPACK's
    assert found and found[0] is not None                             # (not the dense fallback)
    monkeypatch.setattr(floquet, "nearest", krylov.nearest)
    assert abs(mu - mu_ode[1]) < 1e-4 and abs(mu_a - mu) <= 1e-9
    assert np.max(np.abs(V_a - V)) <= 1e-7
    assert np.max(np.abs(V)) == pytest.approx(1.0)
    # a wanted multiplier that the leading ones cannot prove the nearest: the dense matrix's
    mu0, _ = floquet.eigenfunction(lay, terms, x, near=0.01)
    assert abs(mu0) < abs(mu_ode[1])
