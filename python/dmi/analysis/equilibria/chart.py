# Stability charts of a two-parameter model: the rightmost root on a grid, in processes or on Dask,
# and the Hopf curves traced by continuation; the chart's figure.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis.stability_chart and dmi.analysis.plot_stability_chart."""
from __future__ import annotations

import functools
import os
import pickle
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.optimize

from ..._solver import Solver
from ..core.model import Linearisation, call_make, equilibrium
from ..scheme.floquet import StabilityWarning
from ..continuation.driver import ContinuationOptions, continuation
from ..core.newton import ShootingError
from .curves import CurvePoint, curve_of, not_a_start, system
from .root_verdict import RootVerdict, roots_verdict
from .stability import check_of, rightmost_of

#: Relative tolerance (of the range of p) of a traced curve's start p; a tenth of it is the
#: corrector's tolerance on the curve.
TRACE_TOL = 1e-9
#: A crossing root with |Im lambda| above this starts a Hopf curve, else a fold curve.
OMEGA_MIN = 1e-8
#: The fill of the chart's cells without a verdict (grey, hatched).
UNDECIDED_COLOR = "#d9d9d9"


@dataclass
class HopfCurve:
    """A curve of the (p, q) plane where one root lambda = i omega sits on the imaginary axis,
    traced by continuation in q.

    Attributes
    ----------
    p, q : numpy.ndarray
        The parameters of its points, in the order traced.
    omega : numpy.ndarray
        The crossing frequency at each point (radians / time unit); 0 throughout: a real root
        crosses (a fold, not Hopf).
    """
    p: np.ndarray
    q: np.ndarray
    omega: np.ndarray

    @property
    def is_hopf(self) -> bool:
        """True if the crossing root is complex (omega > 0)."""
        return bool(np.median(self.omega) > 1e-8)


@dataclass
class StabilityChart:
    """The result of :func:`stability_chart`.

    Attributes
    ----------
    p_values, q_values : numpy.ndarray
        The grid's parameters, shapes (P,) and (Q,).
    re, im : numpy.ndarray, shape (Q, P)
        ``re[j, i]`` and ``im[j, i]``: the real and imaginary parts (1 / time unit) of the
        rightmost root at (p_values[i], q_values[j]), as the root finder gave them (not a
        verdict: see ``verdict``).
    curves : list of HopfCurve
        The traced Hopf and fold curves.
    verdict : numpy.ndarray of object, shape (Q, P)
        ``verdict[j, i]``: the verified verdict at the grid point
        (:mod:`dmi.analysis.equilibria.root_verdict`, as :attr:`Equilibrium.stable`): True (verified
        stable), False (verified unstable) or None (not decided, ``reason`` says why; or not
        verified: ``verify=False``, or a chart built without verdicts).
    reason : numpy.ndarray of str, shape (Q, P)
        How each cell's verdict was reached, or why there is none.
    error : numpy.ndarray, shape (Q, P)
        The error of ``re`` the verdict used (1 / time unit; nan where not verified).
    """
    p_values: np.ndarray
    q_values: np.ndarray
    re: np.ndarray
    im: np.ndarray
    curves: list[HopfCurve] = field(default_factory=list)
    verdict: np.ndarray | None = None
    reason: np.ndarray | None = None
    error: np.ndarray | None = None

    def __post_init__(self) -> None:
        shape = np.shape(self.re)
        if self.verdict is None:
            self.verdict = np.full(shape, None, dtype=object)
            if self.reason is None:
                self.reason = np.full(shape, "not verified (no verdict was given)", dtype=object)
        if self.reason is None:
            self.reason = np.full(shape, "", dtype=object)
        if self.error is None:
            self.error = np.full(shape, np.nan)

    @property
    def stable(self) -> np.ndarray:
        """Boolean mask of the grid points verified asymptotically stable (verdict True).  A
        cell whose verdict is None is neither in ``stable`` nor in ``unstable``."""
        return _is(self.verdict, True)

    @property
    def unstable(self) -> np.ndarray:
        """Boolean mask of the grid points verified unstable (verdict False)."""
        return _is(self.verdict, False)

    @property
    def undecided(self) -> np.ndarray:
        """Boolean mask of the grid points without a verdict (None: not decided or not
        verified)."""
        return _is(self.verdict, None)

    def to_html(self, path: str | os.PathLike, p_label: str = "parameter p",
                q_label: str = "parameter q", title: str | None = None) -> None:
        """Writes the interactive chart to a standalone HTML file (hover a grid point for its
        rightmost root): :func:`dmi.analysis.plot.interactive.chart_html`.

        Parameters
        ----------
        path : str or os.PathLike
            The HTML file.
        p_label, q_label : str, optional
            The axes' labels.
        title : str, optional
            The figure's title.

        Raises
        ------
        ImportError
            Bokeh is not installed.
        """
        from ..plot.interactive import chart_html
        chart_html(self, path, p_label=p_label, q_label=q_label, title=title)

    def _repr_html_(self) -> str:
        from ..plot.interactive import chart_summary
        return chart_summary(self)


