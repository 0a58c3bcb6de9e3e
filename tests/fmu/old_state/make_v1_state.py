# Writes the format-1 fixtures of test_old_state.py with the oscillator FMU of
# the libdmi 1.0.0 release (commit 5cd99de; FMI 2.0 only, its FMU state
# format 1 holding libdmi's state format 1, without the recursion's sums): a
# state saved by that FMU in step mode (state_v1_fmi2.bin) and the outputs
# that FMU gave after restoring it (outputs_v1_fmi2.json, floats as hex), the
# run of old_state_run.py.  Run once with that commit's build, e.g.
#   git worktree add /tmp/v100 5cd99de   (or: git archive 5cd99de | tar -x -C /tmp/v100)
#   cmake -S /tmp/v100 -B /tmp/v100/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DDMI_BUILD_TESTS=OFF
#   cmake --build /tmp/v100/build --target dmi_fmu_package
#   python make_v1_state.py /tmp/v100/build/fmu/DelayFrictionOscillator.fmu
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import struct
import sys

from old_state_run import OUT, open_fmu, run_from_state, save_state

HERE = os.path.dirname(os.path.abspath(__file__))

fmu, md = open_fmu(sys.argv[1], "2")
state = save_state(fmu, md, "2")
# FMU state format 1 (bytes 8..11), libdmi's state format 1 (its second word)
assert struct.unpack_from("<I", state, 8)[0] == 1
assert struct.unpack_from("<Q", state, 40 + 8 * 22 + 8)[0] == 1
with open(os.path.join(HERE, "state_v1_fmi2.bin"), "wb") as f:
    f.write(state)
rows = run_from_state(fmu, md, "2", state)
with open(os.path.join(HERE, "outputs_v1_fmi2.json"), "w") as f:
    json.dump({"outputs": OUT, "rows": [[float(x).hex() for x in r] for r in rows]}, f)
fmu.terminate()
fmu.freeInstance()
