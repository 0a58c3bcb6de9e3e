#!/usr/bin/env python3
# Benchmark of the FMU (issue 13; not a test): an fmpy FMU2Slave loop with
# communication step 0.01 over Example 4.3 at N = 1000 and N = 100000 (the
# kernel as exponential terms: the recursion), alternating in rounds so that
# machine load hits both alike; the fastest round counts.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import argparse
import os
import shutil
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_FMU = os.path.join(HERE, "..", "build", "fmu", "DelayFrictionOscillator.fmu")


def positive(text: str) -> float:
    value = float(text)
    if not value > 0 or value == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def count(text: str) -> int:
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return int(text)


def one_run(md, unzipdir: str, N: int, T: float, dt: float) -> float:
    """Seconds of the doStep loop of one instance from 0 to T."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setInteger([vr["N"]], [N])
    fmu.exitInitializationMode()
    steps = round(T / dt)
    t0 = time.perf_counter()
    for k in range(steps):
        fmu.doStep(k * dt, dt)
    secs = time.perf_counter() - t0
    fmu.terminate()
    fmu.freeInstance()
    return secs


def main() -> int:
    ap = argparse.ArgumentParser(
        description="Times the FMU's FMU2Slave loop (fmpy, communication step 0.01) on Example "
                    "4.3 at N = 1000 and N = 100000 and prints the time per communication step "
                    "and per solver step h = 1/N, and the ratio of the two N per solver step.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--fmu", default=DEFAULT_FMU, help="the FMU file")
    ap.add_argument("--time", type=positive, default=10.0,
                    help="simulated time per round (seconds of model time)")
    ap.add_argument("--rounds", type=count, default=3, help="rounds of both runs; the fastest counts")
    args = ap.parse_args()
    if not os.path.isfile(args.fmu):
        ap.error(f"--fmu {args.fmu}: no such file (build the project first)")
    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    dt = 0.01
    try:
        best = {}
        for _ in range(args.rounds):
            for N in (1000, 100000):
                s = one_run(md, unzipdir, N, args.time, dt)
                best[N] = min(best.get(N, s), s)
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)
    comm = round(args.time / dt)
    print(f"FMU2Slave loop, communication step {dt}, T = {args.time} per round, "
          f"best of {args.rounds} rounds")
    print(f"{'N':>7} | {'us per doStep':>14} | {'ns per solver step':>18}")
    per_h = {}
    for N, s in best.items():
        per_h[N] = 1e9 * s / (comm * N * dt)
        print(f"{N:>7} | {1e6 * s / comm:>14.1f} | {per_h[N]:>18.1f}")
    print(f"N = 100000 over N = 1000, per solver step: {per_h[100000] / per_h[1000]:.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
