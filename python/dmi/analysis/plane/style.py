# The two-parameter diagram's style and geometry, shared by its matplotlib and Bokeh figures.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The regions' fills, the events' markers, a Hopf curve's dash by its criticality, and the boxes
and curve pieces both figures of the diagram draw."""
from __future__ import annotations

from typing import Any

import numpy as np

from .grid import UNDECIDED, Grid, regions

#: The regions' fills.
REGION_COLORS = {"stable rest": "#c6dbef", "oscillation": "#c7e9c0", "stick-slip": "#fdd0a2",
                 "bistable": "#dadaeb", UNDECIDED: "#d9d9d9"}
#: The grid's events drawn, their markers and colours (matplotlib marker, colour, label).
EVENT_MARKERS = {"hopf": ("o", "black", "Hopf point"),
                 "fold": ("^", "#6a51a3", "fold of orbits"),
                 "stick-onset": ("s", "#d94801", "stick onset"),
                 "grazing": ("D", "#a63603", "grazing"),
                 "period-doubling": ("v", "#238b45", "period doubling"),
                 "torus": ("*", "#238b45", "torus")}
#: The dash of a Hopf curve by its points' criticality.
CRITICALITY_DASH = {"supercritical": "-", "subcritical": "--", None: ":"}
#: The curves other than Hopf curves by kind: (colour, matplotlib dash, legend label).
CURVE_STYLES = {"fold": ("black", "-.", "fold curve"),
                "orbit-fold": ("#6a51a3", "-.", "fold curve of orbits"),
                "stick-onset": ("#d94801", "-", "stick-onset curve"),
                "grazing": ("#a63603", "--", "grazing curve"),
                "period-doubling": ("#238b45", ":", "period-doubling curve"),
                "torus": ("#238b45", "-.", "torus curve")}
#: Samples in q of a region between two curves.
REGION_SAMPLES = 80


def curve_style(kind: str) -> tuple[str, str, str]:
    """(colour, dash, label) of a curve of this kind other than a Hopf curve (an unknown kind:
    grey, solid, its name)."""
    return CURVE_STYLES.get(kind, ("#636363", "-", f"{kind} curve"))


def _p_of_q(curve: Any, keep: Any = None) -> tuple[np.ndarray, np.ndarray] | None:
    """The curve's (q, p) sorted by q, its points selected by ``keep(point)``; None where
    fewer than two are kept or q is not monotone along them (a curve that turns in q)."""
    pts = [pt for pt in curve.points if keep is None or keep(pt)]
    if len(pts) < 2:
        return None
    q = np.array([pt.q for pt in pts], float)
    p = np.array([pt.p for pt in pts], float)
    d = np.diff(q)
    if not (np.all(d > 0) or np.all(d < 0)):
        return None
    order = np.argsort(q)
    return q[order], p[order]


def _between(a: tuple[np.ndarray, np.ndarray], b: tuple[np.ndarray, np.ndarray]
             ) -> tuple[np.ndarray, np.ndarray] | None:
    """The polygon (p, q) between two curves given as (q, p) over their common q range."""
    lo, hi = max(a[0][0], b[0][0]), min(a[0][-1], b[0][-1])
    if not hi > lo:
        return None
    q = np.linspace(lo, hi, REGION_SAMPLES)
    pa, pb = np.interp(q, *a), np.interp(q, *b)
    return np.concatenate([pa, pb[::-1]]), np.concatenate([q, q[::-1]])


def p_range(curves: list, grid: Grid | None) -> tuple[float, float] | None:
    """The range of p the curves and the grid's rows span (None: nothing)."""
    ps = [float(x) for c in curves for x in c.p]
    if grid is not None:
        ps += [float(x) for r in grid.rows if r.error is None for t in r.branches.values()
               for x in t.p]
    return (min(ps), max(ps)) if ps else None


