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
:func:`plot_stability_chart`.  Two parameters: :func:`continue_curve` (Hopf and fold curves of
equilibria, folds, period doublings and tori of orbits), :func:`continue_over` (one-parameter
continuations over q, on Dask) and :func:`plot_curves` (the diagram).

The package is in rooms, each a subpackage whose docstring says what it holds and what it may
import, lowest first: ``core`` and ``plot``, ``scheme``, ``continuation`` (the one driver),
``equilibria``, ``shooting``, ``collocation``, ``branches`` (orbit branches on the driver),
``plane``; ``orbits``, ``hopf_orbits`` and ``curves`` at the top reach several rooms.
"""
from __future__ import annotations

from .branches.discretisation import CollocationDiscretisation, equation_hopf_orbit
from .collocation.collocate import collocate
from .collocation.orbit import EquationOrbit
from .collocation.system import CollocationWarning
from .continuation.branch import (Branch, BranchPoint, Curve, CurveEvent, Event, EventWarning,
                                  HopfPoint)
from .core.model import KinkError
from .core.newton import ShootingError
from .curves import continue_curve
from .equilibria.chart import HopfCurve, StabilityChart, plot_stability_chart, stability_chart
from .equilibria.curves import CurvePoint
from .equilibria.equilibrium import Equilibrium, EquilibriumPoint, continue_equilibrium, equilibrium
from .equilibria.crossing import hopf
from .equilibria.stability import roots
from .hopf_orbits import hopf_orbit
from .orbits import continue_orbit, period_doubled_orbit
from .plane.diagram import plot_curves
from .plane.grid import Grid, GridEvent, GridRow, GridWarning, Trace, continue_over
from .plane.orbit_curves import (FlipCurvePoint, OrbitCurvePoint, TorusCurvePoint,
                                 continue_flip_curve, continue_orbit_curve, continue_torus_curve)
from .plane.stick_curves import StickCurvePoint, continue_stick_curve
from .plot.branch import plot_branch
from .scheme.floquet import Floquet, StabilityWarning, Verify, floquet_multipliers, floquet_verdict
from .scheme.orbit import Orbit
from .scheme.stepmap import StepMap
from .shooting.refine import Refined, refine_orbit
from .shooting.shoot import periodic_orbit

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
    # the equation's orbits by collocation
    "collocate", "EquationOrbit", "CollocationWarning", "EventWarning",
    "CollocationDiscretisation", "equation_hopf_orbit",
    # curves in two parameters: Hopf and fold curves of equilibria, folds, period doublings
    # tori and stick onsets of orbits
    "continue_curve", "Curve", "CurvePoint", "CurveEvent", "continue_orbit_curve",
    "OrbitCurvePoint", "continue_flip_curve", "FlipCurvePoint", "continue_torus_curve",
    "TorusCurvePoint", "continue_stick_curve", "StickCurvePoint",
    # the plane (p, q): one-parameter continuations over q (serially or on Dask) and the diagram
    "continue_over", "Grid", "GridRow", "GridEvent", "Trace", "GridWarning", "plot_curves",
]
