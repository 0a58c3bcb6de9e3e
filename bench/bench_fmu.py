#!/usr/bin/env python3
# Benchmark of the FMU (not a test): an fmpy FMU2Slave loop with
# communication step 0.01 over Example 4.3 at N = 1e3, 1e4, 1e5, 1e6 (the
# kernel as exponential terms: the recursion), alternating in rounds so that
# machine load hits each N alike; the fastest round counts.  Then the same
# loop from C without Python (bench/bench_fmu_loop.c, run by this script), so
# that the FMU's own cost per solver step shows beside Python's per call.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import argparse
import os
import shutil
import subprocess
import sys
import time

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_FMU = os.path.join(HERE, "..", "build", "fmu", "DelayFrictionOscillator.fmu")
DEFAULT_LOOP = os.path.join(HERE, "..", "build", "bench", "bench_fmu_loop")
NS = (1000, 10000, 100000, 1000000)


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
    """CPU seconds of the doStep loop of one instance from 0 to T."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                    modelIdentifier=md.coSimulation.modelIdentifier, instanceName="bench")
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    fmu.setInteger([vr["N"]], [N])
    fmu.exitInitializationMode()
    steps = round(T / dt)
    t0 = time.process_time()
    for k in range(steps):
        fmu.doStep(k * dt, dt)
    secs = time.process_time() - t0
    fmu.terminate()
    fmu.freeInstance()
    return secs


def c_loop(loop: str, T: float, rounds: int, binary: str) -> dict:
    """{N: (us per doStep, ns per solver step)} of bench_fmu_loop's table."""
    out = subprocess.run([loop, repr(T), str(rounds), binary], capture_output=True, text=True,
                         check=True).stdout
    rows = {}
    for line in out.splitlines():
        cells = [c.strip() for c in line.split("|")]
        if cells[0].isdigit():
            rows[int(cells[0])] = (float(cells[1]), float(cells[2]))
    if sorted(rows) != sorted(NS):
        raise RuntimeError(f"{loop}: unexpected output:\n{out}")
    return rows


def main() -> int:
    ap = argparse.ArgumentParser(
        description="Times the FMU's FMU2Slave loop (fmpy, communication step 0.01) on Example "
                    "4.3 at N = 1e3, 1e4, 1e5 and 1e6, then the same loop from C without Python "
                    "(bench_fmu_loop), and prints for both the time per communication step "
                    "(doStep) and per solver step h = 1/N, and each N over N = 1e3 per solver "
                    "step. CPU times of the process, the fastest round for each N.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--fmu", default=DEFAULT_FMU, help="the FMU file (FMI 2.0)")
    ap.add_argument("--loop", default=DEFAULT_LOOP, help="the C loop, bench_fmu_loop")
    ap.add_argument("--time", type=positive, default=10.0,
                    help="simulated time per round (seconds of model time)")
    ap.add_argument("--rounds", type=count, default=3, help="rounds over every N; the fastest counts")
    args = ap.parse_args()
    if not os.path.isfile(args.fmu):
        ap.error(f"--fmu {args.fmu}: no such file (build the project first)")
    if not os.access(args.loop, os.X_OK):
        ap.error(f"--loop {args.loop}: no such program (build the project first)")
    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    dt = 0.01
    try:
        best = {}
        for _ in range(args.rounds):
            for N in NS:
                s = one_run(md, unzipdir, N, args.time, dt)
                best[N] = min(best.get(N, s), s)
        binary = os.path.join(unzipdir, "binaries", "linux64", md.coSimulation.modelIdentifier + ".so")
        c = c_loop(args.loop, args.time, args.rounds, binary)
    finally:
        shutil.rmtree(unzipdir, ignore_errors=True)
    comm = round(args.time / dt)
    print(f"Communication step {dt}, T = {args.time} per round, best of {args.rounds} rounds "
          f"(CPU time); the C loop after the Python one")
    print(f"{'':>7} | {'fmpy FMU2Slave loop (Python)':^44} | {'C loop (bench_fmu_loop)':^44}")
    print(f"{'N':>7} | {'us/doStep':>10} {'ns/solver step':>15} {'vs N=1e3':>16} | "
          f"{'us/doStep':>10} {'ns/solver step':>15} {'vs N=1e3':>16}")
    py = {N: (1e6 * s / comm, 1e9 * s / (comm * N * dt)) for N, s in best.items()}
    for N in NS:
        print(f"{N:>7} | {py[N][0]:>10.2f} {py[N][1]:>15.1f} {py[N][1] / py[NS[0]][1]:>15.2f}x | "
              f"{c[N][0]:>10.2f} {c[N][1]:>15.1f} {c[N][1] / c[NS[0]][1]:>15.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())
