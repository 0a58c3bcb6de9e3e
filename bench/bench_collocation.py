#!/usr/bin/env python3
# The cost of the equation's periodic orbits by collocation (a benchmark, not a test): van der Pol
# with a distributed delay, w'' + (w^2 - 1) w' + w + (a / tau) int_0^tau w(t - s) ds = 0, tau = 1,
# a = 0.5 (DDE-BIFTOOL, Octave 7.3, same kind of machine: 0.55 s for the period to 1.9e-11 with
# 40 intervals of degree 4, 0.69 s a branch point with its stability at 5e-9): collocate from a
# scheme orbit (the shooting not counted) with 40 intervals (the orbit returned has 80: the error
# estimate's finer level) and with tol = 1e-10; one continuation point (a = 0.5 -> 0.55: Newton,
# the multipliers and the error estimate on the mesh of merged interval pairs, and without the
# estimate, as
# DDE-BIFTOOL's points come); and a stick-slip orbit of a belt
# oscillator with a truncated exponential memory (autonomous, its stick segment read from the
# scheme).  Errors against a reference collocation at 320 intervals.  Rounds interleave the cases;
# the fastest of each counts; CPU times; one BLAS thread.  With --against DIR, the same cases on
# another build of dmi (DIR its python directory, e.g. an older commit's build/python) in one run:
# two child processes, one a build, each set up once, then asked for one round in turn (the order
# swapped every round); the table gives both times and their ratio.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_collocation.py [--rounds 3]
#        [--against OTHER/build/python]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
import scipy.sparse.linalg as sla  # noqa: E402

import dmi  # noqa: E402
from dmi import analysis as da  # noqa: E402
from benchtools import cpu, dir_holding, positive_int  # noqa: E402

TAU = 1.0


def vdp(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-u[1], (u[0] ** 2 - 1) * u[1] + u[0]]))
    s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p / TAU, 0.0]]])
    return s


# A belt oscillator in relative velocity: u = (x, y), y = x' - V the velocity relative to the belt;
# x' = y + V, y' = -x + k (y + V) - alpha sigma(y) - g int_0^tau e^{-s} x(t - s) ds (negative
# damping k drives it; it sticks to the belt at y = 0 while |x - k V + memory| <= alpha).
V, K, ALPHA, G, TAU_B = 0.5, 0.2, 0.4, 0.3, 2.0


def belt(p: float, h: float | None = None) -> dmi.Solver:
    s = dmi.Solver(2, TAU_B, h=0.01 if h is None else h)
    s.set_rhs(lambda t, u: np.array([-(u[1] + V), u[0] - K * (u[1] + V)]))
    s.set_friction([0.0, ALPHA])
    s.set_kernel_exp([-1.0], [0.0], [[[0.0, 0.0], [G, 0.0]]])
    return s


def scheme_orbit(make, p: float, start: np.ndarray, T: float, steps: int) -> da.Orbit:
    s = make(p, h=T / steps)
    s.set_history(lambda t: start)
    s.init()
    s.advance(40 * steps)
    return da.periodic_orbit(make, p, None, s, guess_period=T, steps=steps, multipliers=0)


def point(disc, x: np.ndarray, p: float):
    """Newton-chord at p from x (the natural predictor; the factored Jacobian kept while the
    residual falls tenfold a step, as a driver does), then the point with its multipliers."""
    lu, last = None, np.inf
    for _ in range(30):
        r = disc.residual(x, p)
        rn = np.max(np.abs(r))
        if lu is None or rn > 0.1 * last:
            lu = sla.splu(disc.jacobian(x, p)[0])
        last = rn
        dx = lu.solve(-r)
        x = x + dx
        if np.max(np.abs(dx)) < 1e-12 * max(1.0, np.max(np.abs(x))):
            break
    return disc.point(x, p)


def setup() -> tuple[dict, dict]:
    """The cases (name -> a call) and their reference orbits (name -> orbit)."""
    o = scheme_orbit(vdp, 0.5, np.array([2.0, 0.0]), 6.0, 600)
    ref = da.collocate(o, intervals=320, multipliers=4)
    e = da.collocate(o, intervals=40)
    disc, x = da.CollocationDiscretisation.of(e)
    bare, _ = da.CollocationDiscretisation.of(e, estimate=False)
    dref, xref = da.CollocationDiscretisation.of(ref, estimate=False)
    ref2 = point(dref, xref, 0.55)
    ob = scheme_orbit(belt, 1.0, np.array([1.0, 0.0]), 6.46, 1000)
    refb = da.collocate(ob, intervals=320, multipliers=0)
    cases = {
        "vdp, 40 intervals": lambda: da.collocate(o, intervals=40),
        "vdp, tol 1e-10": lambda: da.collocate(o, tol=1e-10),
        "vdp, branch point": lambda: point(disc, x.copy(), 0.55),
        "point, no estimate": lambda: point(bare, x.copy(), 0.55),
        "belt stick-slip": lambda: da.collocate(ob, tol=1e-9),
    }
    refs = {"vdp, 40 intervals": ref, "vdp, tol 1e-10": ref, "vdp, branch point": ref2,
            "point, no estimate": ref2,
            "belt stick-slip": refb}
    return cases, refs


