# dmi.analysis: linear stability of equilibria and periodic orbits of the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis: the analysis of models ``make(p) -> dmi.Solver``.

Equilibria and their stability (docs/stability.md): :func:`equilibrium`,
:func:`continue_equilibrium`, :func:`roots`, :func:`hopf`, :func:`stability_chart` and
:func:`plot_stability_chart`.  Periodic orbits (docs/orbits.md): :func:`periodic_orbit`,
:func:`hopf_orbit`, :func:`floquet_multipliers` (on a :class:`StepMap`), :func:`continue_orbit`,
:func:`period_doubled_orbit`, :func:`refine_orbit` and :func:`plot_branch`.  The answers are the
scheme's (they match simulation); ``of="equation"`` (:func:`roots`, :func:`hopf`,
:func:`stability_chart`, :func:`equilibrium`) and :func:`refine_orbit` give the equation's.
Interactive HTML figures (:mod:`dmi.analysis.plot.interactive`, Bokeh): ``Branch.to_html``,
``StabilityChart.to_html`` and the ``html`` of :func:`plot_branch` and
:func:`plot_stability_chart`.
"""
from __future__ import annotations

from .core.model import KinkError
from .hopf_orbits import hopf_orbit
from .continuation.branch import Branch, BranchPoint, Event, HopfPoint
from .equilibria.chart import HopfCurve, StabilityChart, plot_stability_chart, stability_chart
from .orbits import continue_orbit, period_doubled_orbit
from .equilibria.equilibrium import Equilibrium, EquilibriumPoint, continue_equilibrium, equilibrium
from .scheme.floquet import Floquet, StabilityWarning, Verify, floquet_multipliers, floquet_verdict
from .core.newton import ShootingError
from .scheme.orbit import Orbit
from .plot.branch import plot_branch
from .shooting.refine import Refined, refine_orbit
from .shooting.shoot import periodic_orbit
from .equilibria.crossing import hopf
from .equilibria.stability import roots
from .scheme.stepmap import StepMap

__all__ = [
    # equilibria and their stability (docs/stability.md)
    "equilibrium", "Equilibrium", "continue_equilibrium", "EquilibriumPoint",
    "roots", "hopf", "HopfPoint", "KinkError", "stability_chart", "StabilityChart", "HopfCurve",
    "plot_stability_chart",
    # periodic orbits (docs/orbits.md): shooting, Floquet multipliers, continuation
    "periodic_orbit", "hopf_orbit", "Orbit", "ShootingError", "StepMap", "floquet_multipliers",
    "continue_orbit", "period_doubled_orbit", "Branch", "BranchPoint", "Event", "plot_branch",
    "refine_orbit", "Refined",
    # verified Floquet multipliers and stability verdicts (docs/orbits.md)
    "floquet_verdict", "Floquet", "Verify", "StabilityWarning",
]
from .collocation.collocate import collocate  # noqa: E402
from .collocation.orbit import EquationOrbit  # noqa: E402

from .collocation.system import CollocationWarning  # noqa: E402
from .continuation.branch import EventWarning  # noqa: E402

__all__ += ["collocate", "EquationOrbit", "CollocationWarning", "EventWarning"]
from .branches.discretisation import (CollocationDiscretisation,  # noqa: E402
                                       equation_hopf_orbit)

__all__ += ["CollocationDiscretisation", "equation_hopf_orbit"]
from .equilibria.curves import Curve, CurveEvent, CurvePoint, continue_curve  # noqa: E402

# Hopf and fold curves of the equation's equilibria in two parameters (docs/stability.md)
__all__ += ["continue_curve", "Curve", "CurvePoint", "CurveEvent"]
from .plane.diagram import plot_curves  # noqa: E402
from .plane.grid import Grid, GridEvent, GridRow, GridWarning, Trace, continue_over  # noqa: E402

# the plane (p, q): one-parameter continuations over q (serially or on Dask) and the diagram
__all__ += ["continue_over", "Grid", "GridRow", "GridEvent", "Trace", "GridWarning",
            "plot_curves"]
