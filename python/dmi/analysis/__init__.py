# dmi.analysis: linear stability of equilibria and periodic orbits of the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis: the analysis of models ``make(p) -> dmi.Solver`` (filled in by issues 29 and 30).

Stability of equilibria (docs/stability.md): :func:`roots`, :func:`hopf`,
:func:`stability_chart` and :func:`plot_stability_chart`.  Periodic orbits (docs/orbits.md):
:func:`periodic_orbit`, :func:`floquet_multipliers` (on a :class:`StepMap`),
:func:`continue_orbit`, :func:`period_doubled_orbit` and :func:`plot_branch`.
"""
from __future__ import annotations

from ._model import KinkError
from .chart import HopfCurve, StabilityChart, plot_stability_chart, stability_chart
from .continuation import Branch, BranchPoint, Event, continue_orbit, period_doubled_orbit
from .floquet import floquet_multipliers
from .orbit_plot import plot_branch
from .shooting import Orbit, ShootingError, StepMap, periodic_orbit
from .stability import HopfPoint, hopf, roots

__all__ = [
    # stability of equilibria (issue 29, docs/stability.md)
    "roots", "hopf", "HopfPoint", "KinkError", "stability_chart", "StabilityChart", "HopfCurve",
    "plot_stability_chart",
    # periodic orbits (issue 30, docs/orbits.md): shooting, Floquet multipliers, continuation
    "periodic_orbit", "Orbit", "ShootingError", "StepMap", "floquet_multipliers", "continue_orbit",
    "period_doubled_orbit", "Branch", "BranchPoint", "Event", "plot_branch",
]
