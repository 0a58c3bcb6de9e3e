# dmi.identify.estimate and profile_likelihood: recovery of known parameters from the scheme's own
# data, coverage of the 95 % intervals over simulated noise, rank-deficient fits named, every bad
# input a clear error, stops that keep the best point.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import dmi
from dmi.identify import Record, estimate, profile_likelihood
from models.identify_models import coulomb as coulomb_oscillator


def memory_oscillator(h=0.02, tau=10.0):
    """w'' + k w + mu sigma(w') + int_0^tau sum_k c_k e^{a_k s} w'(t - s) ds + 2 cos 0.8 t ∋ 0 (a
    viscoelastic memory: two Prony terms on the velocity), w = w0, w' = 0 on t <= 0;
    p = (mu, k, c1, a1, c2, a2, w0)."""
    def make(p):
        mu, k, c1, a1, c2, a2, w0 = p
        s = dmi.Solver(2, tau, h=h)
        s.set_rhs(lambda t, u: np.array([-u[1], k * u[0] + 2.0 * math.cos(0.8 * t)]))
        s.set_friction([0.0, mu])
        C = np.zeros((2, 2, 2))
        C[0, 1, 1], C[1, 1, 1] = c1, c2
        s.set_kernel_exp([a1, a2], [0.0, 0.0], C)
        s.set_history(lambda t: np.array([w0, 0.0]))
        return s
    return make


TRUE = np.array([0.5, 1.0, 1.0, -0.3, 3.0, -3.0, 1.0])
NAMES = ["mu", "k", "c1", "a1", "c2", "a2", "w0"]


def data(make, p, T, every=1, comps=(0, 1)):
    s = make(np.array(p, float))
    s.init()
    t, U = s.run(round(T / s.h))
    return t[::every], U[::every][:, list(comps)]


def test_synthetic_recovery_from_twenty_percent_off():
    make = memory_oscillator()
    t, y = data(make, TRUE, 12.0, every=2)
    assert np.any(y[:, 1] == 0.0) and np.any(y[:, 1] > 0) and np.any(y[:, 1] < 0)  # sticks and slips
    p0 = TRUE * np.array([1.2, 0.8, 1.2, 0.8, 0.8, 1.2, 1.2])
    est = estimate(make, p0, Record(t, y), names=NAMES,
                   bounds=([0, 0, -10, -20, -10, -20, -10], [5, 5, 10, 0, 10, 0, 10]))
    assert est.success, est.message
    assert np.abs(est.p / TRUE - 1.0).max() < 1e-8, est.p
    # the exact sensitivities give a trust region's fast convergence: 11 Jacobians from 20 % off
    # here (the count is the route, which rounding may lengthen by a step or two; a wrong
    # Jacobian slows it down, which the bound is for)
    assert est.njev <= 20, est.njev
    assert est.unidentifiable == [] and est.unplaced == []
    assert np.all(np.isfinite(est.stderr))
    assert est.cost < 1e-16 and est.residuals.shape == (2 * len(t),)
    assert est.jacobian.shape == (2 * len(t), 7)


def test_several_records_with_shared_and_own_initial_conditions():
    base = memory_oscillator(h=0.02)

    def model(i):
        def make(p):   # p = (mu, k, w0 of record 0, w0 of record 1)
            q = TRUE.copy()
            q[0], q[1], q[6] = p[0], p[1], p[2 + i]
            return base(q)
        return make
    truth = np.array([0.5, 1.0, 0.3, -0.8])
    recs = []
    for i in range(2):
        t, y = data(model(i), truth, 6.0, every=3, comps=(0,))
        recs.append(Record(t, y[:, 0]))
    est = estimate([model(0), model(1)], truth * 1.2, recs, names=["mu", "k", "w0a", "w0b"])
    assert est.success and np.abs(est.p / truth - 1.0).max() < 1e-8, (est.p, est.message)


def test_fixed_parameters_and_bounds():
    make = memory_oscillator(h=0.02)
    t, y = data(make, TRUE, 6.0, every=3)
    p0 = TRUE.copy()
    p0[:2] *= 1.15
    est = estimate(make, p0, Record(t, y), names=NAMES, free=["mu", "k"],
                   bounds=([0.0, 0.5, -9, -9, -9, -9, -9], [2.0, 2.0, 9, 9, 9, 9, 9]))
    assert np.abs(est.p[:2] / TRUE[:2] - 1).max() < 1e-8
    assert np.all(est.p[2:] == TRUE[2:]) and np.all(est.stderr[2:] == 0.0)
    assert est.jacobian.shape[1] == 2


