# The speed benchmarks of collocation, long memories, meshes and identification run at a small
# size (their --small or smallest options; bench_collocation one round, without --against;
# bench_meshes also its --check-cost, one round): each exits 0 and prints its figures, every
# number finite; bench_longmem's folded and unfolded delay integrals give the same period within
# the sum of the two printed estimates.  Sizes here, not speed: the figures are in
# docs/benchmarks.md.
# PYTHONPATH holds the build's python/ and bench/ (the benches import benchtools and each other).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

BENCH = Path(os.environ["DMI_SOURCE_DIR"]) / "bench"
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?|\bnan\b|\binf\b", re.I)


def run(name: str, *args: str) -> str:
    """The standard output of bench/name with args (exit 0, no traceback)."""
    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MPLBACKEND="Agg")
    r = subprocess.run([sys.executable, str(BENCH / name), *args], capture_output=True,
                       text=True, timeout=900, env=env)
    assert r.returncode == 0 and "Traceback" not in r.stderr, (name, r.returncode, r.stderr[-3000:])
    return r.stdout


def finite(text: str) -> list[float]:
    """The numbers of text, each finite (an assertion names the first that is not)."""
    values = [float(v) for v in NUMBER.findall(text)]
    bad = [v for v in values if not math.isfinite(v)]
    assert not bad, (bad, text)
    return values


@pytest.mark.parametrize("name, args, lines", [
    ("bench_meshes.py", ["--small"],
     [r"^\s*48 x 4 \|", r"^\s*112 x 6 \|", r"^degree 6, tol = 1e-08"]),
    ("bench_meshes.py", ["--check-cost", "--rounds", "1"],
     [r"^eps = 1, tol = 1e-10 \|", r"^eps = 10, tol = 1e-8, degree 6 \|"]),
    ("bench_identify_first_call.py", ["--rounds", "1", "--steps", "200"], [r"^this\s"]),
    ("bench_collocation.py", ["--rounds", "1"],
     [r"^\s*vdp, tol 1e-10\s", r"^\s*vdp, branch point\s"]),
])
def test_bench_runs_small(name, args, lines):
    out = run(name, *args)
    for pattern in lines:
        found = [ln for ln in out.splitlines() if re.search(pattern, ln)]
        assert found, (pattern, out)
        finite("\n".join(found))


def period(out: str, case: str) -> tuple[float, float]:
    """(period, its estimate) of a case line of bench_longmem's table."""
    line = next(ln for ln in out.splitlines() if ln.strip().startswith(case))
    m = re.search(r"period = (\S+) \(\+- (\S+)\)", line)
    assert m, line
    finite(line)
    return float(m.group(1)), float(m.group(2))


def test_bench_longmem_small_folded_as_unfolded():
    folded = run("bench_longmem.py", "--small")
    unfolded = run("bench_longmem.py", "--small", "--unfolded")
    for case in ("stick-slip", "hopf orbit"):
        (a, ea), (b, eb) = period(folded, case), period(unfolded, case)
        assert abs(a - b) <= ea + eb, (case, a, b, ea, eb)
