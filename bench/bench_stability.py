#!/usr/bin/env python3
# dmi.analysis's speed (a benchmark, not a test).
# 1. roots(count = 10) of the distributed-delay oscillator (n = 2,
#    examples/python/stability_chart.py) at N = 1e3, 1e4, 1e5, with its kernel as one exponential
#    term (the O(1) recursion) and as a general callback (numba cfunc; the FFT), against simulating
#    one delay tau (N steps, dmi_advance) of the same model in the same round: the ratio, the
#    applications of the tangent map, and the growth with N.  The rhs is a numba cfunc (C speed in
#    both).  Rounds interleave the cases; the fastest round of each counts; CPU time (the process).
# 2. A stability chart of the oscillator over (a, tau) on the local processes (--workers), the
#    same chart with verify=False (its verdicts not verified), and the same chart through a Dask
#    LocalCluster of as many workers, interleaved; wall-clock time.
# 3. The verified stability verdict (dmi.analysis.scheme.floquet) of the Stribeck belt's orbits born at
#    its Hopf point (examples/python/stribeck_belt.py: fractional damping fitted, a memory of 8
#    periods, velocity-weakening friction), at M steps a period (M = 1250: h = 0.005, N = 1e4):
#    the verdict's wall-clock time, its operator products and plain-run periods, against one
#    period's simulation.
# 4. The verified verdict of an equilibrium by default (dmi.analysis.equilibria.root_verdict): equilibrium()
#    of the oscillator with verify=True against verify=False, for the scheme (a second
#    eigen-solve) and the equation (the argument principle), at N = 1e3, 1e4 (--verify-N), CPU
#    time, the fastest of the interleaved rounds.
# Usage: bench/bench_stability.py [--N 1000 10000 100000] [--rounds R] [--chart P Q] [--chart-N N]
#        [--workers W] [--no-dask] [--chart-rounds R] [--verdict-M 200 1250] [--verify-N 1000 10000]
#        (needs dmi importable: PYTHONPATH=<build>/python; numba)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import functools
import math
import sys
import time
from pathlib import Path

import numba
import numpy as np

import dmi
from dmi import analysis
from dmi.analysis.core import model as _model

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "examples" / "python"))
from stability_chart import B, C, THETA, oscillator  # noqa: E402

A_GAIN, TAU = 1.0, 2.0


@numba.cfunc(dmi.RHS_SIGNATURE)
def rhs_c(t, u, out, user):
    out[0] = -u[1]
    out[1] = C * u[1] + B * u[0]
    return 0


@numba.cfunc(dmi.KERNEL_SIGNATURE)
def kernel_c(s, out, user):   # H(s) = [[0, 0], [a e^{-s/theta} / theta, 0]], a = 1
    out[0] = 0.0
    out[1] = 0.0
    out[2] = A_GAIN * math.exp(-s / THETA) / THETA
    out[3] = 0.0
    return 0


def model(kind: str, N: int, a: float = A_GAIN) -> dmi.Solver:
    s = dmi.Solver(2, TAU, N)
    s.set_rhs(rhs_c)
    if kind == "exp":
        s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [a / THETA, 0.0]]])
    else:
        s.set_kernel(kernel_c)
    return s


def one_tau(kind: str, N: int) -> float:
    s = model(kind, N)
    s.set_history(lambda t: np.array([1e-3, 0.0]))
    s.init()
    t0 = time.process_time()
    s.advance(N)
    return time.process_time() - t0


class Count:
    """Counts the steps of the tangent map (Linearisation.apply)."""
    def __init__(self):
        self.steps = 0
        self._apply = _model.Linearisation.apply

    def __enter__(self):
        count = self

        def apply(lin, v, steps):
            count.steps += steps
            return count._apply(lin, v, steps)
        _model.Linearisation.apply = apply
        return self

    def __exit__(self, *exc):
        _model.Linearisation.apply = self._apply


def time_roots(kind: str, N: int) -> tuple[float, float, np.ndarray]:
    with Count() as c:
        t0 = time.process_time()
        lam = analysis.roots(lambda a: model(kind, N, a), A_GAIN, [0.0, 0.0], 10)
        dt = time.process_time() - t0
    return dt, c.steps / N, lam


