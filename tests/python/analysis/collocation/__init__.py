"""Tests of dmi.analysis.collocation: periodic orbits of the equation by collocation and their
branches."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
