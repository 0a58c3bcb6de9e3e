#!/usr/bin/env python3
# The cost of self-excited oscillations in dmi.analysis (a benchmark, not a test), in periods of
# plain simulation and in roots calls measured in the same run.  The model: a mass on a moving
# belt with a memory that destabilises sliding (tests/python/analysis/shooting/test_selfexcited.py's
# belt: numba right-hand side with the damping c in its user data, a constant kernel by the O(1)
# recursion), with h = tau / N for N about 1e3 and 1e4.  Per N:
# - one period of plain simulation (advance(M));
# - an autonomous continuation step on the stick-slip branch (a branch of 8 points less one of 4,
#   over 4: the start's multipliers and first step cancel), 6 multipliers and the stick profile
#   a point;
# - a successful autonomous solve (periodic_orbit from a state 1 % off the orbit, multipliers
#   off) and a failing one (the same from a guess with a period 40 % too short and the state
#   flattened: Newton gives up), in periods;
# - an equilibrium branch step (a branch of 9 points less one of 5, over 4: every point's roots,
#   the Hopf event located on both) and one roots call at the equilibrium.
# Rounds interleave the quantities; the fastest round of each counts; CPU times of the process;
# one BLAS thread.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_selfexcited.py [--rounds 2] [--N 1000 10000]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

import dmi  # noqa: E402
from dmi import analysis as da  # noqa: E402
from dmi.analysis.core.newton import ShootingError  # noqa: E402
from benchtools import cpu  # noqa: E402

K, G, ALPHA, VB, TAU = 1.0, 0.8, 0.5, 0.3, 1.0
C_ORBIT = 0.2   # the damping of the stick-slip orbits (the sliding equilibrium is unstable)


_F64P = numba.types.CPointer(numba.types.float64)


# dmi's rhs signature with the user pointer typed as double * (the same C ABI): c = user[0]
@numba.cfunc(numba.types.intc(numba.types.float64, _F64P, _F64P, _F64P))
def _rhs(t, u, out, user):
    c = user[0]
    out[0] = -(u[1] + VB)
    out[1] = K * u[0] + c * (u[1] + VB)
    return 0


def model(N: int):
    """make(c, h=None): the belt with memory, h = tau / N unless given."""
    def make(c: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, TAU, h=TAU / N if h is None else h)
        par = np.array([float(c)])
        s.set_rhs(_rhs, par)
        s._keep["belt_c"] = par      # the user data lives as long as the solver
        s.set_kernel_exp([0.0], [0.0], [np.array([[0.0, 0.0], [G / TAU, 0.0]])])
        s.set_friction([0.0, ALPHA])
        return s
    return make


def orbit_at(make, N: int) -> da.Orbit:
    """The stick-slip orbit at C_ORBIT, from a long run's window (period about 5.2)."""
    s = make(C_ORBIT)
    s.set_history(lambda t: np.array([ALPHA / (K + G) + 0.05, -VB]))
    s.init()
    s.advance(round(60 / s.h))
    P = 5.2
    M = round(P / s.h)
    return da.periodic_orbit(make, C_ORBIT, guess=s.get_window(), guess_period=M * s.h, steps=M,
                             multipliers=0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description="Prints the cost of an autonomous continuation step, a successful and a "
                    "failing autonomous solve (in periods of plain simulation) and of an "
                    "equilibrium branch step (in roots calls), for the belt with memory.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=int, default=2, help="interleaved rounds")
    ap.add_argument("--N", type=int, nargs="+", default=[1000, 10000],
                    help="delay cells N = tau / h of the cases")
    a = ap.parse_args(argv)
    print(f"{'N':>6} {'M':>6} {'period s':>9} {'cont.step':>9} {'solve':>7} {'failing':>7} "
          f"{'fail/ok':>7} {'roots s':>8} {'eq.step':>7}   (steps and solves in periods, the "
          f"equilibrium step in roots calls; fastest of {a.rounds} rounds, CPU)")
    for N in a.N:
        make = model(N)
        o = orbit_at(make, N)
        M = o.steps
        best = {k: math.inf for k in ("period", "b4", "b8", "ok", "fail", "roots", "e5", "e9")}
        s = make(C_ORBIT, h=o.h)
        s.init()
        eq = da.equilibrium(make, 1.0, [0.3, -0.3])
        ok_guess = o.state * 1.01
        rows = make(C_ORBIT, h=0.6 * o.h).N + 1
        bad = np.tile(np.mean(o.state.reshape(-1, 2), axis=0), rows)
        bad = bad + 1e-3 * np.sin(np.arange(bad.size))

        def fail():
            try:
                da.periodic_orbit(make, C_ORBIT, guess=bad,
                                  guess_period=0.6 * o.period, steps=M, multipliers=0)
            except ShootingError:
                return
            raise RuntimeError("the failing solve converged")

        for _ in range(a.rounds):
            best["period"] = min(best["period"], cpu(lambda: s.advance(M)))
            best["ok"] = min(best["ok"], cpu(lambda: da.periodic_orbit(
                make, C_ORBIT, guess=ok_guess[-(s.N + 1) * 2:], guess_period=o.period, steps=M,
                multipliers=0)))
            best["fail"] = min(best["fail"], cpu(fail))
            for k in (4, 8):
                best[f"b{k}"] = min(best[f"b{k}"], cpu(
                    lambda: da.continue_orbit(o, -0.5, step=0.02, max_points=k)))
            best["roots"] = min(best["roots"], cpu(lambda: da.roots(make, 1.0, eq.u, 6)))
            for k in (5, 9):
                best[f"e{k}"] = min(best[f"e{k}"], cpu(
                    lambda: da.continue_equilibrium(eq, -1.0, step=0.1, max_points=k)))
        per = best["period"]
        step = (best["b8"] - best["b4"]) / 4 / per
        eqstep = (best["e9"] - best["e5"]) / 4 / best["roots"]
        print(f"{N:>6} {M:>6} {per:9.4f} {step:9.1f} {best['ok'] / per:7.1f} "
              f"{best['fail'] / per:7.1f} {best['fail'] / best['ok']:7.2f} {best['roots']:8.4f} "
              f"{eqstep:7.1f}", flush=True)
    return 0


if __name__ == "__main__":
    sys_exit = main()
    raise SystemExit(sys_exit)
