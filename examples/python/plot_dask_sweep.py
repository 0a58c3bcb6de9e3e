"""
A parameter sweep on a local Dask cluster
=========================================

:mod:`dmi_sweep` runs the FMU of the friction oscillator over a grid of parameters on a Dask
cluster and writes one row per point into a Parquet dataset; a sweep that is interrupted resumes
where it stopped. Here the cluster is a ``LocalCluster`` of two worker processes on this machine,
started for the sweep and stopped at the end; on a real cluster give ``scheduler=`` its address
(or run ``dmi-sweep run SPEC --scheduler ADDRESS``, :doc:`/sweep`).

The spec sweeps the delay :math:`\\tau` of the oscillator
:math:`w'' + w + \\int_0^\\tau 0.5\\,w(t-s)\\,ds + \\sigma(w') + 1.3\\cos(t/2) \\ni 0` (the FMU with
a constant kernel: the parameters ``H_c0 = 0.5``, ``H_a1 = H_a2 = H_a3 = 0``, ``g_omega = 0.5``), and
samples the displacement :math:`w` once per forcing period :math:`4\\pi` after a transient (a
Poincaré section): one dot per period and delay, the bifurcation diagram. The orbit of the forcing
period doubles near :math:`\\tau = 2.35` (compare :doc:`plot_orbit_branch_tau`, which finds the
orbits and the doubling by continuation).
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import logging
import os
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
from dask.distributed import LocalCluster

from dmi_sweep.run import run
from dmi_sweep.spec import load

FMU = Path(os.environ.get("DMI_BUILD_DIR", "build")) / "fmu" / "DelayFrictionOscillator.fmu"
SPEC = f"""
fmu = "{FMU.resolve()}"
stop_time = 600.0
output_interval = 0.05
transient = 300.0
outputs = ["w"]
[start]
N = 500
H_a1 = 0.0
H_a2 = 0.0
H_a3 = 0.0
H_c0 = 0.5
g_omega = 0.5
[grid]
tau = {{ start = 1.9, stop = 3.1, num = 49 }}
[poincare]
period = "g_omega"
"""


def sweep() -> pd.DataFrame:
    """Runs the spec on a local cluster of 2 worker processes; returns the rows of the points."""
    with tempfile.TemporaryDirectory() as tmp:
        (Path(tmp) / "sweep.toml").write_text(SPEC)
        spec = load(Path(tmp) / "sweep.toml")
        out = Path(tmp) / "results"
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                          dashboard_address=None, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                          silence_logs=logging.ERROR) as cluster:
            summary = run(spec, out, scheduler=cluster.scheduler_address, progress=None,
                          messages=None)
        # leaving the with-block closed the cluster: its scheduler and worker processes are gone
        print(f"{summary.computed} of {summary.total} points computed, {summary.failed} failed, "
              f"in {summary.seconds:.1f} s")
        return pd.read_parquet(out)


# The workers are new processes that import this file again: the sweep runs only in the main one.
if __name__ == "__main__":
    df = sweep()
    print("columns:", ", ".join(df.columns))
    df = df.explode("w_poincare")
    fig, ax = plt.subplots(figsize=(7, 4), layout="constrained")
    ax.plot(df["tau"], df["w_poincare"].astype(float), ".", ms=3, color="k")
    ax.set_xlabel("delay τ")
    ax.set_ylabel("w once per forcing period (t in [300, 600])")
    ax.set_title("the friction oscillator's bifurcation diagram (dmi-sweep, 2 Dask workers)")
    plt.show()
