# dmi.analysis.equilibria: equilibria, their roots, Hopf points, charts and curves.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Equilibria and their stability: the scheme's equilibria and their branches
(:mod:`.equilibrium`), the characteristic matrix of the equation (:mod:`.equation`), the roots and
Hopf points (:mod:`.stability`), the verdict checked independently (:mod:`.root_verdict`), the first
Lyapunov coefficient (:mod:`.normal_form`), stability charts (:mod:`.chart`) and Hopf and fold
curves in two parameters (:mod:`.curves`).

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme` and
:mod:`dmi.analysis.continuation`."""
