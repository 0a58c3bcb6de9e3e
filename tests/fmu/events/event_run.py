# The runs of the oscillator FMU with its event outputs, early return on and
# off, event mode, FMI 2.0 and 3.0, that the built-in indicators taken from
# the solver's step must leave bitwise unchanged: make_event_run.py wrote
# their digests (event_run.json) with the FMUs built from main before that
# (commit d2fa8c6), whose indicators read U, W and X back after every step;
# test_events.py compares the FMUs of this tree with them.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from fmpy import simulate_fmu

from plain_run import OUT, digests

EVENT_OUT = OUT + ["stick_slip_events", "last_event_time"]
EVENT_RUNS = {
    "2 plain": {},
    "2 offgrid": {"output_interval": 0.0123},
    "3 plain": {"output_interval": 0.1},
    "3 early": {"early_return_allowed": True, "output_interval": 0.1},
    "3 early offgrid": {"early_return_allowed": True, "output_interval": 0.0492},
    "3 early+event_mode": {"early_return_allowed": True, "use_event_mode": True,
                           "output_interval": 0.1},
    "3 event_mode": {"use_event_mode": True, "output_interval": 0.1},
}


def event_run(path, run):
    """The run's rows and digests (every output, the event outputs too)."""
    r = simulate_fmu(path, output=EVENT_OUT, stop_time=30.0, **EVENT_RUNS[run])
    return len(r), digests(r, names=EVENT_OUT)
