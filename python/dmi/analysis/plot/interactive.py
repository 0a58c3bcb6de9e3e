# Interactive figures of branches and stability charts (Bokeh, one standalone HTML file each), and
# the compact HTML summaries that Jupyter shows for an Orbit, a Branch and a StabilityChart.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Standalone HTML figures drawn with Bokeh, its JavaScript inlined (the file opens offline):

- :func:`branch_html`: a branch over p (what :func:`dmi.analysis.plot_branch` draws); hovering a
  point shows p, the period, the amplitude, the leading multipliers and the stability of its orbit,
  and clicking it draws that orbit (``BranchPoint.t``, ``BranchPoint.u``) in the panel beside; on a
  branch of equilibria, hovering shows p and the rightmost root, and there is no orbit panel;
- :func:`chart_html`: a stability chart, one cell per grid point coloured by Re of its rightmost
  root; hovering a cell shows that root;
- :func:`orbit_summary`, :func:`branch_summary`, :func:`chart_summary`: the small tables
  Jupyter shows (``_repr_html_``) for an Orbit, a Branch and a StabilityChart.

Bokeh is imported by the figure functions only: ``import dmi.analysis`` does not need it."""
from __future__ import annotations

import html as _html
import os
import re
from typing import Any

import numpy as np

#: colour of the stable and of the unstable parts of a branch, and of the parts whose stability
#: is not verified (``stable`` None)
STABLE_COLOR, UNSTABLE_COLOR, UNVERIFIED_COLOR = "#1f77b4", "#d62728", "#7f7f7f"


def _verdict_text(stable: bool | None) -> str:
    """"stable", "unstable" or "not verified" (``stable`` None)."""
    return "not verified" if stable is None else "stable" if stable else "unstable"


def _verdict_style(stable: bool | None) -> tuple[str, str]:
    """(Bokeh line_dash, colour) of a part of a branch: solid blue where stable, dashed red where
    unstable, dotted grey where not verified."""
    if stable is None:
        return "dotted", UNVERIFIED_COLOR
    return ("solid", STABLE_COLOR) if stable else ("dashed", UNSTABLE_COLOR)
#: The orbit panel's line colours, one per component (then repeated).
COMPONENT_COLORS = ("#1f77b4", "#ff7f0e", "#2ca02c", "#9467bd", "#8c564b", "#e377c2")
#: What a branch of each kind is a branch of (titles and summaries).
KIND_NAMES = {"orbits": "forced orbits", "autonomous": "autonomous orbits",
              "equilibria": "equilibria"}
#: Multipliers listed in a branch point's hover text.
HOVER_MULTIPLIERS = 3


def number(x: float) -> str:
    """A number as the hover texts write it.

    Parameters
    ----------
    x : float
        The number.

    Returns
    -------
    str
        x with 6 significant digits.
    """
    return f"{x:.6g}"


def complex_text(z: complex) -> str:
    """A complex number (a root, a multiplier) as the hover texts write it.

    Parameters
    ----------
    z : complex
        The number.

    Returns
    -------
    str
        ``"a + bi"`` (or ``"a - bi"``) with 6 significant digits; ``"none"`` if not finite.
    """
    z = complex(z)
    if not (np.isfinite(z.real) and np.isfinite(z.imag)):
        return "none"
    return f"{z.real:.6g} {'-' if z.imag < 0 else '+'} {abs(z.imag):.6g}i"


def _plain(label: str) -> str:
    """A matplotlib label's $...$ maths as plain text (u_{0} -> u_0): Bokeh would show the TeX."""
    return re.sub(r"\$([^$]*)\$", lambda m: m.group(1).replace("{", "").replace("}", ""), label)


def _bokeh() -> None:
    """Raises ImportError with what to install when Bokeh is missing."""
    try:
        import bokeh  # noqa: F401
    except ImportError as e:
        raise ImportError("dmi.analysis's interactive figures need Bokeh: pip install bokeh "
                          "(or the extra dmi[analysis])") from e


def _write(models: Any, path: str | os.PathLike | None, title: str) -> str:
    """The standalone HTML of the Bokeh models, BokehJS inlined; written to path if given."""
    from bokeh.embed import file_html
    from bokeh.resources import INLINE

    text = file_html(models, INLINE, title)
    if path is not None:
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
    return text


