# Writes the fixtures of test_old_state.py with the oscillator FMU of libdmi
# 1.1 before the FMU framework (commit cfb5f35, fmu/ with model.c holding the
# whole model): a state saved by that FMU in step mode (state_fmi<v>.bin) and
# the outputs that FMU gave after restoring it (outputs_fmi<v>.json, floats
# as hex) and the outputs of its default experiment's first 5 s
# (fresh_fmi<v>.json).  Run once with that commit's build:
#   python make_old_state.py build/fmu/DelayFrictionOscillator.fmu build/fmu/fmi3/DelayFrictionOscillator.fmu
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import sys

from old_state_run import OUT, fresh_run, open_fmu, run_from_state, save_state

HERE = os.path.dirname(os.path.abspath(__file__))

for version, path in (("2", sys.argv[1]), ("3", sys.argv[2])):
    fmu, md = open_fmu(path, version)
    state = save_state(fmu, md, version)
    with open(os.path.join(HERE, f"state_fmi{version}.bin"), "wb") as f:
        f.write(state)
    rows = run_from_state(fmu, md, version, state)
    with open(os.path.join(HERE, f"outputs_fmi{version}.json"), "w") as f:
        json.dump({"outputs": OUT, "rows": [[float(x).hex() for x in r] for r in rows]}, f)
    fmu.terminate()
    fmu.freeInstance()
    fmu, md = open_fmu(path, version)
    rows = fresh_run(fmu, md, version)
    with open(os.path.join(HERE, f"fresh_fmi{version}.json"), "w") as f:
        json.dump({"outputs": OUT, "rows": [[float(x).hex() for x in r] for r in rows]}, f)
    fmu.terminate()
    fmu.freeInstance()