def one_round(cases: dict, best: dict, out: dict) -> None:
    """Each case once, its CPU time kept in best (the fastest) and its result in out."""
    for k, f in cases.items():
        res: list = []
        best[k] = min(best.get(k, np.inf), cpu(lambda: res.append(f())))
        out[k] = res[0]


def rows(cases: dict, refs: dict, out: dict) -> dict[str, list]:
    """name -> [intervals, period error, its estimate, mu2 error, signature]."""
    table = {}
    for k in cases:
        r, R = out[k], refs[k]
        mu = (abs(r.multipliers[1] - R.multipliers[1]) if r.multipliers.size > 1
              and R.multipliers.size > 1 else float("nan"))
        table[k] = [r.intervals, float(abs(r.period - R.period)),
                    float(r.errors.get("period", float("nan"))), float(mu),
                    " ".join(r.signature.describe())]
    return table


def serve() -> int:
    """A child of --against: set up, print "ready", then one round for each "go" line (its CPU
    times as a JSON line); at "stop" the results' rows as a JSON line."""
    cases, refs = setup()
    best: dict = {}
    out: dict = {}
    print("ready", flush=True)
    for line in sys.stdin:
        if line.strip() == "go":
            times: dict = {}
            one_round(cases, times, out)
            print(json.dumps(times), flush=True)
        else:
            print(json.dumps(rows(cases, refs, out)), flush=True)
            break
    return 0


def against(other: str, rounds: int) -> int:
    """This build ("new") and the one at ``other`` ("old") in interleaved rounds."""
    env = dict(os.environ)
    procs = {"new": subprocess.Popen([sys.executable, __file__, "--serve"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True, env=env),
             "old": subprocess.Popen([sys.executable, __file__, "--serve"], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, text=True,
                                     env={**env, "PYTHONPATH": other})}
    try:
        for name, pr in procs.items():
            if pr.stdout.readline().strip() != "ready":
                raise SystemExit(f"bench_collocation: the {name} build's child failed to set up")
        best: dict = {"new": {}, "old": {}}
        for i in range(rounds):
            for name in (("new", "old") if i % 2 == 0 else ("old", "new")):
                procs[name].stdin.write("go\n")
                procs[name].stdin.flush()
                for k, v in json.loads(procs[name].stdout.readline()).items():
                    best[name][k] = min(best[name].get(k, np.inf), v)
        table = {}
        for name, pr in procs.items():
            pr.stdin.write("stop\n")
            pr.stdin.flush()
            table[name] = json.loads(pr.stdout.readline())
    finally:
        for pr in procs.values():
            pr.stdin.close()
            pr.wait(timeout=60)
    print(f"{'case':>20} {'new s':>7} {'old s':>7} {'new/old':>7} {'intervals':>9} "
          f"{'period error':>12} {'estimate':>9} {'mu2 error':>9} (new; old below)")
    for k in best["new"]:
        n, o = best["new"][k], best["old"][k]
        for name in ("new", "old"):
            iv, pe, est, mu, _ = table[name][k]
            lead = (f"{k:>20} {n:7.3f} {o:7.3f} {n / o:7.2f}" if name == "new"
                    else f"{'':>20} {'':>7} {'':>7} {'':>7}")
            print(f"{lead} {iv:9d} {pe:12.2e} {est:9.1e} {mu:9.1e}")
    return 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description="Prints the CPU times and errors of collocate and "
                                 "of a continuation point.",
                                 formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--rounds", type=positive_int, default=3, help="interleaved rounds")
    ap.add_argument("--against", metavar="DIR", default=None,
                    type=dir_holding(os.path.join("dmi", "__init__.py")),
                    help="another build's python directory: both timed in interleaved rounds")
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    if a.serve:
        return serve()
    if a.against is not None:
        return against(a.against, a.rounds)
    cases, refs = setup()
    best: dict = {}
    out: dict = {}
    for _ in range(a.rounds):
        one_round(cases, best, out)
    print(f"{'case':>20} {'CPU s':>7} {'intervals':>9} {'period error':>12} {'estimate':>9} "
          f"{'mu2 error':>9} {'signature'}")
    for k, (iv, pe, est, mu, sig) in rows(cases, refs, out).items():
        print(f"{k:>20} {best[k]:7.3f} {iv:9d} {pe:12.2e} {est:9.1e} {mu:9.1e} {sig}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
