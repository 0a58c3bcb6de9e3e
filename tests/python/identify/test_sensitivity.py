# dmi.identify.sensitivities against exact discrete solutions, central differences of the scheme, an
# event-driven integration of the equation with its own variational equation and saltation (written
# here, SciPy's DOP853 with events), and mpmath's closed form of a linear model with memory.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import dmi
from dmi.identify import sensitivities
from models.identify_models import (P_SMOOTH, forcing_reversed_in_the_crossing_step, oscillator,
                                    smooth_model)


# ---- the exact case u' + mu sigma(u) ∋ g ----------------------------------------------------------

def coulomb(g_of_t, h=1.0 / 64):
    def make(p):
        s = dmi.Solver(1, 1.0, h=h)
        s.set_rhs(lambda t, u: np.array([-g_of_t(t)]))
        s.set_friction([p[0]])
        return s
    return make


@pytest.mark.parametrize("g", [1.7, -2.25])
def test_slip_from_rest_is_minus_p_h_sign_g(g):
    h, mu = 1.0 / 64, 0.6
    r = sensitivities(coulomb(lambda t: g, h), [mu], 80)
    p = np.arange(81)
    assert np.abs(r.u[:, 0] - p * h * (abs(g) - mu) * math.copysign(1, g)).max() < 1e-12
    assert np.abs(r.S[:, 0, 0] + p * h * math.copysign(1, g)).max() < 1e-12


def test_sticking_gives_zero_and_slip_restarts_from_zero():
    h, mu = 1.0 / 64, 1.0
    # g = 0.5 < mu until t = 0.5 (step 32): stuck; then g = 2: U^q = (q - 32) h (2 - 1)
    r = sensitivities(coulomb(lambda t: 0.5 if t < 0.5 else 2.0, h), [mu], 100)
    q = np.arange(101)
    assert np.all(r.S[:33, 0, 0] == 0.0) and np.all(r.u[:33, 0] == 0.0)
    assert np.abs(r.S[33:, 0, 0] + (q[33:] - 32) * h).max() < 1e-12
    # through a stick (always |g| < mu) S stays 0
    r = sensitivities(coulomb(lambda t: 0.3 * math.sin(t), h), [mu], 100)
    assert np.all(r.S == 0.0)


# ---- central differences of the scheme, away from thresholds ----------------------------------------

def central(make, p, steps, j, rel=1e-5):
    d = rel * max(1.0, abs(p[j]))
    up, dn = np.array(p, float), np.array(p, float)
    up[j] += d
    dn[j] -= d
    runs = []
    for q in (up, dn):
        s = make(q)
        s.init()
        runs.append(s.run(steps)[1])
    return (runs[0] - runs[1]) / (up[j] - dn[j])


@pytest.mark.parametrize("kernel,convolution,quadrature,h", [
    ("exp", "auto", "left", None), ("exp", "direct", "cell", None), ("exp", "auto", "left", 0.8 / 37.4),
    ("callback", "fft", "left", None)])
def test_against_central_differences_of_the_scheme(kernel, convolution, quadrature, h):
    make = smooth_model(kernel, convolution, quadrature, h)
    steps = 150
    r = sensitivities(make, P_SMOOTH, steps)
    assert r.S.shape == (steps + 1, 3, len(P_SMOOTH))
    assert all(kind != "reversal" for _, _, kind in r.switches)
    assert np.all(r.u[1:, 2] < 0)                 # u2 slips down all along
    for j in range(len(P_SMOOTH)):
        ref = central(make, P_SMOOTH, steps, j)
        scale = np.abs(ref).max()
        assert scale > 1e-3, j
        assert np.abs(r.S[:, :, j] - ref).max() < 1e-6 * scale, (j, np.abs(r.S[:, :, j] - ref).max() / scale)


