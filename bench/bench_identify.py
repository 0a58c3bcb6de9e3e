#!/usr/bin/env python3
# The cost of dmi.identify.sensitivities (a benchmark, not a test) against the runs it replaces:
# a plain run, a forward-difference Jacobian (P + 1 runs) and a central one (2P + 1 runs).
# The model: a friction oscillator with a viscoelastic memory of two Prony terms on the velocity,
#   w'' + k w + mu sigma(w') + int_0^tau (c1 e^{a1 s} + c2 e^{a2 s}) w'(t - s) ds + g cos 0.8 t ∋ 0,
# w = w0 on t <= 0, P = 8 parameters (k, g: f; mu: friction; w0: history; c1, a1, c2, a2: kernel),
# tau = N h, N = steps.  Variants: f with jit=True (compiled: the sensitivities' compiled loop) or a
# Python function (their Python loop); the history a Python function, or jit=True as well ("all
# jit"); the kernel as exponentials (RECURSIVE) or as a Python callback (DIRECT, FFT; shorter
# runs); "f jit, Python loop" times the Python loop on the compiled model.  Then one
# Gauss-Newton iteration of the gallery's fit (plot_identify_friction_memory.py: one sensitivity
# run and one residual run) against the P + 1 runs it needs.
# Rounds interleave the variants; the fastest round of each counts; CPU times of the process (the
# machine may be shared); one BLAS thread.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_identify.py [--rounds 2]
#        [--steps 1000 100000] [--callback-steps 2000]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import math  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from benchtools import cpu, positive_int  # noqa: E402
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
    args = ap.parse_args()
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
    for _, make, steps, engine in cases:   # compile the jit=True callbacks and the loop first
        plain(make, P0, 2)
        sensitivities(make, P0, 2, engine=engine)
    best: dict = {}
    for _ in range(args.rounds):
        for name, make, steps, engine in cases:
            times = {"run": cpu(lambda: plain(make, P0, steps)),
                     "sens": cpu(lambda: sensitivities(make, P0, steps, engine=engine)),
                     "fwd": cpu(lambda: differences(make, P0, steps, False)),
                     "central": cpu(lambda: differences(make, P0, steps, True))}
            old = best.get(name, {})
            best[name] = {k: min(v, old.get(k, np.inf)) for k, v in times.items()}
    print(f"P = {P} parameters; CPU seconds, fastest of {args.rounds} rounds")
    print(f"{'case':44} {'run':>8} {'sens':>8} {'fwd (P+1)':>10} {'central':>8} "
          f"{'sens/run':>9} {'/(1+P)':>7} {'sens/fwd':>9} {'central/sens':>12}")
    for name, t in best.items():
        print(f"{name:44} {t['run']:8.4f} {t['sens']:8.4f} {t['fwd']:10.4f} {t['central']:8.4f} "
              f"{t['sens'] / t['run']:9.1f} {t['sens'] / t['run'] / (1 + P):7.1f} "
              f"{t['sens'] / t['fwd']:9.2f} {t['central'] / t['sens']:12.2f}")
    # one Gauss-Newton iteration of the gallery's fit: its Jacobian (a sensitivity run) and a
    # residual run, against the P + 1 runs a forward-difference iteration needs
    gallery = model(1200, False, "exp")
    s = gallery(P0)
    s.init()
    t, U = s.run(1200)
    data = [_check_record(Record(t[::2], U[::2, 0]), 0, 2)]
    problem = _Problem([gallery], P0.copy(), np.ones(P, bool), data, None)
    gn, fwd = np.inf, np.inf

    def iteration():
        problem._cache = None            # (a Jacobian at a point it has seen would be reused)
        problem.residuals(P0 * 1.01)
        problem.jacobian(P0 * 1.02)
    for _ in range(args.rounds):
        gn = min(gn, cpu(iteration))
        fwd = min(fwd, cpu(lambda: [problem.residuals(P0 * (1 + 1e-6 * j)) for j in range(P + 1)]))
    print(f"Gauss-Newton iteration (gallery model, Python f, 1200 steps): {gn:.3f} s; P + 1 = {P + 1} "
          f"residual runs {fwd:.3f} s; ratio {gn / fwd:.1f}")


if __name__ == "__main__":
    main()