def _is(verdict: np.ndarray, value: bool | None) -> np.ndarray:
    """Boolean mask of the cells whose verdict is ``value`` (True, False or None)."""
    v = np.asarray(verdict, dtype=object)
    same = ((x is None) if value is None else (x is not None and bool(x) is value)
            for x in v.ravel())
    return np.fromiter(same, dtype=bool, count=v.size).reshape(v.shape)


def _cell(make2: Callable[[float, float], Solver], p: float, q: float, u_eq: Any, count: int,
          tol: float, of: str, verify: bool) -> tuple[complex, RootVerdict]:
    """The rightmost root at (p, q) and its verdict, verified
    (:func:`dmi.analysis.equilibria.root_verdict.check`) or not."""
    lam, verdict = roots_verdict(lambda: call_make(make2, p, q), u_eq, (p, q), count, tol, of,
                                 verify)
    return complex(lam[0]), verdict


def _root_at(make2: Callable[[float, float], Solver], p: float, q: float, u_eq: Any, count: int,
             tol: float, of: str = "scheme") -> np.ndarray:
    with Linearisation(lambda: call_make(make2, p, q), u_eq, (p, q), tol, of) as lin:
        return rightmost_of(lin, count, of)


def _row(make2: Callable, p_values: np.ndarray, q: float, u_eq: Any, count: int,
         tol: float, of: str = "scheme", verify: bool = True
         ) -> list[tuple[complex, RootVerdict]]:
    """The rightmost root and its verdict at every p of one row q (a task of the pool or of
    Dask)."""
    return [_cell(make2, p, q, u_eq, count, tol, of, verify) for p in p_values]


def _given(u_eq: Any, n: int, p: float, q: float) -> np.ndarray:
    """The chart's equilibrium at (p, q): u_eq(p, q), or the constant u_eq."""
    return equilibrium(u_eq, n, (p, q))


def _leg(make2: Callable, p0: float, q0: float, q_end: float, omega0: float, u_eq: Any,
         rows: np.ndarray, tol: float, of: str, lo: float, hi: float) -> list[CurvePoint]:
    """The curve's points on the grid's rows from (p0, q0) towards q_end, in the order traced,
    up to where it leaves the p range [lo, hi]: the driver on the extended system of
    :func:`dmi.analysis.equilibria.curves.system`, the chart's equilibrium given and the
    characteristic matrix of ``of``."""
    s = call_make(make2, p0, q0)
    n = s.n
    s.close()
    given = functools.partial(_given, u_eq, n)
    inside = [q for q in rows if min(q0, q_end) < q < max(q0, q_end)]
    disc, x0 = system("hopf" if omega0 > OMEGA_MIN else "fold", p0, given(p0, q0), omega0,
                      make2, q0, tol=0.1 * TRACE_TOL, given=given, of=of, lin_tol=tol,
                      tests=False)
    try:   # the first step a row's spacing (the points between rows are not kept)
        options = ContinuationOptions(step=abs(q_end - q0) / (len(inside) + 1), at=tuple(inside),
                                      tol=0.1 * TRACE_TOL, max_iter=10, easy=4)
        b = continuation(disc, x0, q0, q_end, options, make=make2, kind=disc.kind)
    except ShootingError as e:
        raise not_a_start(disc, x0, q0, 0.1 * TRACE_TOL, e) from None
    curve = curve_of(b, disc, omega0)
    slack = 1e-9 * max(1.0, hi - lo)
    out = []
    for pt in curve.points:
        if not lo - slack <= pt.p <= hi + slack:
            break
        if pt.q in rows:
            out.append(pt)
    return out


