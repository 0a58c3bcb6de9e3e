"""
An FMU run with stick-slip events (fmpy)
========================================

The project's FMU of the friction oscillator (Example 4.3 by default) simulated by
`fmpy <https://github.com/CATIA-Systems/FMPy>`_ as an FMI 3.0 co-simulation with early return and
event mode: the FMU stops a communication step at each step where the friction sticks or slips
(its event indicator, ``dmi_fmu_stuck``), so the importer sees every transition at its time
:math:`t_p = p h`. The outputs ``sticking``, ``stick_slip_events`` (the number of transitions
so far) and ``last_event_time`` say what happened.

The FMU comes from a CMake build of the repository (``build/fmu/fmi3/``; the environment variable
``DMI_BUILD_DIR`` names another build folder).
"""
# SPDX-License-Identifier: GPL-3.0-or-later
import os
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from fmpy import simulate_fmu

FMU = Path(os.environ.get("DMI_BUILD_DIR", "build")) / "fmu" / "fmi3" / "DelayFrictionOscillator.fmu"

result = simulate_fmu(str(FMU), stop_time=30.0, output_interval=0.05, early_return_allowed=True,
                      use_event_mode=True,
                      output=["w", "v", "sticking", "stick_slip_events", "last_event_time"])

t, w, v = result["time"], result["w"], result["v"]
count = result["stick_slip_events"]
# the rows where the count went up: the transitions (an early return puts a row at each)
events = t[1:][np.diff(count) > 0]
print(f"{count[-1]} stick-slip transitions on t in [0, 30] (h = tau / N = 1/1000); "
      f"the first at t = {events[0]:.3f}, the last at t = {result['last_event_time'][-1]:.3f}")
print(f"the friction sticks over {np.mean(result['sticking']) * 100:.0f} % of the recorded rows")

fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(9, 5), sharex=True, layout="constrained")
ax1.plot(t, w, lw=1)
ax1.set_ylabel("displacement w")
ax2.plot(t, v, lw=1, color="C1")
ax2.set_ylabel("velocity v = w'")
ax2.set_xlabel("time t")
for ax in (ax1, ax2):
    ax.fill_between(t, 0, 1, where=result["sticking"] > 0, color="0.85", step="post",
                    transform=ax.get_xaxis_transform(), label="sticking")
ax2.plot(events, np.zeros_like(events), "|", color="k", ms=6, label="stick-slip event")
ax2.legend(loc="upper right", fontsize=8)
ax1.set_title("DelayFrictionOscillator.fmu (FMI 3.0) through fmpy, event mode")
plt.show()