def counted_model(p_whole: bool):
    """n = 3 with f, history and memory counted: (u0, u1) a nonlinear oscillator with a Prony
    memory of u0, u2 slipping down under friction all along; parameters (k, g, mu, w0, c1, a1,
    c2, a2), k and g in f, w0 in the history; ``p_whole``: f and the history read the whole
    vector p (every parameter then counts as entering both)."""
    calls = {"f": 0, "z": 0}

    def make(p):
        k, g, mu, w0, c1, a1, c2, a2 = p

        def f(t, u):
            calls["f"] += 1
            return np.array([-u[1], k * math.sin(u[0]) + g * math.cos(t), 3.0 + 0.2 * u[0]])

        def z(t):
            calls["z"] += 1
            return np.array([w0, 0.1 * t, -0.1])
        if p_whole:
            v = p.copy()

            def f(t, u):  # noqa: F811  (reads k, g from the vector)
                calls["f"] += 1
                return np.array([-u[1], v[0] * math.sin(u[0]) + v[1] * math.cos(t), 3.0 + 0.2 * u[0]])

            def z(t):  # noqa: F811
                calls["z"] += 1
                return np.array([v[3], 0.1 * t, -0.1])
        s = dmi.Solver(3, 0.8, 40)
        s.set_rhs(f)
        s.set_friction([0.0, 0.0, mu])
        C = np.zeros((2, 3, 3))
        C[0, 1, 0], C[1, 1, 0] = c1, c2
        s.set_kernel_exp([a1, a2], [0.0, 0.0], C)
        s.set_history(z)
        return s
    return make, calls


@pytest.mark.parametrize("p_whole", [False, True])
def test_f_and_history_called_only_for_the_parameters_they_read(p_whole):
    # with k and g the only parameters in f, f_u S + f_p takes 1 + n + 2 = 6 calls of f a step
    # (f_u by n columns) instead of 1 + P = 9; the history is sampled for w0 only (2 inits, not 9).
    # Where f and the history read all of p, every parameter counts: 9 calls a step, 9 inits.
    p = np.array([1.3, 0.7, 0.4, 0.25, 0.8, -1.1, 0.5, -0.6])
    steps = 150
    make, calls = counted_model(p_whole)
    s = make(p)
    s.init()
    sampled = calls["z"]                  # the calls of one init
    s.run(steps)
    plain = calls["f"]                    # the calls of one run
    calls.update(f=0, z=0)
    r = sensitivities(make, p, steps)
    assert r.engine == "python"
    P, n = len(p), 3
    assert calls["f"] == plain + steps * ((1 + P) if p_whole else (1 + n + 2))
    assert calls["z"] == sampled * ((1 + P) if p_whole else 2)
    # the history's S: dU^0/dw0 = e_0, nothing from the other parameters
    expected = np.zeros((3, P))
    expected[0, 3] = 1.0
    assert np.array_equal(r.S[0], expected)
    # against central differences of the scheme (no reversal: u2 slips all along)
    assert np.all(r.u[1:, 2] < 0)
    for j in range(P):
        ref = central(make, p, steps, j)
        scale = np.abs(ref).max()
        assert scale > 1e-3, j
        assert np.abs(r.S[:, :, j] - ref).max() < 1e-6 * scale, (j, np.abs(r.S[:, :, j] - ref).max() / scale)


def test_box_and_resolvent_callback_against_central_differences():
    def make(p, callback=False):
        lo, hi, mu = p
        s = dmi.Solver(2, 0.5, 50)
        s.set_rhs(lambda t, u: np.array([-1.0 - 0.1 * u[1], 0.5 * u[0] - 2.0 * math.cos(t)]))
        if callback:
            s.set_resolvent(lambda lam, x: np.array([min(x[0], hi),
                                                     math.copysign(max(abs(x[1]) - lam * mu, 0.0), x[1])]))
        else:
            s.set_box([lo, -10.0], [hi, 10.0])
        s.set_history(lambda t: np.array([hi - 0.01, 0.5]))
        return s
    r = sensitivities(make, [-5.0, 1.2, 0.3], 120)
    assert r.u[-1, 0] == 1.2                          # u0 pushed against hi from the second step
    assert np.abs(r.S[2:, 0, 1] - 1.0).max() < 1e-12 and np.all(r.S[2:, 0, 0] == 0.0)
    for j in range(3):
        ref = central(make, [-5.0, 1.2, 0.3], 120, j)
        assert np.abs(r.S[:, :, j] - ref).max() < 1e-6 * max(1.0, np.abs(ref).max())
    rc = sensitivities(lambda p: make(p, True), [-5.0, 1.2, 0.3], 120)
    for j in range(3):
        ref = central(lambda p: make(p, True), [-5.0, 1.2, 0.3], 120, j)
        assert np.abs(rc.S[:, :, j] - ref).max() < 1e-6 * max(1.0, np.abs(ref).max())


