"""Tests of dmi.analysis.equilibria: equilibria, roots, Hopf points, criticality, charts, curves."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
