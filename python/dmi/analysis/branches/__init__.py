# dmi.analysis.branches: branches of periodic orbits handed to the one continuation driver.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Branches of periodic orbits as discretisations of the one driver
(:func:`dmi.analysis.continuation.driver.continuation`): the scheme's orbits by shooting
(:mod:`.shooting`, Newton-Picard as the loop's linear solve) and the tests of their events
(:mod:`.events`), the equation's orbits by collocation (:mod:`.discretisation`, and
:mod:`.collocated`: ``EquationBranch``, its mends, sheds and the Hopf start).

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme`,
:mod:`dmi.analysis.continuation`, :mod:`dmi.analysis.equilibria`, :mod:`dmi.analysis.shooting`
and :mod:`dmi.analysis.collocation`."""
