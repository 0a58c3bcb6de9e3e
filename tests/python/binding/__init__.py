"""Tests of the binding (dmi.Solver, jit=True callbacks, the package as pip builds it) against the
paper and the C library's own results (binding_ref.c, meet.c)."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
