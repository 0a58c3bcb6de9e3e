# Identifying a fractional belt: friction level, fractional damping c_f and order beta from noisy
# records of a stick-slip run, the kernel c_f s^-beta / Gamma(beta) fitted once and refitted.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""x'' + c_f D^(1 - beta) x + k x + F(x' - v_b) ∋ 0 (m = k = 1), the Caputo kernel
c_f s^-beta / Gamma(beta) on the velocity over a memory tau, the Stribeck law F(v) = sign(v) (mu +
0.2 e^{-|v| / 0.3}) split as examples/python/stribeck_belt.py does (the sign graph at the static
level mu + 0.2 in A, the continuous rest in f).  The kernel is fitted once at beta = 1/2 on
[h, tau] with its first cell exact (near cells), and refitted in make(p) (KernelFit.refit: the
same rates, so that the model is differentiable in c_f and beta).  p = (mu, c_f, beta); records
of x every few steps with Gaussian noise sigma; each seed fits from 10-20 % off the truth and
reports z = (estimate - truth) / stderr.

Run: PYTHONPATH=build/python python bench/bench_identify_fractional.py [--tau 50] [--seeds 5]
(the full size of docs/identify.md: tau = 50, T = 60, h = 0.005; the test of
tests/python/identify/test_nearcells.py runs a small one)."""
from __future__ import annotations

import argparse
import math
import time

import numpy as np
from scipy.special import gamma

import dmi
from dmi import kernels
from dmi.identify import Record, estimate

TRUTH = np.array([0.3, 0.1, 0.5])          # mu (dynamic friction level), c_f, beta
NAMES = ["mu", "c_f", "beta"]
DROP, V_S, VB = 0.2, 0.3, 0.6              # static - dynamic level, Stribeck velocity, belt speed


def belt(tau: float, h: float):
    """make(p) of the belt with memory tau and step h (the fit made once here)."""
    base = kernels.fit(kernels.PowerKernel(0.5, 1.0), tau, tol=1e-8, relative=True, delta=h)

    def make(p: np.ndarray) -> dmi.Solver:
        mu, cf, beta = (float(x) for x in p)
        c = cf / gamma(beta)
        W = tau ** (1 - beta) / (1 - beta)            # int_0^tau s^-beta ds: the belt's constant part

        def rhs(t: float, u: np.ndarray) -> np.ndarray:
            y = u[1]
            g = -math.copysign(DROP * -math.expm1(-abs(y) / V_S), y)
            return np.array([-(y + VB), u[0] + g + c * W * VB])
        s = dmi.Solver(2, tau, h=h)
        s.set_rhs(rhs, jit=True)
        s.set_friction([0.0, mu + DROP])
        s.set_quadrature("cell")
        s.set_kernel_fit(base.refit(kernels.PowerKernel(beta, c)), entry=(1, 1))
        s.set_history(lambda t: np.array([1.5, -VB]))
        return s
    return make


def study(tau: float, T: float, h: float, every: int, sigma: float, seeds: int) -> np.ndarray:
    """z-scores (seeds, 3) of the fits, printed as they come."""
    make = belt(tau, h)
    s = make(TRUTH)
    s.init()
    t, U = s.run(round(T / h))
    t, x = t[::every], U[::every, 0]
    print(f"tau = {tau}, T = {T}, h = {h}, {len(t)} samples of x, sigma = {sigma}; "
          f"stuck steps: {np.mean(U[:, 1] == 0):.0%}")
    zs = []
    for seed in range(seeds):
        rng = np.random.default_rng(seed)
        y = x + sigma * rng.standard_normal(len(x))
        p0 = TRUTH * (1 + rng.choice([-1, 1], 3) * rng.uniform(0.1, 0.2, 3))
        t0 = time.process_time()
        est = estimate(make, p0, Record(t, y, sigma=sigma), names=NAMES,
                       bounds=([0.0, 0.0, 0.05], [2.0, 2.0, 0.95]))
        z = (est.p - TRUTH) / est.stderr
        zs.append(z)
        print(f"seed {seed}: p = {np.array2string(est.p, precision=5)}, stderr = "
              f"{np.array2string(est.stderr, formatter={'float_kind': lambda v: f'{v:.2e}'})}, z = {np.array2string(z, precision=2)}, "
              f"success {est.success}, {time.process_time() - t0:.1f} s CPU")
    zs = np.array(zs)
    print(f"RMS z = {np.sqrt(np.mean(zs ** 2)):.3f}, max |z| = {np.abs(zs).max():.2f}")
    return zs


def main() -> None:
    ap = argparse.ArgumentParser(
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
        description="Fits the fractional belt's friction level, c_f and beta to noisy records of "
                    "a stick-slip run for each seed and prints each estimate, its standard error "
                    "and z = (estimate - truth) / stderr, and the RMS of z.")
    ap.add_argument("--tau", type=float, default=50.0, help="the memory (time units)")
    ap.add_argument("--T", type=float, default=60.0, help="the records' length (time units)")
    ap.add_argument("--h", type=float, default=0.005, help="the step (time units)")
    ap.add_argument("--every", type=int, default=20, help="steps between two samples of x")
    ap.add_argument("--sigma", type=float, default=0.01,
                    help="the noise's standard deviation (state units)")
    ap.add_argument("--seeds", type=int, default=5, help="fits, one a noise seed")
    a = ap.parse_args()
    study(a.tau, a.T, a.h, a.every, a.sigma, a.seeds)


if __name__ == "__main__":
    main()
