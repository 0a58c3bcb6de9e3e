#!/usr/bin/env python3
# The cost of dmi.analysis's periodic orbits (a benchmark, not a test), in periods of
# plain simulation measured in the same run: the tau-diagram's oscillator
# (examples/python/orbit_tau.py: numba right-hand side, constant kernel by the O(1) recursion)
# at tau = 2.2 with h = 4 pi / M chosen so that N = ceil(tau / h) is about 1e3 and 1e4.  Per N:
# one period (advance(M)), one Newton solve (periodic_orbit from the run's window, multipliers
# off, from a run 10 periods from rest), the 10 leading multipliers, the start of a branch
# (continue_orbit to 2 points: the first point's multipliers from scratch and the first step) and
# one continuation step along it (with 6 multipliers, verified by default, and the stick profile a
# point: a branch of 8 points less one of 4, over 4), the same step with verify=False (the Ritz
# multipliers without a verdict), and what such a step is made of: one evaluation of the M-step
# map and building the map at a new p (make(p), init), each the mean of 10.  Rounds interleave
# the quantities; the fastest round of each counts; CPU times of the process (the machine may be
# shared); one BLAS thread.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_orbit.py [--rounds 3] [--N 1000 10000]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

# One BLAS thread: on the loaded 2-core machine OpenBLAS's spinning threads made GMRES and the
# QR of the multipliers 10 times slower (in CPU time too) than with one thread.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "python"))

import orbit_tau  # noqa: E402

from dmi.analysis import continue_orbit, periodic_orbit  # noqa: E402
from dmi.analysis.scheme.floquet import floquet_multipliers  # noqa: E402
from dmi.analysis.scheme.stepmap import StepMap, state_of  # noqa: E402
from benchtools import cpu  # noqa: E402

TAU = 2.2


def setup(N: int):
    M = round(orbit_tau.P * N / TAU)
    make = orbit_tau.model(M)
    s = make(TAU)
    s.init()
    s.advance(10 * M)  # near the orbit, not on it: the Newton solve has work to do
    return M, make, s


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description="Prints the cost of one Newton solve, the 10 leading multipliers, one "
                    "continuation step, one evaluation of the step map and one build of it, for "
                    "the tau-diagram's oscillator, in periods of plain simulation measured in "
                    "the same run.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds")
    ap.add_argument("--N", type=int, nargs="+", default=[1000, 10000],
                    help="delay cells N = ceil(tau / h) of the cases")
    a = ap.parse_args(argv)
    print(f"{'N':>6} {'M':>6} {'period s':>9} {'Newton':>8} {'its':>4} {'mult10':>8} "
          f"{'start':>7} {'cont.step':>9} {'unverif.':>8} {'eval':>5} {'build':>5}   (costs in "
          f"periods of plain "
          f"simulation; "
          f"fastest of {a.rounds} rounds, CPU)")
    for N in a.N:
        M, make, s = setup(N)
        x0 = state_of(s, M)
        best = {k: math.inf for k in ("period", "newton", "mult", "start", "step", "plain",
                                      "eval", "build")}
        its = 0
        for _ in range(a.rounds):
            best["period"] = min(best["period"], cpu(lambda: s.advance(M)))
            o = None

            def solve():
                nonlocal o, its
                o = periodic_orbit(make, TAU, orbit_tau.P, x0, multipliers=0)
                its = o.iterations
            best["newton"] = min(best["newton"], cpu(solve))
            F = StepMap(make, TAU, M)
            best["mult"] = min(best["mult"], cpu(lambda: floquet_multipliers(F, o.state, 10)))
            best["eval"] = min(best["eval"], cpu(lambda: [F(o.state) for _ in range(10)]) / 10)
            best["build"] = min(best["build"],
                                cpu(lambda: [StepMap(make, TAU, M) for _ in range(10)]) / 10)
            cost, plain = {}, {}
            for points in (2, 4, 8):
                cost[points] = cpu(lambda: continue_orbit(o, TAU + 0.2, step=0.02,
                                                          max_points=points, multipliers=6))
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UserWarning)   # verify=False's notice
                    plain[points] = cpu(lambda: continue_orbit(
                        o, TAU + 0.2, step=0.02, max_points=points, multipliers=6, verify=False))
            best["start"] = min(best["start"], cost[2])
            best["step"] = min(best["step"], (cost[8] - cost[4]) / 4)
            best["plain"] = min(best["plain"], (plain[8] - plain[4]) / 4)
        T = best["period"]
        print(f"{N:>6} {M:>6} {T:9.4f} {best['newton'] / T:8.1f} {its:>4} {best['mult'] / T:8.1f} "
              f"{best['start'] / T:7.1f} {best['step'] / T:9.1f} {best['plain'] / T:8.1f} "
              f"{best['eval'] / T:5.2f} "
              f"{best['build'] / T:5.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
