# dmi.analysis.collocate, hopf_orbit(of="equation") and equation_hopf_orbit refuse what they cannot
# do, within seconds, naming the input at fault: a tol below the floor of double precision, a
# callback kernel's jump not declared (with intervals=None) or declared at the wrong lag, an orbit
# whose period is not steps h or not a period of the model's forcing, a period far shorter than
# the memory, a nan period, a constant autonomous orbit, a model of another dimension, a u_eq that
# is not an equilibrium, and the scheme's orbit near a Hopf point that the equation has no orbit
# near (a belt with friction and a smooth rotating model at a coarse h: Newton falls onto the
# equilibrium).  The hangs run in a subprocess with a time limit (killed past it).  The models
# are written here: a forced scalar model with an exponential memory (its forcing cos t, period
# 2 pi), a piecewise-constant kernel jumping at S1, van der Pol with a distributed delay, the belt
# with a truncated exponential memory (its Hopf point and equilibrium in closed form) and a
# rotating model with a damped-cosine memory.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
import textwrap

import numpy as np
import pytest
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.core.newton import ShootingError
from models import truncated_belt
from models.truncated_belt import V


#: Seconds a subprocess may take before it counts as a hang (the fixed calls answer in about 2).
LIMIT = 90

# ---- the models, written again in each subprocess ------------------------------------------------
MODELS = textwrap.dedent('''
    import math, warnings
    import numpy as np
    import dmi
    from dmi import analysis as da

    def forced(p, h=None):
        """u' + 0.1 u + 0.3 u^3 + int_0^1 0.5 e^-s u(t - s) ds = p cos t."""
        s = dmi.Solver(1, 1.0, h=2 * math.pi / 400 if h is None else h)
        s.set_rhs(lambda t, u: np.array([0.1 * u[0] + 0.3 * u[0] ** 3 - p * math.cos(t)]))
        s.set_kernel_exp([-1.0], [0.0], [[[0.5]]])
        return s

    def jumping(p, h=None):
        """u' + 0.1 u + int_0^1 H u = p cos 2t, H = 0.6 on (0, 0.37), -0.25 after."""
        s = dmi.Solver(1, 1.0, h=math.pi / 400 if h is None else h)
        s.set_rhs(lambda t, u: np.array([0.1 * u[0] - p * math.cos(2 * t)]))
        s.set_kernel(lambda s: np.array([[0.6 if s < 0.37 else -0.25]]))
        return s

    def orbit_of(make, T, M=400, periods=10):
        s = make(1.0)
        s.init()
        s.advance(periods * M)
        return da.periodic_orbit(make, 1.0, T, s, multipliers=0)

    def outcome(call):
        """What call() did: its exception (type, message) and the warnings' messages."""
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                call()
                got = ["none", ""]
            except Exception as err:
                got = [type(err).__name__, str(err)]
        return got + [[str(w.message) for w in caught]]
''')


def run_limited(body: str) -> tuple[str, str, list[str]]:
    """``body`` (after MODELS) in a fresh interpreter, which prints json of outcome(...); the
    process is killed past LIMIT seconds (a hang: the test fails)."""
    code = MODELS + textwrap.dedent(body)
    try:
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             timeout=LIMIT)
    except subprocess.TimeoutExpired:
        pytest.fail(f"no answer within {LIMIT} s (killed)")
    assert out.returncode == 0, out.stderr[-3000:]
    kind, message, warned = json.loads(out.stdout.strip().splitlines()[-1])
    return kind, message, warned


# ---- hangs that become refusals -------------------------------------------------------------------
def test_tol_below_the_floor_refused_with_the_floor_reached():
    kind, message, _ = run_limited('''
        import json
        o = orbit_of(forced, 2 * math.pi)
        print(json.dumps(outcome(lambda: da.collocate(o, tol=1e-17, multipliers=0))))
    ''')
    assert kind == "ValueError", (kind, message)
    assert "tol = 1e-17" in message and "floor" in message and "intervals" in message, message


def test_undeclared_jump_warned_then_refused_before_a_long_refinement():
    kind, message, warned = run_limited('''
        import json
        o = orbit_of(jumping, math.pi)
        print(json.dumps(outcome(lambda: da.collocate(o, multipliers=0))))
    ''')
    assert any("kernel_jumps=(0.37" in w for w in warned), warned
    assert kind == "ValueError", (kind, message)
    assert "MAX_INTERVALS" in message and "kernel_jumps=(0.37" in message, message


