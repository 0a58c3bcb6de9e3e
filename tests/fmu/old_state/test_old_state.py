# The oscillator FMU built with the framework (dmi_add_fmu) against the FMU
# of libdmi 1.1 before it (the fixtures of make_old_state.py): a state that
# FMU saved restores, and the run from it gives the same outputs bitwise;
# the default experiment's first 5 s too.  Both FMI 2.0 and 3.0.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os

import pytest

from old_state_run import fresh_run, open_fmu, run_from_state

HERE = os.path.dirname(os.path.abspath(__file__))


def expected(kind, version):
    with open(os.path.join(HERE, f"{kind}_fmi{version}.json")) as f:
        return [[float.fromhex(x) for x in r] for r in json.load(f)["rows"]]


def path(version):
    return os.environ["DMI_FMU" if version == "2" else "DMI_FMU3"]


@pytest.mark.parametrize("version", ["2", "3"])
def test_old_state_restores_bitwise(version):
    with open(os.path.join(HERE, f"state_fmi{version}.bin"), "rb") as f:
        state = f.read()
    fmu, md = open_fmu(path(version), version)
    rows = run_from_state(fmu, md, version, state)
    assert rows == expected("outputs", version)
    fmu.terminate()
    fmu.freeInstance()


@pytest.mark.parametrize("version", ["2", "3"])
def test_default_run_bitwise(version):
    fmu, md = open_fmu(path(version), version)
    assert fresh_run(fmu, md, version) == expected("fresh", version)
    fmu.terminate()
    fmu.freeInstance()