def test_complex_step_rhs_matches_differences():
    make = smooth_model()
    k = P_SMOOTH[0]

    def rhs(t, u, p):
        return np.array([-u[1], p[0] * np.sin(u[0]) + p[1] * u[1] * np.sqrt(u[1] * u[1]) + np.cos(t),
                         3.0 + 0.2 * u[0]])
    r = sensitivities(make, P_SMOOTH, 100, rhs=rhs)
    r0 = sensitivities(make, P_SMOOTH, 100)
    assert np.abs(r.S - r0.S).max() < 1e-6 * np.abs(r0.S).max()
    with pytest.raises(ValueError, match="not the solver's f"):
        sensitivities(make, P_SMOOTH, 10, rhs=lambda t, u, p: 2 * rhs(t, u, p))
    with pytest.raises(ValueError, match="disagrees"):
        sensitivities(make, P_SMOOTH, 10,
                      rhs=lambda t, u, p: rhs(t, u, p) + np.array([0, 0, 1e-3 * (p[0] - k)]))


# ---- through switches: an event-driven integration of the equation ---------------------------------

def event_driven(T, mu, k=1.0, g=2.0, om=0.8, w0=0.3, c=0.0, a=-5.0, tau=np.inf):
    """w'' + k w + mu sigma(w') + m + g cos(om t) ∋ 0, m = int_0^tau c e^{a s} w(t - s) ds (m' = c w + a m
    when e^{a tau} is negligible), w = w0, w' = 0 on t <= 0: the state (w, v, m) at T and its
    derivatives in (mu, c), by DOP853 on each smooth phase with the variational equation, the
    saltation S_v+ = S_v- F+/F- at a reversal, S_v = 0 from a stick onset, no jump at a slip onset."""
    m0 = c * w0 * (math.exp(a * tau) - 1.0) / a if c else 0.0
    dm0 = w0 * (math.exp(a * tau) - 1.0) / a
    y = np.array([w0, 0.0, m0, 0.0, 0.0, 0.0, 0.0, 0.0, dm0])   # state, S (3 x 2: mu, c) row-major

    def phi(t, y):
        return k * y[0] + y[2] + g * math.cos(om * t)

    def rhs(mode):
        def f(t, y):
            w, v, m = y[:3]
            S = y[3:].reshape(3, 2)
            dS = np.zeros((3, 2))
            dS[2] = c * S[0] + a * S[2] + np.array([0.0, w])
            if mode == 0:
                return np.concatenate([[0.0, 0.0, c * w + a * m], dS.ravel()])
            dS[0] = S[1]
            dS[1] = -k * S[0] - S[2] - np.array([mode, 0.0])
            return np.concatenate([[v, -phi(t, y) - mu * mode, c * w + a * m], dS.ravel()])
        return f

    t = 0.0
    mode = 0 if abs(phi(0.0, y)) <= mu else -int(np.sign(phi(0.0, y)))
    while t < T:
        if mode == 0:
            def ev(t, y):
                return abs(phi(t, y)) - mu
        else:
            def ev(t, y):
                return y[1]
        ev.terminal = True
        ev.direction = 1 if mode == 0 else (-mode)
        sol = solve_ivp(rhs(mode), (t, T), y, method="DOP853", rtol=1e-12, atol=1e-13, events=ev,
                        first_step=1e-6)
        y = sol.y[:, -1].copy()
        t = sol.t[-1]
        if sol.status != 1:
            break
        if mode == 0:
            mode = -int(np.sign(phi(t, y)))
            y[1] = 0.0
            continue
        y[1] = 0.0
        ph = phi(t, y)
        S = y[3:].reshape(3, 2)
        if abs(ph) <= mu:
            S[1] = 0.0
            mode = 0
        else:
            before = -ph - mu * mode
            after = -ph + mu * mode
            S[1] *= after / before
            mode = -mode
        y[3:] = S.ravel()
    return y[:3], y[3:].reshape(3, 2)


def test_event_driven_reference_is_the_measured_value_and_its_own_differences():
    _, S = event_driven(6.0, 0.5)
    assert abs(S[0, 0] + 2.967) < 1.5e-3 and abs(S[1, 0] - 2.359) < 1.5e-3
    d = 1e-6
    yp, _ = event_driven(6.0, 0.5 + d)
    ym, _ = event_driven(6.0, 0.5 - d)
    assert np.abs((yp - ym)[:2] / (2 * d) - S[:2, 0]).max() < 1e-5


def errors(T, mu, hs, jumps=True, **kw):
    _, ref = event_driven(T, mu, **kw)
    out = []
    for h in hs:
        steps = round(T / h)
        with warnings.catch_warnings():
            warnings.simplefilter("error", RuntimeWarning)      # no reversal left unplaced here
            r = sensitivities(oscillator(h, mu, **kw), [mu, kw.get("c", 0.0)], steps, jumps=jumps)
        assert r.unplaced == []
        kinds = {kind for _, _, kind in r.switches}
        out.append((np.abs(r.S[-1, :, :] - ref[:2]).max(), kinds))
    return out


