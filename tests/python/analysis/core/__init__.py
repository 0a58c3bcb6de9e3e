"""Tests of dmi.analysis.core: the model's mirror, the BLAS calls, the Newton loop."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
