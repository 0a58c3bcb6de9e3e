#!/usr/bin/env python3
# Old against new, interleaved (a benchmark, not a test): runs the benchmarks of two checkouts, each
# built alike (its own bench binaries, FMUs and Python package, in BUILD), in pairs of processes
# A B, B A, A B, ... and prints, per figure, each tree's median over its processes and the ratio
# new / old taken pair by pair (median, quartiles, range), with the load average before each pair.
# Benchmarks (--set):
#   c       bench_cells (dmi_init, callback kernel, cell rule; the step with friction: exponential
#           kernel by the recursion, callback kernel by DIRECT and by the FFT; N = 1000),
#           bench_binding (the recursion with friction, N = 1e4), bench_init (dmi_init and
#           dmi_set_window, exponential kernel by the recursion and DIRECT, N = 1e3..1e6),
#           bench_fmu_loop with the FMI 2.0 and the FMI 3.0 binary (ns per solver step)
#   python  bench_identify.py (sensitivities and a forward difference, the cases of --identify-args)
#           and this script's --solver-child (Solver.run, Solver.step and Solver.init of a small
#           model, bench_jit.py's forced belt: n = 2, friction, one exponential memory term, its
#           rhs a Python function and jit=True), each run with the tree's own Python package
#           (bench_identify.py the tree's own script; the solver child this one, the same code),
#           and this tree's bench_identify_fit.py (estimate against least_squares; the same
#           script with each tree's package)
# Every figure is a CPU time inside the process (the bench's own, fastest of its rounds).
# Usage: python3 bench/bench_against.py OLD NEW [--build build-rel] [--pairs 6] [--set c]
#        [--only cells,binding] [--python .venv/bin/python] [--log FILE]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys

from benchtools import nonempty, positive_int

FMU2 = "fmu/DelayFrictionOscillator/binaries/linux64/DelayFrictionOscillator.so"
FMU3 = "fmu/fmi3/DelayFrictionOscillator/binaries/x86_64-linux/DelayFrictionOscillator.so"


def c_runs(tree: str, build: str) -> list[tuple[str, list[str], dict]]:
    b = os.path.join(tree, build)
    return [("cells", [f"{b}/bench/bench_cells", "3", "1000", "200000", "20"], {}),
            ("binding", [f"{b}/bench/bench_binding", "10000", "2000000"], {}),
            ("init", [f"{b}/bench/bench_init", "1"], {}),
            ("fmu2", [f"{b}/bench/bench_fmu_loop", "2", "2", f"{b}/{FMU2}"], {}),
            ("fmu3", [f"{b}/bench/bench_fmu_loop", "2", "2", f"{b}/{FMU3}"], {})]


def python_runs(tree: str, build: str, python: str,
                identify_args: list[str]) -> list[tuple[str, list[str], dict]]:
    here = os.path.dirname(os.path.abspath(__file__))
    env = {"PYTHONPATH": f"{tree}/{build}/python:{tree}/bench", "OPENBLAS_NUM_THREADS": "1",
           "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    return [("identify", [python, f"{tree}/bench/bench_identify.py", *identify_args], env),
            ("fit", [python, f"{here}/bench_identify_fit.py", "--rounds", "2"],
             {**env, "PYTHONPATH": f"{tree}/{build}/python:{here}"}),
            ("solver", [python, os.path.abspath(__file__), "--solver-child", "x", "x"], env)]


