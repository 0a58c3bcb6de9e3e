# Writes event_run.json: the digests of event_run.py's runs with the FMUs
# built from main before the built-in indicators were taken from the
# solver's step (commit d2fa8c6), FMI 2.0 and 3.0.  Run once:
#   python make_event_run.py OLD_FMI2.fmu OLD_FMI3.fmu
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import sys

from event_run import EVENT_RUNS, event_run

HERE = os.path.dirname(os.path.abspath(__file__))
out = {}
for run in EVENT_RUNS:
    rows, digests = event_run(sys.argv[1] if run.startswith("2") else sys.argv[2], run)
    out[run] = dict(rows=rows, digests=digests)
with open(os.path.join(HERE, "event_run.json"), "w") as f:
    json.dump(out, f, indent=1, sort_keys=True)
