# dmi.identify refuses what it cannot do and says when a fit is not what it seems: a record asking
# for too many steps refused up front (in a subprocess with a time limit), the reduced chi-square
# and its p-value against scipy.stats, covariance scaling, parameters without effect named before
# the fit moves them, a saddle found at the end, the fit report, fixed parameters by name, a
# profile open on both sides, and observe returning NaN named.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import os
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pytest
from scipy import stats

import dmi
from dmi.identify import (MAX_STEPS, FitOptions, Parameter, Record, estimate, profile_likelihood,
                          sensitivities)
from models.identify_models import coulomb


def run(make, p, steps):
    s = make(np.array(p, float))
    s.init()
    return s.run(steps)


def noisy(make, p, steps, sigma, seed, every=3):
    t, U = run(make, p, steps)
    y = U[::every, 0] + sigma * np.random.default_rng(seed).standard_normal(len(t[::every]))
    return t[::every], y


# ---- 1. too many steps: refused before any run --------------------------------------------------

def test_a_record_at_t_1e6_is_refused_at_once_in_a_subprocess():
    """One record time at t = 1e6 with h = 0.01 (1e8 steps): a ValueError naming the steps, the
    bound and the memory, well within the time limit (a run would take minutes and GiBs)."""
    code = textwrap.dedent("""
        import math, numpy as np, dmi
        from dmi.identify import Record, estimate, sensitivities
        def make(p):
            s = dmi.Solver(2, 1.0, h=0.01)
            s.set_rhs(lambda t, u: np.array([-u[1], p[1] * u[0]]))
            s.set_friction([0.0, p[0]])
            s.set_history(lambda t: np.array([0.3, 0.0]))
            return s
        for call in (lambda: estimate(make, [0.5, 1.0], Record([0.0, 1e6], [0.3, 0.0])),
                     lambda: sensitivities(make, [0.5, 1.0], 10**8)):
            try:
                call()
                print("NO ERROR")
            except ValueError as e:
                print("REFUSED", e)
    """)
    env = dict(os.environ)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60,
                         env=env)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert len(lines) == 2 and all(x.startswith("REFUSED") for x in lines), out.stdout
    assert "records[0]" in lines[0] and "100000000 steps" in lines[0]
    assert f"max_steps = {MAX_STEPS}" in lines[0] and "GiB" in lines[0]
    # the memory: S, dX (n P numbers a step each, plus S of N + 1 history rows), U and X (n each)
    n, P, N, steps = 2, 2, 100, 10**8
    gib = 8 * ((N + steps + 1) * n * P + 2 * steps * n * P + 2 * (steps + 1) * n) / 2 ** 30
    assert f"{gib:.3g} GiB" in lines[0], (gib, lines[0])
    assert "sensitivities asks for 100000000 steps" in lines[1]


def test_an_explicit_max_steps_bounds_and_allows():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 150, 0.02, 1)
    with pytest.raises(ValueError, match=r"records\[0\] .*asks for 150 steps.*max_steps = 100;"):
        estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), options=FitOptions(max_steps=100))
    est = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), options=FitOptions(max_steps=150))
    assert est.success, est.message
    with pytest.raises(ValueError, match="sensitivities asks for 150 steps"):
        sensitivities(make, [0.5, 1.0], 150, max_steps=149)
    with pytest.raises(ValueError, match="max_steps = 0: expected an integer >= 1"):
        sensitivities(make, [0.5, 1.0], 150, max_steps=0)


def test_progress_display_is_off_when_stderr_is_not_a_terminal_and_on_when_asked(capfd):
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 150, 0.02, 2)
    estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02))
    assert capfd.readouterr().err == ""
    estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), options=FitOptions(progress=True))
    err = capfd.readouterr().err
    assert "estimate: start 1/1, iteration 1, cost" in err and err.endswith("\n")


# ---- 2. the noise model: reduced chi-square, p-value, warning, scaling ---------------------------

