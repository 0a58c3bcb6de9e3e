#!/usr/bin/env python3
# A weakly singular kernel in O(1) per step (a benchmark, not a test): the
# fractional relaxation u' + int_0^tau s^-1/2 / Gamma(1/2) u(t - s) ds = 0,
# u(0) = 1, zero history, h = 1e-3, tau = N h, with the exact cell weights
# (set_quadrature("cell")) three ways: the kernel fitted by dmi.kernels.fit
# (tol relative on [h, tau]) through the recursion with the first cell exact
# (set_kernel_fit), and the exact kernel (a numba cfunc) by the FFT and by
# DIRECT, the FMU's only exact method.  Rounds interleave the three; the
# fastest round of each counts; CPU time of the process (the machine may be
# shared).  Needs dmi importable (PYTHONPATH=<build>/python) and numba.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import math
import time
from benchtools import positive_int


def tolerance(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not 0 < value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not in (0, 1)")
    return value


def parse() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description="Times the fractional relaxation (kernel s^-1/2/Gamma(1/2), "
                                 "exact cell weights, h = 1e-3, tau = N h) with the kernel fitted by "
                                 "dmi.kernels.fit through the recursion, against the exact kernel by the "
                                 "FFT and by DIRECT; prints the fit, ns per step of each and the ratios.")
    ap.add_argument("--N", type=positive_int, nargs="+", default=[100000, 1000000],
                    help="cells per delay (default: [100000, 1000000])")
    ap.add_argument("--tol", type=tolerance, default=1e-8,
                    help="the fit's relative tolerance on [h, tau] (default: 1e-08)")
    ap.add_argument("--steps", type=positive_int, default=20000,
                    help="steps of the recursion and the FFT per round (default: 20000)")
    ap.add_argument("--direct-work", type=positive_int, default=200000000,
                    help="DIRECT's steps per round are this / N (default: 200000000)")
    ap.add_argument("--rounds", type=positive_int, default=5, help="interleaved rounds (default: 5)")
    return ap.parse_args()


def main() -> None:
    args = parse()
    import numba

    import dmi
    from dmi import kernels

    h, c = 1e-3, 1 / math.sqrt(math.pi)

    @numba.cfunc(dmi.KERNEL_SIGNATURE)
    def kernel(s, out, user):
        out[0] = c / math.sqrt(s)
        return 0

    @numba.cfunc(dmi.HISTORY_SIGNATURE)
    def history(t, out, user):
        out[0] = 1.0 if t == 0 else 0.0
        return 0

    print(f"u' + int_0^tau s^-1/2/Gamma(1/2) u(t-s) ds = 0, u(0) = 1, h = {h}, exact cell weights; "
          f"best of {args.rounds} interleaved rounds, CPU time; dmi {dmi.version()}")
    print(f"{'N':>8} {'terms':>5} {'fit s':>6} {'fit error':>9} {'init rec/fft/direct s':>22} "
          f"{'rec ns':>8} {'fft ns':>8} {'direct ns':>10} {'rec/fft':>8} {'direct/rec':>10} {'|rec-fft|':>9}")
    for N in args.N:
        tau = N * h
        t0 = time.process_time()
        f = kernels.fit(kernels.PowerKernel(0.5, c), tau, tol=args.tol, relative=True, delta=h)
        fit_time = time.process_time() - t0

        solvers, init = {}, {}
        for kind in ("rec", "fft", "direct"):
            s = dmi.Solver(1, tau, N)
            s.set_history(history)
            s.set_quadrature("cell")
            if kind == "rec":
                s.set_kernel_fit(f)
                s.set_convolution("recursive")
            else:
                s.set_kernel(kernel)
                s.set_convolution(kind)
            t0 = time.process_time()
            s.init()
            init[kind] = time.process_time() - t0
            solvers[kind] = s
        steps = {"rec": args.steps, "fft": args.steps, "direct": max(1, args.direct_work // N)}
        best = {k: math.inf for k in solvers}
        for _ in range(args.rounds):
            for kind, s in solvers.items():
                t0 = time.process_time()
                s.advance(steps[kind])
                best[kind] = min(best[kind], 1e9 * (time.process_time() - t0) / steps[kind])
        # rec and fft took the same steps: the same scheme up to the fit's error
        dev = abs(solvers["rec"].state[0] - solvers["fft"].state[0])
        print(f"{N:>8} {f.terms:>5} {fit_time:>6.1f} {f.max_error:>9.1e} "
              f"{init['rec']:>7.2f} {init['fft']:>6.2f} {init['direct']:>7.2f} "
              f"{best['rec']:>8.0f} {best['fft']:>8.0f} {best['direct']:>10.0f} "
              f"{best['rec'] / best['fft']:>8.2f} {best['direct'] / best['rec']:>10.0f} {dev:>9.1e}")
    print("targets: rec/fft <= 1.25 at N = 1e5 and < 1 at 1e6; direct/rec >= 50 at 1e5")


if __name__ == "__main__":
    main()
