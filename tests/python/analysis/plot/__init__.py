"""Tests of dmi.analysis.plot: the static and interactive figures."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
