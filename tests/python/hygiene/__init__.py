"""Tests of the source tree as a whole: no import circles, complete docstrings, no control
characters in the manual, no issue numbers, no test module importing another."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
