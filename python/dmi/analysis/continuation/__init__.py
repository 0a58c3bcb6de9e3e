# dmi.analysis.continuation: the one continuation driver and the records of a branch.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The one pseudo-arclength continuation driver (:mod:`.driver`: predictor, corrector, step
control, events, landing) and the records it returns (:mod:`.branch`: ``Branch``, ``BranchPoint``,
``Event``, ``HopfPoint``).  Every branch of dmi.analysis (equilibria, orbits by shooting or
collocation, curves in two parameters) is a discretisation handed to :func:`.driver.continuation`.

May import: :mod:`dmi.analysis.core` and :mod:`dmi.analysis.plot`."""
