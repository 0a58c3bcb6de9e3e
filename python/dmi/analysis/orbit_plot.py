# Drawing a continued branch of periodic orbits or equilibria.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""plot_branch: a branch's Poincare-section values over p, stable solid, unstable dashed,
events marked and named beside the marker (no legend over the data)."""
from __future__ import annotations

from typing import Any

import numpy as np

from .branch import Branch

#: marker of each event kind
MARKERS = {"fold": "s", "period-doubling": "D", "torus": "^", "stick-onset": "o", "grazing": "v"}


def plot_branch(branch: Branch, ax: Any, component: int = 0, color: str = "C0",
                label_events: bool = True) -> None:
    """Draws ``branch`` on the matplotlib Axes ``ax``: u_component on the Poincare section
    (``BranchPoint.section``, one curve per section of a k-periodic orbit) against p; solid
    where the orbit is stable, dashed where it is not; each event a black marker
    (:data:`MARKERS`) on the curve at the event's p, its kind written beside it."""
    p = branch.p
    if p.size == 0:
        return
    st = branch.stable
    sec = np.array([q.section[:, component] for q in branch.points])  # (points, k)
    for j in range(sec.shape[1]):
        y = sec[:, j]
        # runs of equal stability, each joined to the next point so the curve is unbroken
        start = 0
        for k in range(1, len(p) + 1):
            if k == len(p) or st[k] != st[start]:
                end = min(k + 1, len(p))
                ax.plot(p[start:end], y[start:end], "-" if st[start] else "--", color=color,
                        lw=1.6, zorder=3)
                start = k
    for e in branch.events:
        i = min(max(e.index, 1), len(p) - 1)
        for j in range(sec.shape[1]):
            a, b = sec[i - 1, j], sec[i, j]
            w = 0.0 if p[i] == p[i - 1] else (e.p - p[i - 1]) / (p[i] - p[i - 1])
            y = a + min(max(w, 0.0), 1.0) * (b - a)
            ax.plot([e.p], [y], MARKERS.get(e.kind, "x"), color="k", ms=5, zorder=4,
                    fillstyle="none")
            if label_events and j == 0:
                ax.annotate(e.kind, (e.p, y), xytext=(4, 6), textcoords="offset points",
                            fontsize=7)