def _stability_lines(fig: Any, p: np.ndarray, y: np.ndarray, stable: np.ndarray) -> None:
    """One curve y(p): solid where stable, dashed where not, dotted where not verified
    (:func:`_verdict_style`), each run joined to the next point."""
    start = 0
    for k in range(1, len(p) + 1):
        if k == len(p) or stable[k] is not stable[start]:
            end = min(k + 1, len(p))
            dash, color = _verdict_style(stable[start])
            fig.line(p[start:end], y[start:end], line_width=2, line_dash=dash, color=color)
            start = k


def _point_texts(branch: Any) -> dict[str, list[str]]:
    """The hover texts of the branch's points, by field."""
    pts = branch.points
    out = {"p_text": [number(q.p) for q in pts],
           "stable_text": [_verdict_text(q.stable) for q in pts]}
    if branch.kind == "equilibria":
        out["root_text"] = [complex_text(q.rightmost) for q in pts]
        return out
    out["period_text"] = [number(q.period) for q in pts]
    out["amplitude_text"] = [", ".join(number(a) for a in np.atleast_1d(q.amplitude))
                             for q in pts]
    out["multipliers_text"] = [
        "; ".join(f"{complex_text(m)} (|mu| {abs(m):.4g})"
                  for m in np.atleast_1d(q.multipliers)[:HOVER_MULTIPLIERS]) or "none"
        for q in pts]
    return out


def _orbit_panel(branch: Any, points: Any, height: int) -> Any:
    """The panel that draws the orbit of the selected point, and the callback that fills it: all
    orbits stacked in one data source (a point's rows are start .. stop), the shown one in
    another (name ``orbit``), which the tap on a point replaces."""
    from bokeh.models import ColumnDataSource, CustomJS
    from bokeh.plotting import figure

    pts = branch.points
    n = max(np.atleast_2d(q.u).shape[1] for q in pts)
    sizes = [len(q.t) for q in pts]
    stop = np.cumsum(sizes)
    names = [f"u{j}" for j in range(n)]
    store = ColumnDataSource({"t": np.concatenate([np.asarray(q.t, float) for q in pts]),
                              **{c: np.concatenate([np.asarray(q.u, float)[:, j] for q in pts])
                                 for j, c in enumerate(names)}}, name="orbits")
    points.data["start"] = stop - np.asarray(sizes)
    points.data["stop"] = stop
    first = slice(0, sizes[0])
    shown = ColumnDataSource({c: store.data[c][first] for c in ["t"] + names}, name="orbit")
    fig = figure(sizing_mode="stretch_width", height=height, name="orbit_panel",
                 title=f"orbit at p = {number(pts[0].p)} (click a point)",
                 x_axis_label="t (time units, from the section t = 0)", y_axis_label="u",
                 tools="pan,wheel_zoom,box_zoom,reset,save")
    for j, c in enumerate(names):
        fig.line("t", c, source=shown, line_width=2, legend_label=f"u_{j}",
                 color=COMPONENT_COLORS[j % len(COMPONENT_COLORS)], name=f"orbit_{c}")
    fig.legend.location = "top_right"
    fig.legend.click_policy = "hide"
    points.selected.js_on_change("indices", CustomJS(
        args={"points": points, "store": store, "shown": shown, "names": ["t"] + names,
              "title": fig.title},
        code="""
const i = points.selected.indices[0];
if (i === undefined) return;
const a = points.data.start[i], b = points.data.stop[i];
const data = {};
for (const c of names) data[c] = store.data[c].slice(a, b);
shown.data = data;
title.text = "orbit at p = " + points.data.p_text[i] + " (click a point)";
"""))
    points.selected.indices = [0]
    return fig


