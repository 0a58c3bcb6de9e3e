# dmi.analysis.curves: the one entry point of curves in two parameters, by the start's type.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
""":func:`continue_curve`: a curve in the plane (p, q) from its start, as BifurcationKit's
``continuation`` takes a problem of any kind: a Hopf point or a fold of the equation's equilibria
(:func:`dmi.analysis.equilibria.curves.continue_curve`), or a fold of the equation's periodic
orbits, an orbit branch's ``fold`` event given with its ``branch=``, an EquationOrbit near a fold
(:func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve`) or a Hopf curve's ``bautin`` event
(:func:`continue_bautin_fold`), or its ``period-doubling``
or ``torus`` event (:func:`dmi.analysis.plane.orbit_curves.continue_flip_curve`,
:func:`dmi.analysis.plane.orbit_curves.continue_torus_curve`), or its ``stick-onset`` or
``grazing`` event (:func:`dmi.analysis.plane.stick_curves.continue_stick_curve`).  It sits above
the rooms because it reaches both.

The fold of orbits from a Bautin point (:func:`continue_bautin_fold`): at a Bautin point
(p_B, q_B) of a Hopf curve the first Lyapunov coefficient l1 changes sign; on the side where l1 > 0 (subcritical) an unstable small orbit is born and, where the second
coefficient is negative, folds at an amplitude ~ sqrt|q - q_B| and a distance in p ~ (q - q_B)^2
from the Hopf curve; the fold curve of orbits ends at the Bautin point.  The start steps off the
Bautin point along the Hopf curve by delta q towards q_end (default OFFSET_SHARE |q_end - q_B|,
so that the fold's orbit is large enough for collocation and the step stays small against the
curve's span), takes the Hopf point there from the Hopf curve continued to q_B + delta q (its
l1 must be decided positive), the orbit born there of a small amplitude
(``hopf_orbit(..., of="equation")``), continues it in p away from the Hopf point to its ``fold``
event, and hands that to :func:`dmi.analysis.plane.orbit_curves.continue_orbit_curve` towards
q_end.  The curve's first event is a ``bautin`` event at (p_B, q_B), index 0: the curve begins
there; its first computed point is at q_B + delta q (between the two the fold's orbits shrink
to the equilibrium, too small to collocate reliably).  Not covered: a fold on the side where
l1 < 0 (a positive second coefficient): the start is refused there.
"""
from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

from .._solver import Solver
from .branches.collocated import continue_equation_orbit, equation_branch_start
from .collocation.orbit import EquationOrbit
from .continuation.branch import Curve, CurveEvent, Event
from .continuation.driver import ContinuationOptions, curve_range
from .equilibria.curves import CurvePoint
from .equilibria.curves import continue_curve as equilibrium_curve
from .equilibria.normal_form import CriticalityWarning
from .scheme.problem import AtQ
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
        :func:`continue_bautin_fold`, with ``make2`` the Hopf
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
        :func:`dmi.analysis.plane.stick_curves.continue_stick_curve` (stick onset, grazing);
        for a curve of forced orbits, ``period=lambda p, q: ...`` gives the orbit's period at
        (p, q) where the forcing's period changes with them.

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


#: The default step off the Bautin point in q, as a share of |q_end - q_B|.
OFFSET_SHARE = 0.1
#: Points at most on the small orbit's branch in p up to its fold.
ORBIT_POINTS = 80


def _hopf_at(start: CurveEvent, make2: Callable[[float, float], Solver], q: float
             ) -> CurvePoint | None:
    """The Hopf curve's point on q (continued from the Bautin point), with its l1; None where
    the Hopf curve does not get there or l1 is not decided positive there."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", CriticalityWarning)   # l1 ~ 0 at the start
        c = equilibrium_curve(start.hopf, make2, start.q, q, u_eq=start.u,
                              step=abs(q - start.q) / 2, max_points=20)
    pt = c.points[-1]
    if pt.q != q or pt.hopf is None or pt.hopf.criticality != "subcritical" or not pt.hopf.side:
        return None
    return pt


def continue_bautin_fold(start: CurveEvent, make2: Callable[[float, float], Solver],
                         q0: float, q_end: float, *, offset: float | None = None,
                         amplitude: float = 0.01, **options: Any) -> Curve:
    """The fold curve of orbits from a ``bautin`` event of a Hopf curve, towards q_end.

    ``start`` is the event (its ``hopf`` and ``u``), ``make2`` the Hopf curve's model, q0 the
    event's q; ``offset`` the step off it in q (default OFFSET_SHARE |q_end - q0|), ``amplitude``
    the small orbit's at the Hopf point there (as ``hopf_orbit``'s, state units; below the
    fold's); ``options`` go to :func:`continue_orbit_curve`.  Returns its Curve with the
    ``bautin`` event first (index 0).  Raises ValueError: an event without its Hopf point or
    equilibrium, bad q_end or offset, l1 not positive on q_end's side (the message says whether
    it is on the other side or on neither), or no fold of the small orbits found.
    """
    if start.hopf is None or start.u is None:
        raise ValueError("continue_curve: the bautin event has no Hopf point or equilibrium: "
                         "give a 'bautin' event of a Hopf curve (continue_curve of a Hopf point)")
    q0, q_end, _ = curve_range("continue_curve", q0, q_end)
    span = q_end - q0
    dq = OFFSET_SHARE * abs(span) if offset is None else float(offset)
    if not (math.isfinite(dq) and 0.0 < dq < abs(span)):
        raise ValueError(f"continue_curve: offset = {offset!r}: give 0 < offset < |q_end - q0| "
                         f"= {abs(span)!r}")
    q1 = q0 + math.copysign(dq, span)
    pt = _hopf_at(start, make2, q1)
    if pt is None:
        other = _hopf_at(start, make2, q0 - math.copysign(dq, span)) is not None
        where = ("it is on the other side: q_end must lie on that side of q0" if other else
                 "nor on the other side: no subcritical side, no fold of orbits to start")
        raise ValueError(f"continue_curve: from the Bautin point at q0 = {q0!r}, l1 is not "
                         f"decided positive at q = {q1!r} towards q_end = {q_end!r}; {where} "
                         "(or give a larger offset=)")
    h = pt.hopf
    orbit = equation_branch_start(AtQ(make2, q1), h, pt.u, amplitude, 10, 1e-12, 30)
    reach = max(1.0, abs(h.p))
    branch = continue_equation_orbit(
        orbit, h.p + h.side * reach,
        ContinuationOptions(step=2 * amplitude, max_points=ORBIT_POINTS), multipliers=6)
    folds = [e for e in branch.events if e.kind == "fold"]
    if not folds:
        raise ValueError(f"continue_curve: the small orbit born at the Hopf point (p, q) = "
                         f"({h.p!r}, {q1!r}) does not fold within {ORBIT_POINTS} points "
                         f"({branch.status}): give a smaller amplitude= or a larger offset=")
    curve = continue_orbit_curve(folds[0], make2, q1, q_end, branch=branch, **options)
    detail = (f"the fold curve begins at the Bautin point (p, q) = ({start.p!r}, {q0!r}); its "
              f"first point is the fold of the small orbits born at the Hopf point on q = "
              f"{q1!r}")
    curve.events.insert(0, CurveEvent("bautin", float(start.p), q0, 0, detail, u=start.u,
                                      hopf=start.hopf))
    return curve