def test_friction_force_and_complex_step_in_a_fit():
    """Records of the friction force (X - U)/h through observe, with rhs by complex step."""
    make = memory_oscillator(h=0.02)
    s = make(TRUE)
    s.init()
    t, U, X = s.run_terms(300)
    force = (X[:, 1] - U[1:, 1]) / s.h
    assert np.any(np.abs(force) < TRUE[0] - 1e-9) and np.any(np.abs(np.abs(force) - TRUE[0]) < 1e-12)

    def rhs(t, u, p):
        return np.array([-u[1], p[1] * u[0] + 2.0 * np.cos(0.8 * t)])
    recs = [Record(t[1:], force, observe=lambda t, u, a: a[1]), Record(t[::3], U[::3, 0])]
    p0 = TRUE.copy()
    p0[:2] *= 1.2
    est = estimate([make, make], p0, recs, names=NAMES, free=["mu", "k"], rhs=rhs)
    assert est.success and np.abs(est.p[:2] / TRUE[:2] - 1).max() < 1e-8, (est.p, est.message)


def test_coverage_of_wald_intervals_over_400_data_sets():
    """Wald intervals (sigma known): the fraction of 95 % intervals holding the true value, over 400
    noisy data sets at the fit's h, within 95 +- 4 %, for each parameter."""
    make = coulomb_oscillator()
    truth = np.array([0.5, 1.0])
    t, y = data(make, truth, 6.0, every=5, comps=(0,))
    rng = np.random.default_rng(20261127)
    sigma = 0.02
    hits = np.zeros(2)
    for _ in range(400):
        noisy = y[:, 0] + sigma * rng.standard_normal(len(t))
        est = estimate(make, truth, Record(t, noisy, sigma=sigma), polish=False)
        for j in range(2):
            lo, hi = est.wald_interval(j)
            hits[j] += lo <= truth[j] <= hi
    frac = hits / 400
    assert np.all(np.abs(frac - 0.95) <= 0.04), frac


def test_equal_exponents_leave_the_prony_weights_undetermined():
    make = memory_oscillator(h=0.02)
    truth = TRUE.copy()
    truth[5] = truth[3]                              # a2 = a1: only c1 + c2 matters
    t, y = data(make, truth, 6.0, every=3)
    rng = np.random.default_rng(3)
    rec = Record(t, y + 0.01 * rng.standard_normal(y.shape), sigma=0.01)
    est = estimate(make, truth, rec, names=NAMES, free=["mu", "c1", "c2"])
    assert len(est.unidentifiable) == 1
    combo = est.unidentifiable[0]
    assert "c1" in combo and "c2" in combo and "mu" not in combo, combo
    assert np.isinf(est.stderr[2]) and np.isinf(est.stderr[4]) and np.isfinite(est.stderr[0])


def test_friction_of_a_mass_that_never_slips_is_undetermined():
    def make(p):
        k, mu = p
        s = dmi.Solver(2, 1.0, h=0.02)
        s.set_rhs(lambda t, u: np.array([k * u[0], -0.3 * math.cos(t)]))   # |force| 0.3 < mu
        s.set_friction([0.0, mu])
        s.set_history(lambda t: np.array([1.0, 0.0]))
        return s
    t, y = data(make, [0.7, 1.0], 4.0, every=4)
    assert np.all(y[:, 1] == 0.0)
    rng = np.random.default_rng(5)
    est = estimate(make, [0.6, 1.1], Record(t, y + 0.01 * rng.standard_normal(y.shape), sigma=0.01),
                   names=["k", "mu"])
    assert est.unidentifiable == ["1.00*mu"]
    assert np.isinf(est.stderr[1]) and 0 < est.stderr[0] < 0.05
    assert abs(est.p[0] - 0.7) < 5 * est.stderr[0]


def test_a_zero_jacobian_returns_failure_with_the_cost():
    def make(p):
        s = dmi.Solver(1, 1.0, h=0.05)
        s.set_rhs(lambda t, u: np.array([1.0]))
        return s
    t = np.linspace(0, 1, 11)
    est = estimate(make, [1.0, 2.0], Record(t, np.ones(11)), names=["a", "b"])
    assert not est.success
    assert "cost" in est.message and f"{est.cost:.6g}"[:5] in est.message
    assert len(est.unidentifiable) == 2


