#!/usr/bin/env python3
# The stability chart of an oscillator with a distributed delay (dmi.analysis):
#     w'' + c w' + b w + a int_0^tau G(s) w(t - s) ds = 0,   G(s) = exp(-s / theta) / theta,
# over the delay gain a and the delay tau; writes the figure (PNG) and the Hopf curves (CSV).
# Usage: examples/python/stability_chart.py OUT.png [--grid P Q] [--N N] [--workers W]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The distributed-delay oscillator as a two-parameter model for dmi.analysis.stability_chart."""
from __future__ import annotations

import argparse
import time

import numpy as np

import dmi
from dmi import analysis

B, C, THETA = 1.0, 0.3, 1.0   # stiffness b (1/s^2), damping c (1/s), kernel time theta (s)


def oscillator(a: float, tau: float, N: int = 128, c: float = C) -> dmi.Solver:
    """u = (w, w'): u' + f(u) + int_0^tau H(s) u(t - s) ds = 0 with f(u) = (-w', c w' + b w) and
    H(s) = [[0, 0], [a G(s), 0]] as one exponential term (the O(1) recursion); h = tau / N."""
    s = dmi.Solver(2, tau, N)
    s.set_rhs(lambda t, u: np.array([-u[1], c * u[1] + B * u[0]]))
    s.set_kernel_exp([-1.0 / THETA], [0.0], [[[0.0, 0.0], [a / THETA, 0.0]]])
    return s


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("out", help="the figure (PNG); the Hopf curves go to the same name .csv")
    ap.add_argument("--grid", type=int, nargs=2, default=[100, 100], metavar=("P", "Q"))
    ap.add_argument("--N", type=int, default=128, help="steps per delay tau")
    ap.add_argument("--workers", type=int, default=None)
    a = ap.parse_args()
    import functools

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    gains = np.linspace(-1.5, 3.0, a.grid[0])
    delays = np.linspace(0.2, 8.0, a.grid[1])
    t0 = time.perf_counter()
    chart = analysis.stability_chart(functools.partial(oscillator, N=a.N), gains, delays,
                                     [0.0, 0.0], workers=a.workers)
    dt = time.perf_counter() - t0
    ax = analysis.plot_stability_chart(chart, p_label="delay gain a (1/s²)",
                                       q_label="delay τ (s)",
                                       title="w'' + c w' + b w + a ∫₀^τ G(s) w(t−s) ds = 0, "
                                             f"G(s) = e^(−s/θ)/θ\nc = {C:g}/s, b = {B:g}/s², "
                                             f"θ = {THETA:g} s, N = {a.N} steps per τ")
    ax.figure.savefig(a.out, dpi=130)
    plt.close(ax.figure)
    with open(a.out.rsplit(".", 1)[0] + ".csv", "w") as f:
        f.write("curve,a,tau,omega\n")
        for k, cv in enumerate(chart.curves):
            for row in zip(cv.p, cv.q, cv.omega):
                f.write(f"{k},{row[0]:.12g},{row[1]:.12g},{row[2]:.12g}\n")
    stable = float(np.mean(chart.stable))
    print(f"stability chart {a.grid[0]}x{a.grid[1]}, N = {a.N}: {dt:.1f} s, "
          f"{len(chart.curves)} curves, stable fraction {stable:.3f} -> {a.out}")


if __name__ == "__main__":
    main()
