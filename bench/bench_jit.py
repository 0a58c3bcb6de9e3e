#!/usr/bin/env python3
# The speed of jit=True where dmi.analysis spends it (a benchmark, not a test): a forced mass on
# a moving belt with dry friction and a fading memory, its right-hand side a plain Python
# function given to Solver.set_rhs as it is and with jit=True (the same function, compiled by
# numba).  Per variant: one shooting solve (dmi.analysis.periodic_orbit from a run near the
# orbit, no multipliers) and one continuation step (continue_orbit: a branch of 4 points less
# one of 2, over 2, 4 multipliers a point), and the ratio Python / jit=True.  The model:
#   x'' + c x' + x + g int_0^tau exp(-s / theta) x(t - s) ds + alpha sigma(x' - v) ∋ a cos(w t),
# u = (x, y), y = x' - v (friction on y), p = a; the orbit has the forcing's period, M steps.
# Rounds interleave the variants; the fastest round of each counts; CPU times of the process
# (the machine may be shared); one BLAS thread.  jit=True compiles once per process, before the
# rounds (the compilation time is printed apart).  Also the cost of a step (advance over --steps
# steps) with jit=True against the same rhs written by hand as a numba cfunc (its parameter in
# the user pointer): what jit=True's index checks, error model, copy of u and exception capture
# cost.  And one make(p) (a Solver with its rhs set; with jit=True a bind of the compiled code).
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_jit.py [--rounds 2] [--M 400]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # (see bench_orbit.py)
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from dmi.analysis import continue_orbit, periodic_orbit  # noqa: E402
from dmi.analysis.scheme.stepmap import state_of  # noqa: E402
from benchtools import cpu  # noqa: E402

C, V, ALPHA, G, THETA, TAU, W = 0.1, 0.4, 0.3, 0.2, 0.5, 1.0, 1.1
A = 1.0  # the forcing amplitude p at the start


def belt(M: int, jit: bool):
    """make(p): the belt model at forcing amplitude p, M steps a forcing period."""
    h = 2 * math.pi / (W * M)

    def make(a: float) -> dmi.Solver:
        def rhs(t, u):
            return np.array([-(u[1] + V), u[0] + C * (u[1] + V) - a * math.cos(W * t)])
        s = dmi.Solver(2, TAU, h=h)
        s.set_rhs(rhs, jit=jit)
        s.set_friction([0.0, ALPHA])
        s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [G, 0.0]]])
        return s
    return make


def belt_cfunc(M: int):
    """make(p) of belt() with the rhs written by hand as a numba cfunc, p in its user data."""
    import numba
    h = 2 * math.pi / (W * M)

    @numba.cfunc(dmi.RHS_SIGNATURE)
    def rhs(t, u, out, user):
        a = numba.carray(user, (1,), numba.float64)[0]
        out[0] = -(u[1] + V)
        out[1] = u[0] + C * (u[1] + V) - a * math.cos(W * t)
        return 0

    def make(a: float) -> dmi.Solver:
        s = dmi.Solver(2, TAU, h=h)
        p = np.array([a])
        s.set_rhs(rhs, p)
        s.p = p   # (kept alive with the solver)
        s.set_friction([0.0, ALPHA])
        s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [G, 0.0]]])
        return s
    return make


def per_step(make, steps: int) -> tuple[float, np.ndarray]:
    """ns of CPU time per step over steps steps from t = 0, and the final state."""
    s = make(A)
    s.init()
    t = cpu(lambda: s.advance(steps))
    return 1e9 * t / steps, s.state


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description="Times a shooting solve and a continuation step of a forced belt model with "
                    "a Python right-hand side, as it is and with jit=True, and prints their CPU "
                    "seconds and ratio.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=int, default=2, help="interleaved rounds")
    ap.add_argument("--M", type=int, default=400, help="steps a forcing period")
    ap.add_argument("--steps", type=int, default=2_000_000,
                    help="steps of the per-step comparison with a hand-written cfunc")
    a = ap.parse_args(argv)
    if a.rounds < 1 or a.M < 10 or a.steps < 1:
        ap.error("--rounds and --steps must be >= 1 and --M >= 10")
    P = 2 * math.pi / W
    compile_s = cpu(lambda: belt(a.M, True)(A))
    best = {(k, jit): math.inf for k in ("solve", "step", "period", "make")
            for jit in (False, True)}
    ns = {"jit": math.inf, "cfunc": math.inf}
    states = {}
    for _ in range(a.rounds):
        for name, make in (("jit", belt(a.M, True)), ("cfunc", belt_cfunc(a.M))):
            t, states[name] = per_step(make, a.steps)
            ns[name] = min(ns[name], t)
        for jit in (False, True):
            make = belt(a.M, jit)
            best["make", jit] = min(best["make", jit], cpu(lambda: [make(A) for _ in range(200)]) / 200)
            s = make(A)
            s.init()
            s.advance(20 * a.M)  # near the orbit, not on it
            x0 = state_of(s, a.M)
            best["period", jit] = min(best["period", jit], cpu(lambda: s.advance(a.M)))
            o = None

            def solve():
                nonlocal o
                o = periodic_orbit(make, A, P, x0, multipliers=0)
            best["solve", jit] = min(best["solve", jit], cpu(solve))
            o = periodic_orbit(make, A, P, x0, multipliers=4)
            cost = {k: cpu(lambda: continue_orbit(o, A + 0.5, step=0.02, max_points=k,
                                                  multipliers=4)) for k in (2, 4)}
            best["step", jit] = min(best["step", jit], (cost[4] - cost[2]) / 2)
    print(f"forced belt, M = {a.M} steps a period, N = {dmi.Solver(2, TAU, h=P / a.M).N} delay "
          f"cells; fastest of {a.rounds} interleaved rounds, CPU seconds; jit=True compiled once "
          f"in {compile_s:.2f} s")
    print(f"per step over {a.steps} steps: jit=True {ns['jit']:.1f} ns, hand-written cfunc "
          f"{ns['cfunc']:.1f} ns, ratio {ns['jit'] / ns['cfunc']:.3f} (final states differ by "
          f"{np.max(np.abs(states['jit'] - states['cfunc'])):.1e})")
    print(f"{'':<22} {'Python rhs':>11} {'jit=True':>9} {'Python / jit':>13}")
    print(f"make(p), a Solver with its rhs set: Python rhs {best['make', False] * 1e6:.1f} us, "
          f"jit=True {best['make', True] * 1e6:.1f} us (a bind of the compiled code)")
    for k, label in (("period", "one period (advance)"), ("solve", "shooting solve"),
                     ("step", "continuation step")):
        py, jt = best[k, False], best[k, True]
        print(f"{label:<22} {py:11.4f} {jt:9.4f} {py / jt:12.1f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
