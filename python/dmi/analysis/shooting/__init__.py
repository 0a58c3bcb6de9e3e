# dmi.analysis.shooting: periodic orbits of the scheme by shooting, and their branches.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Periodic orbits of the scheme: shooting on the step map (:mod:`.shoot`: :mod:`.forced` for a
given period, :mod:`.autonomous` for an unknown one), the orbit recomputed at finer steps
(:mod:`.refine`), the shooting discretisation of a branch (:mod:`.branch`) and the tests of its
events (:mod:`.events`).

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme` and
:mod:`dmi.analysis.continuation`."""
