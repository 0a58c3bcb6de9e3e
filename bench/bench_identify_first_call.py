#!/usr/bin/env python3
# The first dmi.identify.sensitivities call of a fresh process with an empty numba cache (a benchmark,
# not a test): CPU seconds of the user's own model first (make, init and a short run: the compile of
# its jit=True callbacks), then of the first sensitivities call, then of a second one.  Each
# measurement is a new Python process with NUMBA_CACHE_DIR a new empty directory.  --baseline DIR
# times another version of dmi.identify (DIR: a copy of its python/dmi/identify, e.g. from
# `git archive <commit> python/dmi/identify`, loaded as a subpackage of the same dmi, as
# bench_identify.py does) in the same rounds, interleaved.
# The model: bench_identify.py's friction oscillator with a two-term Prony memory, P = 8, f and
# the history jit=True, N = steps = 1000.
# Usage: PYTHONPATH=build/python:bench .venv/bin/python bench/bench_identify_first_call.py
#        [--rounds 3] [--steps 1000] [--baseline DIR]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile

from benchtools import dir_holding, positive_int

CHILD = r"""
import json, os, sys, time
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
sys.path.insert(0, {bench!r})
import bench_identify as b
baseline = {baseline!r}
cpu = time.process_time
t0 = cpu()
if baseline:
    sensitivities = b.baseline(baseline).sensitivities
else:
    from dmi.identify import sensitivities
imported = cpu() - t0
make = b.model({steps}, True, "exp", True)
t0 = cpu()
b.plain(make, b.P0, 10)                       # the user's own model: its compile
model = cpu() - t0
t0 = cpu()
sensitivities(make, b.P0, {steps})
first = cpu() - t0
t0 = cpu()
sensitivities(make, b.P0, {steps})
second = cpu() - t0
print(json.dumps({{"import": imported, "model": model, "first": first, "second": second}}))
"""


def once(steps: int, baseline: str | None) -> dict:
    """One fresh process with an empty numba cache; its CPU seconds per stage."""
    with tempfile.TemporaryDirectory(prefix="dmi-numba-cache-") as cache:
        env = dict(os.environ, NUMBA_CACHE_DIR=cache)
        code = CHILD.format(bench=os.path.dirname(os.path.abspath(__file__)), baseline=baseline,
                            steps=steps)
        out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, timeout=3600, check=True)
        return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=(
        "Prints the CPU seconds of the first dmi.identify.sensitivities call in a fresh process "
        "with an empty numba cache, beside the user's own model compile."))
    ap.add_argument("--rounds", type=positive_int, default=3,
                    help="fresh processes per version, interleaved (default 3)")
    ap.add_argument("--steps", type=positive_int, default=1000,
                    help="run length N = steps (default 1000)")
    ap.add_argument("--baseline", metavar="DIR", type=dir_holding("__init__.py"),
                    help="a copy of another version's python/dmi/identify (default: none)")
    args = ap.parse_args()
    versions = {"this": None}
    if args.baseline:
        versions["baseline"] = os.path.abspath(args.baseline)
    results: dict = {k: [] for k in versions}
    for _ in range(args.rounds):
        for name, path in versions.items():
            results[name].append(once(args.steps, path))
    print(f"CPU seconds, fresh process, empty numba cache, N = steps = {args.steps}, "
          f"{args.rounds} rounds (each figure: min / max over the rounds)")
    print(f"{'version':10} {'import':>14} {'user model':>14} {'first sens':>14} {'second sens':>14}")
    for name, rows in results.items():
        cells = []
        for key in ("import", "model", "first", "second"):
            values = [r[key] for r in rows]
            cells.append(f"{min(values):6.3f}/{max(values):6.3f}")
        print(f"{name:10} " + " ".join(f"{c:>14}" for c in cells))


if __name__ == "__main__":
    main()
