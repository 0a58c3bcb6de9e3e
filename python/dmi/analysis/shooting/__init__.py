# dmi.analysis.shooting: periodic orbits of the scheme by shooting.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Periodic orbits of the scheme: shooting on the step map (:mod:`.shoot`: :mod:`.forced` for a
given period, :mod:`.autonomous` for an unknown one), the orbit recomputed at finer steps
(:mod:`.refine`).  Their branches are in :mod:`dmi.analysis.branches`.

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme` and
:mod:`dmi.analysis.continuation`."""
