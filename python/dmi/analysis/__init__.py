# dmi.analysis: linear stability of equilibria and periodic orbits of the scheme's step map.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""dmi.analysis: the analysis of models ``make(p) -> dmi.Solver`` (filled in by issues 29 and 30)."""
from __future__ import annotations

__all__: list[str] = []

# ---- periodic orbits (issue 30): shooting, Floquet multipliers, continuation ----------------
from .continuation import Branch, BranchPoint, Event, continue_orbit, period_doubled_orbit  # noqa: E402,E501
from .floquet import floquet_multipliers  # noqa: E402
from .orbit_plot import plot_branch  # noqa: E402
from .shooting import Orbit, ShootingError, periodic_orbit  # noqa: E402

__all__ += ["periodic_orbit", "Orbit", "ShootingError", "floquet_multipliers", "continue_orbit",
            "period_doubled_orbit", "Branch", "BranchPoint", "Event", "plot_branch"]
