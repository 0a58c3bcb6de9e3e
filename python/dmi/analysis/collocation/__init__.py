# dmi.analysis.collocation: periodic orbits of the equation by collocation.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Periodic orbits of the equation (not of the scheme), smooth and stick-slip: the piecewise
polynomials and the mesh (:mod:`.mesh`), the mesh's adaptation and the error estimate
(:mod:`.adapt`), the signature of a nonsmooth orbit (:mod:`.signature`) and
its mends (:mod:`.mend`), the collocation equations (:mod:`.system`), the multipliers
(:mod:`.floquet`), and :func:`.collocate.collocate` and its orbit (:mod:`.orbit`).  Their branches
are in :mod:`dmi.analysis.branches`.

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme`,
:mod:`dmi.analysis.continuation` and :mod:`dmi.analysis.shooting`."""
