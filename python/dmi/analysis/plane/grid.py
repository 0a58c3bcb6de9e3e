# Grids of one-parameter continuations in the plane (p, q): one task a value of q, serially or on
# a Dask cluster, each task's branches kept as plain records.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis.continue_over: one-parameter continuations over the values of a second parameter.

The user's function ``branches(q)`` computes the branches at one q (equilibria from
:func:`dmi.analysis.continue_equilibrium`, orbits from :func:`dmi.analysis.continue_orbit`, any
number of them, with the options the user picks); :func:`continue_over` calls it once a value of
q, in this process or as one task each on a ``dask.distributed.Client``, and keeps of each branch
a :class:`Trace` (its points' p, verified verdicts, amplitudes and sticking, its events, its
status): plain arrays and strings, which travel back from a worker by pickle and compare bitwise.
A q whose task raises, or whose task the cluster loses, gets a :class:`GridRow` with the error
and no branches: every q has exactly one row, in the order given.
"""
from __future__ import annotations

import functools
import math
import traceback
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..collocation.signature import HI, LO, STUCK

#: Event kinds a branch of equilibria reports whose side decides the rest's verdict.
REST_EVENTS = ("hopf", "fold", "branch-point")
#: Event kinds of an orbit branch where its verdict may change.
ORBIT_EVENTS = ("fold", "period-doubling", "torus", "stick-onset", "grazing")
#: Event kinds of an orbit branch where its sticking may change.
STICK_EVENTS = ("stick-onset", "grazing")


class GridWarning(UserWarning):
    """Values of q whose continuation failed (their :class:`GridRow` holds the error), or whose
    task issued warnings (kept in :attr:`GridRow.warnings`)."""


@dataclass(frozen=True)
class GridEvent:
    """An event of one branch of the grid.

    Attributes
    ----------
    kind : str
        The branch event's kind (``"hopf"``, ``"fold"``, ``"branch-point"`` on equilibria;
        ``"fold"``, ``"period-doubling"``, ``"torus"``, ``"stick-onset"``, ``"grazing"`` on
        orbits; ``"user"``).
    p, q : float
        Where (the event's p on the branch at this q).
    branch : str
        The name of its branch in the row.
    on : str
        ``"equilibria"`` or ``"orbits"``: what the branch holds.
    index : int
        The branch point after the event (it lies between points index - 1 and index).
    criticality : str or None
        A Hopf event's ``"supercritical"`` or ``"subcritical"`` (None: not decided, or not a
        Hopf event, or a Hopf point of the scheme).
    l1, l1_error : float or None
        A Hopf event's first Lyapunov coefficient and its estimated error.
    omega : float or None
        A Hopf event's frequency.
    component : int or None
        The friction component of a stick event.
    detail : str
        The branch event's description.
    """
    kind: str
    p: float
    q: float
    branch: str
    on: str
    index: int
    criticality: str | None = None
    l1: float | None = None
    l1_error: float | None = None
    omega: float | None = None
    component: int | None = None
    detail: str = ""


@dataclass
class Trace:
    """What the grid keeps of one branch (plain arrays: it travels by pickle).

    Attributes
    ----------
    name : str
        Its name in the row (the key ``branches(q)`` gave, or ``"branch"``).
    on : str
        ``"equilibria"`` or ``"orbits"`` (the branch's kind ``"orbits"`` or ``"autonomous"``).
    p : numpy.ndarray
        The points' parameters, in the order continued.
    stable : numpy.ndarray of object
        The points' verified verdicts: True, False or None (not decided).
    amplitude : numpy.ndarray
        Shape (points, n): (max - min) / 2 of each component (0 on equilibria).
    sticks : numpy.ndarray of object
        Orbits: True where a friction component sticks (or a box holds one) somewhere in the
        period, else False; None on equilibria.
    events : list of GridEvent
        The branch's events.
    status : str
        Why the branch ended.
    """
    name: str
    on: str
    p: np.ndarray
    stable: np.ndarray
    amplitude: np.ndarray
    sticks: np.ndarray
    events: list[GridEvent]
    status: str


@dataclass
class GridRow:
    """The continuations at one value of q.

    Attributes
    ----------
    q : float
        The value.
    branches : dict of str to Trace
        Its branches (empty when the task failed).
    error : str or None
        ``"<exception type>: <message>"`` and the traceback's last lines when ``branches(q)``
        raised, or why the cluster lost the task; None when it ran.
    warnings : tuple of str
        The warnings the task issued (``"<category>: <message>"``), kept in the row because a
        worker's warnings do not reach this process.
    """
    q: float
    branches: dict[str, Trace]
    error: str | None = None
    warnings: tuple[str, ...] = ()


@dataclass
class Grid:
    """One-parameter continuations over the values of q (:func:`continue_over`).

    Attributes
    ----------
    q_values : numpy.ndarray
        The values, in the order given.
    rows : list of GridRow
        One a value, in that order.
    """
    q_values: np.ndarray
    rows: list[GridRow] = field(default_factory=list)

    @property
    def failed(self) -> list[GridRow]:
        """The rows whose task failed (their ``error``)."""
        return [r for r in self.rows if r.error is not None]

    def events(self, kind: str | None = None, on: str | None = None) -> list[GridEvent]:
        """The events of every branch of every row.

        Parameters
        ----------
        kind : str, optional
            Only events of this kind (e.g. ``"hopf"``).
        on : str, optional
            Only events of branches of ``"equilibria"`` or of ``"orbits"``.

        Returns
        -------
        list of GridEvent
            In the rows' order, then the branches', then each branch's.
        """
        return [e for r in self.rows for t in r.branches.values() for e in t.events
                if (kind is None or e.kind == kind) and (on is None or e.on == on)]


def _sticks(point: Any) -> bool:
    """An orbit point sticks somewhere in its period: a stuck step (the scheme's BranchPoint) or a
    stuck or held segment (the equation's EquationOrbit)."""
    if hasattr(point, "stick_steps"):
        return bool(np.any(np.asarray(point.stick_steps) > 0))
    modes = np.asarray(point.signature.modes)
    return bool(np.any((modes == STUCK) | (modes == LO) | (modes == HI)))


def trace_of(name: str, branch: Any, q: float) -> Trace:
    """The :class:`Trace` of a branch (from :func:`dmi.analysis.continue_equilibrium` or
    :func:`dmi.analysis.continue_orbit`) at q.

    Raises
    ------
    TypeError
        ``branch`` is not such a branch.
    """
    kind = getattr(branch, "kind", None)
    if kind not in ("equilibria", "orbits", "autonomous") or not hasattr(branch, "points"):
        raise TypeError(f"branches(q = {q!r}) gave {name} = {type(branch).__name__}: give a "
                        "branch of dmi.analysis.continue_equilibrium or continue_orbit (or a "
                        "dict of them)")
    on = "equilibria" if kind == "equilibria" else "orbits"
    pts = branch.points
    n = len(pts[0].u) if on == "equilibria" and pts else (
        len(pts[0].amplitude) if pts else 0)
    amplitude = np.array([np.zeros(n) if on == "equilibria" else np.asarray(pt.amplitude, float)
                          for pt in pts]).reshape(len(pts), n)
    sticks = np.array([None if on == "equilibria" else _sticks(pt) for pt in pts], dtype=object)
    events = []
    for e in branch.events:
        hp = getattr(e, "hopf", None)
        events.append(GridEvent(
            e.kind, float(e.p), float(q), name, on, int(e.index),
            criticality=getattr(hp, "criticality", None),
            l1=None if getattr(hp, "l1", None) is None else float(hp.l1),
            l1_error=None if getattr(hp, "l1_error", None) is None else float(hp.l1_error),
            omega=None if hp is None else float(hp.omega),
            component=e.component, detail=str(e.detail)))
    return Trace(name, on, np.array([float(pt.p) for pt in pts]),
                 np.array([pt.stable if pt.stable is None else bool(pt.stable) for pt in pts],
                          dtype=object),
                 amplitude, sticks, events, str(branch.status))


def _row(branches: Callable[[float], Any], q: float) -> GridRow:
    """One task: branches(q) and its traces; an exception becomes the row's error."""
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        try:
            got = branches(q)
            named = dict(got) if isinstance(got, Mapping) else {"branch": got}
            traces = {str(k): trace_of(str(k), b, q) for k, b in named.items()}
            error = None
        except Exception as e:   # the row says what failed; the other rows go on
            tb = traceback.format_exception(type(e), e, e.__traceback__)
            traces, error = {}, f"{type(e).__name__}: {e}\n" + "".join(tb[-3:])
    said = tuple(f"{w.category.__name__}: {w.message}" for w in seen)
    return GridRow(q, traces, error, said)


def continue_over(q_values: Sequence[float], branches: Callable[[float], Any], *,
                  client: Any = None) -> Grid:
    """Runs ``branches(q)`` (one-parameter continuations at q) for every value of q, serially or
    on a Dask cluster, and keeps their branches as :class:`Trace` s.

    Parameters
    ----------
    q_values : sequence of float
        The values of q: one-dimensional, finite, no value twice.
    branches : callable
        ``branches(q)`` returns a branch of :func:`dmi.analysis.continue_equilibrium` or
        :func:`dmi.analysis.continue_orbit`, or a dict name -> branch (e.g. ``{"rest": ...,
        "orbits": ...}``), of the model ``make2(p, q)`` at that q.  With ``client`` it travels to
        the workers by Dask's pickle (cloudpickle: closures and lambdas go).
    client : dask.distributed.Client, optional
        Runs one task a value of q on its cluster (a ``LocalCluster``, a scheduler reached over
        tcp or tls, e.g. ``dmi_sweep.run.make_client``, a dask-jobqueue ``SLURMCluster``, a
        Kubernetes cluster; any object with ``submit(fn)`` returning futures with ``.result()``).
        None: in this process, one q after the other.  The rows are the same bitwise either way
        (each task runs the same code on the same inputs).

    Returns
    -------
    Grid
        One :class:`GridRow` a value of q, in the order given.  A task that raised, or that the
        cluster lost (a worker killed, ...), gives a row with its ``error`` and no branches, and
        one :class:`GridWarning` names those values; the others are kept.  The tasks' own
        warnings are kept in their rows (``GridRow.warnings``), one :class:`GridWarning` saying
        which rows have some.

    Raises
    ------
    ValueError
        ``q_values`` empty, not one-dimensional, not finite or with a value twice; ``branches``
        not callable.
    TypeError
        ``client`` given and ``branches`` cannot be sent to it (pickle).

    Examples
    --------
    A grid of the equilibria and the orbits born at their Hopf point, on the cluster of a
    scheduler reached over TLS (``dmi_sweep.run.make_client``; ``make_client(4, None)`` starts a
    LocalCluster of 4 processes; a dask-jobqueue ``SLURMCluster`` or a Kubernetes cluster gives
    its ``Client(cluster)`` the same way)::

        def branches(q):
            make = lambda p: make2(p, q)
            rest = continue_equilibrium(equilibrium(make, p0, u0, of="equation"), p1)
            (h,) = [e for e in rest.events if e.kind == "hopf"]
            orbit = hopf_orbit(make, h.hopf, h.u, amplitude=0.01, of="equation")
            return {"rest": rest, "orbits": continue_orbit(orbit, p0)}

        address = "tls://scheduler:8786"
        client = make_client(None, address, security(address, ca_file, cert_file, key_file))
        grid = continue_over(np.linspace(q0, q1, 40), branches, client=client)
        plot_curves(curves, grid, html="map.html")
    """
    Q = np.array(q_values, dtype=float, ndmin=1)
    if Q.ndim != 1 or Q.size == 0 or not np.all(np.isfinite(Q)):
        raise ValueError(f"continue_over: q_values = {q_values!r}: give a one-dimensional "
                         "sequence of finite values (at least one)")
    if np.unique(Q).size != Q.size:
        raise ValueError(f"continue_over: q_values has a value twice "
                         f"({sorted({float(x) for x in Q if np.sum(Q == x) > 1})}): give each "
                         "value once")
    if not callable(branches):
        raise ValueError(f"continue_over: branches = {branches!r}: give a function q -> the "
                         "branches at q")
    if client is None:
        rows = [_row(branches, float(q)) for q in Q]
    else:
        rows = _on_cluster(client, branches, Q)
    grid = Grid(Q, rows)
    said = [r for r in rows if r.warnings]
    if said:   # a task's warnings are kept in its row (a worker's would not reach here)
        warnings.warn(f"continue_over: the tasks at {len(said)} of {len(Q)} values of q issued "
                      f"warnings, the first at q = {said[0].q:.8g}: {said[0].warnings[0]} "
                      "(GridRow.warnings has each)", GridWarning, stacklevel=2)
    if grid.failed:
        warnings.warn(f"continue_over: the continuations at {len(grid.failed)} of {len(Q)} "
                      f"values of q failed, at q = "
                      f"{', '.join(f'{r.q:.8g}' for r in grid.failed[:6])}"
                      f"{', ...' if len(grid.failed) > 6 else ''}: "
                      f"{grid.failed[0].error.splitlines()[0]} (the first; GridRow.error has "
                      "each)", GridWarning, stacklevel=2)
    return grid


def _on_cluster(client: Any, branches: Callable[[float], Any], Q: np.ndarray) -> list[GridRow]:
    """One task a q on the client; a task that fails on the cluster gives a row with the error.
    An interrupt cancels the tasks not finished."""
    futures = []
    try:
        for q in Q:
            try:
                futures.append(client.submit(functools.partial(_row, branches, float(q))))
            except Exception as e:
                raise TypeError(f"continue_over: branches could not be sent to the cluster: "
                                f"{type(e).__name__}: {e}") from e
        rows = []
        for q, f in zip(Q, futures):
            try:
                rows.append(f.result())
            except Exception as e:   # the cluster lost the task: the row says so
                rows.append(GridRow(float(q), {}, f"the cluster lost the task: "
                                    f"{type(e).__name__}: {e}"))
        return rows
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def _nodes(trace: Trace) -> list[tuple[float, int | None, GridEvent | None]]:
    """The branch as a path in p: its points with its events between them, (p, point index or
    None, event or None) in the order continued (a fold is a node where p turns back)."""
    out: list[tuple[float, int | None, GridEvent | None]] = []
    for i, p in enumerate(trace.p):
        out += [(e.p, None, e) for e in trace.events if e.index == i and i > 0
                and math.isfinite(e.p)]
        out.append((float(p), i, None))
    return out


def _stretch_value(nodes: list, k: int, values: np.ndarray, kinds: tuple[str, ...]) -> Any:
    """The value (a verdict, or sticking) on the piece between nodes k and k + 1: that of the
    points reached from it in either direction before an event of the kinds; where the two
    sides' points disagree (a change without such an event), or a side's is None, None."""
    found = []
    for rng in (range(k, -1, -1), range(k + 1, len(nodes))):
        for j in rng:
            _, i, e = nodes[j]
            if e is not None and e.kind in kinds:
                break
            if i is not None:
                found.append(values[i])
                break
    if not found or any(v is None for v in found) or any(v != found[0] for v in found):
        return None
    return found[0]


def _pieces(trace: Trace, p: float, values: np.ndarray, kinds: tuple[str, ...]) -> list[Any]:
    """The values on the pieces of the trace's path that pass p (strictly inside)."""
    nodes = _nodes(trace)
    return [_stretch_value(nodes, k, values, kinds) for k in range(len(nodes) - 1)
            if min(nodes[k][0], nodes[k + 1][0]) < p < max(nodes[k][0], nodes[k + 1][0])]


def facts_at(row: GridRow, p: float) -> tuple[bool | None, bool | None, bool | None, bool]:
    """(rest stable, a stable orbit, it sticks, undecided) at p in a row, from verified verdicts
    only.

    rest: True where a branch of equilibria is verified stable at p, False where every branch of
    equilibria through p is verified unstable, None otherwise (no branch through p, or a verdict
    not decided).  orbit: True where an orbit branch is verified stable at p, None where a
    branch through p is not decided, else False.  sticks: whether the stable orbit sticks (None:
    not decided, or no stable orbit).  undecided: a verdict or a sticking through p is None (not
    decided) where it would decide the region."""
    rest: list[Any] = []
    orbit: list[tuple[Any, Any]] = []
    for t in row.branches.values():
        if t.on == "equilibria":
            rest += _pieces(t, p, t.stable, REST_EVENTS)
        else:
            orbit += zip(_pieces(t, p, t.stable, ORBIT_EVENTS),
                         _pieces(t, p, t.sticks, STICK_EVENTS))
    r = True if True in rest else (False if rest and all(v is False for v in rest) else None)
    stable = [s for v, s in orbit if v is True]
    o = True if stable else (None if any(v is None for v, _ in orbit) else False)
    sticks = None
    if stable and all(s == stable[0] for s in stable):
        sticks = stable[0]
    undecided = (r is None and None in rest) or (o is None) or (
        r is False and o is True and sticks is None)
    return r, o, sticks, bool(undecided)


#: The regions of the diagram, by name: what holds there.
REGIONS = {
    "stable rest": "the equilibrium is stable and no stable orbit was found",
    "oscillation": "the equilibrium is unstable and a stable orbit slips throughout",
    "stick-slip": "the equilibrium is unstable and a stable orbit sticks for part of its period",
    "bistable": "a stable equilibrium and a stable orbit coexist",
}
#: The name of an interval where a verdict that would decide the region is not decided.
UNDECIDED = "undecided"


def region_of(rest: bool | None, orbit: bool | None, sticks: bool | None,
              undecided: bool = False) -> str | None:
    """The region's name for the facts at a point (:func:`facts_at`): a key of
    :data:`REGIONS`; :data:`UNDECIDED` where a verdict that would decide it is None; None where
    the verified facts name no region (nothing stable found, or no branch there)."""
    if rest is True and orbit is not None:
        return "bistable" if orbit else "stable rest"
    if rest is False and orbit is True and sticks is not None:
        return "stick-slip" if sticks else "oscillation"
    return UNDECIDED if undecided else None


def regions(row: GridRow) -> list[tuple[float, float, str | None]]:
    """The row's intervals of p and their regions: (p_lo, p_hi, name), in p, cut at every point
    and event of the row's branches (name: as :func:`region_of`), neighbours of one name
    merged."""
    cuts = sorted({float(x) for t in row.branches.values() for x in t.p}
                  | {e.p for t in row.branches.values() for e in t.events
                     if math.isfinite(e.p)})
    out: list[tuple[float, float, str | None]] = []
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        if hi <= lo:
            continue
        name = region_of(*facts_at(row, 0.5 * (lo + hi)))
        if out and out[-1][2] == name and out[-1][1] == lo:
            out[-1] = (out[-1][0], hi, name)
        else:
            out.append((lo, hi, name))
    return out
