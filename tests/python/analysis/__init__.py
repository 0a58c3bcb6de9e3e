"""Tests of dmi.analysis: one folder a room (core, scheme, continuation, equilibria, shooting,
collocation, plot), the package's structure at this level."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