def test_two_reversals_converge_at_order_one():
    hs = [1 / 250, 1 / 500, 1 / 1000, 1 / 2000]
    err = errors(6.0, 0.5, hs)
    for (e, kinds), h in zip(err, hs):
        assert kinds == {"reversal"}
        assert e < 12.0 * h, (h, e)
    assert err[0][0] / err[-1][0] > 5.0
    # the plain tangent of the step does not converge (off by 0.2 to 0.5 here)
    plain = errors(6.0, 0.5, hs[1:], jumps=False)
    assert max(e for e, _ in plain) > 0.1


def test_stick_slip_converges_at_order_one():
    # sticks at t = 1.88 and 5.5, slips again, reverses at t = 9.3
    mu = 1.2
    hs = [1 / 250, 1 / 500, 1 / 1000, 1 / 2000]
    err = errors(10.0, mu, hs)
    for (e, kinds), h in zip(err, hs):
        assert kinds == {"stick", "reversal"}
        assert e < 15.0 * h, (h, e)
    assert err[0][0] / err[-1][0] > 5.0


def test_memory_stick_slip_converges_at_order_one():
    # sticks at t = 1.75 and 5.4, slipping after each
    kw = dict(c=0.6, a=-4.0, tau=10.0)
    mu = 1.4
    hs = [1 / 250, 1 / 500, 1 / 1000]
    err = errors(8.0, mu, hs, **kw)
    for (e, kinds), h in zip(err, hs):
        assert "stick" in kinds
        assert e < 20.0 * h, (h, e)
    assert err[-1][0] < err[0][0] / 2.0


@pytest.mark.parametrize("engine", ["python", "auto"])
def test_a_reversal_that_cannot_be_placed_is_flagged(engine):
    jit = engine == "auto"
    if jit:
        pytest.importorskip("numba")
    make = forcing_reversed_in_the_crossing_step(0.01, jit)
    with pytest.warns(RuntimeWarning, match=r"could not be placed.*steps 5.*smaller h"):
        r = sensitivities(make, [1.0], 12, engine=engine)
    # the scheme: U = 0.215 - 0.04 q down to U^5 = 0.015, then U^6 = 0.015 - 0.03 + 0.01 < 0
    assert np.abs(r.u[:7, 0] - [0.215, 0.175, 0.135, 0.095, 0.055, 0.015, -0.005]).max() < 1e-12
    assert r.unplaced == [5] and (5, 0, "unplaced") in r.switches
    assert r.engine == ("compiled" if jit else "python")
    # a step ten times smaller puts the jump of f after the crossing step: placed, no warning
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        fine = sensitivities(forcing_reversed_in_the_crossing_step(0.001, jit), [1.0], 120,
                             engine=engine)
    assert fine.unplaced == [] and (53, 0, "reversal") in fine.switches


# ---- kernel parameters: mpmath's closed form of u' + k u + int c e^{a s} u(t - s) ds = 0 ---------------

def closed_form(T, k, a, c, u0):
    """u(T) for constant history u0 and a kernel long enough to be infinite: the Laplace transform
    U(s) = (u0 (s - a) + c u0 / a) / ((s + k)(s - a) + c), inverted by its residues."""
    def u(a_, c_):
        disc = mpmath.sqrt((k - a_) ** 2 - 4 * (c_ - k * a_) + 0j)
        roots = [((a_ - k) + disc) / 2, ((a_ - k) - disc) / 2]
        total = 0
        for i, r in enumerate(roots):
            num = u0 * (r - a_) + c_ * u0 / a_
            total += num / (roots[i] - roots[1 - i]) * mpmath.exp(r * T)
        return mpmath.re(total)
    with mpmath.workdps(30):
        return (float(u(a, c)), float(mpmath.diff(lambda x: u(x, c), a)),
                float(mpmath.diff(lambda x: u(a, x), c)))


