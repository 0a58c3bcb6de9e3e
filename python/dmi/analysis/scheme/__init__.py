# dmi.analysis.scheme: the scheme's step map, its orbits and their multipliers.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The scheme seen as a map: the M-step map on windows of states (:mod:`.stepmap`), a periodic
orbit of the scheme (:mod:`.orbit`), its verified Floquet multipliers (:mod:`.floquet`) and the
one cache of what a continuation builds from a model (:mod:`.problem`).

May import: :mod:`dmi.analysis.core` and :mod:`dmi.analysis.plot`."""