def test_jump_declared_at_a_lag_where_none_is_refused():
    kind, message, _ = run_limited('''
        import json
        o = orbit_of(jumping, math.pi)
        print(json.dumps(outcome(lambda: da.collocate(o, multipliers=0, kernel_jumps=(0.5,)))))
    ''')
    assert kind == "ValueError", (kind, message)
    assert "does not jump at s = 0.5" in message and "0.37" in message, message


def test_jump_declared_beside_its_lag_refused_with_the_lag():
    kind, message, _ = run_limited('''
        import json
        o = orbit_of(jumping, math.pi)
        print(json.dumps(outcome(lambda: da.collocate(o, intervals=8, multipliers=0,
                                                      kernel_jumps=(0.3701,)))))
    ''')
    assert kind == "ValueError", (kind, message)
    assert "near s = 0.3701 is at s = 0.37" in message, message


def test_period_far_shorter_than_the_memory_refused_up_front():
    # a consistent Orbit (period = steps h) of period 1e-9 against the memory tau = 1
    kind, message, _ = run_limited('''
        import dataclasses, json
        o = orbit_of(forced, 2 * math.pi)
        h = 1e-9 / o.steps
        q = dataclasses.replace(o, period=1e-9, h=h, t=np.arange(o.steps + 1) * h)
        print(json.dumps(outcome(lambda: da.collocate(q, multipliers=0))))
    ''')
    assert kind == "ValueError", (kind, message)
    assert "MAX_DELAY_NODES" in message and "orbit.period" in message, message


# ---- in process: the refusals are immediate -----------------------------------------------------
def forced(p: float, h: float | None = None) -> dmi.Solver:
    """u' + 0.1 u + 0.3 u^3 + int_0^1 0.5 e^-s u(t - s) ds = p cos t (forcing period 2 pi)."""
    s = dmi.Solver(1, 1.0, h=2 * math.pi / 200 if h is None else h)
    s.set_rhs(lambda t, u: np.array([0.1 * u[0] + 0.3 * u[0] ** 3 - p * math.cos(t)]))
    s.set_kernel_exp([-1.0], [0.0], [[[0.5]]])
    return s


@pytest.fixture(scope="module")
def forced_orbit() -> da.Orbit:
    s = forced(1.0)
    s.init()
    s.advance(2000)
    return da.periodic_orbit(forced, 1.0, 2 * math.pi, s, multipliers=0)