def solver_child(rounds: int = 3) -> None:
    """Prints CPU ns of Solver.run, .step, .init of bench_jit.py's belt (fastest of rounds)."""
    import math
    import time
    import numpy as np
    import dmi
    C, V, ALPHA, G, THETA, TAU, W, A = 0.1, 0.4, 0.3, 0.2, 0.5, 1.0, 1.1, 1.0
    h = 2 * math.pi / (W * 400)

    def make(jit: bool) -> dmi.Solver:
        def rhs(t, u):
            return np.array([-(u[1] + V), u[0] + C * (u[1] + V) - A * math.cos(W * t)])
        s = dmi.Solver(2, TAU, h=h)
        s.set_rhs(rhs, jit=jit)
        s.set_friction([0.0, ALPHA])
        s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [G, 0.0]]])
        return s

    def cpu(f) -> float:
        t = time.process_time()
        f()
        return time.process_time() - t
    solvers = {jit: make(jit) for jit in (False, True)}
    for s in solvers.values():
        s.init()
        s.run(10)
    best: dict[str, float] = {}
    cases = {"Solver.run, Python rhs, ns/step": (False, "run", 20000),
             "Solver.run, jit=True, ns/step": (True, "run", 500000),
             "Solver.step, jit=True, ns/call": (True, "step", 20000),
             "Solver.init, jit=True, ns/call": (True, "init", 2000)}
    for _ in range(rounds):
        for name, (jit, what, k) in cases.items():
            s = solvers[jit]
            s.init()
            if what == "run":
                t = cpu(lambda: s.run(k))
            elif what == "step":
                t = cpu(lambda: [s.step() for _ in range(k)])
            else:
                t = cpu(lambda: [s.init() for _ in range(k)])
            best[name] = min(best.get(name, math.inf), 1e9 * t / k)
    for name, v in best.items():
        print(f"{name} = {v:.6g}")


NUM = r"([0-9.]+(?:e[-+]?\d+)?)"


def parse(name: str, out: str) -> dict[str, float]:
    """The figures of one bench's output, by a name of their own."""
    fig: dict[str, float] = {}
    if name == "cells":
        for m in re.finditer(r"^(init|step)[^\n]*?\s+" + NUM + r" (ms/init|ns/step)", out, re.M):
            fig[m.group(0).split("  ")[0].strip()] = float(m.group(2))
    elif name == "binding":
        fig["step, exp (recursion), N = 1e4"] = float(re.search(r"ns_per_step " + NUM, out).group(1))
    elif name == "init":
        for m in re.finditer(r"^(exp \(recursion\)|exp, DIRECT)\s+(\d+)\s+" + NUM + r"\s+" + NUM,
                             out, re.M):
            fig[f"init/N, {m.group(1)}, N = {m.group(2)}"] = float(m.group(3))
            fig[f"set_window/N, {m.group(1)}, N = {m.group(2)}"] = float(m.group(4))
    elif name in ("fmu2", "fmu3"):
        for m in re.finditer(r"^\s*(\d+) \|\s+" + NUM + r" \|\s+" + NUM + r" \|\s+" + NUM, out, re.M):
            fig[f"{name} ns/step, N = {m.group(1)}"] = float(m.group(3))
    elif name == "identify":
        for line in out.splitlines():
            m = re.match(r"^(\S.{0,43}?)\s+" + r"\s+".join([NUM] * 8) + r"\s*$", line)
            if m:
                fig[f"sens, {m.group(1).strip()}"] = float(m.group(3))
                fig[f"fwd, {m.group(1).strip()}"] = float(m.group(4))
        # (its Gauss-Newton line is left out: since the identify cache became dmi._cache.Cache,
        # bench_identify.py's `problem._cache = None` no longer clears it, and the line times a
        # cached Jacobian)
    elif name == "fit":
        for m in re.finditer(r"^(estimate|estimate, polish=False|least_squares 2-point)\s+" + NUM + " s",
                             out, re.M):
            fig[f"fit: {m.group(1)}"] = float(m.group(2))
        m = re.search(r"one sensitivity run " + NUM + " s.*1 \+ P = 8 runs " + NUM + " s", out)
        if m:
            fig["fit model: one sensitivity run"] = float(m.group(1))
            fig["fit model: 1 + P = 8 plain runs"] = float(m.group(2))
    elif name == "solver":
        for m in re.finditer(r"^(Solver\..*) = " + NUM + "$", out, re.M):
            fig[m.group(1)] = float(m.group(2))
    return fig


def run(cmd: list[str], env: dict, log) -> str:
    e = dict(os.environ)
    e.update(env)
    p = subprocess.run(cmd, capture_output=True, text=True, env=e, check=False)
    log.write(f"$ {' '.join(cmd)}  (rc {p.returncode})\n{p.stdout}{p.stderr}\n")
    log.flush()
    if p.returncode != 0:
        raise SystemExit(f"{' '.join(cmd)} failed (rc {p.returncode}):\n{p.stderr[-2000:]}")
    return p.stdout