def test_bad_inputs_are_clear_errors():
    make = coulomb_oscillator()
    t = np.linspace(0, 2, 21)
    y = np.zeros(21)
    with pytest.raises(ValueError, match=r"y has shape \(20,\); expected \(21,\)"):
        estimate(make, [0.5, 1.0], Record(t, y[:-1]))
    bad = y.copy()
    bad[4] = np.nan
    with pytest.raises(ValueError, match="NaN .*row 4"):
        estimate(make, [0.5, 1.0], Record(t, bad))
    with pytest.raises(ValueError, match="outside the run"):
        estimate(make, [0.5, 1.0], Record(t - 0.5, y))
    with pytest.raises(ValueError, match="bounds exclude p0: p1 = 1.0"):
        estimate(make, [0.5, 1.0], Record(t, y), bounds=([0, 0], [1, 0.9]))
    with pytest.raises(ValueError, match="components"):
        estimate(make, [0.5, 1.0], Record(t, y, components=[3]))

    def refuses(p):
        if p[0] < 0:
            raise ValueError("mu must be >= 0")
        return make(p)
    with pytest.raises(ValueError, match="make\\(p0\\).*mu must be >= 0"):
        estimate(refuses, [-0.5, 1.0], Record(t, y))

    def changes_n(p):
        s = dmi.Solver(2, 1.0, 50 if p[1] <= 1.0 else 51)
        s.set_friction([0.0, p[0]])
        return s
    with pytest.raises(ValueError, match="changes N"):
        estimate(changes_n, [0.5, 1.0], Record(t, y))

    def changes_method(p):
        s = make(p)
        s.set_kernel_exp([-1.0], [0.0], np.zeros((1, 2, 2)))
        s.set_convolution("direct" if p[1] > 1.0 else "auto")
        return s
    with pytest.raises(ValueError, match="convolution method"):
        estimate(changes_method, [0.5, 1.0], Record(t, y))


def test_an_unplaced_reversal_withholds_the_covariance():
    # the constructed case of identify/test_sensitivity.py: at h = 0.01 the reversal of step 5
    # cannot be placed inside its step, so the Jacobian there is not the equation's derivative
    from models.identify_models import forcing_reversed_in_the_crossing_step
    make = forcing_reversed_in_the_crossing_step(0.01)
    t, y = data(make, [1.0], 0.12, comps=(0,))
    with pytest.warns(RuntimeWarning, match=r"could not place 1 .*step 5 of record 0.*smaller h"):
        est = estimate(make, [1.1], Record(t, y[:, 0]), names=["mu"])
    assert abs(est.p[0] - 1.0) < 1e-8                      # the residuals are the scheme's own
    assert est.unplaced == [(0, 5)] and "smaller h" in est.message
    assert np.isnan(est.stderr[0]) and np.isnan(est.cov[0, 0])
    # at h = 0.001 every reversal is placed: a covariance, and no warning
    make = forcing_reversed_in_the_crossing_step(0.001)
    t, y = data(make, [1.0], 0.12, comps=(0,))
    noisy = y[:, 0] + 1e-3 * np.random.default_rng(2).standard_normal(len(t))
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        est = estimate(make, [1.1], Record(t, noisy, sigma=1e-3), names=["mu"])
    assert est.success and est.unplaced == [] and 0.0 < est.stderr[0] < 0.1


def test_profile_of_an_estimate_that_did_not_converge_is_refused():
    record = noisy_decay()
    stopped = estimate(decay, [1.5, -0.3], record, names=["z0", "k"], callback=lambda info: True)
    assert not stopped.success
    with pytest.raises(ValueError, match="did not converge.*refit"):
        profile_likelihood(stopped, "z0")


def test_a_callback_stop_and_ctrl_c_keep_the_best_point():
    make = memory_oscillator(h=0.02)
    t, y = data(make, TRUE, 6.0, every=3)
    seen = []

    def stop(info):
        seen.append(info["cost"])
        return info["iteration"] == 2
    est = estimate(make, TRUE * 1.2, Record(t, y), callback=stop)
    assert not est.success and "stopped" in est.message and len(seen) == 2
    assert abs(est.cost - seen[-1]) <= 1e-12 * seen[-1]

    def interrupt(info):
        seen.append(info["cost"])
        if info["iteration"] == 2:
            raise KeyboardInterrupt
    seen.clear()
    est = estimate(make, TRUE * 1.2, Record(t, y), callback=interrupt)
    assert not est.success and "KeyboardInterrupt" in est.message
    assert est.cost <= seen[-1] * (1 + 1e-12)


