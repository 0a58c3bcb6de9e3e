# The plain runs of the oscillator FMU that early return must leave
# unchanged: fmpy's simulate_fmu of the default experiment (Example 4.3, t in
# [0, 30]) with fmpy's default communication step (0.04, on the solver's
# grid) and with 0.0123 (fmpy makes it 0.0492: between grid points, so that
# the outputs interpolate), the five physical outputs.  make_plain_run.py
# wrote its digests with the FMUs built from main before events existed
# (commit 39e6429); test_events.py compares the FMUs of this tree with them.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import hashlib

import numpy as np
from fmpy import simulate_fmu

OUT = ["w", "v", "friction", "delay_force", "sticking"]
RUNS = {"default": {}, "offgrid": {"output_interval": 0.0123}}


def plain_run(path, **options):
    return simulate_fmu(path, output=OUT, **options)


def digests(result, keep=None, names=OUT):
    """sha256 of each output's float64 bytes (rows where keep, all if None)."""
    rows = result if keep is None else result[keep]
    return {name: hashlib.sha256(np.ascontiguousarray(rows[name], dtype=np.float64).tobytes()).hexdigest()
            for name in ["time"] + names}
