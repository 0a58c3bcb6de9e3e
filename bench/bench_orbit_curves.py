#!/usr/bin/env python3
# The cost of a point of a fold, period-doubling or torus curve of collocated orbits
# (continue_orbit_curve, continue_flip_curve, continue_torus_curve) against a point of the
# one-parameter branch of the same orbit and mesh (a benchmark, not a test).
# The rotationally symmetric oscillator with a memory (tests/python/models/hopf_models.py), c1 = q: the
# one-parameter branch at q = 1 from its Hopf point through the fold of its circles (as a user
# computes it, with the fold located), then the large circles past the fold continued up in p at
# the same q (no event), and the fold curve from q = 1 to 2; degree 4, 24 intervals, 10
# multipliers a point with their error estimates on every curve.  The period doubling: the forced
# damped Mathieu equation x'' + 0.1 x' + (d + e cos t) x + 0.05 x^3 = 0.2 cos t, its branch in d
# at e = 0.6 from 0.7 to 0.3 through the doubling, and the doubling's curve from e = 0.6 to 1;
# the torus: the forced van der Pol oscillator x'' + (x^2 - a) x' + x = F cos(1.5 t), its branch
# in F at a = 0.2 from 1.2 to 0.5 through the torus bifurcation, and its curve from a = 0.2 to
# 0.5 (tests/python/analysis/plane/test_plane_orbit_flip.py's models); degree 4, 40 intervals, 10
# multipliers.  CPU time of the process a point (time.process_time), the fastest of the rounds.
# Usage: bench/bench_orbit_curves.py [--rounds R]
#        (needs dmi importable: PYTHONPATH=<build>/python)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import scipy.optimize as so

import dmi
from dmi import analysis as da
from dmi.analysis.plane.orbit_curves import (continue_flip_curve, continue_orbit_curve,
                                             continue_torus_curve)

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
try:
    from models import hopf_models
except ImportError:
    import hopf_models

W0, TAU, G, C2 = 1.0, 2.0, 0.3, -1.0


def make2(mu: float, q: float):
    return hopf_models.circle_solver(complex(mu, W0), q, C2, G, TAU, 100, False)


def mathieu2(d: float, e: float):
    s = dmi.Solver(2, 1.0, h=2 * math.pi / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -0.1 * u[1] - (d + e * math.cos(t)) * u[0]
                                      - 0.05 * u[0] ** 3 + 0.2 * math.cos(t)]))
    return s


def vdp2(F: float, a: float):
    s = dmi.Solver(2, 1.0, h=2 * math.pi / 1.5 / 400)
    s.set_rhs(lambda t, u: -np.array([u[1], -(u[0] ** 2 - a) * u[1] - u[0]
                                      + F * math.cos(1.5 * t)]))
    return s


def forced(make2, p0: float, q0: float, period: float, guess: list[float]):
    o = da.periodic_orbit(lambda p: make2(p, q0), p0, period, np.array(guess), steps=400,
                          multipliers=4)
    return da.collocate(o, multipliers=10, intervals=40)


def per_point(fn) -> tuple[float, int, object]:
    t = time.process_time()
    out = fn()
    return (time.process_time() - t) / len(out.points), len(out.points), out


def main() -> None:
    warnings.simplefilter("ignore")   # the branches' unverified verdicts at the events
    ap = argparse.ArgumentParser(description="Prints the CPU time of a point of a fold curve of collocated orbits "
                                 "(continue_orbit_curve) against a point of the one-parameter branch of "
                                 "the same orbit and mesh, and their ratio.")
    ap.add_argument("--rounds", type=int, default=3, help="rounds, the fastest kept (default: 3)")
    a = ap.parse_args()
    om = so.brentq(lambda w: w + hopf_models.ghat(1j * w, G, TAU).imag - W0, 0.1, 3.0)
    mu_h = hopf_models.ghat(1j * om, G, TAU).real
    make = lambda mu: make2(mu, 1.0)   # noqa: E731
    rest = da.continue_equilibrium(da.equilibrium(make, mu_h - 0.6, [0.0, 0.0], of="equation"),
                                   mu_h + 0.3, step=0.1)
    (h,) = [e for e in rest.events if e.kind == "hopf"]
    start = da.hopf_orbit(make, h.hopf, h.u, amplitude=0.01, of="equation")
    best = {"branch through the fold": [], "branch without events": [], "fold curve": []}
    for _ in range(a.rounds):
        t, k, b = per_point(lambda: da.continue_orbit(start, mu_h - 0.6, step=0.02))
        best["branch through the fold"].append((t, k))
        (f,) = [e for e in b.events if e.kind == "fold"]
        large = b.points[f.index + 1]
        t, k, _ = per_point(lambda: da.continue_orbit(large, mu_h + 0.3, step=0.05))
        best["branch without events"].append((t, k))
        t, k, _ = per_point(lambda: continue_orbit_curve(f, make2, 1.0, 2.0, branch=b,
                                                         step=0.1))
        best["fold curve"].append((t, k))
    flip = forced(mathieu2, 0.7, 0.6, 2 * math.pi, [-0.65, 0.0])
    torus = forced(vdp2, 1.2, 0.2, 2 * math.pi / 1.5, [-1.0, 0.0])
    more = {"doubling branch": [], "period-doubling curve": [], "torus branch": [],
            "torus curve": []}
    for _ in range(a.rounds):
        t, k, b = per_point(lambda: da.continue_orbit(flip, 0.3, step=0.02))
        more["doubling branch"].append((t, k))
        (e,) = [e for e in b.events if e.kind == "period-doubling"]
        t, k, _ = per_point(lambda: continue_flip_curve(e, mathieu2, 0.6, 1.0, branch=b,
                                                        step=0.05))
        more["period-doubling curve"].append((t, k))
        t, k, b = per_point(lambda: da.continue_orbit(torus, 0.5, step=0.05))
        more["torus branch"].append((t, k))
        (e,) = [e for e in b.events if e.kind == "torus"]
        t, k, _ = per_point(lambda: continue_torus_curve(e, vdp2, 0.2, 0.5, branch=b,
                                                         step=0.05))
        more["torus curve"].append((t, k))
    best.update(more)
    lo = {name: min(v) for name, v in best.items()}
    for name, (t, k) in lo.items():
        print(f"{name:26s} {1e3 * t:8.1f} ms a point ({k} points)")
    for ref in ("branch through the fold", "branch without events"):
        print(f"fold curve / {ref}: {lo['fold curve'][0] / lo[ref][0]:.2f}")
    print(f"period-doubling curve / doubling branch: "
          f"{lo['period-doubling curve'][0] / lo['doubling branch'][0]:.2f}")
    print(f"torus curve / torus branch: {lo['torus curve'][0] / lo['torus branch'][0]:.2f}")


if __name__ == "__main__":
    main()