def test_reduced_chi_square_and_p_value_against_scipy_and_sigma_ten_times_too_small():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 300, 0.02, 3)
    right = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), names=["mu", "k"])
    M, F = len(t), 2
    chi2 = float(np.sum(right.residuals ** 2))                   # from the residuals themselves
    assert right.dof == M - F
    assert right.chisqr == pytest.approx(chi2, rel=1e-12)
    assert right.redchi == pytest.approx(chi2 / (M - F), rel=1e-12)
    assert right.pvalue == pytest.approx(float(stats.chi2.sf(chi2, M - F)), rel=1e-10)
    assert 0.001 < right.pvalue < 0.999 and right.success
    # sigma stated ten times too small: chi2/dof about 100, a warning, and the message says so
    with pytest.warns(RuntimeWarning, match=r"reduced chi-square .* implausible .* understated"):
        small = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.002), names=["mu", "k"])
    assert 60 < small.redchi < 160 and small.pvalue < 1e-10
    assert "implausible" in small.message and not small.covar_scaled
    # its standard errors are ten times too small as stated ...
    assert np.allclose(small.stderr, right.stderr / 10, rtol=1e-3)
    # ... and scaled by the reduced chi-square they are those of the right sigma (scaled too:
    # exactly, as chi2 scales with 1/sigma^2), and within sqrt(redchi) of the unscaled ones
    with pytest.warns(RuntimeWarning, match="scaled by it"):
        fixed = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.002), names=["mu", "k"],
                         options=FitOptions(scale_covar=True))
    right_scaled = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), names=["mu", "k"],
                            options=FitOptions(scale_covar=True))
    assert fixed.covar_scaled
    assert np.allclose(fixed.stderr, right_scaled.stderr, rtol=1e-5)
    assert np.allclose(fixed.stderr, right.stderr * math.sqrt(right.redchi), rtol=1e-5)
    assert np.allclose(fixed.stderr, right.stderr, rtol=0.15)
    # sigma ten times too large: the lower tail
    with pytest.warns(RuntimeWarning, match="overstated"):
        big = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.2))
    assert big.redchi < 0.05 and stats.chi2.cdf(big.chisqr, big.dof) < 1e-3


def test_without_sigma_the_p_value_is_not_reported():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 300, 0.02, 4)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        est = estimate(make, [0.6, 0.9], Record(t, y))
    assert math.isnan(est.pvalue) and est.covar_scaled
    assert est.redchi == pytest.approx(np.sum(est.residuals ** 2) / (len(t) - 2), rel=1e-12)


# ---- 3. a parameter that does not enter the model ------------------------------------------------

def test_a_parameter_without_effect_is_named_and_kept_before_the_fit_moves_the_others():
    base = coulomb()

    def make(p):                      # p = (mu, k, nu): nu enters nothing
        return base(p[:2])
    t, y = noisy(base, [0.5, 1.0], 300, 0.02, 5, every=5)
    with pytest.warns(RuntimeWarning, match=r"nu does not move the records at p0"):
        est = estimate(make, [0.6, 0.9, 1.0], Record(t, y, sigma=0.02), names=["mu", "k", "nu"])
    assert est.success, est.message
    assert est.insensitive == ["nu"] and "1.00*nu" in est.unidentifiable
    assert est.p[2] == 1.0 and math.isinf(est.stderr[2]) and not est.free[2]
    # mu and k as in the fit without nu (nothing walked into the model's own refusal)
    ref = estimate(base, [0.6, 0.9], Record(t, y, sigma=0.02))
    assert np.allclose(est.p[:2], ref.p, rtol=1e-8) and np.allclose(est.stderr[:2], ref.stderr, rtol=1e-8)
    assert abs(est.p[0] - 0.5) < 4 * est.stderr[0]


# ---- 4. a saddle at the end ------------------------------------------------------------------------

def two_terms(p):
    """u' = 0.2 u - cos t - int_0^5 (c1 e^{a1 s} + c2 e^{a2 s}) u(t - s) ds, u = 1 on t <= 0;
    p = (c1, a1, c2, a2)."""
    c1, a1, c2, a2 = p
    s = dmi.Solver(1, 5.0, h=0.05)
    s.set_rhs(lambda t, u: np.array([0.2 * u[0] - math.cos(t)]))
    s.set_kernel_exp([a1, a2], [0.0, 0.0], np.array([[[c1]], [[c2]]]))
    s.set_history(lambda t: np.array([1.0]))
    return s


