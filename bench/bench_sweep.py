#!/usr/bin/env python3
# The sweep's throughput with 1 and 2 local workers in one run, and its time per
# point against a bare fmpy FMU2Slave loop over the same point.
# Usage: bench/bench_sweep.py [--fmu FMU] [--points P] [--stop-time T] [--N N] [--repeat R]
#   (--help says what each means; needs dmi_sweep importable: .venv after
#   scripts/deps.sh, or PYTHONPATH=python)
# Each LocalCluster is started and warmed up (FMU shipped, unpacked and
# instantiated on every worker) before the clock starts: the figures are the
# sweep's, not Dask's start-up, which is printed separately.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import logging
import math
import os
import tempfile
import time
from pathlib import Path

from distributed import Client, LocalCluster
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

from dmi_sweep import run as sweep_run
from dmi_sweep.cli import positive_int
from dmi_sweep.simulate import FMUPlugin, Runner, communication_plan, in_window
from dmi_sweep.spec import SpecError, load

ROOT = Path(__file__).resolve().parents[1]
SPEC = """fmu = "{fmu}"
stop_time = {T}
output_interval = 0.01
transient = {transient}
outputs = ["w", "v", "friction", "delay_force", "sticking"]
[start]
N = {N}
[grid]
g_amp = {{ start = 0.5, stop = 3.0, num = {P} }}
"""


class Bare:
    """A plain FMU2Slave loop: one instance, reset between points, doStep over simulate_fmu's
    communication points, the outputs read in [transient, T]."""

    def __init__(self, fmu_path: str, N: int, T: float, transient: float):
        md = read_model_description(fmu_path)
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.fmu = FMU2Slave(guid=md.guid, unzipDirectory=extract(fmu_path),
                             modelIdentifier=md.coSimulation.modelIdentifier)
        self.fmu.instantiate()
        self.N, self.T, self.transient = N, T, transient
        self.times = [t for t, _, _ in communication_plan(0.0, T, 0.01, True, [])]

    def point(self, g: float) -> None:
        fmu, vr = self.fmu, self.vr
        reals = [vr[n] for n in ("w", "v", "friction", "delay_force")]
        sticking = [vr["sticking"]]
        fmu.reset()
        fmu.setupExperiment(startTime=0.0, stopTime=self.T)
        fmu.enterInitializationMode()
        fmu.setInteger([vr["N"]], [self.N])
        fmu.setReal([vr["g_amp"]], [g])
        fmu.exitInitializationMode()
        t = 0.0
        for tn in self.times:
            fmu.doStep(t, tn - t)
            t = tn
            if in_window(t, self.transient):
                fmu.getReal(reals)
                fmu.getBoolean(sticking)
        fmu.terminate()


def interleaved(spec_path: Path, g_amps: list[float]) -> tuple[float, float]:
    """Seconds per point of the bare loop and of the sweep's worker code (Runner, in this process),
    point by point in alternation so that machine load hits both alike."""
    spec = load(spec_path)
    bare = Bare(str(spec.fmu), spec.start["N"], spec.stop_time, spec.transient)
    runner = Runner(extract(str(spec.fmu)))
    job = spec.job()
    tb = tr = 0.0
    for g in g_amps:
        t0 = time.perf_counter()
        bare.point(g)
        t1 = time.perf_counter()
        r = runner.run(job, {"g_amp": g})
        t2 = time.perf_counter()
        assert r["error"] is None
        tb += t1 - t0
        tr += t2 - t1
    return tb / len(g_amps), tr / len(g_amps)


def bare_points(fmu_path: str, N: int, T: float, transient: float, g_amps: list[float]) -> float:
    """Wall-clock and CPU seconds per point of the bare loop over g_amps (run in a Dask worker by
    timed_sweep)."""
    bare = Bare(fmu_path, N, T, transient)
    bare.point(g_amps[0])
    t0, c0 = time.perf_counter(), time.process_time()
    for g in g_amps:
        bare.point(g)
    return (time.perf_counter() - t0) / len(g_amps), (time.process_time() - c0) / len(g_amps)


