#!/usr/bin/env python3
# The cost of collocation on a long memory (a benchmark, not a test): the fractional belt, a mass on
# a belt with velocity-weakening (Stribeck) friction and a Caputo damping of order 1/2
# (tests/python/models/fractional_belt.py: the kernel c_f s^-1/2 / Gamma(1/2) on the relative
# velocity, fitted by exponential terms plus exact near cells), tau = 50 (about eight periods).
# Two cases:
#   stick-slip: collocate (default tol, 10 multipliers) of the stick-slip orbit at v_b = 0.6 from
#               the scheme's orbit (h = 0.005; the shooting not counted);
#   hopf orbit: hopf_orbit(of="equation") at the equation's Hopf point (v_b ~ 1.025, not counted),
#               amplitude 0.1.
# CPU time of the process, the fastest of --rounds rounds, one BLAS thread.  --small: tau = 15 (about
# two periods) and 8 intervals for the stick-slip orbit, a size for a quick check.  --intervals L:
# the stick-slip orbit at L intervals instead of the default tol.  --unfolded: the periodic orbit's
# delay integrals over the whole memory (dmi.analysis.collocation.fold.FOLD off), as before the fold.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_longmem.py [--rounds 1] [--small]
#        [--intervals L] [--only stick-slip|hopf] [--unfolded]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from dmi import analysis as da  # noqa: E402
from benchtools import cpu, positive_int  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
from models.fractional_belt import model, stick_slip_orbit  # noqa: E402

AMPLITUDE = 0.1                               # of the orbit born at the Hopf point


def hopf_point(make):
    """The equation's Hopf point of the sliding equilibrium (v_b in (0.8, 1.3)) and its
    equilibrium."""
    def u_eq(vb: float) -> np.ndarray:
        return da.equilibrium(make, vb, [0.6, -vb], of="equation").u
    hp = da.hopf(make, 0.8, 1.3, u_eq, of="equation")
    return hp, u_eq(hp.p)


def setup(small: bool, intervals: int | None, only: str | None) -> dict:
    """The cases (name -> a call)."""
    make, fit = model(15.0 if small else 50.0)
    print(f"tau = {fit.tau:g}: {fit.a.size} exponential terms, near cells delta = {fit.delta:g}")
    cases = {}
    if only in (None, "stick-slip"):
        o = stick_slip_orbit(make)
        L = 8 if small and intervals is None else intervals
        cases["stick-slip"] = lambda: da.collocate(o, intervals=L, multipliers=10)
    if only in (None, "hopf"):
        hp, ue = hopf_point(make)
        print(f"Hopf point v_b = {hp.p:.10f}, omega = {hp.omega:.10f}, kappa = "
              f"{getattr(hp, 'kappa', None)}")
        cases["hopf orbit"] = lambda: da.hopf_orbit(make, hp, ue, amplitude=AMPLITUDE,
                                                    of="equation", multipliers=10)
    return cases


def describe(r) -> str:
    """The result's figures: p, intervals, period and its estimate, leading multipliers."""
    mu = np.asarray(r.multipliers)[:4]
    err = r.errors.get("period", float("nan"))
    mer = r.errors.get("multipliers")
    mer = float(np.max(mer[:4])) if mer is not None and np.size(mer) else float("nan")
    return (f"p = {r.p:.12g}, L = {r.intervals}, period = {r.period:.14g} (+- {err:.1e}), "
            f"|mu| = {' '.join(f'{abs(x):.10f}' for x in mu)} (+- {mer:.1e})")


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Prints the CPU times of collocation on the "
                                 "fractional belt (a memory of eight periods).",
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=positive_int, default=1, help="rounds (the fastest counts)")
    ap.add_argument("--small", action="store_true", help="tau = 15 and 8 intervals: a quick size")
    ap.add_argument("--intervals", type=positive_int, default=None,
                    help="the stick-slip orbit at this many intervals (default: the default tol)")
    ap.add_argument("--only", choices=("stick-slip", "hopf"), default=None, help="one case")
    ap.add_argument("--unfolded", action="store_true",
                    help="the orbit's delay integrals over the whole memory (no fold)")
    a = ap.parse_args(argv)
    if a.unfolded:
        from dmi.analysis.collocation import fold
        fold.FOLD = False
    warnings.simplefilter("ignore")
    cases = setup(a.small, a.intervals, a.only)
    best: dict = {}
    out: dict = {}
    for _ in range(a.rounds):
        for k, f in cases.items():
            res: list = []
            best[k] = min(best.get(k, np.inf), cpu(lambda: res.append(f())))
            out[k] = res[0]
    print(f"{'case':>12} {'CPU s':>8}  result")
    for k in cases:
        print(f"{k:>12} {best[k]:8.2f}  {describe(out[k])}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
