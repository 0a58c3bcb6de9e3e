# The interactive page of the two-parameter diagram (Bokeh, one standalone HTML file).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""diagram_html: what :func:`dmi.analysis.plot_curves` draws, as a standalone HTML page (BokehJS
inlined, nothing fetched): the regions of the grid's rows (hovering one shows its name, its q and
its interval of p), the regions the curves decide (bistable, stick-slip: hovering one shows its
name), the curves by kind (hovering a Hopf curve's point shows p, q, omega, l1 and its
criticality), their codimension-two points (with the crossings of an orbits' fold), and the grid's events (hovering one shows its kind,
p, q and, on a Hopf point, l1 and the criticality).  Bokeh is imported here only."""
from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..plot.interactive import _bokeh, _plain, _write, number
from .style import (CRITICALITY_DASH, EVENT_MARKERS, REGION_COLORS, curve_pieces,
                    curve_regions, curve_style, p_range, region_boxes)

#: Bokeh's dash for matplotlib's.
_DASH = {"-": "solid", "--": "dashed", ":": "dotted", "-.": "dashdot"}
#: Bokeh's marker for matplotlib's.
_MARKER = {"o": "circle", "^": "triangle", "s": "square", "D": "diamond",
           "v": "inverted_triangle", "*": "star"}


def _text(x: float | None) -> str:
    return "-" if x is None else number(x)


def diagram_html(curves: Sequence[Any], grid: Any, path: str | os.PathLike | None = None, *,
                 p_label: str = "parameter p", q_label: str = "parameter q",
                 title: str | None = None, height: int = 560) -> str:
    """The interactive two-parameter diagram as a standalone HTML file (see the module).

    Parameters
    ----------
    curves : sequence of Curve
        From :func:`dmi.analysis.continue_curve`.
    grid : Grid or None
        From :func:`dmi.analysis.continue_over`.
    path : str or os.PathLike, optional
        The HTML file; None writes nothing.
    p_label, q_label : str, optional
        The axes' labels.
    title : str, optional
        The title.
    height : int, optional
        The height in pixels (the page is as wide as the window).

    Returns
    -------
    str
        The HTML text.

    Raises
    ------
    ImportError
        Bokeh is not installed.
    OSError
        ``path`` cannot be written.
    """
    _bokeh()
    from bokeh.models import ColumnDataSource, HoverTool
    from bokeh.plotting import figure

    fig = figure(sizing_mode="stretch_width", height=height, name="diagram",
                 x_axis_label=_plain(p_label), y_axis_label=_plain(q_label),
                 tools="pan,wheel_zoom,box_zoom,reset,save",
                 title=title or "two-parameter diagram")
    boxes = region_boxes(grid) if grid is not None else []
    if boxes:
        src = ColumnDataSource({
            "left": [b[0] for b in boxes], "right": [b[1] for b in boxes],
            "bottom": [b[2] for b in boxes], "top": [b[3] for b in boxes],
            "color": [REGION_COLORS[b[4]] for b in boxes], "region": [b[4] for b in boxes],
            "q_text": [number(b[5]) for b in boxes],
            "p_text": [f"{number(b[0])} to {number(b[1])}" for b in boxes]}, name="regions")
        quads = fig.quad("left", "right", "top", "bottom", source=src, fill_color="color",
                         line_color=None, fill_alpha=0.9, name="region_quads",
                         legend_field="region")
        fig.add_tools(HoverTool(renderers=[quads], name="region_hover", tooltips=[
            ("region", "@region"), ("q", "@q_text"), ("p", "@p_text")]))
    _curve_regions(fig, curves, grid)
    _curves(fig, curves)
    if grid is not None:
        for kind, (marker, color, label) in EVENT_MARKERS.items():
            evs = [e for e in grid.events(kind) if kind != "fold" or e.on == "orbits"]
            if not evs:
                continue
            fill = [("white" if e.criticality == "subcritical" else
                     "#bbbbbb" if e.criticality is None else color) if kind == "hopf" else color
                    for e in evs]
            src = ColumnDataSource({
                "p": [e.p for e in evs], "q": [e.q for e in evs], "fill": fill,
                "p_text": [number(e.p) for e in evs], "q_text": [number(e.q) for e in evs],
                "l1_text": [_text(e.l1) for e in evs],
                "crit": [str(e.criticality) for e in evs],
                "detail": [e.detail[:120] for e in evs]}, name=f"grid_{kind}")
            r = fig.scatter("p", "q", source=src, marker=_MARKER[marker], size=9,
                            fill_color="fill", line_color=color, name=f"grid_{kind}_points",
                            legend_label=f"{label} (grid)")
            tips = [("", kind), ("p", "@p_text"), ("q", "@q_text")]
            if kind == "hopf":
                tips += [("l1", "@l1_text"), ("criticality", "@crit")]
            else:
                tips += [("", "@detail")]
            fig.add_tools(HoverTool(renderers=[r], tooltips=tips))
    fig.legend.location = "top_left"
    fig.legend.click_policy = "hide"
    return _write(fig, path, fig.title.text)


def _curve_regions(fig: Any, curves: Sequence[Any], grid: Any) -> None:
    """The regions the curves decide, as patches (hovering one shows its name)."""
    from bokeh.models import ColumnDataSource, HoverTool

    regions = curve_regions(list(curves), p_range(list(curves), grid))
    if not regions:
        return
    src = ColumnDataSource({"xs": [list(p) for _, p, _ in regions],
                            "ys": [list(q) for _, _, q in regions],
                            "color": [REGION_COLORS[n] for n, _, _ in regions],
                            "curve_region": [f"{n} (from the curves)" for n, _, _ in regions]},
                           name="curve_regions")
    r = fig.patches("xs", "ys", source=src, fill_color="color", line_color=None,
                    fill_alpha=0.85, legend_field="curve_region", name="curve_region_patches")
    fig.add_tools(HoverTool(renderers=[r], tooltips=[("region", "@curve_region")]))


def _curves(fig: Any, curves: Sequence[Any]) -> None:
    """The curves (Hopf curves by criticality, the others by kind), their points (hovering one
    shows p, q and, on a Hopf curve, omega, l1 and the criticality) and their events."""
    from bokeh.models import ColumnDataSource, HoverTool

    for k, c in enumerate(curves):
        for j, (p, q, crit) in enumerate(curve_pieces(c)):
            if c.kind == "hopf":
                fig.line(p, q, color="black", line_width=2,
                         line_dash=_DASH[CRITICALITY_DASH[crit]],
                         legend_label=f"Hopf curve ({crit or 'not decided'})")
            else:
                color, ls, label = curve_style(c.kind)
                fig.line(p, q, color=color, line_width=2, line_dash=_DASH[ls],
                         legend_label=label)
        pts = c.points
        src = ColumnDataSource({
            "p": np.asarray(c.p, float), "q": np.asarray(c.q, float),
            "p_text": [number(pt.p) for pt in pts], "q_text": [number(pt.q) for pt in pts],
            "omega_text": [_text(pt.omega) if c.kind == "hopf" else "-" for pt in pts],
            "l1_text": [_text(pt.l1) if c.kind == "hopf" else "-" for pt in pts],
            "crit": [str(pt.criticality) if c.kind == "hopf" else "-" for pt in pts]},
            name=f"curve{k}")
        dots = fig.scatter("p", "q", source=src, size=5, color="black", name=f"curve{k}_points")
        fig.add_tools(HoverTool(renderers=[dots], tooltips=[
            ("curve", c.kind), ("p", "@p_text"), ("q", "@q_text"), ("omega", "@omega_text"),
            ("l1", "@l1_text"), ("criticality", "@crit")]))
        codim = [e for e in c.events if e.kind not in ("user",)]
        if codim:
            src = ColumnDataSource({"p": [e.p for e in codim], "q": [e.q for e in codim],
                                    "kind": [e.kind for e in codim],
                                    "p_text": [number(e.p) for e in codim],
                                    "q_text": [number(e.q) for e in codim]},
                                   name=f"curve{k}_events")
            r = fig.scatter("p", "q", source=src, marker="plus", size=14, color="#cb181d",
                            legend_label="codimension-two point")
            fig.add_tools(HoverTool(renderers=[r], tooltips=[
                ("", "@kind"), ("p", "@p_text"), ("q", "@q_text")]))
