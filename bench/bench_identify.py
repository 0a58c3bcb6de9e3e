#!/usr/bin/env python3
# The cost of dmi.identify.sensitivities (a benchmark, not a test) against the runs it replaces:
# a plain run, a forward-difference Jacobian (P + 1 runs) and a central one (2P + 1 runs).
# The model: a friction oscillator with a viscoelastic memory of two Prony terms on the velocity,
#   w'' + k w + mu sigma(w') + int_0^tau (c1 e^{a1 s} + c2 e^{a2 s}) w'(t - s) ds + g cos 0.8 t ∋ 0,
# w = w0 on t <= 0, P = 8 parameters (k, g: f; mu: friction; w0: history; c1, a1, c2, a2: kernel),
# tau = N h, N = steps; f reads k and g only and the history w0 only (make unpacks p), so the
# sensitivities differentiate f in 2 parameters (f_u by n = 2 columns) and sample 1 history.  Variants: f with jit=True (compiled: the sensitivities' compiled loop) or a
# Python function (their Python loop); the history a Python function, or jit=True as well ("all
# jit"); the kernel as exponentials (RECURSIVE) or as a Python callback (DIRECT, FFT; shorter
# runs); "f jit, Python loop" times the Python loop on the compiled model.  Then one
# Gauss-Newton iteration of the gallery's fit (plot_identify_friction_memory.py: one sensitivity
# run and one residual run) against the P + 1 runs it needs.
# Rounds interleave the variants; the fastest round of each counts; CPU times of the process (the
# machine may be shared); one BLAS thread; a case whose forward difference takes under 50 ms is
# repeated within each timing to about 50 ms (the time of one call is printed).  --baseline DIR times another version of dmi.identify
# (DIR: a copy of its python/dmi/identify, e.g. from `git show main:...`, loaded as a subpackage
# of the same dmi) in the same rounds, interleaved: its columns "sens (base)" and "base/sens".
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_identify.py [--rounds 2]
#        [--steps 1000 100000] [--callback-steps 2000] [--cases TEXT] [--baseline DIR]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from benchtools import cpu, dir_holding, nonempty, positive_int  # noqa: E402
from dmi.identify import Record, sensitivities  # noqa: E402
from dmi.identify.fitting import _Problem, _check_record  # noqa: E402

P0 = np.array([1.0, 2.0, 0.5, 1.0, 1.0, -0.3, 3.0, -3.0])   # k, g, mu, w0, c1, a1, c2, a2
H = 0.01


def model(steps: int, jit: bool, kernel: str, history_jit: bool = False):
    """make(p) at N = steps, f (and the history) compiled or not, the kernel as exponentials or a
    callback."""
    def make(p):
        k, g, mu, w0, c1, a1, c2, a2 = p

        def rhs(t, u):
            return np.array([-u[1], k * u[0] + g * math.cos(0.8 * t)])
        s = dmi.Solver(2, steps * H, steps)
        s.set_rhs(rhs, jit=jit)
        s.set_friction([0.0, mu])
        if kernel == "exp":
            C = np.zeros((2, 2, 2))
            C[0, 1, 1], C[1, 1, 1] = c1, c2
            s.set_kernel_exp([a1, a2], [0.0, 0.0], C)
        else:
            def H_(x):
                return np.array([[0.0, 0.0], [0.0, c1 * math.exp(a1 * x) + c2 * math.exp(a2 * x)]])
            s.set_kernel(H_)
            s.set_convolution(kernel)
        s.set_history(lambda t: np.array([w0, 0.0]), jit=history_jit)
        return s
    return make


def plain(make, p, steps):
    s = make(p)
    s.init()
    s.run(steps)


def differences(make, p, steps, central: bool):
    plain(make, p, steps)
    for j in range(len(p)):
        for sign in ((1.0, -1.0) if central else (1.0,)):
            q = p.copy()
            q[j] += sign * 1e-6
            plain(make, q, steps)


def baseline(path: str):
    """The package in directory path (a copy of python/dmi/identify) as dmi._identify_baseline."""
    spec = importlib.util.spec_from_file_location("dmi._identify_baseline", os.path.join(path, "__init__.py"),
                                                  submodule_search_locations=[path])
    if spec is None or spec.loader is None:
        raise SystemExit(f"--baseline {path}: no __init__.py there")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