def test_kernel_parameters_against_the_laplace_closed_form():
    k, a, c, u0, T, tau = 0.5, -2.0, 1.5, 1.0, 3.0, 20.0
    ref = closed_form(T, k, a, c, u0)

    def make_h(h):
        def make(p):
            s = dmi.Solver(1, tau, h=h)
            s.set_rhs(lambda t, u: k * u)
            s.set_kernel_exp([p[0]], [0.0], [[[p[1]]]])
            s.set_history(lambda t: np.array([u0]))
            return s
        return make
    errs = []
    for h in (0.02, 0.01, 0.005):
        r = sensitivities(make_h(h), [a, c], round(T / h))
        errs.append(np.abs(r.S[-1, 0, :] - ref[1:]).max())
        assert abs(r.u[-1, 0] - ref[0]) < 2.0 * h
    assert all(e < 2.0 * h for e, h in zip(errs, (0.02, 0.01, 0.005)))
    assert 1.6 < errs[0] / errs[1] < 2.5 and 1.6 < errs[1] / errs[2] < 2.5
    # and the scheme's central differences to 1e-6
    r = sensitivities(make_h(0.01), [a, c], 300)
    for j in range(2):
        ref_j = central(make_h(0.01), [a, c], 300, j)
        assert np.abs(r.S[:, :, j] - ref_j).max() < 1e-6 * np.abs(ref_j).max()


# ---- refusals -------------------------------------------------------------------------------------

def test_parameters_that_change_the_structure_are_refused():
    def make(p):
        s = dmi.Solver(1, 1.0, 10 if p[0] <= 1.0 else 11)
        s.set_friction([0.5])
        return s
    with pytest.raises(ValueError, match="changes N"):
        sensitivities(make, [1.0], 10)

    def make_conv(p):
        s = dmi.Solver(1, 1.0, 10)
        s.set_kernel_exp([-1.0], [0.0], [[[1.0]]])
        s.set_convolution("direct" if p[0] > 1.0 else "auto")
        return s
    with pytest.raises(ValueError, match="convolution method"):
        sensitivities(make_conv, [1.0], 10)

    def make_terms(p):
        s = dmi.Solver(1, 1.0, 10)
        K = 1 if p[0] <= 1.0 else 2
        s.set_kernel_exp([-1.0] * K, [0.0] * K, [[[1.0]]] * K)
        return s
    with pytest.raises(ValueError, match="number of kernel terms"):
        sensitivities(make_terms, [1.0], 10)

    def refuses(p):
        if p[0] != 1.0:
            raise ValueError("only p = 1")
        return dmi.Solver(1, 1.0, 10)
    with pytest.raises(ValueError, match="make.*raised ValueError: only p = 1"):
        sensitivities(refuses, [1.0], 10)
    with pytest.raises(TypeError, match="dmi.Solver"):
        sensitivities(lambda p: None, [1.0], 10)
    with pytest.raises(ValueError, match="finite"):
        sensitivities(make, [float("nan")], 10)
    with pytest.raises(ValueError, match="steps"):
        sensitivities(make_conv, [1.0], 0)


def test_near_cells_and_a_callback_kernel_under_the_cell_rule_are_followed():
    # once refused (their weights were libdmi's alone), now through Solver.kernel_weights: S of a
    # parameter of f against central differences of the scheme (more in test_nearcells.py)
    def near(p):            # an exponential fit beyond delta = 0.2 and the exact kernel below it
        s = dmi.Solver(1, 1.0, 20)
        s.set_rhs(lambda t, u: -p[0] * u)
        s.set_quadrature("cell")
        s.set_kernel_exp([-1.0], [0.0], [[[0.5]]])
        s.set_kernel_near(lambda x: np.array([[0.5 * math.exp(-x) / math.sqrt(x)]]), 0.2)
        s.set_history(lambda t: np.array([1.0]))
        return s

    def cell(p):
        s = dmi.Solver(1, 1.0, 20)
        s.set_rhs(lambda t, u: -p[0] * u)
        s.set_quadrature("cell")
        s.set_kernel(lambda x: np.array([[math.exp(-x) / math.sqrt(x)]]))
        s.set_history(lambda t: np.array([1.0]))
        return s
    for make in (near, cell):
        S = sensitivities(make, [1.0], 30).S[:, 0, 0]
        runs = []
        for q in (1.0 + 1e-5, 1.0 - 1e-5):
            m = make([q])
            m.init()
            runs.append(m.run(30)[1][:, 0])
        ref = (runs[0] - runs[1]) / 2e-5
        assert np.abs(ref).max() > 0.1
        assert np.abs(S - ref).max() < 1e-6 * np.abs(ref).max()


def test_a_failing_callback_of_a_perturbed_model_names_the_call():
    def make(p):
        s = dmi.Solver(1, 1.0, 10)

        def f(t, u):
            if p[0] != 1.0 and t > 0.35:     # only the perturbed model fails, through eval_rhs
                raise RuntimeError("f fails")
            return np.array([p[0]])
        s.set_rhs(f)
        return s
    with pytest.raises(RuntimeError, match="f fails") as e:
        sensitivities(make, [1.0], 10)
    assert any("raised by the model's rhs at t = 0.4" in note for note in e.value.__notes__)
