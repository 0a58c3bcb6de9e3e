"""Models, references and helpers shared by several test modules (a test module imports
from here, never from another test module)."""
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
