# The two-parameter diagram: the curves of continue_curve, the grid's events and the regions they
# decide, drawn with matplotlib (and as an interactive Bokeh page).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis.plot_curves: the map of the plane (p, q) a user reads.

The regions are decided row by row of a :class:`~dmi.analysis.plane.grid.Grid` (one row a value
of q) from verified verdicts only (:func:`dmi.analysis.plane.grid.regions`): the rest's verdicts
on the branches of equilibria, the orbits' on the orbit branches, their sticking, each changing
only at an event of its branch (a Hopf point or fold of the equilibria; a fold, period doubling,
torus, stick onset or grazing of the orbits); an interval where a verdict that would decide it is
None is drawn hatched grey, with one :class:`dmi.analysis.StabilityWarning`.  Each row's
regions fill the band of q half-way to its neighbours.  The curves decide regions too
(:func:`dmi.analysis.plane.style.curve_regions`): *bistable* between a subcritical Hopf curve
and the curve that ends the unstable orbit born there (a fold curve of orbits, or a stick-onset or
grazing curve whose orbits are verified unstable), *stick-slip* on the side of a stick-onset curve
where its verified stable orbits stick; they are drawn as polygons between the curves, keyed
"(from the curves)".  The curves are drawn over them: a Hopf curve solid where supercritical,
dashed where subcritical, dotted where its criticality is not decided; the other kinds by
:data:`dmi.analysis.plane.style.CURVE_STYLES` (fold curves dash-dotted, stick-onset curves solid
orange, grazing curves dashed brown, period-doubling and torus curves green); their
codimension-two points marked, with the crossing of an orbits' fold and a stick-onset curve
(``"orbit-fold"`` events of a stick-onset curve).  The grid's events mark where its branches met
a Hopf point (filled: supercritical, open: subcritical), a fold of orbits, a stick onset or a
grazing: the cross-check of the curves.
"""
from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from typing import Any

from ..scheme.floquet import StabilityWarning
from .grid import REGIONS, UNDECIDED, Grid
from .style import (CRITICALITY_DASH, EVENT_MARKERS, REGION_COLORS, curve_pieces,
                    curve_regions, curve_style, p_range, region_boxes)

#: The curve events marked as points of codimension two (with the crossing of an orbits' fold
#: curve and a stick-onset or grazing curve).
CODIM2 = ("bautin", "bogdanov-takens", "zero-hopf", "hopf-hopf", "cusp", "orbit-fold")

def _warn_undecided(boxes: list) -> None:
    open_ = [b for b in boxes if b[4] == UNDECIDED]
    if open_:
        lo, hi, _, _, _, q = open_[0]
        warnings.warn(f"plot_curves: {len(open_)} intervals of the grid's rows are not decided "
                      f"(a verdict None where it would decide the region), the first at q = "
                      f"{q:.8g}, p in [{lo:.8g}, {hi:.8g}]; they are drawn hatched grey and "
                      "name no region (the rows' Trace.stable has the verdicts)",
                      StabilityWarning, stacklevel=3)


def plot_curves(curves: Sequence[Any] = (), grid: Grid | None = None, ax: Any = None, *,
                p_label: str = "parameter p", q_label: str = "parameter q",
                title: str | None = None, html: str | os.PathLike | None = None) -> Any:
    """Draws the two-parameter diagram: the regions the grid decides (stable rest, oscillation
    without sticking, stick-slip, bistable; hatched grey where a verdict is not decided), the
    curves (Hopf curves by criticality, fold curves) with their codimension-two points, and the
    grid's events (Hopf points by criticality, folds of orbits, stick onsets, grazings, period
    doublings, tori).  p on the horizontal axis, q on the vertical one; the key below the axes.
    The curves decide regions too: bistable between a subcritical Hopf curve and the fold,
    stick-onset or grazing curve that ends the unstable orbit, stick-slip beside a stick-onset
    curve of stable orbits (see the module).

    Parameters
    ----------
    curves : sequence of Curve
        From :func:`dmi.analysis.continue_curve` (may be empty): Hopf and fold curves of
        equilibria, fold, period-doubling and torus curves of orbits, stick-onset and grazing
        curves.
    grid : Grid, optional
        From :func:`dmi.analysis.continue_over`: the regions and the events.
    ax : matplotlib.axes.Axes, optional
        Where to draw (a new figure if None).
    p_label, q_label : str, optional
        The axes' labels (the parameters in words and symbols with units).
    title : str, optional
        The title.
    html : str or os.PathLike, optional
        A path where the interactive page (:func:`dmi.analysis.plane.interactive.diagram_html`)
        is written too.

    Returns
    -------
    matplotlib.axes.Axes
        The Axes drawn on.

    Raises
    ------
    ValueError
        Nothing to draw (no curve and no grid), or a curve without ``p``, ``q`` and ``kind``.
    ImportError
        ``html`` given and Bokeh not installed.

    Warns
    -----
    StabilityWarning
        Intervals of the rows not decided (a verdict None where it would decide the region).
    """
    curves = list(curves)
    if not curves and grid is None:
        raise ValueError("plot_curves: nothing to draw: give curves (continue_curve) or a grid "
                         "(continue_over)")
    for c in curves:
        if not all(hasattr(c, a) for a in ("p", "q", "kind", "points")):
            raise ValueError(f"plot_curves: {type(c).__name__} is not a Curve: give the curves "
                             "of dmi.analysis.continue_curve")
    boxes = region_boxes(grid) if grid is not None else []
    _warn_undecided(boxes)
    if html is not None:
        from .interactive import diagram_html
        diagram_html(curves, grid, html, p_label=p_label, q_label=q_label, title=title)
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(7.0, 5.4), constrained_layout=True)
    handles = (_draw_regions(ax, boxes) + _draw_curve_regions(ax, curves, grid)
               + _draw_curves(ax, curves))
    if grid is not None:
        handles += _draw_grid_events(ax, grid)
    ax.margins(0.02)
    ax.autoscale_view()
    ax.set_xlabel(p_label)
    ax.set_ylabel(q_label)
    if title:
        ax.set_title(title)
    ax.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, -0.13), ncol=3,
              frameon=False, fontsize="small")
    return ax


def _draw_regions(ax: Any, boxes: list) -> list:
    """The regions' rectangles (hatched grey where undecided), and their keys."""
    from matplotlib.patches import Patch, Rectangle

    seen = set()
    for lo, hi, qlo, qhi, name, _ in boxes:
        hatch = "///" if name == UNDECIDED else None
        ax.add_patch(Rectangle((lo, qlo), hi - lo, qhi - qlo, facecolor=REGION_COLORS[name],
                               edgecolor="#969696" if hatch else "none", hatch=hatch, lw=0.0))
        seen.add(name)
    return [Patch(facecolor=REGION_COLORS[name], label=name,
                  hatch="///" if name == UNDECIDED else None,
                  edgecolor="#969696" if name == UNDECIDED else "none")
            for name in list(REGIONS) + [UNDECIDED] if name in seen]


