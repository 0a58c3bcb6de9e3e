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
