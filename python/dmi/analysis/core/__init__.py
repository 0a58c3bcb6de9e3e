# dmi.analysis.core: what every room of dmi.analysis builds on.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""The base of dmi.analysis: the model's mirror and its linearisation (:mod:`.model`), the one
Newton loop (:mod:`.newton`), and BLAS on one thread (:mod:`.blas`).

May import: dmi's own modules (``dmi._solver``, ``dmi._lib``, ``dmi._transform``, ``dmi._errors``,
``dmi._make``, ``dmi._resolvent``)
only, no other room of dmi.analysis."""