def bench_roots(Ns: list[int], rounds: int) -> None:
    cases = [(k, N) for N in Ns for k in ("exp", "callback")]
    best = {c: [math.inf, math.inf, 0.0, None] for c in cases}
    for _ in range(rounds):
        for c in cases:
            sim = one_tau(*c)
            dt, taus, lam = time_roots(*c)
            b = best[c]
            b[0], b[1], b[2], b[3] = min(b[0], dt), min(b[1], sim), taus, lam
    print(f"roots(count = 10), n = 2, tau = {TAU}: best of {rounds} interleaved rounds, CPU time")
    print(f"{'kernel':>8} {'N':>7} {'roots (s)':>10} {'one tau (s)':>12} {'ratio':>8} "
          f"{'tau-maps':>9} {'rightmost root':>26}")
    for (k, N), (dt, sim, taus, lam) in best.items():
        print(f"{k:>8} {N:>7} {dt:10.4f} {sim:12.6f} {dt / sim:8.1f} {taus:9.1f} "
              f"{lam[0].real:+.10f}{lam[0].imag:+.10f}j")
    for k in ("exp", "callback"):
        for N0, N1 in zip(Ns, Ns[1:]):
            g = best[(k, N1)][0] / best[(k, N0)][0]
            nlogn = N1 * math.log(N1) / (N0 * math.log(N0))
            print(f"growth {k}: N {N0} -> {N1}: x{g:.2f} (N log N: x{nlogn:.2f})")


def bench_chart(P: int, Q: int, N: int, workers: int, dask: bool, rounds: int) -> None:
    gains, delays = np.linspace(-1.5, 3.0, P), np.linspace(0.2, 8.0, Q)
    make2 = functools.partial(oscillator, N=N)
    cluster = client = None
    if dask:
        from distributed import Client, LocalCluster
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None)
        client = Client(cluster)
        client.submit(abs, -1).result()       # workers up before the clock
    import warnings
    times: dict[str, list[float]] = {"processes": [], "processes, verify=False": [], "dask": []}
    charts = {}
    try:
        for _ in range(rounds):               # interleaved: processes, unverified, Dask, each round
            for how in list(times) if dask else list(times)[:2]:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    t0 = time.perf_counter()
                    charts[how] = analysis.stability_chart(
                        make2, gains, delays, [0.0, 0.0], workers=workers,
                        client=client if how == "dask" else None, verify="verify" not in how)
                    times[how].append(time.perf_counter() - t0)
    finally:
        if client is not None:
            client.close()
            cluster.close()
    for how, ts in times.items():
        if ts:
            print(f"stability chart {P}x{Q}, N = {N}, {workers} {how}: "
                  f"{', '.join(f'{t:.1f}' for t in ts)} s wall ({1e3 * min(ts) / (P * Q):.1f} ms a "
                  f"point at best, tracing included), {len(charts[how].curves)} curves, "
                  f"{int(charts[how].undecided.sum())} cells undecided")
    ratio = min(times["processes"]) / min(times["processes, verify=False"])
    print(f"verified against verify=False: x{ratio:.2f} (best of {rounds})")
    if dask:
        print("the same grid bitwise:", np.array_equal(charts["processes"].re, charts["dask"].re))


def bench_verdict(Ms: list[int]) -> None:
    """The verdict of the belt's orbits (amplitudes 0.05 and 0.8) at each M: wall-clock time of
    floquet_verdict() at the orbit found by hopf_orbit (without multipliers), against one period."""
    import stribeck_belt as belt
    for M in Ms:
        make = belt.model(M)
        eq = analysis.equilibrium(make, 1.0, [0.3, -1.0])
        (hp,) = [e for e in analysis.continue_equilibrium(eq, 0.3, step=0.05).events
                 if e.kind == "hopf"]
        for amplitude in (0.05, 0.8):
            o = analysis.hopf_orbit(make, hp.hopf, hp.u, amplitude=amplitude, steps=M,
                                    multipliers=0)
            F = analysis.StepMap(o.make, o.p, o.steps, o.rows)
            t0 = time.perf_counter()
            F.trajectory(o.state)
            one = time.perf_counter() - t0
            t0 = time.perf_counter()
            fl = analysis.floquet_verdict(F, o.state, 10, autonomous=True)
            took = time.perf_counter() - t0
            print(f"M = {M} (N = {F.N}, state {F.dim} values), amplitude {amplitude}: verdict "
                  f"{fl.stable} in {took:.1f} s ({took / one:.0f} periods' time; one period "
                  f"{one * 1e3:.1f} ms), {fl.products} products, {fl.reason}")


