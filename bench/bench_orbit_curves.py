#!/usr/bin/env python3
# The cost of a point of a fold curve of collocated orbits (continue_orbit_curve) against a point
# of the one-parameter branch of the same orbit and mesh (a benchmark, not a test).
# The rotationally symmetric oscillator with a memory (tests/python/models/hopf_models.py), c1 = q: the
# one-parameter branch at q = 1 from its Hopf point through the fold of its circles (as a user
# computes it, with the fold located), then the large circles past the fold continued up in p at
# the same q (no event), and the fold curve from q = 1 to 2; degree 4, 24 intervals, 10
# multipliers a point with their error estimates on every curve.  CPU time of the process a point
# (time.process_time), the fastest of the rounds.
# Usage: bench/bench_orbit_curves.py [--rounds R]
#        (needs dmi importable: PYTHONPATH=<build>/python)
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import scipy.optimize as so

from dmi import analysis as da
from dmi.analysis.plane.orbit_curves import continue_orbit_curve

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "python"))
try:
    from models import hopf_models
except ImportError:
    import hopf_models

W0, TAU, G, C2 = 1.0, 2.0, 0.3, -1.0


def make2(mu: float, q: float):
    return hopf_models.circle_solver(complex(mu, W0), q, C2, G, TAU, 100, False)


def per_point(fn) -> tuple[float, int, object]:
    t = time.process_time()
    out = fn()
    return (time.process_time() - t) / len(out.points), len(out.points), out


def main() -> None:
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
    lo = {name: min(v) for name, v in best.items()}
    for name, (t, k) in lo.items():
        print(f"{name:26s} {1e3 * t:8.1f} ms a point ({k} points)")
    for ref in ("branch through the fold", "branch without events"):
        print(f"fold curve / {ref}: {lo['fold curve'][0] / lo[ref][0]:.2f}")


if __name__ == "__main__":
    main()
