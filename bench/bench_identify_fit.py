#!/usr/bin/env python3
# dmi.identify.estimate against SciPy's least_squares with 2-point forward differences of plain runs
# (a benchmark, not a test): the same model, data, start and h.  The model: bench_identify.py's
# friction oscillator with a two-term Prony memory, 7 free parameters (k, mu, w0, c1, a1, c2, a2;
# g = 2 fixed), f and the history jit=True, 1000 steps of h = 0.01 with stick-slip, 500 samples of
# the position with Gaussian noise 1e-3 (seeded); the start 5-15 % off the truth.  estimate as it is
# (its default polish: a second least_squares at tolerance 1e-8 after the first at 1e-5) and with
# polish=False; least_squares at its default tolerances.  CPU seconds of
# the process, fastest of the rounds (interleaved), one BLAS thread; each fit's runs of the model
# and its cost at the end are printed, and the machine's load.  Then the floor: one sensitivity run
# against the 1 + P plain runs of one forward-difference Jacobian, and the costs of estimate's
# Jacobians (one model per parameter, grouped models, kept models; the make calls, the tangent).  --baseline DIR fits with another version of
# dmi.identify in the same rounds (as bench_identify.py); --baseline-package DIR with another
# version of the whole package (a copy of a build's build/python/dmi, its libraries with it,
# imported as dmi_baseline: its model, its estimate and least_squares on its runs), and prints
# the ratios of the two versions.
# Usage: PYTHONPATH=build/python:bench .venv/bin/python bench/bench_identify_fit.py [--rounds 3]
#        [--baseline DIR] [--baseline-package DIR]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402

import numpy as np  # noqa: E402
from scipy import optimize  # noqa: E402

import bench_identify as b  # noqa: E402
from benchtools import cpu, dir_holding, positive_int  # noqa: E402
from dmi.identify import Record, _grouped, estimate, fitting, sensitivities  # noqa: E402
from dmi.identify.sensitivity import _sensitivities_of  # noqa: E402

STEPS = 1000
G = 2.0
TRUTH = np.delete(b.P0, 1)                          # k, mu, w0, c1, a1, c2, a2
START = TRUTH * (1 + np.array([0.1, -0.1, 0.05, 0.15, -0.1, 0.1, -0.05]))


def model(bench=b):
    """make(p) of the 7 free parameters (g fixed), with bench_identify's model (or that of a
    copy of bench_identify bound to another package)."""
    make8 = bench.model(STEPS, True, "exp", True)

    def make(p):
        return make8(np.insert(np.asarray(p, dtype=float), 1, G))
    return make


def data(make):
    """500 samples of the position, noise 1e-3."""
    s = make(TRUTH)
    s.init()
    t, U = s.run(STEPS)
    rng = np.random.default_rng(1)
    return t[2::2], U[2::2, 0] + 1e-3 * rng.standard_normal(STEPS // 2)


def residuals_fd(make, t, y):
    """The residual function of a least_squares fit by differences (the plain runs)."""
    def residuals(p):
        s = make(p)
        s.init()
        _, U = s.run(STEPS)
        return U[2::2, 0] - y
    return residuals


def baseline_package(path: str):
    """(dmi.identify, bench_identify) of the package in path imported as dmi_baseline: a copy
    of bench_identify whose models are that package's Solvers."""
    spec = importlib.util.spec_from_file_location("dmi_baseline", os.path.join(path, "__init__.py"),
                                                  submodule_search_locations=[path])
    if spec is None or spec.loader is None:
        raise SystemExit(f"--baseline-package {path}: no __init__.py there")
    package = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = package
    spec.loader.exec_module(package)
    identify = importlib.import_module("dmi_baseline.identify")
    spec = importlib.util.spec_from_file_location("bench_identify_baseline", b.__file__)
    bench = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bench)
    bench.dmi = package                 # (model() reads the global at each call)
    return identify, bench