def bench_verify(Ns: list[int], rounds: int) -> None:
    """equilibrium() with and without the verdict's verification, interleaved."""
    import warnings
    cases = [(k, N, of, a) for N in Ns for k in ("exp", "callback") for of in ("scheme", "equation")
             for a in ((0.5, A_GAIN) if k == "exp" else (A_GAIN,))]
    # a = 0.5: a stable point, where the count runs (the callback kernel's gain is fixed at 1)
    best: dict = {}
    for _ in range(rounds):
        for c in cases:
            k, N, of, a = c
            for verify in (False, True):
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore", UserWarning)
                    t0 = time.process_time()
                    eq = analysis.equilibrium(lambda g: model(k, N, g), a, [0.0, 0.0],
                                              of=of, verify=verify)
                    dt = time.process_time() - t0
                key = c + (verify,)
                if dt < best.get(key, (math.inf,))[0]:
                    best[key] = (dt, eq.stable, eq.reason)
    print(f"equilibrium(count = 6), n = 2, tau = {TAU}: verify=False against verify=True, best of "
          f"{rounds} interleaved rounds, CPU time")
    print(f"{'kernel':>8} {'N':>7} {'of':>9} {'a':>4} {'unverified (s)':>15} {'verified (s)':>13} "
          f"{'ratio':>6}  verdict")
    for c in cases:
        off, on = best[c + (False,)], best[c + (True,)]
        print(f"{c[0]:>8} {c[1]:>7} {c[2]:>9} {c[3]:4} {off[0]:15.4f} {on[0]:13.4f} "
              f"{on[0] / off[0]:6.2f}"
              f"  {on[1]} ({on[2][:60]})")


def main() -> None:
    ap = argparse.ArgumentParser(
        description="Prints the cost of roots(count = 10) of the distributed-delay oscillator "
                    "against simulating one delay tau, the time of a stability chart on local "
                    "processes and on a Dask LocalCluster, and of the verified verdict of the "
                    "Stribeck belt's orbits.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    ap.add_argument("--N", type=int, nargs="*", default=[1000, 10000, 100000],
                    help="steps per delay of the roots cases (none: skip parts 1-3)")
    ap.add_argument("--rounds", type=int, default=3, help="interleaved rounds of the roots cases")
    ap.add_argument("--chart", type=int, nargs=2, default=[100, 100], metavar=("P", "Q"),
                    help="grid of the chart (0 0: no chart)")
    ap.add_argument("--chart-N", type=int, default=128, help="steps per delay of the chart's model")
    ap.add_argument("--workers", type=int, default=2, help="processes, and Dask workers, of the chart")
    ap.add_argument("--no-dask", action="store_true", help="time the chart on processes only")
    ap.add_argument("--chart-rounds", type=int, default=2, help="interleaved rounds of the chart")
    ap.add_argument("--verdict-M", type=int, nargs="*", default=[200, 1250],
                    help="steps a period of the belt's verdicts (none: skip)")
    ap.add_argument("--verify-N", type=int, nargs="*", default=[1000, 10000],
                    help="steps per delay of the verified equilibria (none: skip)")
    a = ap.parse_args()
    if a.verify_N:
        bench_verify(a.verify_N, a.rounds)
    if not a.N:
        return
    bench_roots(a.N, a.rounds)
    if a.chart[0] > 0:
        bench_chart(a.chart[0], a.chart[1], a.chart_N, a.workers, not a.no_dask, a.chart_rounds)
    if a.verdict_M:
        bench_verdict(a.verdict_M)


if __name__ == "__main__":
    main()
