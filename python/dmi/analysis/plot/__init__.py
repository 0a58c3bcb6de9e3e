# dmi.analysis.plot: figures of branches and charts.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Figures: a continued branch drawn with matplotlib (:mod:`.branch`) and the interactive Bokeh
pages of branches, orbits and stability charts (:mod:`.interactive`).

May import: nothing of dmi.analysis (the records it draws are passed in)."""