def test_an_over_parameterised_fit_stopped_on_the_saddle_line_is_reported():
    """Data from one memory term, fitted with two: from this start the fit stops on the line
    a1 = a2 (SciPy's convergence, unidentifiable c1 - c2) though a fit 0.25 lower exists; the
    saddle check finds a lower cost near the line, which a plain run in the test confirms."""
    t, U = run(two_terms, [1.0, -0.5, 0.0, -0.5], 200)
    sig = 0.02
    rec = Record(t, U[:, 0] + sig * np.random.default_rng(4).standard_normal(len(t)), sigma=sig)
    bounds = ([-3, -3, -3, -3], [3, 0, 3, 0])
    start = [0.82177012, -2.19063986, -2.75415886, -2.95041709]
    names = ["c1", "a1", "c2", "a2"]
    stuck = estimate(two_terms, start, rec, names=names, bounds=bounds,
                     options=FitOptions(saddle_check=False))
    assert stuck.success and abs(stuck.p[1] - stuck.p[3]) < 1e-4      # today's answer
    with pytest.warns(RuntimeWarning, match="saddle"):
        est = estimate(two_terms, start, rec, names=names, bounds=bounds)
    assert not est.success and "saddle" in est.message and "Estimate.lower" in est.message
    assert est.cost == stuck.cost and est.lower is not None
    # the lower point's cost, from a plain run here
    _, V = run(two_terms, est.lower, 200)
    cost = 0.5 * float(np.sum(((V[:, 0] - rec.y) / sig) ** 2))
    assert cost == pytest.approx(est.lower_cost, rel=1e-12) and cost < est.cost - 1e-3
    assert f"{est.lower_cost:.10g}" in est.message
    # a fit 0.25 lower exists off the line (found by multistart=8 from p0 and bounds as here)
    _, V = run(two_terms, [0.04048169, -0.28263346, 0.96135711, -0.51252815], 200)
    assert 0.5 * float(np.sum(((V[:, 0] - rec.y) / sig) ** 2)) < est.cost - 0.2


def test_no_saddle_reported_where_the_null_direction_is_flat():
    """Equal exponents fixed: only c1 + c2 matters, the cost is exactly flat along c1 - c2 and no
    lower point exists."""
    def make(p):
        return two_terms([p[0], -0.5, p[1], -0.5])
    t, U = run(make, [0.6, 0.4], 200)
    rec = Record(t, U[:, 0] + 0.02 * np.random.default_rng(6).standard_normal(len(t)), sigma=0.02)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        est = estimate(make, [0.5, 0.3], rec, names=["c1", "c2"])
    assert est.success and est.lower is None and len(est.unidentifiable) == 1


# ---- 5. the report and fixed parameters by name ----------------------------------------------------