def test_multistart_finds_the_lower_minimum():
    def make(p):
        s = dmi.Solver(2, 1.0, h=0.02)
        om = p[0]
        s.set_rhs(lambda t, u: np.array([-u[1], om * om * u[0]]))
        s.set_history(lambda t: np.array([1.0, 0.0]))
        return s
    t, y = data(make, [3.0], 10.0, every=2, comps=(0,))
    one = estimate(make, [1.2], Record(t, y[:, 0]))
    many = estimate(make, [1.2], Record(t, y[:, 0]), multistart=[[2.0], [2.9]])
    assert abs(one.p[0] - 3.0) > 0.1                # a local minimum from the first start
    assert abs(many.p[0] - 3.0) < 1e-8 and len(many.starts) == 3


def decay(p):
    """u' = k u, u = z0 on t <= 0; p = (z0, k)."""
    z0, k = p
    s = dmi.Solver(1, 1.0, h=0.05)
    s.set_rhs(lambda t, u: k * u)
    s.set_history(lambda t: np.array([z0]))
    return s


def test_profile_equals_wald_for_a_linear_parameter_and_differs_for_a_rate():
    make = decay
    t, y = data(make, [1.0, 0.8], 3.0, comps=(0,))
    rng = np.random.default_rng(11)
    noisy = y[:, 0] + 0.15 * rng.standard_normal(len(t))
    est = estimate(make, [1.0, 0.8], Record(t, noisy, sigma=0.15), free=[0], names=["z0", "k"])
    prof = profile_likelihood(est, "z0")
    # u is linear in z0: the cost is an exact quadratic, so both intervals are the same
    assert prof.quadratic and np.allclose(prof.interval, prof.wald, rtol=0, atol=1e-4 * est.stderr[0])
    # the decay rate from 20 points with much noise: the cost is far from quadratic
    noisy = y[:20, 0] + 0.5 * np.random.default_rng(12).standard_normal(20)
    est = estimate(make, [1.0, 0.8], Record(t[:20], noisy, sigma=0.5), free=[1], names=["z0", "k"])
    prof = profile_likelihood(est, "k")
    assert not prof.quadratic and "not quadratic" in prof.message
    # the interval's ends are where the cost (computed here from plain runs) has risen by chi2/2
    for v in prof.interval:
        s = make([1.0, v])
        s.init()
        _, U = s.run(19)
        cost = 0.5 * np.sum(((U[:, 0] - noisy) / 0.5) ** 2)
        assert abs(cost - est.cost - 1.920729) < 1e-3
    with pytest.raises(ValueError, match="fixed"):
        profile_likelihood(est, "z0")



def noisy_decay():
    """A record of decay at (1, -0.8) over t in [0, 3] with noise 0.05 (sigma given)."""
    t, y = data(decay, [1.0, -0.8], 3.0, comps=(0,))
    return Record(t, y[:, 0] + 0.05 * np.random.default_rng(5).standard_normal(len(t)), sigma=0.05)


def test_profile_end_through_a_refit_that_did_not_converge_is_not_reported(monkeypatch):
    """A refit stopped before converging overstates the profile's cost: an end found through it is
    reported as infinite, with a warning, not as a number."""
    import scipy.optimize

    est = estimate(decay, [1.1, -0.7], noisy_decay(), names=["z0", "k"])
    assert est.success, est.message
    assert np.all(np.isfinite(profile_likelihood(est, "z0").interval))
    real = scipy.optimize.least_squares

    def stopped_early(*args, **kwargs):     # the refit's result, marked as stopped by max_nfev
        res = real(*args, **kwargs)
        res.status, res.success = 0, False
        return res
    monkeypatch.setattr(scipy.optimize, "least_squares", stopped_early)
    with pytest.warns(RuntimeWarning, match="did not converge"):
        prof = profile_likelihood(est, "z0")
    assert prof.interval == (-math.inf, math.inf) and not prof.quadratic
    assert "not verified" in prof.message


def test_a_wald_interval_of_a_fit_that_did_not_converge_warns():
    record = noisy_decay()
    done = estimate(decay, [1.1, -0.7], record, names=["z0", "k"])
    assert done.success, done.message
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.all(np.isfinite(done.wald_interval("k")))
    stopped = estimate(decay, [1.5, -0.3], record, names=["z0", "k"], callback=lambda info: True)
    assert not stopped.success
    with pytest.warns(RuntimeWarning, match="did not converge"):
        stopped.wald_interval("k")