def _trace(make2: Callable, p_values: np.ndarray, q_values: np.ndarray, u_eq: Any, count: int,
           tol: float, j0: int, p_a: float, p_b: float, of: str = "scheme") -> HopfCurve:
    """The curve through the crossing of the rightmost root between p_a and p_b on row j0 (by
    Brent's method), continued by arclength both ways in q over the grid's rows
    (:func:`_leg`, through turning points in q): its points on
    the rows, in the order traced, until it leaves the grid (a task).  A curve that cannot be
    continued from its crossing is that one point, with a ``UserWarning`` saying why."""
    q0 = float(q_values[j0])
    span = float(np.ptp(p_values)) or 1.0
    lo, hi = float(np.min(p_values)), float(np.max(p_values))
    g = lambda p: float(_root_at(make2, p, q0, u_eq, count, tol, of)[0].real)  # noqa: E731
    p0 = scipy.optimize.brentq(g, p_a, p_b, xtol=TRACE_TOL * span)
    lam0 = _root_at(make2, p0, q0, u_eq, count, tol, of)[0]
    omega0 = abs(lam0.imag)
    rows = np.array(q_values, dtype=float)
    first, last = (rows.min(), rows.max()) if rows[0] <= rows[-1] else (rows.max(), rows.min())
    legs = []
    for q_end in (first, last):
        if q_end == q0:
            legs.append([])
            continue
        try:
            legs.append(_leg(make2, p0, q0, q_end, omega0, u_eq, rows, tol, of, lo, hi))
        except ValueError as e:
            warnings.warn(f"stability_chart: the curve through (p, q) = ({p0:.10g}, {q0:.10g}) "
                          f"could not be continued towards q = {q_end:.10g}: {e}", UserWarning,
                          stacklevel=2)
            legs.append([])
    here = [CurvePoint(p=p0, q=q0, u=np.empty(0), omega=omega0)]
    pts = (legs[0] or here)[::-1] + (legs[1] or here)[1:]   # each leg starts at q0
    return HopfCurve(p=np.array([pt.p for pt in pts]), q=np.array([pt.q for pt in pts]),
                     omega=np.array([abs(pt.omega) for pt in pts]))