def test_report_and_html_carry_the_fit_and_a_fixed_parameter_stays():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 300, 0.02, 7)
    # the same fit as today's positional call with free=, by a mapping of Parameters
    est = estimate(make, {"mu": Parameter(0.6, lower=0.0, upper=2.0), "k": 0.9},
                   Record(t, y, sigma=0.02))
    old = estimate(make, [0.6, 0.9], Record(t, y, sigma=0.02), names=["mu", "k"],
                   bounds=([0.0, -np.inf], [2.0, np.inf]))
    assert est.names == ["mu", "k"] and np.array_equal(est.p, old.p)
    text = est.report()
    M = len(t)
    chi2 = float(np.sum(est.residuals ** 2))
    assert f"{chi2:.6g}" in text and f"{chi2 / (M - 2):.6g}" in text
    assert f"{stats.chi2.sf(chi2, M - 2):.4g}" in text
    for j, name in enumerate(["mu", "k"]):
        assert f"{est.p[j]:.10g}" in text and f"{est.stderr[j]:.6g}" in text
    # the correlation from the covariance, computed here from the Jacobian
    cov = np.linalg.inv(est.jacobian.T @ est.jacobian)
    corr = cov[0, 1] / math.sqrt(cov[0, 0] * cov[1, 1])
    assert f"C(mu, k) = {corr:+.4f}" in text or f"C(k, mu) = {corr:+.4f}" in text
    assert "free in [0, 2]" in text
    page = est._repr_html_()
    assert "<table>" in page and f"{est.p[0]:.10g}" in page and f"{chi2:.6g}" in page
    # a fixed parameter stays at its value exactly, and the report says it is fixed
    with pytest.warns(RuntimeWarning, match="understated"):          # mu = 0.55 is off
        fixed = estimate(make, {"mu": Parameter(0.55, fixed=True), "k": Parameter(0.9)},
                         Record(t, y, sigma=0.02))
    assert fixed.p[0] == 0.55 and fixed.stderr[0] == 0.0 and not fixed.free[0]
    line = next(x for x in fixed.report().splitlines() if x.strip().startswith("mu "))
    assert line.rstrip().endswith("fixed") and "0.55" in line
    with pytest.warns(RuntimeWarning, match="understated"):
        ref = estimate(make, [0.55, 0.9], Record(t, y, sigma=0.02), free=["p1"])
    assert fixed.p[1] == pytest.approx(ref.p[1], rel=1e-12)
    with pytest.raises(ValueError, match="mapping of Parameters"):
        estimate(make, {"mu": 0.5, "k": 1.0}, Record(t, y), free=["mu"])


def test_report_lists_unplaced_switches_and_undetermined_parameters():
    from models.identify_models import forcing_reversed_in_the_crossing_step
    make = forcing_reversed_in_the_crossing_step(0.01)
    t, U = run(make, [1.0], 12)
    with pytest.warns(RuntimeWarning, match="could not place"):
        est = estimate(make, [1.1], Record(t, U[:, 0]), names=["mu"])
    assert "unplaced switches (record, step): (0, 5)" in est.report()


# ---- 6. clear messages -------------------------------------------------------------------------------

def test_a_profile_open_on_both_sides_says_both():
    """A parameter the data hardly touch: the profile stays below the threshold on both sides."""
    def make(p):                      # b enters only through 1e-9 b
        a, b = p
        s = dmi.Solver(1, 1.0, h=0.05)
        s.set_rhs(lambda t, u: np.array([a + 1e-9 * b]))
        return s
    t = np.linspace(0, 2, 21)
    y = -0.3 * t + 0.05 * np.random.default_rng(8).standard_normal(21)
    est = estimate(make, [0.2, 1.0], Record(t, y, sigma=0.05), names=["a", "b"],
                   options=FitOptions(saddle_check=False))
    prof = profile_likelihood(est, "b", step=1.0, max_steps=3)
    assert prof.interval == (-math.inf, math.inf)
    assert "both sides" in prof.message and "one side" not in prof.message


def test_observe_returning_nan_is_named_with_the_record_and_time():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 100, 0.02, 9)

    def observe(tt, u, a):
        return math.nan if tt > 0.5 else u[0]
    rec = Record(t, y, observe=observe)
    with pytest.raises(ValueError, match=r"records\[1\] at t = 0\.54 \(row 9\): observe\(t, u, a\) "
                                         r"returned \[nan\]"):
        estimate([make, make], [0.6, 0.9], [Record(t, y), rec])


def test_options_of_the_wrong_kind_are_refused():
    make = coulomb()
    t, y = noisy(make, [0.5, 1.0], 30, 0.02, 10)
    with pytest.raises(TypeError, match="expected a dmi.identify.FitOptions"):
        estimate(make, [0.6, 0.9], Record(t, y), options={"max_steps": 10})
    with pytest.raises(ValueError, match=r"chi2_alpha = 0.7: expected a probability in \(0, 0.5\)"):
        estimate(make, [0.6, 0.9], Record(t, y), options=FitOptions(chi2_alpha=0.7))