def timed_sweep(spec_path: Path, workers: int, work: Path, bare_g: list[float]):
    """Start-up seconds, sweep seconds of the sweep on a warmed-up LocalCluster of `workers`, the
    CPU seconds it took (workers, and this process: client and scheduler), and the bare loop's
    (wall, CPU) seconds per point in one of its workers just before and just after the sweep."""
    t0 = time.perf_counter()
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                      scheduler_kwargs={"dashboard_address": "127.0.0.1:0"}, host="127.0.0.1",
                      silence_logs=logging.ERROR) as cluster, Client(cluster) as client:
        warm = load(spec_path)
        warm.values = warm.values[: 2 * workers]      # two points per worker: ship, unpack, instantiate
        # registered here, the plugin stays for the timed sweep (run() removes only its own)
        client.register_plugin(FMUPlugin(warm.fmu.read_bytes(), warm.sha256))
        sweep_run.run(warm, work / f"warm{workers}", scheduler=cluster.scheduler_address,
                      chunk_size=1, progress=None)
        startup = time.perf_counter() - t0
        spec = load(spec_path)
        args = (str(spec.fmu), spec.start["N"], spec.stop_time, spec.transient, bare_g)
        before = client.submit(bare_points, *args, pure=False).result()
        cpu_w0, cpu_c0 = sum(client.run(time.process_time).values()), time.process_time()
        t1 = time.perf_counter()
        s = sweep_run.run(spec, work / f"w{workers}", scheduler=cluster.scheduler_address, progress=None)
        seconds = time.perf_counter() - t1
        cpu_c = time.process_time() - cpu_c0
        cpu_w = sum(client.run(time.process_time).values()) - cpu_w0
        print(f"  {workers} worker(s): CPU seconds in the workers {cpu_w:.2f}, in the client and scheduler {cpu_c:.2f}")
        cpu = cpu_w + cpu_c
        after = client.submit(bare_points, *args, pure=False).result()
        assert s.computed == spec.n_points and s.failed == 0
        return startup, seconds, cpu, (before, after)


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not 0 < value < math.inf:
        raise argparse.ArgumentTypeError(f"{text!r} is not a finite number > 0")
    return value


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(
        description="Benchmark of dmi-sweep (not a test): a sweep of --points values of g_amp over "
                    "[0.5, 3] (Example 4.3, output interval 0.01, statistics over [T/2, T]) on a "
                    "LocalCluster of 1 and of 2 workers, and a bare fmpy FMU2Slave loop over the same "
                    "points. Prints the points per second with 1 and 2 workers and their ratio, the "
                    "time per point of the sweep against the bare loop (overhead in %), the CPU "
                    "seconds of the workers, client and scheduler, and the load average. Exit status: "
                    "0; 2 for a bad argument.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--fmu", default=str(ROOT / "build" / "fmu" / "DelayFrictionOscillator.fmu"),
                    help="the FMU to sweep (FMI 2.0 co-simulation, the oscillator's variables)")
    ap.add_argument("--points", type=positive_int, default=48, help="points of the sweep (values of g_amp)")
    ap.add_argument("--stop-time", type=positive_float, default=60.0, metavar="T",
                    help="simulated time per point in s; the statistics are over [T/2, T]")
    ap.add_argument("--N", type=positive_int, default=9991, help="the FMU's N: solver steps per unit time")
    ap.add_argument("--repeat", type=positive_int, default=1,
                    help="pairs of 1- and 2-worker sweeps, alternating")
    return ap


def main():
    ap = parser()
    a = ap.parse_args()
    if not os.path.isfile(a.fmu):
        ap.error(f"--fmu {a.fmu!r}: no such file (build the project first)")
    a.fmu = str(Path(a.fmu).resolve())    # the spec is written into a temporary folder
    T, transient = a.stop_time, a.stop_time / 2
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        spec_path = work / "spec.toml"
        spec_path.write_text(SPEC.format(fmu=a.fmu, T=T, transient=transient, N=a.N, P=a.points))
        try:
            g_amps = [float(x) for x in load(spec_path).values[:, 0]]
        except SpecError as e:           # the FMU refuses a value (N too large, say)
            ap.error(f"the FMU {a.fmu} refuses the sweep: {e}")
        print(f"sweep: {a.points} points of g_amp, N = {a.N}, T = {T:g}, output interval 0.01, "
              f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f} at start")
        bare1, runner1 = interleaved(spec_path, g_amps[::4])
        pairs = []
        for r in range(a.repeat):
            start1, t1, cpu1, ((wb1, cb1), (wb2, cb2)) = timed_sweep(spec_path, 1, work / f"r{r}", g_amps[1::6])
            start2, t2, cpu2, _ = timed_sweep(spec_path, 2, work / f"r{r}", g_amps[1::6])
            p1, p2 = a.points / t1, a.points / t2
            pairs.append((p1, p2, t1, wb1, wb2))
            print(f"1 worker : {p1:7.3f} points/s ({t1:.2f} s; cluster start and warm-up {start1:.1f} s)")
            print(f"2 workers: {p2:7.3f} points/s ({t2:.2f} s; cluster start and warm-up {start2:.1f} s)")
            print(f"ratio 2/1 workers: {p2 / p1:.2f}")
            wb = (wb1 + wb2) / 2
            print(f"per point, in the worker: bare loop {wb * 1e3:.1f} ms (just before the sweep "
                  f"{wb1 * 1e3:.1f}, just after {wb2 * 1e3:.1f}); the whole sweep on 1 worker (Dask, "
                  f"Parquet, progress) {t1 / a.points * 1e3:.1f} ms: overhead {100 * (t1 / a.points / wb - 1):+.1f} %")
            cb = (cb1 + cb2) / 2
            print(f"CPU time per point: bare loop {cb * 1e3:.1f} ms; the sweep (worker, client, scheduler) "
                  f"{cpu1 / a.points * 1e3:.1f} ms with 1 worker ({100 * (cpu1 / a.points / cb - 1):+.1f} %), "
                  f"{cpu2 / a.points * 1e3:.1f} ms with 2 ({100 * (cpu2 / a.points / cb - 1):+.1f} %)")
        bare2, runner2 = interleaved(spec_path, g_amps[2::4])
        bare, runner = (bare1 + bare2) / 2, (runner1 + runner2) / 2
        print(f"per point, in this process, alternating: bare FMU2Slave loop {bare * 1e3:.1f} ms, the "
              f"sweep's worker code {runner * 1e3:.1f} ms: overhead {100 * (runner / bare - 1):+.1f} % "
              f"(first half {100 * (runner1 / bare1 - 1):+.1f} %, second half {100 * (runner2 / bare2 - 1):+.1f} %)")
        if a.repeat > 1:
            ratios = sorted(p2 / p1 for p1, p2, *_ in pairs)
            print(f"ratios 2/1 workers over {a.repeat} pairs: " + ", ".join(f"{x:.2f}" for x in ratios))
        print(f"load average {os.getloadavg()[0]:.2f} at the end")


if __name__ == "__main__":
    main()
