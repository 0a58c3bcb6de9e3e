#!/usr/bin/env python3
# The adaptive mesh and the error estimate of collocate against true errors (a benchmark, not a
# test): van der Pol with a distributed delay, w'' + eps (w^2 - 1) w' + w + a int_0^1 w(t - s) ds
# = 0, a = 0.5, at eps = 1 (degree 4 to 6) and its relaxation oscillation at eps = 10 (degree 6),
# each from a scheme orbit.  True errors against a collocation of degree 8 (80 intervals at eps =
# 1, 128 at eps = 10).  For each mesh: the true error of the period and the multipliers of the
# orbit returned (the finer level), the two-level difference and the three-level estimate
# (Richardson's where the levels are steady) over it; the refinement to tol = 1e-8 at eps = 10
# (its mesh, true error, estimate); the Newton iterations and CPU time of each level: the orbit on
# the mesh, the halved mesh from its solution (transfer) and from the start, the merged mesh.
# Usage: PYTHONPATH=build/python .venv/bin/python bench/bench_meshes.py [--small]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import time  # noqa: E402

import numpy as np  # noqa: E402

import dmi  # noqa: E402
from dmi import analysis as da  # noqa: E402
from dmi.analysis.collocation import adapt  # noqa: E402
from dmi.analysis.collocation.collocate import first_solve  # noqa: E402
from dmi.analysis.collocation.floquet import multipliers as floquet  # noqa: E402
from dmi.analysis.collocation.signature import read_signature  # noqa: E402
from dmi.analysis.collocation.system import Layout, Terms, carried, reference, solve  # noqa: E402
from dmi.analysis.scheme.stepmap import build  # noqa: E402


def van_der_pol(eps: float):
    def make(p: float, h: float | None = None) -> dmi.Solver:
        s = dmi.Solver(2, 1.0, h=h or 0.01)
        s.set_rhs(lambda t, u: np.array([-u[1], eps * (u[0] ** 2 - 1) * u[1] + u[0]]))
        s.set_kernel_exp([0.0], [0.0], [[[0.0, 0.0], [p, 0.0]]])
        return s
    return make


def scheme_orbit(eps: float, T: float, steps: int) -> da.Orbit:
    make = van_der_pol(eps)
    s = make(0.5, h=T / steps)
    s.set_history(lambda t: np.array([2.0, 0.0]))
    s.init()
    s.advance(40 * steps)
    return da.periodic_orbit(make, 0.5, None, s, guess_period=T, steps=steps, multipliers=0)


def timed_solve(lay, terms, x0, ref):
    t = time.process_time()
    x, res = solve(lay, terms, x0, ref)
    return x, len(res), time.process_time() - t


def mesh_row(o, ref, L: int, m: int) -> None:
    """One mesh: the levels' costs, the true errors and the estimates."""
    terms = Terms(build(o.make, o.p))
    sig, b0 = read_signature(o.u, o.h, terms.alpha, terms.lo, terms.hi)
    lay = Layout(m, terms.n, sig, [], True, o.period, carried(terms, sig))
    lay0, x0 = first_solve(o, terms, lay, b0, max(8, L // 2), "bench")
    r = reference(lay0, x0)
    lay1 = lay0.with_fractions(adapt.adapted(lay0, x0, L))
    x1, n1, t1 = timed_solve(lay1, terms, adapt.transfer(lay0, x0, lay1), r)
    fine = lay1.with_fractions(adapt.halved(lay1.fractions))
    x2, n2, t2 = timed_solve(fine, terms, adapt.transfer(lay1, x1, fine), r)
    _, n2s, t2s = timed_solve(fine, terms, adapt.transfer(lay0, x0, fine), r)
    low = lay1.with_fractions(adapt.merged(lay1.fractions))
    x3, n3, t3 = timed_solve(low, terms, adapt.transfer(lay1, x1, low), r)
    c, f, g = adapt.Solved(lay1, x1), adapt.Solved(fine, x2), adapt.Solved(low, x3)
    for s in (g, c, f):
        s.mu = floquet(s.lay, terms, s.x, 4)
    two = adapt.estimate(c, f)
    three = adapt.estimate(c, f, coarser=g)
    tT = abs(f.T - ref.period)
    k = 1                                          # the largest nontrivial multiplier
    tmu = float(np.min(np.abs(ref.multipliers - f.mu[k])))
    seen = tmu > 100 * np.spacing(max(1.0, abs(f.mu[k])))       # above 100 ulp
    mu = (f"{two['multipliers'][k] / tmu:8.3g} | {three['multipliers'][k] / tmu:8.3g}" if seen
          else f"{'-':>8} | {'-':>8}")
    print(f"{fine.L:4d} x {m} | {tT:9.2e} | {two['period'] / tT:8.3g} | {three['period'] / tT:8.3g}"
          f" | {tmu:9.2e} | {mu} | {n1}, {t1:.2f} s | {n2}, {t2:.2f} s | {n2s}, {t2s:.2f} s | "
          f"{n3}, {t3:.2f} s", flush=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=(
        "Prints, for meshes of van der Pol with a distributed delay (eps = 1 and its relaxation "
        "oscillation at eps = 10), the true errors of the period and a multiplier, the two- and "
        "three-level estimates over them and the Newton cost of each level; then the refinement "
        "to tol = 1e-8 at eps = 10."))
    ap.add_argument("--small", action="store_true",
                    help="one mesh of each orbit (for CI; default: all meshes)")
    a = ap.parse_args()
    print("mesh | period: true | 2-level/true | 3-level/true | mu_2: true | 2-level/true | "
          "3-level/true | Newton its, CPU: on L | 2L from L | 2L from start | L/2 from L")
    o1 = scheme_orbit(1.0, 6.0, 600)
    ref1 = da.collocate(o1, intervals=40, degree=8, multipliers=4)
    for L, m in ((24, 4),) if a.small else ((12, 4), (24, 4), (32, 4), (8, 5), (16, 5), (12, 6)):
        mesh_row(o1, ref1, L, m)
    o2 = scheme_orbit(10.0, 16.0, 1000)
    ref2 = da.collocate(o2, intervals=64, degree=8, multipliers=4)
    for L in (56,) if a.small else (40, 44, 48, 56, 64):
        mesh_row(o2, ref2, L, 6)
    t = time.process_time()
    e = da.collocate(o2, degree=6, tol=1e-8, multipliers=0)
    print(f"eps = 10, tol = 1e-8: {e.intervals} x 6 returned (its coarser level "
          f"{e.intervals // 2}), true {abs(e.period - ref2.period):.2e}, estimate "
          f"{e.errors['period']:.2e}, CPU {time.process_time() - t:.1f} s")


if __name__ == "__main__":
    main()