def vdp(p: float, h: float | None = None) -> dmi.Solver:
    """w'' + (w^2 - 1) w' + w + p int_0^1 w(t - s) ds = 0 as u = (w, w')."""
    s = dmi.Solver(2, 1.0, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
    return s


@pytest.fixture(scope="module")
def vdp_orbit() -> da.Orbit:
    s = vdp(0.5)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(6000)
    return da.periodic_orbit(vdp, 0.5, None, s, guess_period=6.0, steps=600, multipliers=0)


def test_forced_orbit_at_a_period_the_forcing_does_not_have_refused(forced_orbit):
    o = forced_orbit
    e = da.collocate(o, multipliers=0)               # the orbit as made: 2 pi
    assert abs(e.period - 2 * math.pi) < 1e-14
    h = 3 * math.pi / o.steps                        # 3 pi, every field consistent with it
    q = dataclasses.replace(o, period=3 * math.pi, h=h, t=np.arange(o.steps + 1) * h)
    with pytest.raises(ValueError, match="not a period of the model's forcing"):
        da.collocate(q, multipliers=2)
    with pytest.raises(ValueError, match="is not its steps h"):     # the period alone edited
        da.collocate(dataclasses.replace(o, period=3 * math.pi), multipliers=2)


def test_nan_period_named(forced_orbit):
    with pytest.raises(ValueError, match=r"orbit\.period = nan"):
        da.collocate(dataclasses.replace(forced_orbit, period=math.nan))


def test_model_of_another_dimension_named(forced_orbit):
    def three(p: float) -> dmi.Solver:
        s = dmi.Solver(3, 1.0, h=0.01)
        s.set_rhs(lambda t, u: u)
        return s
    with pytest.raises(ValueError, match=r"1 components.*n = 3.*another model"):
        da.collocate(dataclasses.replace(forced_orbit, make=three))


def test_constant_autonomous_orbit_called_an_equilibrium(vdp_orbit):
    q = dataclasses.replace(vdp_orbit, u=np.full_like(vdp_orbit.u, 0.3))
    with pytest.raises(ValueError, match="equilibrium"):
        da.collocate(q)


# ---- the belt: x' = y + V, y' in -x + p (y + V) - g int_0^tau e^-s x(t - s) ds - alpha Sign y ----
def belt(p: float, h: float | None = None) -> dmi.Solver:
    """The belt of models/truncated_belt.py at a coarse default step."""
    return truncated_belt.belt(p, 0.1 if h is None else h)


def test_u_eq_that_is_no_equilibrium_refused():
    om, pH, xe = truncated_belt.hopf()
    hp = da.HopfPoint(p=pH, omega=om, root=1j * om)
    for ue in ([xe + 0.2, -V], [xe, -V + 0.1]):
        with pytest.raises(ValueError, match="not an equilibrium"):
            da.hopf_orbit(belt, hp, ue, amplitude=0.1, of="equation", multipliers=0)
    e = da.hopf_orbit(belt, hp, [xe, -V], amplitude=0.1, of="equation", multipliers=0)
    assert abs(e.period - 2 * math.pi / om) < 1e-8    # the closed form's equilibrium is taken


def scheme_near_hopf(make, p_lo: float, p_hi: float, u_eq, amplitude: float) -> da.Orbit:
    """The scheme's orbit of the given amplitude born at the scheme's Hopf point (h = 0.1)."""
    def ue(p: float) -> np.ndarray:
        return da.equilibrium(make, p, u_eq).u
    hp = da.hopf(make, p_lo, p_hi, ue)
    M = round(2 * math.pi / hp.omega / 0.1)
    return da.hopf_orbit(make, hp, ue(hp.p), amplitude=amplitude, steps=M, multipliers=0)


def assert_too_far(err: ShootingError) -> None:
    msg = str(err)
    assert "too far from the equation's" in msg and "of='equation'" in msg, msg
    assert "segment" not in msg and "signature" not in msg, msg


def test_belt_scheme_orbit_near_hopf_says_too_far():
    om, pH, xe = truncated_belt.hopf()
    o = scheme_near_hopf(belt, pH - 0.2, pH + 0.2, [xe, -V], 0.1)
    assert o.p < pH - 0.05              # the scheme's Hopf point is O(h) off the equation's
    with pytest.raises(ShootingError) as got:
        da.collocate(o, multipliers=0)
    assert_too_far(got.value)


def rotating(p: float, h: float | None = None) -> dmi.Solver:
    """u' = (p - |u|^2) u + J u - int_0^2 0.5 e^-s cos(2 s) u(t - s) ds in R^2."""
    s = dmi.Solver(2, 2.0, h=0.1 if h is None else h)
    s.set_rhs(lambda t, u: -((p - u @ u) * u + np.array([-u[1], u[0]])))
    s.set_kernel_exp([-1.0], [2.0], [0.5 * np.eye(2)])
    return s


def rotating_hopf() -> float:
    """The equation's Hopf point p_H = Re K(i W), W = 1 - Im K(i W), K(q) = int_0^2 0.5 e^-s
    cos(2 s) e^{-q s} ds in closed form (z = r e^{i W t}: i W = p - r^2 + i - K(i W))."""
    def K(q: complex) -> complex:
        return sum(0.25 * (np.exp(2 * c) - 1) / c for c in (-1 + 2j - q, -1 - 2j - q))
    W = so.brentq(lambda w: w - 1 + K(1j * w).imag, 0.1, 3.0, xtol=1e-15)
    return float(K(1j * W).real)


def test_smooth_scheme_orbit_near_hopf_says_too_far_not_segments():
    # the scheme's Hopf point at h = 0.1 is O(h) below the equation's: its orbit just above it
    # has no orbit of the equation near it (the equation's circles need p > p_H)
    pH = rotating_hopf()
    o = scheme_near_hopf(rotating, pH - 0.3, pH + 0.3, [0.0, 0.0], 0.05)
    assert o.p < pH - 0.01, (o.p, pH)
    with pytest.raises(ShootingError) as got:
        da.collocate(o, multipliers=0)
    assert_too_far(got.value)
    assert "equilibrium" in str(got.value)
