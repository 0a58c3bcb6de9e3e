# dmi-sweep: parameter sweeps and bifurcation diagrams of a co-simulation FMU on Dask.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Parameter sweeps of a co-simulation FMU (FMI 2.0/3.0) on Dask: ``dmi-sweep run|plot``."""
__version__ = "1.0.0"

#: Seconds without any worker after which a run stops (exit 3): --no-worker-timeout, and
#: run()'s no_worker_timeout.
NO_WORKER_TIMEOUT = 60.0
