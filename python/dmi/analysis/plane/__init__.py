# dmi.analysis.plane: the plane of two parameters (p, q).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The plane of two parameters (p, q): grids of one-parameter continuations over q, serially or
on Dask (:mod:`.grid`), the two-parameter diagram with its curves, the grid's events and the
regions they decide (:mod:`.diagram`, :mod:`.style`), its interactive Bokeh page
(:mod:`.interactive`), and the curves of collocated orbits' bifurcations: what their systems share
and the fold's system (:mod:`.orbit_system`), the fold, period-doubling and torus curves
(:mod:`.orbit_curves`), the stick-onset and grazing boundaries (:mod:`.stick_curves`).

May import every room below it: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`,
:mod:`dmi.analysis.scheme`, :mod:`dmi.analysis.continuation`, :mod:`dmi.analysis.equilibria`,
:mod:`dmi.analysis.shooting`, :mod:`dmi.analysis.collocation` and :mod:`dmi.analysis.branches`."""