def _event_y(branch: Any, e: Any, p: np.ndarray, y: np.ndarray, component: int) -> float:
    """Where :func:`plot_branch` marks the event e on the curve y(p): the equilibrium's value at
    the event, else y interpolated linearly at the event's p between its two points."""
    if e.u is not None and branch.kind == "equilibria":
        return float(e.u[component])
    i = min(max(e.index, 1), len(p) - 1)
    w = 0.0 if p[i] == p[i - 1] else (e.p - p[i - 1]) / (p[i] - p[i - 1])
    return float(y[i - 1] + min(max(w, 0.0), 1.0) * (y[i] - y[i - 1]))


def branch_html(branch: Any, values: np.ndarray, label: str,
                path: str | os.PathLike | None = None, *, component: int = 0,
                p_label: str = "parameter p", title: str | None = None,
                height: int = 420) -> str:
    """The interactive figure of a branch, as an HTML file that needs nothing else (BokehJS is
    inlined).  The panels share the width of the window.  :func:`dmi.analysis.plot_branch` with
    ``html`` and ``Branch.to_html`` call this.

    The left panel draws what :func:`plot_branch` draws (the values against p, solid blue where
    stable, dashed red where not, the events marked and named) with a marker per point.
    Hovering a point shows p, the period, the amplitude (per component), the leading multipliers
    (:data:`HOVER_MULTIPLIERS`, with their moduli) and the stability of its orbit; clicking it
    draws that orbit (``BranchPoint.t``, ``BranchPoint.u``, every component) in the right panel,
    which starts with the first point's.  A branch of equilibria has no orbit panel, and
    hovering a point shows p, the rightmost root and the stability.

    Parameters
    ----------
    branch : dmi.analysis.Branch
        The branch.
    values : numpy.ndarray, shape (m, k)
        What is drawn against p at the m points (:func:`dmi.analysis.plot.branch.branch_values` of
        ``component``).
    label : str
        Its name, the vertical axis' label (matplotlib's ``$...$`` maths shown as plain text).
    path : str or os.PathLike, optional
        The HTML file; None writes nothing.
    component : int, optional
        The state component of ``values`` (where the events are marked on a branch of
        equilibria).
    p_label : str, optional
        The horizontal axis' label.
    title : str, optional
        The title (default: the branch's kind and number of points).
    height : int, optional
        The panels' height in pixels.

    Returns
    -------
    str
        The HTML text (also with ``path=None``).

    Raises
    ------
    ValueError
        A branch without points, or of orbits whose points keep no orbit (empty
        ``BranchPoint.t``).
    ImportError
        Bokeh is not installed.
    OSError
        ``path`` cannot be written.
    """
    _bokeh()
    from bokeh.layouts import row
    from bokeh.models import ColumnDataSource, HoverTool, LabelSet
    from bokeh.plotting import figure

    if not branch.points:
        raise ValueError("dmi.analysis.branch_html: the branch has no points")
    if branch.kind != "equilibria" and any(len(q.t) == 0 for q in branch.points):
        raise ValueError("dmi.analysis.branch_html: the branch's points keep no orbit "
                         "(BranchPoint.t and .u are empty): continue the orbit again")
    p = np.asarray(branch.p, float)
    stable = [None if q.stable is None else bool(q.stable) for q in branch.points]
    fig = figure(sizing_mode="stretch_width", height=height, name="branch", x_axis_label=p_label,
                 y_axis_label=_plain(label), tools="pan,wheel_zoom,box_zoom,reset,save,tap",
                 title=title or f"{KIND_NAMES.get(branch.kind, branch.kind)}: {len(p)} points")
    for j in range(values.shape[1]):
        _stability_lines(fig, p, values[:, j], stable)
    points = ColumnDataSource({"p": p, "y": values[:, 0], **_point_texts(branch),
                               "color": [_verdict_style(s)[1] for s in stable]},
                              name="points")
    dots = fig.scatter("p", "y", source=points, size=8, name="point_markers", color="color",
                       selection_color="black", nonselection_alpha=0.6)
    if branch.kind == "equilibria":
        tips = [("p", "@p_text"), ("rightmost root", "@root_text"), ("", "@stable_text")]
    else:
        tips = [("p", "@p_text"), ("period", "@period_text"), ("amplitude", "@amplitude_text"),
                ("multipliers", "@multipliers_text"), ("", "@stable_text")]
    fig.add_tools(HoverTool(renderers=[dots], tooltips=tips, name="point_hover"))
    if branch.events:
        events = ColumnDataSource({"p": [e.p for e in branch.events],
                                   "y": [_event_y(branch, e, p, values[:, 0], component)
                                         for e in branch.events],
                                   "kind": [e.kind for e in branch.events]})
        fig.scatter("p", "y", source=events, marker="square", size=9, fill_color=None,
                    line_color="black")
        fig.add_layout(LabelSet(x="p", y="y", text="kind", source=events, x_offset=5, y_offset=5,
                                text_font_size="9pt"))
    if branch.kind == "equilibria":
        return _write(fig, path, fig.title.text)
    return _write(row(fig, _orbit_panel(branch, points, height), sizing_mode="stretch_width"),
                  path, fig.title.text)


