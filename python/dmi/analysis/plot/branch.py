# Drawing a continued branch of periodic orbits or equilibria.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""plot_branch: a branch's values over p, stable solid, unstable dashed, not verified (``stable``
None) dotted, events marked and named beside the marker (no legend over the data), both axes
labelled with what is drawn."""
from __future__ import annotations

import os
from typing import Any

import numpy as np

# Branch in the annotations is dmi.analysis.continuation.branch.Branch, not imported here: Branch.to_html
# calls plot_branch, and the imports have no circles.

#: marker of each event kind
MARKERS = {"fold": "s", "period-doubling": "D", "torus": "^", "stick-onset": "o", "grazing": "v",
           "hopf": "*"}


def line_style(stable: bool | None) -> str:
    """The matplotlib line style of a part of a branch: ``"-"`` where stable, ``"--"`` where
    unstable, ``":"`` where its stability is not verified (``stable`` None).

    Parameters
    ----------
    stable : bool or None
        A point's verdict.

    Returns
    -------
    str
        The line style.
    """
    if stable is None:
        return ":"
    return "-" if stable else "--"


def branch_values(branch: Branch, component: int = 0) -> tuple[np.ndarray, str]:
    """What :func:`plot_branch` draws against p, and its axis label:

    - a branch of equilibria: u_component of each equilibrium (one curve);
    - a forced branch: u_component at t = 0 of each orbit and at the other Poincare sections
      of a k-periodic orbit (``BranchPoint.section``: t = j period / k), one curve each;
    - an autonomous branch: the half range (max - min) / 2 of u_component over the period
      (``BranchPoint.amplitude``; u at t = 0 is an arbitrary phase there), one curve.

    Parameters
    ----------
    branch : Branch
        The branch.
    component : int, optional
        The state component.

    Returns
    -------
    values : numpy.ndarray, shape (m, k)
        The k curves at the branch's m points (state units).
    label : str
        Their axis label (matplotlib ``$...$`` maths).
    """
    if branch.kind == "equilibria":
        return (np.array([[q.u[component]] for q in branch.points]),
                f"equilibrium $u_{{{component}}}$")
    if branch.kind == "autonomous":
        return (np.array([[q.amplitude[component]] for q in branch.points]),
                f"amplitude of $u_{{{component}}}$, (max - min) / 2 over the period")
    values = np.array([q.section[:, component] for q in branch.points])
    if branch.sections > 1:
        return values, f"$u_{{{component}}}$ at $t = j P / {branch.sections}$ (Poincare sections)"
    return values, f"$u_{{{component}}}$ at $t = 0$ (Poincare section at the forcing period)"


def plot_branch(branch: Branch, ax: Any = None, component: int = 0, color: str = "C0",
                label_events: bool = True, p_label: str = "parameter p",
                html: str | os.PathLike | None = None) -> None:
    """Draws a branch: the values of :func:`branch_values` against p; solid where the orbit or
    equilibrium is stable, dashed where it is not, dotted where its stability is not verified
    (``stable`` None: no multipliers or roots computed, or none that decide); each event a black marker (:data:`MARKERS`) on
    the curve at the event's p, its kind written beside it; the x axis labelled ``p_label``, the
    y axis with what is drawn.

    Parameters
    ----------
    branch : Branch
        From :func:`continue_orbit` or :func:`continue_equilibrium`.
    ax : matplotlib.axes.Axes, optional
        Where to draw; may be None only with ``html`` (then only the HTML file is written).
    component : int, optional
        The state component drawn.
    color : str, optional
        The curves' matplotlib colour.
    label_events : bool, optional
        Write each event's kind beside its marker.
    p_label : str, optional
        The x axis' label.
    html : str or os.PathLike, optional
        A path, where the interactive figure of :func:`dmi.analysis.plot.interactive.branch_html` is
        written too.

    Raises
    ------
    ValueError
        Neither ``ax`` nor ``html`` given; with ``html``, as
        :func:`dmi.analysis.plot.interactive.branch_html` (no points, or points without orbits).
    ImportError
        ``html`` given and Bokeh not installed.
    """
    if html is not None:
        from .interactive import branch_html
        branch_html(branch, *branch_values(branch, component), html, component=component,
                    p_label=p_label)
        if ax is None:
            return
    elif ax is None:
        raise ValueError("dmi.analysis.plot_branch: give the Axes ax, or html (a path)")
    p = branch.p
    if p.size == 0:
        return
    st = [None if q.stable is None else bool(q.stable) for q in branch.points]
    sec, label = branch_values(branch, component)
    for j in range(sec.shape[1]):
        y = sec[:, j]
        # runs of equal stability, each joined to the next point so the curve is unbroken
        start = 0
        for k in range(1, len(p) + 1):
            if k == len(p) or st[k] is not st[start]:
                end = min(k + 1, len(p))
                ax.plot(p[start:end], y[start:end], line_style(st[start]), color=color,
                        lw=1.6, zorder=3)
                start = k
    for e in branch.events:
        i = min(max(e.index, 1), len(p) - 1)
        for j in range(sec.shape[1]):
            a, b = sec[i - 1, j], sec[i, j]
            if e.u is not None and branch.kind == "equilibria":
                y = float(e.u[component])
            else:
                w = 0.0 if p[i] == p[i - 1] else (e.p - p[i - 1]) / (p[i] - p[i - 1])
                y = a + min(max(w, 0.0), 1.0) * (b - a)
            ax.plot([e.p], [y], MARKERS.get(e.kind, "x"), color="k", ms=5, zorder=4,
                    fillstyle="none")
            if label_events and j == 0:
                ax.annotate(e.kind, (e.p, y), xytext=(4, 6), textcoords="offset points",
                            fontsize=7)
    ax.set_xlabel(p_label)
    ax.set_ylabel(label)
