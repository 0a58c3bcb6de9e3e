# python -m dmi_sweep: the same as the dmi-sweep command.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import sys

from .cli import main

sys.exit(main())