def _edges(v: np.ndarray) -> np.ndarray:
    """Cell edges around grid values v (midpoints, the ends mirrored)."""
    if len(v) == 1:
        return np.array([v[0] - 0.5, v[0] + 0.5])
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[2 * v[0] - mid[0]], mid, [2 * v[-1] - mid[-1]]])


def chart_html(chart: Any, path: str | os.PathLike | None = None, *,
               p_label: str = "parameter p", q_label: str = "parameter q",
               title: str | None = None, height: int = 520) -> str:
    """The interactive figure of a stability chart, as a standalone HTML file (BokehJS inlined).
    The chart is as wide as the window: one cell per grid point, coloured by Re of its rightmost
    root (blue < 0: stable, red > 0, grey where no root was found) on a scale symmetric about 0
    whose ten colours change at 0; the traced Hopf curves solid black, the fold curves dashed.
    Hovering a cell shows p, q, the rightmost root and the stability.

    Parameters
    ----------
    chart : dmi.analysis.StabilityChart
        The chart.
    path : str or os.PathLike, optional
        The HTML file; None writes nothing.
    p_label, q_label : str, optional
        The axes' labels.
    title : str, optional
        The title.
    height : int, optional
        The height in pixels.

    Returns
    -------
    str
        The HTML text (also with ``path=None``).

    Raises
    ------
    ImportError
        Bokeh is not installed.
    OSError
        ``path`` cannot be written.
    """
    _bokeh()
    from bokeh.models import ColorBar, ColumnDataSource, HoverTool, LinearColorMapper
    from bokeh.palettes import RdBu10
    from bokeh.plotting import figure

    P = np.asarray(chart.p_values, float)
    Q = np.asarray(chart.q_values, float)
    re, im = np.asarray(chart.re, float), np.asarray(chart.im, float)
    pe, qe = _edges(P), _edges(Q)
    pp, qq = np.meshgrid(P, Q)
    ww, hh = np.meshgrid(np.diff(pe), np.diff(qe))
    finite = np.isfinite(re)
    scale = float(np.max(np.abs(re[finite]))) if finite.any() else 1.0
    cells = ColumnDataSource({
        "p": pp.ravel(), "q": qq.ravel(), "w": ww.ravel(), "h": hh.ravel(),
        "re": np.where(finite, re, np.nan).ravel(),
        "p_text": [number(x) for x in pp.ravel()], "q_text": [number(x) for x in qq.ravel()],
        "root_text": [complex_text(complex(a, b)) for a, b in zip(re.ravel(), im.ravel())],
        "stable_text": [_verdict_text(v) if np.isfinite(a) else "no root"
                        for a, v in zip(re.ravel(), np.asarray(chart.verdict).ravel())]},
        name="cells")
    mapper = LinearColorMapper(palette=RdBu10, low=-scale or -1.0, high=scale or 1.0,
                               nan_color="#bbbbbb")
    fig = figure(sizing_mode="stretch_width", height=height, name="chart", x_axis_label=p_label,
                 y_axis_label=q_label, x_range=(pe[0], pe[-1]), y_range=(qe[0], qe[-1]),
                 tools="pan,wheel_zoom,box_zoom,reset,save",
                 title=title or "stability chart: Re of the rightmost root (< 0: stable)")
    rects = fig.rect("p", "q", "w", "h", source=cells, line_color=None, name="cell_rects",
                     fill_color={"field": "re", "transform": mapper})
    for c in chart.curves:
        fig.line(c.p, c.q, color="black", line_width=2,
                 line_dash="solid" if c.is_hopf else "dashed")
    fig.add_tools(HoverTool(renderers=[rects], name="cell_hover", tooltips=[
        ("p", "@p_text"), ("q", "@q_text"), ("rightmost root", "@root_text"),
        ("", "@stable_text")]))
    fig.add_layout(ColorBar(color_mapper=mapper, title="Re of the rightmost root"), "right")
    return _write(fig, path, fig.title.text)


