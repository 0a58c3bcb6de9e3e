#!/usr/bin/env python3
# The cost of the equation's answers (a benchmark, not a test): roots(of="equation") against the
# scheme's roots() on the same model, and refine_orbit (3 levels) against one periodic_orbit.
# Models: w'' + c w' + b w + a int_0^tau G(s) w(t - s) ds = 0 with an exponential kernel G
# (set_kernel_exp: the closed-form transform) and with the kernel 1 / (1 + s) as a Python
# callback (the panels' quadrature), 6 roots at N = 1e3, 1e4, 1e5; van der Pol with a
# distributed delay (an autonomous orbit, M = 2000, 4 multipliers; periodic_orbit from a plain
# run's window, 60 time units from a constant history).  Rounds interleave the two
# sides; the fastest of each counts; CPU times; one BLAS thread.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_equation.py [--rounds 3] [--N 1000 10000 100000]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from dmi import analysis as da  # noqa: E402
from benchtools import cpu  # noqa: E402

TAU, B, C = 1.0, 1.0, 0.3


def oscillator(a: float, N: int, kernel: str) -> dmi.Solver:
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(lambda t, u: np.array([-u[1], B * u[0] + C * u[1]]))
    if kernel == "exp":
        s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [a, 0.0]]])
    else:
        s.set_kernel(lambda x: np.array([[0.0, 0.0], [a / (1 + x), 0.0]]))
    return s


def vdp(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [0.5, 0.0]]])
    return s


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Prints roots(of='equation') / roots() and "
                                 "refine_orbit / periodic_orbit, CPU time ratios in one run.",
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds")
    ap.add_argument("--N", type=int, nargs="+", default=[1000, 10000, 100000],
                    help="delay cells N = tau / h of the roots cases")
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    print(f"{'kernel':>8} {'N':>7} {'scheme s':>9} {'equation s':>10} {'ratio':>6}")
    for kernel in ("exp", "callback"):
        for N in a.N:
            def make(p, N=N, kernel=kernel):
                return oscillator(p, N, kernel)
            t_s = t_e = math.inf
            for _ in range(a.rounds):
                t_s = min(t_s, cpu(lambda: da.roots(make, 0.8, [0.0, 0.0], 6)))
                t_e = min(t_e, cpu(lambda: da.roots(make, 0.8, [0.0, 0.0], 6, of="equation")))
            print(f"{kernel:>8} {N:>7} {t_s:9.4f} {t_e:10.4f} {t_e / t_s:6.2f}", flush=True)
    M = 2000
    s = vdp(0.0, h=5.63 / M)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(round(60 / s.h))
    o = da.periodic_orbit(vdp, 0.0, guess=s, guess_period=5.63, steps=M, multipliers=4)
    t_o = t_r = math.inf
    for _ in range(a.rounds):
        t_o = min(t_o, cpu(lambda: da.periodic_orbit(vdp, 0.0, guess=s, guess_period=5.63,
                                                     steps=M, multipliers=4)))
        t_r = min(t_r, cpu(lambda: da.refine_orbit(o)))
    print(f"van der Pol, M = {M}: periodic_orbit {t_o:.3f} s, refine_orbit (3 levels) "
          f"{t_r:.3f} s, ratio {t_r / t_o:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