def _draw_curve_regions(ax: Any, curves: list, grid: Grid | None) -> list:
    """The regions the curves decide (:func:`~dmi.analysis.plane.style.curve_regions`), as
    polygons under the curves, and their keys."""
    from matplotlib.patches import Patch

    seen = []
    for name, p, q in curve_regions(curves, p_range(curves, grid)):
        ax.fill(p, q, facecolor=REGION_COLORS[name], edgecolor="none", alpha=0.85, zorder=1)
        if name not in seen:
            seen.append(name)
    return [Patch(facecolor=REGION_COLORS[n], label=f"{n} (from the curves)") for n in seen]


def _draw_curves(ax: Any, curves: list) -> list:
    """The curves (Hopf curves dashed by criticality, the others by kind: fold curves
    dash-dotted, stick-onset and grazing curves in orange) and their codimension-two points,
    and their keys."""
    from matplotlib.lines import Line2D

    kinds = set()
    for c in curves:
        for p, q, crit in curve_pieces(c):
            if c.kind == "hopf":
                ax.plot(p, q, color="black", lw=1.6, ls=CRITICALITY_DASH[crit], zorder=3)
            else:
                color, ls, _ = curve_style(c.kind)
                ax.plot(p, q, color=color, lw=1.6, ls=ls, zorder=3)
            kinds.add((c.kind, crit))
        for e in c.events:
            if e.kind in CODIM2:
                ax.plot([e.p], [e.q], "P", color="#cb181d", ms=9, zorder=5)
                ax.annotate(e.kind, (e.p, e.q), textcoords="offset points", xytext=(6, 6),
                            fontsize="small", color="#cb181d")
                kinds.add(("codim-2", None))
    handles = []
    for kind, crit in sorted(kinds, key=str):
        if kind == "hopf":
            handles.append(Line2D([], [], color="black", lw=1.6, ls=CRITICALITY_DASH[crit],
                                  label=f"Hopf curve ({crit or 'criticality not decided'})"))
        elif kind == "codim-2":
            handles.append(Line2D([], [], ls="", marker="P", color="#cb181d",
                                  label="codimension-two point"))
        else:
            color, ls, label = curve_style(kind)
            handles.append(Line2D([], [], color=color, lw=1.6, ls=ls, label=label))
    return handles


def _draw_grid_events(ax: Any, grid: Grid) -> list:
    """The grid's events as markers (Hopf points filled by criticality), and their keys."""
    from matplotlib.lines import Line2D

    handles = []
    for kind, (marker, color, label) in EVENT_MARKERS.items():
        evs = [e for e in grid.events(kind) if kind != "fold" or e.on == "orbits"]
        if not evs:
            continue
        if kind != "hopf":
            ax.plot([e.p for e in evs], [e.q for e in evs], ls="", marker=marker,
                    color=color, ms=6, zorder=6)
            handles.append(Line2D([], [], ls="", marker=marker, color=color,
                                  label=f"{label} (grid)"))
            continue
        for crit, fill in (("supercritical", color), ("subcritical", "white"), (None, "#bbbbbb")):
            sel = [e for e in evs if e.criticality == crit]
            if sel:
                ax.plot([e.p for e in sel], [e.q for e in sel], ls="", marker=marker,
                        mfc=fill, mec=color, ms=6, zorder=6)
                handles.append(Line2D([], [], ls="", marker=marker, mfc=fill, mec=color,
                                      label=f"Hopf point of the grid ({crit or 'not decided'})"))
    return handles
