"""Tests of dmi.identify: sensitivities, fits, profiles and refusals."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