def main() -> None:
    ap = argparse.ArgumentParser(description=(
        "Prints the CPU time of dmi.identify.sensitivities against a plain run, a forward- and a "
        "central-difference Jacobian, per model variant, and of one Gauss-Newton iteration of the "
        "gallery fit against the P + 1 runs it needs."))
    ap.add_argument("--rounds", type=positive_int, default=2,
                    help="interleaved rounds; the fastest of each variant counts (default 2)")
    ap.add_argument("--steps", type=positive_int, nargs="+", default=[1000, 100000],
                    help="run lengths N = steps (tau = N h) of the exponential-kernel cases "
                         "(default 1000 100000)")
    ap.add_argument("--callback-steps", type=positive_int, default=2000,
                    help="run length of the callback-kernel cases, DIRECT and FFT (default 2000)")
    ap.add_argument("--cases", metavar="TEXT", type=nonempty, default=None,
                    help="only the cases whose name contains TEXT (default: all)")
    ap.add_argument("--baseline", metavar="DIR", type=dir_holding("__init__.py"),
                    help="a copy of another version's python/dmi/identify, timed in the same "
                         "rounds (default: none)")
    args = ap.parse_args()
    base = baseline(args.baseline) if args.baseline else None
    P = len(P0)
    cases = []
    for steps in args.steps:
        cases.append((f"exp, all jit, steps = N = {steps}", model(steps, True, "exp", True), steps,
                      "auto"))
        cases.append((f"exp, f jit, steps = N = {steps}", model(steps, True, "exp"), steps, "auto"))
        cases.append((f"exp, f jit, Python loop, N = {steps}", model(steps, True, "exp"), steps,
                      "python"))
        cases.append((f"exp, f Python, steps = N = {steps}", model(steps, False, "exp"), steps,
                      "auto"))
    for kernel in ("direct", "fft"):
        cases.append((f"{kernel} kernel callback, f jit, N = {args.callback_steps}",
                      model(args.callback_steps, True, kernel), args.callback_steps, "auto"))
    cases = [c for c in cases if args.cases is None or args.cases in c[0]]
    for _, make, steps, engine in cases:   # compile the jit=True callbacks and the loop first
        plain(make, P0, 2)
        sensitivities(make, P0, 2, engine=engine)
        if base is not None:
            base.sensitivities(make, P0, 2, engine=engine)
    # short cases repeated within each timing (at least about 50 ms of CPU), the time of one call
    reps = {name: max(1, min(50, int(0.05 / max(cpu(lambda: differences(make, P0, steps, False)),
                                                1e-4))))
            for name, make, steps, _ in cases}

    def timed(name, f):
        return cpu(lambda: [f() for _ in range(reps[name])]) / reps[name]
    best: dict = {}
    for _ in range(args.rounds):
        for name, make, steps, engine in cases:
            times = {"run": timed(name, lambda: plain(make, P0, steps)),
                     "sens": timed(name, lambda: sensitivities(make, P0, steps, engine=engine)),
                     "fwd": timed(name, lambda: differences(make, P0, steps, False)),
                     "central": timed(name, lambda: differences(make, P0, steps, True))}
            if base is not None:
                times["base"] = timed(name, lambda: base.sensitivities(make, P0, steps,
                                                                       engine=engine))
            old = best.get(name, {})
            best[name] = {k: min(v, old.get(k, np.inf)) for k, v in times.items()}
    print(f"P = {P} parameters; CPU seconds, fastest of {args.rounds} rounds")
    print(f"{'case':44} {'run':>8} {'sens':>8} {'fwd (P+1)':>10} {'central':>8} "
          f"{'sens/run':>9} {'/(1+P)':>7} {'sens/fwd':>9} {'central/sens':>12}"
          + (f" {'sens (base)':>11} {'base/sens':>9}" if base is not None else ""))
    for name, t in best.items():
        print(f"{name:44} {t['run']:8.4f} {t['sens']:8.4f} {t['fwd']:10.4f} {t['central']:8.4f} "
              f"{t['sens'] / t['run']:9.1f} {t['sens'] / t['run'] / (1 + P):7.2f} "
              f"{t['sens'] / t['fwd']:9.2f} {t['central'] / t['sens']:12.2f}"
              + (f" {t['base']:11.4f} {t['base'] / t['sens']:9.2f}" if base is not None else ""))
    # one Gauss-Newton iteration of the gallery's fit: its Jacobian (a sensitivity run) and a
    # residual run, against the P + 1 runs a forward-difference iteration needs
    gallery = model(1200, False, "exp")
    s = gallery(P0)
    s.init()
    t, U = s.run(1200)
    data = [_check_record(Record(t[::2], U[::2, 0]), 0, 2)]
    problems = {"this": _Problem([gallery], P0.copy(), np.ones(P, bool), data, None)}
    if base is not None:
        problems["base"] = base.fitting._Problem([gallery], P0.copy(), np.ones(P, bool), data, None)
    gn = {k: np.inf for k in problems}
    fwd = np.inf

    def iteration(problem):
        # forget what the problem has computed (a Jacobian at a point it has seen would be
        # reused): its Cache now, the attribute _cache before
        if hasattr(problem, "cache"):
            problem.cache = type(problem.cache)(1)
        else:
            problem._cache = None
        problem.residuals(P0 * 1.01)
        problem.jacobian(P0 * 1.02)
    for _ in range(args.rounds):
        for key, problem in problems.items():
            gn[key] = min(gn[key], cpu(lambda: iteration(problem)))
        fwd = min(fwd, cpu(lambda: [problems["this"].residuals(P0 * (1 + 1e-6 * j))
                                    for j in range(P + 1)]))
    print(f"Gauss-Newton iteration (gallery model, Python f, 1200 steps): {gn['this']:.3f} s; "
          f"P + 1 = {P + 1} residual runs {fwd:.3f} s; ratio {gn['this'] / fwd:.2f}"
          + (f"; baseline {gn['base']:.3f} s, ratio {gn['base'] / fwd:.2f}" if base is not None else ""))

if __name__ == "__main__":
    main()
