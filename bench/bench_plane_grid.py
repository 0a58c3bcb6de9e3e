#!/usr/bin/env python3
# dmi.analysis.continue_over's cost on Dask (a benchmark, not a test).
# 1. The per-task overhead: T tasks that do no work (branches(q) returns no branch) through a Dask
#    LocalCluster of W processes, against the same in this process; wall-clock time a task, the
#    fastest of the rounds (the cluster started once, outside the timing; its start-up reported
#    apart).
# 2. A real grid: one equilibrium branch and one collocated orbit branch a value of q of the
#    rotationally symmetric oscillator with a memory (tests/python/models/hopf_models.py), Q values,
#    serially and on the cluster, interleaved; wall-clock time, the speed-up, and the load of the
#    machine (os.getloadavg) before each round.
# Usage: bench/bench_plane_grid.py [--workers W] [--tasks T] [--q Q] [--rounds R]
#        (needs dmi importable: PYTHONPATH=<build>/python; distributed)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from dmi import analysis as da

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
try:
    from models import hopf_models
except ImportError:
    import hopf_models

W0, TAU, C1, C2 = 1.0, 2.0, 1.0, -1.0


def nothing(q: float) -> dict:
    return {}


def circle_branches(G: float) -> dict:
    """The rest of the symmetric oscillator from mu = -0.5 to 0.6 and the orbits born at its Hopf
    point, continued down through their fold."""
    make = lambda mu: hopf_models.circle_solver(complex(mu, W0), C1, C2, G, TAU, 100, False)  # noqa: E731
    rest = da.continue_equilibrium(da.equilibrium(make, -0.5, [0.0, 0.0], of="equation"), 0.6,
                                   step=0.1)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    orbit = da.hopf_orbit(make, h.hopf, h.u, amplitude=0.01, of="equation")
    return {"rest": rest, "orbits": da.continue_orbit(orbit, -0.5, step=0.02)}


def timed(fn) -> float:
    t = time.perf_counter()
    fn()
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description="Prints continue_over's per-task overhead on a Dask "
                                 "LocalCluster against one process, and a real grid's time serially "
                                 "and on the cluster with the machine's load.")
    ap.add_argument("--workers", type=int, default=2, help="cluster processes (default: 2)")
    ap.add_argument("--tasks", type=int, default=200, help="empty tasks timed (default: 200)")
    ap.add_argument("--q", type=int, default=4, help="values of q in the real grid (default: 4)")
    ap.add_argument("--rounds", type=int, default=3, help="rounds, the fastest kept (default: 3)")
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    warnings.simplefilter("ignore")
    t0 = time.perf_counter()
    cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                           dashboard_address=None, host="127.0.0.1")
    client = Client(cluster)
    print(f"LocalCluster of {a.workers} processes started in {time.perf_counter() - t0:.2f} s; "
          f"{os.cpu_count()} cores")
    try:
        qs = np.arange(a.tasks) * 1e-3
        client.submit(nothing, 0.0).result()        # the workers import dmi once
        da.continue_over([0.0], nothing, client=client)
        over, serial = [], []
        for r in range(a.rounds):
            load = os.getloadavg()[0]
            over.append(timed(lambda: da.continue_over(qs, nothing, client=client)) / a.tasks)
            serial.append(timed(lambda: da.continue_over(qs, nothing)) / a.tasks)
            print(f"round {r}: load {load:.1f}: {a.tasks} empty tasks: {1e3 * over[-1]:.2f} ms a "
                  f"task on the cluster, {1e6 * serial[-1]:.1f} us in this process")
        print(f"per-task overhead (fastest of {a.rounds}): {1e3 * min(over):.2f} ms on the cluster,"
              f" {1e6 * min(serial):.1f} us serially")
        Gs = np.linspace(0.3, 0.6, a.q)
        ts, td = [], []
        for r in range(a.rounds):
            load = os.getloadavg()[0]
            ts.append(timed(lambda: da.continue_over(Gs, circle_branches)))
            td.append(timed(lambda: da.continue_over(Gs, circle_branches, client=client)))
            print(f"round {r}: load {load:.1f}: {a.q} rows of the symmetric oscillator: serial "
                  f"{ts[-1]:.2f} s ({ts[-1] / a.q:.2f} s a row), cluster {td[-1]:.2f} s: "
                  f"speed-up {ts[-1] / td[-1]:.2f}")
        print(f"fastest: serial {min(ts):.2f} s, cluster {min(td):.2f} s, speed-up "
              f"{min(ts) / min(td):.2f} on {a.workers} workers; the overhead is "
              f"{100 * min(over) * a.q / min(ts):.2f} % of the serial grid")
    finally:
        client.close()
        cluster.close()


if __name__ == "__main__":
    main()