def _brackets(re: np.ndarray) -> list[tuple[int, int]]:
    """(row j, column i) of the sign changes of re between columns i and i + 1, one per chain of
    such changes linked from row to row (at most one column apart): one start per curve."""
    changes = [(j, i) for j in range(re.shape[0]) for i in range(re.shape[1] - 1)
               if np.isfinite(re[j, i]) and np.isfinite(re[j, i + 1])
               and (re[j, i] < 0) != (re[j, i + 1] < 0)]
    parent = {c: c for c in changes}

    def find(c):
        while parent[c] != c:
            parent[c] = parent[parent[c]]
            c = parent[c]
        return c
    for (j, i) in changes:
        for di in (-1, 0, 1):
            other = (j + 1, i + di)
            if other in parent:
                parent[find(other)] = find((j, i))
    chains: dict = {}
    for c in changes:
        chains.setdefault(find(c), []).append(c)
    return [sorted(chain)[len(chain) // 2] for chain in chains.values()]


def _same_curve(a: HopfCurve, b: HopfCurve, span: float) -> bool:
    """b lies on a: at least 80 % of b's points at a point of a on the same row within 1e-6
    span in p."""
    on = 0
    for p, q in zip(b.p, b.q):
        on += bool(np.any((a.q == q) & (np.abs(a.p - p) <= 1e-6 * span)))
    return on >= 0.8 * len(b.p)


def _run_all(executor: Any, tasks: list[Callable[[], Any]]) -> list[Any]:
    """Runs the tasks (callables without arguments) on executor (.submit(fn) -> future with
    .result(): a concurrent.futures executor or a dask.distributed Client), in order; the first
    failure cancels the others and is raised."""
    futures = [executor.submit(t) for t in tasks]
    try:
        return [f.result() for f in futures]
    except BaseException:
        for f in futures:
            f.cancel()
        raise


def stability_chart(make2: Callable[[float, float], Solver], p_values: Sequence[float],
                    q_values: Sequence[float], u_eq: Any, *, count: int = 4,
                    workers: int | None = None, client: Any = None, trace: bool = True,
                    tol: float = 1e-9, of: str = "scheme", verify: bool = True
                    ) -> StabilityChart:
    """The stability chart of a two-parameter model: the rightmost root (:func:`roots`) at every
    grid point and its verified verdict (:mod:`dmi.analysis.equilibria.root_verdict`, as
    :func:`equilibrium`'s), computed row by row (one task per q), and the :class:`HopfCurve` s
    traced by continuation from each chain of sign changes of the grid (one task per chain).  The
    pool this function starts is shut down before it returns, also on an error.

    Parameters
    ----------
    make2 : callable
        The model ``make2(p, q) -> dmi.Solver``, configured, not initialised.  It travels to other
        processes by pickle: a module-level function or a ``functools.partial`` of one, not a
        lambda or a closure.
    p_values : sequence of float
        The grid's p, >= 2 finite values.
    q_values : sequence of float
        The grid's q, >= 1 finite values.
    u_eq : array_like or callable
        The constant history (the equilibrium), shape (n,), or a function ``u_eq(p, q)``;
        pickled as ``make2``.
    count : int, optional
        Roots computed at each point (the rightmost is kept).
    workers : int, optional
        Processes of the pool (default: the cores this process may use).
    client : optional
        A Dask cluster's ``dask.distributed.Client`` (e.g. from ``dmi_sweep.run.make_client``; any
        object with ``submit(fn)`` returning futures) that runs the tasks instead of a pool.
    trace : bool, optional
        Trace the Hopf and fold curves.
    tol : float, optional
        The equilibrium's residual tolerance, as for :func:`roots`.
    of : {"scheme", "equation"}, optional
        ``"scheme"`` (the default: the roots that match simulation) or ``"equation"`` (each root
        refined to the continuous equation's, :func:`roots`).
    verify : bool, optional
        True (the default): every cell's verdict is verified (the equation's roots counted by
        the argument principle, the scheme's largest multiplier by a second eigen-solve); one
        :class:`dmi.analysis.StabilityWarning` names the cells not decided (verdict None) and
        the first one's reason.  False opts out: every verdict is None, with a ``UserWarning``
        (the roots ``re``, ``im`` and the curves are computed as with True).

    Returns
    -------
    StabilityChart
        The grid's rightmost roots, their verdicts and the traced curves.

    Raises
    ------
    ValueError
        Fewer than 2 p values or 1 q value, not one-dimensional or not finite, ``of`` unknown,
        ``verify`` not a bool, or as :func:`roots` at a grid point (u_eq not an equilibrium,
        :class:`KinkError`).
    TypeError
        ``make2`` or ``u_eq`` cannot be pickled (without ``client``).
    Exception
        The model's own, when ``make2(p, q)`` fails.
    """
    of = check_of(of)
    P = np.array(p_values, dtype=float, ndmin=1)
    Q = np.array(q_values, dtype=float, ndmin=1)
    if P.ndim != 1 or Q.ndim != 1 or len(P) < 2 or len(Q) < 1:
        raise ValueError("dmi.analysis.stability_chart: p_values needs >= 2 values and q_values "
                         ">= 1, one-dimensional")
    if not (np.all(np.isfinite(P)) and np.all(np.isfinite(Q))):
        raise ValueError("dmi.analysis.stability_chart: p_values and q_values must be finite")
    if not isinstance(verify, bool):
        raise ValueError(f"dmi.analysis.stability_chart(..., verify = {verify!r}): give True (the "
                         "default: verified verdicts) or False (opt out: verdicts None)")
    args = (make2, u_eq, int(count), float(tol))
    pool = None
    if client is None:
        try:
            pickle.dumps((make2, u_eq))
        except Exception as e:
            raise TypeError(f"dmi.analysis.stability_chart: make2 and u_eq go to other processes "
                            f"by pickle, and {e}: use a module-level function or a "
                            "functools.partial of one, not a lambda or a closure") from e
        n = workers or len(os.sched_getaffinity(0))
        pool = ProcessPoolExecutor(max_workers=max(1, min(n, len(Q))))
    try:
        ex = client if client is not None else pool
        rows = _run_all(ex, [functools.partial(_row, make2, P, q, u_eq, args[2], args[3], of,
                                               verify) for q in Q])
        lam = np.array([[c[0] for c in row] for row in rows], dtype=complex)
        verdict = np.empty(lam.shape, dtype=object)
        reason = np.empty(lam.shape, dtype=object)
        error = np.empty(lam.shape)
        for j, row in enumerate(rows):
            for i, (_, v) in enumerate(row):
                verdict[j, i], reason[j, i], error[j, i] = v.stable, v.reason, v.error
        chart = StabilityChart(P, Q, lam.real.copy(), lam.imag.copy(), verdict=verdict,
                               reason=reason, error=error)
        _warn_undecided(chart, verify)
        if trace:
            starts = _brackets(chart.re)
            curves = _run_all(ex, [functools.partial(_trace, make2, P, Q, u_eq, args[2], args[3],
                                                     j, P[i], P[i + 1], of) for j, i in starts])
            span = float(np.ptp(P))
            for c in sorted(curves, key=lambda c: -len(c.p)):
                if not any(_same_curve(k, c, span) for k in chart.curves):
                    chart.curves.append(c)
        return chart
    finally:
        if pool is not None:
            pool.shutdown(wait=True, cancel_futures=True)


def _edges(x: np.ndarray) -> np.ndarray:
    """The cells' edges of grid values x (sorted either way): half-way between neighbours, the
    outer ones as far out as the inner ones."""
    mid = 0.5 * (x[:-1] + x[1:])
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


def _warn_undecided(chart: StabilityChart, verify: bool) -> None:
    """verify=False: one UserWarning; otherwise one StabilityWarning naming the cells not
    decided, if any, and the first one's reason."""
    if not verify:
        warnings.warn("stability_chart(verify=False): the roots are ARPACK's Ritz values without "
                      "an error bound, so every verdict is None (stable is empty); leave verify at "
                      "its default (True) for verified verdicts", UserWarning, stacklevel=3)
        return
    open_ = np.argwhere(chart.undecided)
    if len(open_):
        where = ", ".join(f"(p, q) = ({chart.p_values[i]:.8g}, {chart.q_values[j]:.8g})"
                          for j, i in open_[:4])
        j, i = open_[0]
        warnings.warn(f"stability_chart: the stability of {len(open_)} of {chart.re.size} grid "
                      f"points is not decided (verdict None), at {where}"
                      f"{', ...' if len(open_) > 4 else ''}: {chart.reason[j, i]} (the first; "
                      "StabilityChart.reason has each cell's)", StabilityWarning, stacklevel=3)


def plot_stability_chart(chart: StabilityChart, ax: Any = None, *, p_label: str = "parameter p",
                         q_label: str = "parameter q", title: str | None = None,
                         html: str | os.PathLike | None = None) -> Any:
    """Draws a stability chart: the stable region shaded (Re lambda_1 < 0, its zero level
    interpolated between grid points, where the verdicts are verified), the grid points whose
    verdict is None (not decided, or not verified) as grey hatched cells, left out of the shading
    (each cell reaches half-way to its neighbours), the traced Hopf curves as solid lines and the
    fold curves (a real root crossing) dashed, p on the horizontal axis, q on the vertical one.  A
    cell verified unstable is not shaded, whatever its ``re``.  The key sits below the axes, not
    over the data.

    Parameters
    ----------
    chart : StabilityChart
        The chart, from :func:`stability_chart`.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure if None).
    p_label, q_label : str, optional
        The axes' labels: the parameters in words and symbols with units (e.g.
        ``"delay gain a (1/s^2)"``).
    title : str, optional
        The title.
    html : str or os.PathLike, optional
        A path, where the interactive chart of :func:`dmi.analysis.plot.interactive.chart_html` is
        written too.

    Returns
    -------
    matplotlib.axes.Axes
        The Axes drawn on.

    Raises
    ------
    ImportError
        ``html`` given and Bokeh not installed.
    """
    if html is not None:
        from ..plot.interactive import chart_html
        chart_html(chart, html, p_label=p_label, q_label=q_label, title=title)
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch, Rectangle

    if ax is None:
        _, ax = plt.subplots(figsize=(6.4, 5.2), constrained_layout=True)
    P, Q = chart.p_values, chart.q_values
    undecided = chart.undecided
    if len(Q) > 1:   # Re lambda_1 < 0, its zero level interpolated between the grid points
        re = np.clip(np.nan_to_num(chart.re, nan=np.inf, neginf=-1e300), -1.0, 1.0)
        re[chart.unstable & (re < 0)] = 1.0      # a cell verified unstable is not shaded
        ax.contourf(P, Q, np.ma.masked_array(re, mask=undecided), levels=[-2.0, 0.0],
                    colors=["#c6dbef"])
        pe, qe = _edges(P), _edges(Q)
        for j, i in np.argwhere(undecided):
            ax.add_patch(Rectangle((pe[i], qe[j]), pe[i + 1] - pe[i], qe[j + 1] - qe[j],
                                   facecolor=UNDECIDED_COLOR, edgecolor="#969696", hatch="///",
                                   lw=0.0))
    for c in chart.curves:
        ax.plot(c.p, c.q, color="black", lw=1.4, ls="-" if c.is_hopf else "--")
    ax.set_xlim(P.min(), P.max())
    if len(Q) > 1:
        ax.set_ylim(Q.min(), Q.max())
    ax.set_xlabel(p_label)
    ax.set_ylabel(q_label)
    if title:
        ax.set_title(title)
    handles = [Patch(facecolor="#c6dbef", label="stable: Re λ₁ < 0"),
               Line2D([], [], color="black", lw=1.4, label="Hopf curve: λ = ±iω"),
               Line2D([], [], color="black", lw=1.4, ls="--", label="fold: λ = 0")]
    if len(Q) > 1 and undecided.any():
        handles.append(Patch(facecolor=UNDECIDED_COLOR, edgecolor="#969696", hatch="///",
                             label="not decided"))
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13),
              ncol=len(handles), frameon=False, fontsize="small")
    return ax
