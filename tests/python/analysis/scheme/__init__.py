"""Tests of dmi.analysis.scheme: the scheme's step maps, Floquet multipliers and orbits."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
