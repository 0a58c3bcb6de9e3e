#!/usr/bin/env python3
# The Python binding's speed (a benchmark, not a test): Example 4.3
# at N = 1e4 with its kernel as exponential terms and the built-in friction,
# the right-hand side as a numba cfunc, as a Python function and as that same
# function compiled with set_rhs(..., jit=True), against the C
# program bench_binding (the rhs in C) and a plain NumPy implementation of the
# scheme as a user would write it (direct delay sum).  Rounds interleave the
# five; the fastest round of each counts; CPU times of the process (the
# machine may be shared).  Needs dmi importable (.venv after scripts/deps.sh,
# or PYTHONPATH=<build>/python) and numba.  The C program runs with the
# binding's libdmi.so.1 (LD_LIBRARY_PATH), so both time the same library.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import math
import os
import subprocess
import time
from pathlib import Path
from benchtools import positive_int

ROOT = Path(__file__).resolve().parents[1]


def program(text: str) -> str:
    path = Path(text)
    if not (path.is_file() and os.access(path, os.X_OK)):
        raise argparse.ArgumentTypeError(f"{text!r} is not an executable file (build bench_binding: "
                                         "cmake --build build --target bench_binding)")
    return text


def parse() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description="Times Example 4.3 (N = 1e4, exponential kernel, "
                                 "friction) through the Python binding with a numba cfunc rhs and "
                                 "a Python rhs (also compiled with jit=True), beside the C program "
                                 "bench_binding and plain NumPy; prints ns per step and the ratios "
                                 "to C.")
    ap.add_argument("--N", type=positive_int, default=10000, help="steps per delay, h = 1/N (default: 10000)")
    ap.add_argument("--steps", type=positive_int, default=1000000,
                    help="steps of the C, numba and jit=True runs (default: 1000000)")
    ap.add_argument("--python-steps", type=positive_int, default=30000,
                    help="steps of the Python-rhs and NumPy runs (default: 30000)")
    ap.add_argument("--rounds", type=positive_int, default=7, help="interleaved rounds (default: 7)")
    ap.add_argument("--c-program", type=program, default=str(ROOT / "build" / "bench" / "bench_binding"),
                    help="the C program (default: build/bench/bench_binding)")
    return ap.parse_args()


def c_run(program: str, N: int, steps: int) -> tuple[float, list[float]]:
    """ns per step and the final state of the C program, run with the binding's own libdmi."""
    import dmi
    env = dict(os.environ, LD_LIBRARY_PATH=str(Path(dmi.__file__).parent))  # before its RUNPATH
    out = subprocess.run([program, str(N), str(steps)], capture_output=True, text=True, check=True,
                         env=env)
    lines = out.stdout.split("\n")
    return float(lines[0].split()[1]), [float(x) for x in lines[1].split()]


def solver(N: int, rhs, jit: bool = False):
    import dmi
    s = dmi.Solver(2, 1.0, N)
    s.set_rhs(rhs, jit=jit)
    s.set_friction([0.0, 1.0])
    s.set_kernel_exp([0.0, 0.0, 0.0], [2 * math.pi, 10 * math.pi, 20 * math.pi],
                     [[[0.0, 0.0], [1.0, 0.0]]] * 3)
    s.init()
    return s


def timed_advance(N: int, rhs, steps: int, jit: bool = False) -> tuple[float, list[float]]:
    s = solver(N, rhs, jit)
    t0 = time.process_time()
    s.advance(steps)
    return 1e9 * (time.process_time() - t0) / steps, list(s.state)


def numpy_run(N: int, steps: int) -> tuple[float, list[float]]:
    """The scheme (3.12)-(3.13) for Example 4.3 in plain NumPy, the delay sum directly."""
    import numpy as np
    t0 = time.process_time()
    h = 1.0 / N
    s = np.arange(N) * h
    Hs = np.cos(2 * np.pi * s) + np.cos(10 * np.pi * s) + np.cos(20 * np.pi * s)
    w = np.zeros(N + steps + 1)  # w[N + p] = w^p, zero history
    v = 0.0
    for p in range(steps):
        W = h * np.dot(Hs, w[p + 1:N + p + 1][::-1])
        x = v - h * (w[N + p] + 1.3 * math.cos(8 * p * h)) - h * W
        w[N + p + 1] = w[N + p] + h * v
        v = math.copysign(max(abs(x) - h, 0.0), x)
    return 1e9 * (time.process_time() - t0) / steps, [w[N + steps], v]


def main() -> None:
    args = parse()
    import numba
    import numpy as np

    import dmi

    @numba.cfunc(dmi.RHS_SIGNATURE)
    def rhs_numba(t, u, out, user):
        out[0] = -u[1]
        out[1] = u[0] + 1.3 * math.cos(8 * t)
        return 0

    def rhs_python(t, u):
        return np.array([-u[1], u[0] + 1.3 * math.cos(8 * t)])

    N, big, small = args.N, args.steps, args.python_steps
    best = {"C": math.inf, "numba": math.inf, "jit": math.inf, "Python": math.inf, "NumPy": math.inf}
    for _ in range(args.rounds):
        ns, c_state = c_run(args.c_program, N, big)
        best["C"] = min(best["C"], ns)
        ns, nb_state = timed_advance(N, rhs_numba, big)
        best["numba"] = min(best["numba"], ns)
        ns, jit_state = timed_advance(N, rhs_python, big, jit=True)  # compiled once (cached)
        best["jit"] = min(best["jit"], ns)
        ns, py_state = timed_advance(N, rhs_python, small)
        best["Python"] = min(best["Python"], ns)
        ns, np_state = numpy_run(N, small)
        best["NumPy"] = min(best["NumPy"], ns)
    print(f"Example 4.3, N = {N}, kernel as 3 exponential terms (recursion), friction; "
          f"best of {args.rounds} interleaved rounds, CPU time")
    print(f"dmi {dmi.version()} ({Path(dmi.__file__).parent / 'libdmi.so.1'}, also for the C "
          f"program), numba {numba.__version__}, numpy {np.__version__}")
    print(f"{'rhs':<28} {'steps':>9} {'ns/step':>10} {'x C':>8}")
    rows = [("C (bench_binding)", "C", big), ("numba cfunc (dmi.Solver)", "numba", big),
            ("Python function, jit=True", "jit", big),
            ("Python function (dmi.Solver)", "Python", small), ("plain NumPy scheme", "NumPy", small)]
    for label, key, steps in rows:
        print(f"{label:<28} {steps:>9} {best[key]:>10.1f} {best[key] / best['C']:>7.2f}x")
    dev_nb = max(abs(a - b) for a, b in zip(nb_state, c_state))
    dev_np = max(abs(a - b) for a, b in zip(np_state, py_state))
    print(f"final state: numba - C {dev_nb:.1e} (after {big} steps), NumPy - Python rhs {dev_np:.1e} "
          f"(after {small} steps)")
    dev_jit = max(abs(a - b) for a, b in zip(jit_state, nb_state))
    print(f"final state: jit=True - numba cfunc {dev_jit:.1e} (after {big} steps)")
    print(f"numba / C = {best['numba'] / best['C']:.2f} (target <= 1.2)")
    print(f"jit=True / numba cfunc = {best['jit'] / best['numba']:.2f} (target <= 1.3), "
          f"Python / jit=True = {best['Python'] / best['jit']:.1f} (target >= 20)")


if __name__ == "__main__":
    main()