def _table(title: str, rows: list[tuple[str, str]]) -> str:
    body = "".join(f"<tr><th style='text-align:left'>{_html.escape(k)}</th>"
                   f"<td style='text-align:left'>{_html.escape(v)}</td></tr>" for k, v in rows)
    return f"<table><caption>{_html.escape(title)}</caption>{body}</table>"


def _range(x: np.ndarray) -> str:
    return f"{number(float(np.min(x)))} .. {number(float(np.max(x)))}" if len(x) else "empty"


def orbit_summary(orbit: Any) -> str:
    """The HTML table Jupyter shows for an orbit (``Orbit._repr_html_``).

    Parameters
    ----------
    orbit : dmi.analysis.Orbit
        The orbit.

    Returns
    -------
    str
        A table of p, the period (steps x h), the amplitude, the leading multipliers and the
        stability.
    """
    mu = np.atleast_1d(orbit.multipliers)[:HOVER_MULTIPLIERS]
    return _table("Orbit" + (" (autonomous)" if orbit.autonomous else ""), [
        ("p", number(orbit.p)),
        ("period", f"{number(orbit.period)} ({orbit.steps} steps of h = {number(orbit.h)})"),
        ("amplitude", ", ".join(number(a) for a in np.atleast_1d(orbit.amplitude))),
        ("multipliers", "; ".join(complex_text(m) for m in mu) or "not computed"),
        ("stability", _verdict_text(orbit.stable))])


def branch_summary(branch: Any) -> str:
    """The HTML table Jupyter shows for a branch (``Branch._repr_html_``).

    Parameters
    ----------
    branch : dmi.analysis.Branch
        The branch.

    Returns
    -------
    str
        A table of its kind, the number of points, the range of p, how many points are stable,
        the events (kind at p) and the status.
    """
    p = np.array([q.p for q in branch.points])
    unverified = sum(q.stable is None for q in branch.points)
    stable = sum(q.stable is not None and bool(q.stable) for q in branch.points)
    events = ", ".join(f"{e.kind} at p = {number(e.p)}" for e in branch.events) or "none"
    return _table(f"Branch of {KIND_NAMES.get(branch.kind, branch.kind)}", [
        ("points", str(len(branch.points))), ("p", _range(p)),
        ("stable points", f"{stable} of {len(branch.points)}"
                          + (f" ({unverified} not verified)" if unverified else "")),
        ("events", events), ("status", str(branch.status))])


def chart_summary(chart: Any) -> str:
    """The HTML table Jupyter shows for a stability chart (``StabilityChart._repr_html_``).

    Parameters
    ----------
    chart : dmi.analysis.StabilityChart
        The chart.

    Returns
    -------
    str
        A table of the grid (sizes, ranges of p and q), how many grid points are verified
        stable (and how many have no verdict), the largest Re of a rightmost root and the curves.
    """
    re = np.asarray(chart.re, float)
    hopf = sum(c.is_hopf for c in chart.curves)
    unverified = int(np.sum(chart.undecided))
    return _table("StabilityChart", [
        ("grid", f"{len(chart.p_values)} p x {len(chart.q_values)} q"),
        ("p", _range(chart.p_values)), ("q", _range(chart.q_values)),
        ("stable points", f"{int(np.sum(chart.stable))} of {re.size}"
                          + (f" ({unverified} not verified)" if unverified else "")),
        ("largest Re", number(float(np.nanmax(re))) if np.isfinite(re).any() else "none"),
        ("curves", f"{hopf} Hopf, {len(chart.curves) - hopf} fold")])
