# The records of a continued branch: its points, its events, the branch.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Branch, BranchPoint, Event and HopfPoint: what :func:`dmi.analysis.continue_orbit`,
:func:`dmi.analysis.continue_equilibrium` and :func:`dmi.analysis.hopf` return (records only:
this module imports no other of the package)."""
from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np



#: |Im lambda| <= REAL max(1, |lambda|): a real root (the roots' own rounding is about 1e-12).
REAL = 1e-8
#: |Re lambda| <= ON_AXIS max(1, |lambda|) at a located Hopf point: a pair on the imaginary axis.
ON_AXIS = 1e-6


@dataclass(frozen=True)
class HopfPoint:
    """Where the rightmost root crosses the imaginary axis.

    Attributes
    ----------
    p : float
        The parameter.
    omega : float
        The crossing frequency |Im lambda| (radians / time unit); 0: a real root crosses (a fold,
        not a Hopf point).
    root : complex
        The root there, Im >= 0 (1 / time unit).
    l1 : float or None
        The first Lyapunov coefficient in Kuznetsov's normalisation (q^H q = 1,
        p Delta'(i omega) q = 1; l1 = Re c1 / omega), of the equation's Hopf points only
        (``hopf(..., of="equation")``, a branch of the equation's equilibria); None for the
        scheme's, or where it could not be computed (a warning says why).
    l1_error : float or None
        Its estimated error (units of l1).
    criticality : str or None
        ``"supercritical"`` (l1 < 0: a stable orbit is born) or ``"subcritical"`` (l1 > 0: an
        unstable one), only where |l1| > l1_error; else None.
    kappa : numpy.ndarray or None
        Shape (n,): the amplitude coefficients of the orbit born there, (max - min) / 2 of
        component j ~ kappa_j sqrt|p - p_H| on the side :attr:`side` (state units per
        sqrt(parameter unit)); None where the criticality or the crossing speed is not decided.
    crossing_speed : float or None
        Re lambda'(p_H), the speed at which the pair crosses the imaginary axis (1 / (time unit
        parameter unit)); None where not computed.
    """
    p: float
    omega: float
    root: complex
    l1: float | None = None
    l1_error: float | None = None
    criticality: str | None = None
    kappa: np.ndarray | None = field(default=None, compare=False)
    crossing_speed: float | None = None

    @property
    def side(self) -> int | None:
        """+1 where the orbit born exists for p > p_H, -1 for p < p_H (the sign of
        -l1 Re lambda'(p_H)); None where the criticality or the crossing speed is unknown."""
        if self.criticality is None or not self.crossing_speed:
            return None
        return -1 if (self.l1 > 0) == (self.crossing_speed > 0) else 1


#: Samples of the period a branch point keeps (:attr:`BranchPoint.u`).
ORBIT_SAMPLES = 200


def thinned(U: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(t, u) of one period U (M + 1 rows, step h) thinned to at most ORBIT_SAMPLES rows, the
    first and the last kept."""
    M = U.shape[0] - 1
    idx = np.unique(np.round(np.linspace(0, M, min(M + 1, ORBIT_SAMPLES))).astype(int))
    return idx * h, np.array(U[idx])


def corner_sentence(component: int, p: float, towards: str, evidence: str, other: str) -> str:
    """The status of a branch that ended at a corner of a component's stick pattern (its stick
    onset or its grazing), one sentence whatever route the corrector took to fail there.

    Parameters
    ----------
    component : int
        The component whose stick pattern changes at the corner.
    p : float
        The last point's parameter.
    towards : str
        ``"larger"`` or ``"smaller"``: the side of p the branch could not pass to; or
        ``"either"`` where the last points are at one p (a vertical branch).
    evidence : str
        What the last points show of the corner.
    other : str
        What is known of the branch on the other side, and how to follow it.

    Returns
    -------
    str
        ``"the branch ended at a corner of component i's stick pattern near p = ..., which it
        could not pass towards ... p: <evidence>; <other>"``.
    """
    return (f"the branch ended at a corner of component {component}'s stick pattern near "
            f"p = {p:.10g}, which it could not pass towards {towards} p: {evidence}; {other}")


def travel(ps: list[float]) -> str:
    """The way p went over the points ps: ``"larger"``, ``"smaller"``, or ``"either"`` where
    they lie at one p to 1e-7 (relative)."""
    if max(ps) - min(ps) <= 1e-7 * max(1.0, abs(ps[-1])):
        return "either"
    return "larger" if ps[-1] > ps[0] else "smaller"


def non_real(values: np.ndarray) -> np.ndarray:
    """The values (roots, multipliers) that are not real: |Im| > 1e-8 max(1, |value|)."""
    values = np.asarray(values)
    return values[np.abs(values.imag) > 1e-8 * np.maximum(1.0, np.abs(values))]


@dataclass
class BranchPoint:
    """One orbit of a branch.

    Attributes
    ----------
    p : float
        The parameter.
    period : float
        The period (time units).
    amplitude : numpy.ndarray
        Shape (n,): (max - min) / 2 per component (state units).
    multipliers : numpy.ndarray of complex
        The leading Floquet multipliers, largest |mu| first.
    stable : bool or None
        All |mu| < 1 (on an autonomous branch: all but its phase's multiplier 1), verified
        (:func:`dmi.analysis.floquet_verdict`); None where no multiplier was computed
        (``multipliers=0``), where the verification was opted out of (``verify=False``: Ritz
        values have no error bound), or where the verdict stays undecided.
    stick_steps : numpy.ndarray
        Shape (n,): stuck steps per period.
    stick_phases : numpy.ndarray
        Shape (n,): stuck intervals per period.
    margin : numpy.ndarray
        Shape (n,): a component's least force besides friction at its velocity reversals, less the
        friction threshold (force units): > 0 where every reversal slips through, <= 0 where the
        component sticks (:mod:`dmi.analysis.orbits`).
    section : numpy.ndarray
        Shape (k, n): u at t = j period / k, j < k (k = ``Branch.sections``: a Poincare section at
        the forcing period of a k-periodic orbit).
    state : numpy.ndarray
        The shooting state.
    dpds : float
        The tangent's p component (its sign flips at a fold).
    iterations : int
        The corrector's iterations.
    corrector : str
        ``"newton-picard"`` or ``"newton"`` (:mod:`dmi.analysis.orbits`); empty at the
        start.
    t : numpy.ndarray, shape (k,)
        Times of one period of the orbit from t = 0, thinned to at most :data:`ORBIT_SAMPLES`
        samples (both ends kept), for plots (time units).
    u : numpy.ndarray
        Shape (k, n): the orbit at those times (state units).
    floquet : dmi.analysis.Floquet or None
        The verified multipliers and verdict (:func:`dmi.analysis.floquet_verdict`) when the
        branch was continued with ``verify=``; then ``stable`` is its verdict and the
        multipliers' events read its ``nontrivial()`` multipliers.  None otherwise.
    """
    p: float
    period: float
    amplitude: np.ndarray
    multipliers: np.ndarray
    stable: bool | None
    stick_steps: np.ndarray
    stick_phases: np.ndarray
    margin: np.ndarray
    section: np.ndarray
    state: np.ndarray = field(repr=False)
    dpds: float = 0.0
    iterations: int = 0
    corrector: str = ""
    t: np.ndarray = field(default_factory=lambda: np.empty(0), repr=False)
    u: np.ndarray = field(default_factory=lambda: np.empty((0, 0)), repr=False)
    floquet: Any = field(default=None, repr=False)



class EventWarning(RuntimeWarning):
    """A multipliers' event (period doubling, torus) not reported, or a point where it is not
    decided: the multipliers' error bound is larger than their distance to the unit circle."""


@dataclass
class Event:
    """A detected event between points ``index - 1`` and ``index`` of the branch.

    Attributes
    ----------
    kind : str
        ``"fold"``, ``"period-doubling"``, ``"torus"``, ``"stick-onset"`` or ``"grazing"``; on a
        branch of equilibria ``"fold"`` or ``"hopf"``.
    p : float
        Where: the linear interpolation of the test function's zero (located further on a
        branch of equilibria); on a collocated branch (of ``EquationOrbit`` points) a
        ``stick-onset`` or ``grazing`` at the middle of the two points' p, not located (the
        bracket is in ``detail``).
    index : int
        The branch point after the event.
    component : int or None
        The friction component of a stick event, else None.
    detail : str
        A description.
    u : numpy.ndarray or None
        On a branch of equilibria: the equilibrium at the event (state units).
    hopf : HopfPoint or None
        The :class:`HopfPoint` of a ``hopf`` event.
    """
    kind: str
    p: float
    index: int
    component: int | None = None
    detail: str = ""
    u: np.ndarray | None = field(default=None, repr=False)
    hopf: HopfPoint | None = None


@dataclass
class Branch:
    """A continued branch.

    Attributes
    ----------
    points : list of BranchPoint or EquilibriumPoint
        The points, in the order continued.
    events : list of Event
        The detected events.
    status : str
        Why it ended.
    make : callable
        The model ``make(p) -> dmi.Solver``.
    steps : int
        M, the steps of a period.
    h : float
        The start's step (time units).
    rows : int
        L, the rows of the shooting state.
    sections : int
        The Poincare sections per period (:attr:`BranchPoint.section`).
    period : callable or None
        The function p -> period given to :func:`continue_orbit`, or None: the period M h was
        kept.
    kind : str
        ``"orbits"`` (forced), ``"autonomous"`` (orbits of free period: ``column("period")``) or
        ``"equilibria"`` (points are :class:`dmi.analysis.equilibria.equilibrium.EquilibriumPoint`).
    """
    points: list[Any]
    events: list[Event]
    status: str
    make: Callable[..., Any] = field(repr=False)
    steps: int = 0
    h: float = 0.0
    rows: int = 0
    sections: int = 1
    period: Callable[[float], float] | None = field(default=None, repr=False)
    kind: str = "orbits"

    @property
    def p(self) -> np.ndarray:
        """The points' parameters p, in the order continued."""
        return np.array([q.p for q in self.points])

    @property
    def stable(self) -> np.ndarray:
        """The points' ``stable`` verdicts: a boolean array when every point's is verified, else
        an object array of True, False and None (None: not verified, drawn dotted by
        :func:`dmi.analysis.plot_branch`); ``column("stable")`` is the same."""
        return self.column("stable")

    def column(self, name: str) -> np.ndarray:
        """An attribute of every point, stacked.

        Parameters
        ----------
        name : str
            An attribute of the points, e.g. ``"amplitude"``.

        Returns
        -------
        numpy.ndarray
            Shape (points,) + the attribute's shape: ``branch.column("amplitude")`` -> (points, n);
        an object array of the values when one of them is None (``stable`` not verified).

        Raises
        ------
        AttributeError
            The points have no attribute ``name``.
        """
        values = [getattr(q, name) for q in self.points]
        if any(v is None for v in values):   # a verdict not verified: None stays None
            return np.array(values, dtype=object)
        return np.array(values)

    def to_html(self, path: str | os.PathLike, component: int = 0,
                p_label: str = "parameter p") -> None:
        """Writes the interactive figure of the branch to a standalone HTML file (hover a point
        for its data, click it to draw its orbit):
        ``plot_branch(self, html=path, component=component, p_label=p_label)``, see
        :func:`dmi.analysis.plot.interactive.branch_html`.

        Parameters
        ----------
        path : str or os.PathLike
            The HTML file.
        component : int, optional
            The state component plotted.
        p_label : str, optional
            The horizontal axis' label.

        Raises
        ------
        ImportError
            Bokeh is not installed.
        """
        from ..plot.branch import plot_branch
        plot_branch(self, html=path, component=component, p_label=p_label)

    def _repr_html_(self) -> str:
        from ..plot.interactive import branch_summary
        return branch_summary(self)


class AlongQ:
    """A curve point's tangent under the driver's name: the driver's parameter is q on a curve
    in (p, q), so its ``dpds`` is the point's ``dqds`` (a dataclass field of the point)."""
    dqds: float

    @property
    def dpds(self) -> float:
        """The driver's name of ``dqds``."""
        return self.dqds

    @dpds.setter
    def dpds(self, value: float) -> None:
        self.dqds = float(value)


@dataclass
class CurveEvent:
    """A point of codimension two on a :class:`Curve`, or a point asked for with ``at=``.

    Attributes
    ----------
    kind : str
        ``"bautin"`` (l1 changes sign on a Hopf curve), ``"zero-hopf"`` (a real root crosses 0 on
        a Hopf curve; a pair crosses the imaginary axis on a fold curve), ``"hopf-hopf"`` (a
        second pair crosses on a Hopf curve), ``"cusp"`` and ``"bogdanov-takens"`` (on a fold
        curve), ``"orbit-fold"`` (a stick-onset or grazing curve crosses a fold of its orbits),
        or ``"user"``.
    p, q : float
        Where.
    index : int
        The curve's point after the event (the point itself for ``"user"``).
    detail : str
        A description, with the located test function's values.
    u : numpy.ndarray or None
        The equilibrium there.
    hopf : HopfPoint or None
        A Bautin point's Hopf point (l1 about 0).
    """
    kind: str
    p: float
    q: float
    index: int
    detail: str = ""
    u: np.ndarray | None = field(default=None, repr=False)
    hopf: HopfPoint | None = field(default=None, repr=False)


@dataclass
class Curve:
    """A curve in the plane (p, q) from :func:`dmi.analysis.continue_curve`: a Hopf or fold curve
    of the equation's equilibria, a fold of its orbits (``"orbit-fold"``), or where its orbits
    begin to stick or graze (``"stick-onset"``, ``"grazing"``).

    Attributes
    ----------
    kind : str
        ``"hopf"``, ``"fold"``, ``"orbit-fold"``, ``"stick-onset"`` or ``"grazing"``.
    points : list of CurvePoint, OrbitCurvePoint or StickCurvePoint
        The points, in the order continued (the last on q_end when it was reached).
    events : list of CurveEvent
        The codimension-two points located on it, and the ``user`` points, in the order met.
    status : str
        Why it ended: ``"reached q_end = ..."``, ``"left the range [...] after a fold"`` (it
        turned back in q past its start), ``"max_points reached"``, or the corrector failing
        at the smallest step (with, on a Hopf curve whose omega fell towards 0, a sentence
        saying that a Bogdanov-Takens point is near).
    make2 : callable
        The model.
    """
    kind: str
    points: list[Any]
    events: list[CurveEvent]
    status: str
    make2: Callable[[float, float], Any] = field(repr=False)

    @property
    def p(self) -> np.ndarray:
        """The points' p."""
        return np.array([pt.p for pt in self.points])

    @property
    def q(self) -> np.ndarray:
        """The points' q."""
        return np.array([pt.q for pt in self.points])

    @property
    def omega(self) -> np.ndarray:
        """The points' omega (0 on a fold curve)."""
        return np.array([pt.omega for pt in self.points])
