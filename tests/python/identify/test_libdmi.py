# dmi.identify.sensitivities through libdmi's loop (dmi_tangent_run): against the Python loop, and the
# plain tangent against central differences of plain runs of the scheme, on a friction oscillator with
# a two-term memory whose parameters enter f, the friction, the kernel (rates and coefficients) and the
# history; a partial last cell; and the loop's independence of numba (a model without callbacks runs
# it in a process where numba cannot be imported).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import dmi
from dmi.identify import sensitivities

P0 = np.array([1.0, 0.6, 0.8, -0.7, 0.5, -2.0, 1.0])   # k, mu, c1, a1, c2, a2, w0
TAU = 1.5


def oscillator(jit: bool, h: float | None = None, quadrature: str = "left"):
    """make(p): w'' + k w + mu sigma(w') + int_0^tau (c1 e^{a1 s} + c2 e^{a2 s}) w'(t - s) ds
    = 0.9 cos 1.3 t, w = w0 cos t on [-tau, 0] (u = (w, w'))."""
    def make(p):
        k, mu, c1, a1, c2, a2, w0 = p

        def rhs(t, u):
            return np.array([-u[1], k * u[0] - 0.9 * math.cos(1.3 * t)])

        def history(t):
            return np.array([w0 * math.cos(t), -w0 * math.sin(t)])
        s = dmi.Solver(2, TAU, 150) if h is None else dmi.Solver(2, TAU, h=h)
        s.set_rhs(rhs, jit=jit)
        s.set_friction([0.0, mu])
        C = np.zeros((2, 2, 2))
        C[0, 1, 1], C[1, 1, 1] = c1, c2
        s.set_kernel_exp([a1, a2], [0.0, 0.0], C)
        s.set_quadrature(quadrature)
        s.set_history(history, jit=jit)
        return s
    return make


def plain(make, p, steps):
    s = make(p)
    s.init()
    return s.run(steps)[1]


@pytest.mark.parametrize("h,quadrature", [(None, "left"), (None, "cell"), (TAU / 143.4, "left")])
def test_libdmi_loop_agrees_with_the_python_loop(h, quadrature):
    pytest.importorskip("numba")                 # (the model's jit=True callbacks)
    make = oscillator(True, h, quadrature)
    fast = sensitivities(make, P0, 700)
    slow = sensitivities(make, P0, 700, engine="python")
    assert (fast.engine, slow.engine) == ("compiled", "python")
    assert np.array_equal(fast.u, slow.u) and np.array_equal(fast.x, slow.x)
    scale = float(np.abs(slow.S).max())
    assert scale > 0.5 and np.abs(fast.S - slow.S).max() <= 1e-11 * scale
    assert np.abs(fast.dx - slow.dx).max() <= 1e-11 * float(np.abs(slow.dx).max())
    assert fast.switches == slow.switches
    kinds = {kind for _, _, kind in fast.switches}
    assert "stick" in kinds                      # the run sticks: the holds are exercised


def test_plain_tangent_against_differences_of_the_scheme():
    # jumps=False: the derivative of the scheme itself, which central differences of plain runs
    # (libdmi's steps, no tangent code) approach to O(eps^2) where no hold changes within +-eps
    pytest.importorskip("numba")
    make = oscillator(True)
    steps = 500
    sens = sensitivities(make, P0, steps, jumps=False)
    assert sens.engine == "compiled"
    worst = 0.0
    for j in range(len(P0)):
        eps = 1e-7 * max(1.0, abs(P0[j]))
        up, down = P0.copy(), P0.copy()
        up[j] += eps
        down[j] -= eps
        D = (plain(make, up, steps) - plain(make, down, steps)) / (up[j] - down[j])
        worst = max(worst, float(np.max(np.abs(sens.S[:, :, j] - D) / (1 + np.abs(D)))))
    assert worst < 1e-5, worst


def test_libdmi_loop_needs_no_numba():
    # a model without callbacks (friction, an exponential kernel with a parameter, no f): libdmi's
    # loop in a process where importing numba fails, against the exact tangent of u' + mu sigma(u) = 0
    # while slipping, dU^p/dmu = -p h sign(U)
    code = textwrap.dedent("""
        import json, sys
        sys.modules["numba"] = None              # import numba raises ImportError
        import numpy as np, dmi
        from dmi.identify import sensitivities
        def make(p):
            s = dmi.Solver(1, 1.0, 10)
            s.set_friction([p[0]])
            s.set_kernel_exp([-1.0], [0.0], [[[p[1]]]])
            s.set_history(lambda t: np.array([5.0]))
            return s
        r = sensitivities(make, [0.5, 0.0], 5)
        print(json.dumps([r.engine, r.S[:, 0, 0].tolist(), r.u[:, 0].tolist()]))
        assert "numba" not in [m for m in sys.modules if sys.modules[m] is not None]
    """)
    env = dict(os.environ)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    engine, S, u = json.loads(out.stdout.strip().splitlines()[-1])
    assert engine == "compiled"
    S = np.array(S)
    assert np.all(np.array(u) > 0)
    h = 0.1
    assert np.allclose(S, -np.arange(6) * h, rtol=1e-12, atol=1e-15)
