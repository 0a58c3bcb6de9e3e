# Small, fast branches and a chart for the interactive figures' tests (analysis/plot/test_interactive.py
# and tests/docs/browser_check.py figures): the Stuart-Landau oscillator with a distributed memory
# of examples/python/landau_memory.py, whose frequency grows with the amplitude, so that the period
# changes along its orbit branch.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import dmi
from dmi import analysis as da

sys.path.insert(0, str(Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3]))
                       / "examples" / "python"))
from landau_memory import N, TAU, make as landau  # noqa: E402  (the gallery example's model)


def landau2(mu: float, q: float) -> dmi.Solver:
    """The two-parameter model of the chart: mu and the kernel gain q."""
    return landau(mu, k=q)


def branches(points: int = 5) -> tuple[da.Branch, da.Branch]:
    """The branch of equilibria u = 0 over mu in [0, 0.6] (a Hopf point near mu = 0.25) and the
    branch of orbits born there (``points`` points, their period shrinking as they grow)."""
    eq = da.equilibrium(landau, 0.0, [0.02, -0.01])
    equilibria = da.continue_equilibrium(eq, 0.6, step=0.1)
    hopf = next(e for e in equilibria.events if e.kind == "hopf")
    M = round(2 * math.pi / hopf.hopf.omega / (TAU / N))
    o = da.hopf_orbit(landau, hopf.hopf, hopf.u, amplitude=0.1, steps=M, component=0)
    orbits = da.continue_orbit(o, 1.0, step=0.1, max_points=points, multipliers=3)
    return equilibria, orbits


def chart() -> da.StabilityChart:
    """The rightmost root of u = 0 on a 4 x 3 grid of (mu, q), without traced curves."""
    return da.stability_chart(landau2, [0.0, 0.2, 0.4, 0.6], [0.2, 0.5, 0.8], [0.0, 0.0],
                              workers=1, trace=False)
