# dmi.analysis.equilibria: equilibria, their roots, Hopf points, charts and curves.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Equilibria and their stability: the scheme's equilibria and their branches
(:mod:`.equilibrium`), the characteristic matrix of the equation (:mod:`.equation`), the roots
(:mod:`.stability`), the Hopf point of a one-parameter model (:mod:`.crossing`), the verdict
checked independently (:mod:`.root_verdict`), the first Lyapunov coefficient and the orbit's
predicted parameter (:mod:`.normal_form`), stability charts (:mod:`.chart`), Hopf and fold
curves in two parameters (:mod:`.curves`) and the small numerical tools they share
(:mod:`.numerics`).

Inside the room, lowest first: numerics and equation import no module of the room; stability
imports equation; normal_form imports equation and numerics; root_verdict imports stability;
curves imports stability and normal_form; crossing, equilibrium and chart the ones below them
(no import chain longer than four modules).

May import: :mod:`dmi.analysis.core`, :mod:`dmi.analysis.plot`, :mod:`dmi.analysis.scheme` and
:mod:`dmi.analysis.continuation`."""
