# Writes plain_run.json: the digests of plain_run.py's run with the FMUs built
# from main before events (commit 39e6429), FMI 2.0 and 3.0.  Run once:
#   python make_plain_run.py OLD_FMI2.fmu OLD_FMI3.fmu
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import sys

from plain_run import RUNS, digests, plain_run

HERE = os.path.dirname(os.path.abspath(__file__))
out = {}
for version, path in (("2", sys.argv[1]), ("3", sys.argv[2])):
    for run, options in RUNS.items():
        r = plain_run(path, **options)
        out[f"{version} {run}"] = dict(rows=len(r), digests=digests(r))
with open(os.path.join(HERE, "plain_run.json"), "w") as f:
    json.dump(out, f, indent=1, sort_keys=True)
