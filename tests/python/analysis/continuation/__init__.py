"""Tests of dmi.analysis.continuation: the one driver, branches and their events."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