def quartiles(x: list[float]) -> tuple[float, float]:
    if len(x) < 4:
        return min(x), max(x)
    q = statistics.quantiles(x, n=4)
    return q[0], q[2]


def main() -> int:
    if sys.argv[1:2] == ["--solver-child"]:
        solver_child()
        return 0
    ap = argparse.ArgumentParser(description="Runs the benchmarks of two checkouts in interleaved "
                                 "pairs of processes and prints new / old pair by pair.")
    ap.add_argument("old", nargs="?", type=nonempty, help="the old checkout (its BUILD built)")
    ap.add_argument("new", nargs="?", type=nonempty, help="the new checkout (its BUILD built alike)")
    ap.add_argument("--build", type=nonempty, default="build-rel",
                    help="the build directory in each (default build-rel)")
    ap.add_argument("--pairs", type=positive_int, default=6,
                    help="pairs of processes per bench (default 6)")
    ap.add_argument("--set", choices=("c", "python"), default="c", help="which benchmarks (default c)")
    ap.add_argument("--python", type=nonempty, default=sys.executable,
                    help="the Python of --set python (default this one)")
    ap.add_argument("--identify-args", type=nonempty,
                    default="--rounds 2 --steps 1000 --callback-steps 2000",
                    help="bench_identify.py's arguments (default --rounds 2 --steps 1000 "
                         "--callback-steps 2000)")
    ap.add_argument("--only", type=nonempty, default=None,
                    help="only these benches, by the names of parse(), e.g. cells,binding "
                         "(default all of --set)")
    ap.add_argument("--log", type=nonempty, default=None, help="a file for every process's output (default none)")
    a = ap.parse_args()
    if a.old is None or a.new is None:
        ap.error("give the two checkouts, OLD and NEW")
    trees = {"old": a.old, "new": a.new}
    if a.set == "c":
        runs = {k: c_runs(t, a.build) for k, t in trees.items()}
    else:
        runs = {k: python_runs(t, a.build, a.python, a.identify_args.split())
                for k, t in trees.items()}
    if a.only:
        runs = {k: [r for r in v if r[0] in a.only.split(",")] for k, v in runs.items()}
        if not runs["old"]:
            ap.error(f"--only {a.only}: no such bench")
    log = open(a.log, "a") if a.log else open(os.devnull, "w")
    figs: dict[str, dict[str, list[float]]] = {"old": {}, "new": {}}
    ratios: dict[str, list[float]] = {}
    loads: list[float] = []
    for i in range(a.pairs):
        loads.append(os.getloadavg()[0])
        order = ("old", "new") if i % 2 == 0 else ("new", "old")
        for j in range(len(runs["old"])):
            got = {}
            for k in order:
                name, cmd, env = runs[k][j]
                got[k] = parse(name, run(cmd, env, log))
                if i == 0 and not got[k]:
                    raise SystemExit(f"{name}: no figure found in its output (see --log)")
            for f in got["new"].keys() & got["old"].keys():
                for k in ("old", "new"):
                    figs[k].setdefault(f, []).append(got[k][f])
                ratios.setdefault(f, []).append(got["new"][f] / got["old"][f])
        print(f"pair {i + 1}/{a.pairs} done, load {loads[-1]:.1f}", file=sys.stderr, flush=True)
    print(f"{a.pairs} pairs of processes (A B, B A, ...); load average (1 min) before each pair: "
          f"{min(loads):.1f}-{max(loads):.1f}, median {statistics.median(loads):.1f}")
    print(f"{'figure':48} {'old med':>10} {'new med':>10} {'new/old':>8} {'quartiles':>12} {'range':>12}")
    for f in ratios:
        r = ratios[f]
        lo, hi = quartiles(r)
        print(f"{f:48} {statistics.median(figs['old'][f]):10.4g} {statistics.median(figs['new'][f]):10.4g} "
              f"{statistics.median(r):8.3f} {lo:5.2f}-{hi:<6.2f} {min(r):5.2f}-{max(r):<6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