def curve_regions(curves: list, p_range: tuple[float, float] | None = None
                  ) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """The regions the curves decide, as polygons (name, p, q):

    * ``"bistable"``: between a Hopf curve where it is subcritical and a curve that ends the
      unstable orbit born there: a fold curve of orbits (``"orbit-fold"``), or a stick-onset or
      grazing curve where its orbits are verified unstable (``stable`` False);
    * ``"stick-slip"``: on the side of a stick-onset curve where its verified stable orbits
      stick (a point's ``side``), out to the nearest Hopf curve on that side or else to the edge
      of ``p_range`` (the drawn range of p).

    Only curves monotone in q over the points used are paired (a curve that turns in q is drawn
    but decides no region)."""
    hopf = [c for c in curves if c.kind == "hopf"]
    ends = [c for c in curves if c.kind == "orbit-fold"] + [
        c for c in curves if c.kind in ("stick-onset", "grazing")]
    out: list[tuple[str, np.ndarray, np.ndarray]] = []
    for h in hopf:
        sub = _p_of_q(h, lambda pt: pt.criticality == "subcritical")
        if sub is None:
            continue
        for c in ends:
            end = _p_of_q(c, None if c.kind == "orbit-fold" else
                          (lambda pt: getattr(pt, "stable", None) is False))
            got = _between(sub, end) if end is not None else None
            if got is not None:
                out.append(("bistable", *got))
    for c in curves:
        if c.kind != "stick-onset":
            continue
        kept = [pt for pt in c.points if pt.stable is True and getattr(pt, "side", 0) != 0]
        sides = {pt.side for pt in kept}
        ids = {id(pt) for pt in kept}
        on = _p_of_q(c, lambda pt: id(pt) in ids)
        if on is None or len(sides) != 1:
            continue
        side = sides.pop()
        far = [_p_of_q(h) for h in hopf]
        far = [f for f in far if f is not None and
               np.all(side * (np.interp(on[0], *f) - on[1]) > 0)]
        if far:
            edge = min(far, key=lambda f: float(np.mean(np.abs(np.interp(on[0], *f) - on[1]))))
        elif p_range is not None:
            edge = (on[0], np.full(on[0].size, p_range[1] if side > 0 else p_range[0]))
        else:
            continue
        got = _between(on, edge)
        if got is not None:
            out.append(("stick-slip", *got))
    return out


def edges(q: np.ndarray) -> np.ndarray:
    """The bands' edges around sorted values q: half-way between neighbours, the outer ones as
    far out as the inner ones (a single value: +-0.5)."""
    if len(q) == 1:
        return np.array([q[0] - 0.5, q[0] + 0.5])
    mid = 0.5 * (q[1:] + q[:-1])
    return np.concatenate([[2 * q[0] - mid[0]], mid, [2 * q[-1] - mid[-1]]])


def region_boxes(grid: Grid) -> list[tuple[float, float, float, float, str, float]]:
    """The regions of every row that ran, as boxes (p_lo, p_hi, q_lo, q_hi, name, q), the band of
    each row half-way to its neighbours in q (rows that failed are left out)."""
    rows = sorted((r for r in grid.rows if r.error is None), key=lambda r: r.q)
    if not rows:
        return []
    qe = edges(np.array([r.q for r in rows]))
    return [(lo, hi, qe[j], qe[j + 1], name, r.q) for j, r in enumerate(rows)
            for lo, hi, name in regions(r) if name is not None]


def curve_pieces(curve: Any) -> list[tuple[np.ndarray, np.ndarray, str | None]]:
    """A curve cut where its points' criticality changes: (p, q, criticality) pieces, each joined
    to the next point (a fold curve: one piece, criticality None)."""
    p, q = np.asarray(curve.p, float), np.asarray(curve.q, float)
    if curve.kind != "hopf":
        return [(p, q, None)]
    crit = [pt.criticality for pt in curve.points]
    out, start = [], 0
    for k in range(1, len(p) + 1):
        if k == len(p) or crit[k] != crit[start]:
            end = min(k + 1, len(p))
            out.append((p[start:end], q[start:end], crit[start]))
            start = k
    return out
