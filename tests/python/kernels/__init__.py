"""Tests of dmi.kernels and dmi._transform: fits, closed forms, quadrature, refusals."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
