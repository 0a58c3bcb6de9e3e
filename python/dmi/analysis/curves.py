# dmi.analysis.curves: the one entry point of curves in two parameters, by the start's type.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
""":func:`continue_curve`: a curve in the plane (p, q) from its start, as BifurcationKit's
``continuation`` takes a problem of any kind: a Hopf point or a fold of the equation's equilibria
(:func:`dmi.analysis.equilibria.curves.continue_curve`), or a fold of the equation's periodic
orbits, an orbit branch's ``fold`` event given with its ``branch=``, an EquationOrbit near a fold
(:func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`) or a Hopf curve's ``bautin`` event
(:func:`dmi.analysis.plane.bautin_fold.continue_bautin_fold`), or its ``period-doubling``
or ``torus`` event (:func:`dmi.analysis.plane.orbit_curves.continue_flip_curve`,
:func:`dmi.analysis.plane.orbit_curves.continue_torus_curve`), or its ``stick-onset`` or
``grazing`` event (:func:`dmi.analysis.plane.stick_curves.continue_stick_curve`).  It sits above
the rooms because it reaches both."""
from __future__ import annotations

from collections.abc import Callable
from typing import Any

from .._solver import Solver
from .collocation.orbit import EquationOrbit
from .equilibria.curves import Curve
from .equilibria.curves import continue_curve as equilibrium_curve
from .continuation.branch import CurveEvent, Event
from .plane.bautin_fold import continue_bautin_fold
from .plane.orbit_curves import continue_flip_curve, continue_orbit_curve, continue_torus_curve
from .plane.stick_curves import continue_stick_curve

#: The curve of each kind of an orbit branch's event other than a fold.
BY_EVENT = {"period-doubling": continue_flip_curve, "torus": continue_torus_curve,
            "stick-onset": continue_stick_curve, "grazing": continue_stick_curve}


def continue_curve(start: Any, make2: Callable[[float, float], Solver], q0: float, q_end: float,
                   **options: Any) -> Curve:
    """Continues a curve of codimension one in the plane (p, q) from ``start`` at q0 to q_end.

    Parameters
    ----------
    start : HopfPoint, Event, CurveEvent or EquationOrbit
        A ``bautin`` event of a Hopf curve (the fold curve of orbits from it:
        :func:`dmi.analysis.plane.bautin_fold.continue_bautin_fold`, with ``make2`` the Hopf
        curve's model; its options ``offset=``, ``amplitude=`` and those of
        :func:`~dmi.analysis.plane.orbit_curves.continue_orbit_curve`), a Hopf point of the
        equation (``hopf(..., of="equation")``, with ``u_eq=``), a ``hopf``
        or ``fold`` event of a branch of the equation's equilibria, a ``fold``,
        ``period-doubling``, ``torus``, ``stick-onset`` or ``grazing`` event of a branch of
        EquationOrbits (with ``branch=``, that branch), or an EquationOrbit near a fold (for the others, call
        :func:`~dmi.analysis.plane.orbit_curves.continue_flip_curve` or
        :func:`~dmi.analysis.plane.orbit_curves.continue_torus_curve` with it).
    make2 : callable
        The model ``make2(p, q) -> dmi.Solver``, configured, not initialised.
    q0 : float
        The start's q.
    q_end : float
        Where to stop; the last point lies on it exactly when the curve gets there.
    **options
        The options of :func:`dmi.analysis.equilibria.curves.continue_curve` (equilibria) or of
        :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve` (orbits; the same for
        period-doubling and torus curves) or of
        :func:`dmi.analysis.plane.stick_curves.continue_stick_curve` (stick onset, grazing).

    Returns
    -------
    Curve
        The curve: ``kind`` ``"hopf"``, ``"fold"``, ``"orbit-fold"``, ``"period-doubling"``,
        ``"torus"``, ``"stick-onset"`` or ``"grazing"``, its points, events and status.
    """
    if isinstance(start, CurveEvent) and start.kind == "bautin":
        return continue_bautin_fold(start, make2, q0, q_end, **options)
    if isinstance(start, Event) and start.kind in BY_EVENT:
        return BY_EVENT[start.kind](start, make2, q0, q_end, **options)
    if isinstance(start, EquationOrbit) or options.get("branch") is not None:
        return continue_orbit_curve(start, make2, q0, q_end, **options)
    return equilibrium_curve(start, make2, q0, q_end, **options)
