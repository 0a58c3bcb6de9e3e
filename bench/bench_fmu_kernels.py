#!/usr/bin/env python3
# The exported FMU of a weakly singular kernel (a benchmark, not a test): the
# Bagley-Torvik oscillator with dry friction of examples/fmu-fractional
# (FractionalOscillator, FMI 2.0, built by cmake in build/bench) with its
# fractional damping s^-1/2 / Gamma(1/2) as the fitted exponential sum (the
# recursion, parameter exact = false) against the same model with the exact
# kernel (exact = true: DIRECT, the FMU's only exact method), tau = 10,
# h = tau / N.  fmpy's FMU2Slave, communication steps of 0.1; rounds
# interleave the two instances, each advancing a chunk; the fastest chunk of
# each counts; CPU time of the process (the machine may be shared).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path
from benchtools import positive_int

ROOT = Path(__file__).resolve().parents[1]
TAU, COMM = 10.0, 0.1


def fmu_file(text: str) -> str:
    if not Path(text).is_file():
        raise argparse.ArgumentTypeError(f"{text!r} is not a file (build it: cmake --build build "
                                         "--target bench_fractional_fmu_package)")
    return text


def parse() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description="Times the FMU of examples/fmu-fractional (the Bagley-Torvik "
                                 "oscillator with dry friction, tau = 10) with its fitted s^-1/2 kernel "
                                 "against the same FMU with the exact kernel (DIRECT); prints ns per "
                                 "solver step of each, their ratio and the largest output difference.")
    ap.add_argument("--N", type=positive_int, nargs="+", default=[100000],
                    help="steps per tau, h = 10 / N (default: [100000])")
    ap.add_argument("--chunk", type=float, default=1.0,
                    help="time the fitted FMU advances per round, <= 10 / rounds (default: 1.0)")
    ap.add_argument("--exact-chunk", type=float, default=0.2,
                    help="time the exact FMU advances per round (default: 0.2)")
    ap.add_argument("--rounds", type=positive_int, default=5, help="interleaved rounds (default: 5)")
    ap.add_argument("--fmu", type=fmu_file,
                    default=str(ROOT / "build" / "bench" / "FractionalOscillator.fmu"),
                    help="the FMI 2.0 FMU (default: build/bench/FractionalOscillator.fmu)")
    args = ap.parse_args()
    for name in ("chunk", "exact_chunk"):
        value = getattr(args, name)
        if not (value >= COMM and value * args.rounds <= TAU + 1e-9):
            ap.error(f"--{name.replace('_', '-')} {value}: expected {COMM} <= chunk and chunk x rounds "
                     f"<= {TAU}")
    return args


class Slave:
    """One instance of the FMU, initialised with N and exact, advanced in communication steps."""

    def __init__(self, path: str, unzipdir: str, md, N: int, exact: bool) -> None:
        from fmpy.fmi2 import FMU2Slave
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipdir,
                             modelIdentifier=md.coSimulation.modelIdentifier, instanceName=path)
        self.fmu.instantiate()
        self.fmu.setInteger([self.vr["N"]], [N])
        self.fmu.setBoolean([self.vr["exact"]], [exact])
        self.fmu.setupExperiment(startTime=0.0, stopTime=TAU)
        self.fmu.enterInitializationMode()
        self.fmu.exitInitializationMode()
        self.k = 0  # communication steps taken

    def advance(self, duration: float) -> list[float]:
        """Advances by duration; the outputs w, v at each communication point."""
        rows = []
        for _ in range(round(duration / COMM)):
            self.fmu.doStep(self.k * COMM, COMM)
            self.k += 1
            rows.append(self.fmu.getReal([self.vr["w"], self.vr["v"]]))
        return rows

    def free(self) -> None:
        self.fmu.terminate()
        self.fmu.freeInstance()


def main() -> None:
    args = parse()
    from fmpy import extract, read_model_description

    md = read_model_description(args.fmu)
    unzipdir = extract(args.fmu)
    print(f"{args.fmu}: w'' + c D^1/2 w + k w + mu sigma(w') = F cos(omega t), the model's start values, "
          f"tau = {TAU}; best of {args.rounds} interleaved rounds, CPU time, fmpy, communication step {COMM}")
    print(f"{'N':>8} {'fitted ns/step':>15} {'exact ns/step':>14} {'exact/fitted':>13} "
          f"{'|fitted-exact|':>15}")
    for N in args.N:
        h = TAU / N
        fitted, exact = Slave(args.fmu, unzipdir, md, N, False), Slave(args.fmu, unzipdir, md, N, True)
        best = {"fitted": math.inf, "exact": math.inf}
        for _ in range(args.rounds):
            for name, inst, chunk in (("fitted", fitted, args.chunk), ("exact", exact, args.exact_chunk)):
                t0 = time.process_time()
                inst.advance(chunk)
                best[name] = min(best[name], 1e9 * (time.process_time() - t0) / (chunk / h))
        # the fit's effect on the outputs: both from the start over the exact run's chunk
        runs = []
        for inst, is_exact in ((fitted, False), (exact, True)):
            inst.free()
            fresh = Slave(args.fmu, unzipdir, md, N, is_exact)
            runs.append(fresh.advance(args.exact_chunk))
            fresh.free()
        dev = max(abs(x - y) for ra, rb in zip(*runs) for x, y in zip(ra, rb))
        print(f"{N:>8} {best['fitted']:>15.0f} {best['exact']:>14.0f} "
              f"{best['exact'] / best['fitted']:>13.0f} {dev:>15.1e}")
    print("target: exact/fitted >= 50 at N = 1e5")


if __name__ == "__main__":
    main()