def main() -> None:
    ap = argparse.ArgumentParser(description=(
        "Prints the CPU seconds of dmi.identify.estimate against least_squares with 2-point "
        "differences on a 7-parameter friction model with a two-term memory."))
    ap.add_argument("--rounds", type=positive_int, default=5,
                    help="interleaved rounds; the fastest of each counts (default 5)")
    ap.add_argument("--baseline", metavar="DIR", type=dir_holding("__init__.py"),
                    help="a copy of another version's python/dmi/identify (default: none)")
    ap.add_argument("--baseline-package", metavar="DIR", type=dir_holding("__init__.py"),
                    help="a copy of another build's build/python/dmi (default: none)")
    args = ap.parse_args()
    make = model()
    t, y = data(make)
    record = Record(t, y)
    fits = {"estimate": lambda: estimate(make, START, record),
            "estimate, polish=False": lambda: estimate(make, START, record, polish=False),
            "least_squares 2-point": lambda: optimize.least_squares(
                residuals_fd(make, t, y), START, jac="2-point", method="trf", x_scale="jac")}
    if args.baseline:
        base = b.baseline(args.baseline)
        base_record = base.Record(t, y)        # (the baseline's own Record class)
        fits["estimate (baseline)"] = lambda: base.estimate(make, START, base_record)
    if args.baseline_package:
        ident, bench = baseline_package(args.baseline_package)
        make_b = model(bench)
        record_b = ident.Record(t, y)
        fits["estimate (package baseline)"] = lambda: ident.estimate(make_b, START, record_b)
        fits["least_squares (package baseline)"] = lambda: optimize.least_squares(
            residuals_fd(make_b, t, y), START, jac="2-point", method="trf", x_scale="jac")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for f in fits.values():                     # compile and warm up
            f()
        best = {k: np.inf for k in fits}
        last: dict = {}
        for _ in range(args.rounds):
            for name, f in fits.items():
                box: list = []
                best[name] = min(best[name], cpu(lambda: box.append(f())))
                last[name] = box[0]
    ref = best["least_squares 2-point"]
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"7 parameters, {len(t)} samples, {STEPS} steps; CPU seconds, fastest of {args.rounds} "
          f"interleaved rounds; load average {load:.2f} on {os.cpu_count()} CPUs")
    for name, r in last.items():
        x = r.x if hasattr(r, "x") else r.p
        cost = float(r.cost)
        err = np.max(np.abs(np.asarray(x) - TRUTH) / np.abs(TRUTH))
        print(f"{name:24} {best[name]:8.3f} s  ratio {best[name] / ref:5.2f}  runs {r.nfev:4d}  "
              f"jacobians {r.njev if r.njev is not None else 0:3d}  cost {cost:.6g}  "
              f"max rel. error {err:.2e}")
    if args.baseline_package:
        old = best["estimate (package baseline)"] / best["least_squares (package baseline)"]
        print(f"estimate / least_squares: this version {best['estimate'] / ref:.2f}, the baseline "
              f"package {old:.2f}; estimate this / baseline "
              f"{best['estimate'] / best['estimate (package baseline)']:.2f}")
    floor(make, t, y)


def floor(make, t, y) -> None:
    """The costs a fit is made of (CPU seconds, fastest of 5): a sensitivity run of one model per
    parameter against the 1 + P runs of one forward-difference Jacobian, and the Jacobians of
    estimate: of one model per parameter (its first), of the grouped models (the others), of
    models kept from the last Jacobian at the same point (the covariance's), their make calls
    and libdmi's tangent loop alone."""
    P = len(TRUTH)
    resid = residuals_fd(make, t, y)
    sens = min(cpu(lambda: sensitivities(make, START, STEPS)) for _ in range(5))
    fwd = min(cpu(lambda: [resid(START) for _ in range(P + 1)]) for _ in range(5))
    one = min(cpu(lambda: resid(START)) for _ in range(5))
    print(f"one sensitivity run {sens:.4f} s; one residual run {one:.4f} s; 1 + P = {P + 1} "
          f"runs {fwd:.4f} s; sensitivities / (1 + P runs) = {sens / fwd:.2f}")
    problem = fitting._Problem([make], START.copy(), np.ones(P, bool),
                               [fitting._check_record(Record(t, y), 0, 2)], None)
    problem.jumps = False
    problem.linearised(START)                    # the groups, learned
    plan = problem.cache.pop(("plan", 0))
    rng = np.random.default_rng(0)

    def jacobian(grouped: bool, kept: bool = False):
        problem.grouped = grouped
        x = START * (1 + 1e-4 * rng.standard_normal(P))
        problem.linearised(x)
        if kept:                                 # the same models, the other jumps setting
            problem.jumps = True
            problem.linearised(x)
            problem.jumps = False
    full = min(cpu(lambda: jacobian(False)) for _ in range(5))
    grouped = min(cpu(lambda: jacobian(True)) for _ in range(5))
    kept = min(cpu(lambda: jacobian(True, True)) for _ in range(5)) - grouped
    makes = min(cpu(lambda: _grouped.build(make, START, plan)) for _ in range(5))
    mod = _grouped.build(make, START, plan)
    loop = min(cpu(lambda: _sensitivities_of(mod, START, STEPS, jumps=False)) for _ in range(5))
    calls = 1 + len(plan.groups) + len(plan.own)
    print(f"estimate's Jacobians: one model per parameter {full:.4f} s; grouped ({calls} make "
          f"calls, groups {plan.groups}) {grouped:.4f} s, of which the make calls and their checks "
          f"{makes:.4f} s, the sensitivities {loop:.4f} s; with the models kept {kept:.4f} s")


if __name__ == "__main__":
    main()
