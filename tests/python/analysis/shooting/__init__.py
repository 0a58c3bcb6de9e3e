"""Tests of dmi.analysis.shooting: periodic orbits of the scheme by shooting, their branches,
events and refinement."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
