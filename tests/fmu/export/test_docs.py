# docs/fmu-export.md, "Export your own model as an FMU": its model (the first
# C block, at most 80 lines; the second, its events) and its CMake lines (the first cmake block),
# built as written from an installed dmi; the FMUs run and agree with
# independent computations: without friction and memory the scheme is
# explicit Euler for x'' + k x = F_in (a recurrence computed here), with
# friction above the spring's force the block never moves; with the page's
# event indicators (its second C block) the FMI 3.0 FMU returns early at the
# scheme's stick-slip transitions.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re

import pytest
from fmpy.validation import validate_fmu

from conftest import Instance, build, fmus


def blocks(source_dir, lang):
    with open(os.path.join(source_dir, "docs", "fmu-export.md"), encoding="utf-8") as f:
        return re.findall(r"^```" + lang + r"\n(.*?)^```$", f.read(), re.M | re.S)


@pytest.fixture(scope="module")
def block_fmus(prefix, source_dir, tmp_path_factory):
    src = tmp_path_factory.mktemp("block")
    (src / "block.c").write_text(blocks(source_dir, "c")[0])
    (src / "CMakeLists.txt").write_text(blocks(source_dir, "cmake")[0])
    build(src, src / "build", prefix)
    return fmus(src / "build", "FrictionBlock")


def test_model_is_short(source_dir):
    code = blocks(source_dir, "c")
    # the model, its events (then other snippets, such as a fitted kernel's configure)
    assert len(code) >= 2 and len(code[0].splitlines()) <= 80
    assert "dmi_add_fmu(FrictionBlock SOURCES block.c)" in blocks(source_dir, "cmake")[0]


@pytest.mark.parametrize("version", ["2", "3"])
def test_block_without_friction_is_explicit_euler(block_fmus, version):
    assert validate_fmu(block_fmus[version]) == []
    inst = Instance(block_fmus[version])
    inst.set("alpha", 0.0)
    inst.set("g", 0.0)
    inst.set("F_in", 0.5)
    inst.start()
    h, k, x, v = 5.0 / 500, 4.0, 1.0, 0.0
    for step in range(40):  # communication step 0.05 = 5 h
        inst.fmu.doStep(step * 0.05, 0.05)
        for _ in range(5):
            x, v = x + h * v, v - h * (k * x - 0.5)
        got = inst.get(["x", "v"])
        assert abs(got[0] - x) <= 1e-12 and abs(got[1] - v) <= 1e-12, (step, got, x, v)
    assert x < 0.9  # it moved
    inst.free()


@pytest.mark.parametrize("version", ["2", "3"])
def test_block_sticks_under_strong_friction(block_fmus, version):
    inst = Instance(block_fmus[version])
    inst.set("alpha", 10.0)  # above k x0 = 4 plus the memory force
    inst.start()
    for step in range(100):
        inst.fmu.doStep(step * 0.05, 0.05)
        assert inst.get(["x", "v"]) == [1.0, 0.0]
    with pytest.raises(Exception):
        inst.set("F_in", float("nan"))
    assert any("F_in = nan" in m for _, _, m in inst.log), inst.log
    inst.free()


@pytest.fixture(scope="module")
def block_events_fmus(prefix, source_dir, tmp_path_factory):
    """The block with the page's second C block (its indicators) added as it says."""
    src = tmp_path_factory.mktemp("block_events")
    model, events = blocks(source_dir, "c")[:2]
    anchor = "const dmi_fmu_model DMI_FMU_MODEL = {"
    fields = ".configure = configure, .outputs = outputs, .accept = accept,"
    assert model.count(anchor) == 1 and model.count(fields) == 1
    model = model.replace(anchor, events + "\n" + anchor)
    model = model.replace(fields, fields + "\n    .nindicators = 1, .indicators = indicators,")
    (src / "block.c").write_text(model)
    (src / "CMakeLists.txt").write_text(blocks(source_dir, "cmake")[0])
    build(src, src / "build", prefix)
    return fmus(src / "build", "FrictionBlock")


def test_block_events_return_early_at_the_recurrences_transitions(block_events_fmus):
    """Without memory and input, the scheme for the block is the recurrence
    X = (x + h v, v - h k x), x' = X_0, v' = X_1 shrunk by h alpha (libdmi's
    friction resolvent), computed here; the block is stuck after step p when
    |X_1| <= h alpha.  The FMI 3.0 FMU with early return (communication step
    0.05 = 5 h) stops at every transition's step before a communication point."""
    from fmpy import extract, read_model_description
    from fmpy.simulation import instantiate_fmu
    path = block_events_fmus["3"]
    md = read_model_description(path)
    assert md.coSimulation.mightReturnEarlyFromDoStep and md.coSimulation.hasEventMode
    fmu = instantiate_fmu(extract(path), md, "CoSimulation", early_return_allowed=True)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    fmu.setFloat64([vr["g"]], [0.0])
    fmu.enterInitializationMode(startTime=0.0)
    fmu.exitInitializationMode()
    h, k, lam, x, v = 5.0 / 500, 4.0, 5.0 / 500 * 0.5, 1.0, 0.0
    stuck, want = [abs(v) <= lam], []
    for p in range(1, 2001):  # t in [0, 20]
        X0, X1 = x + h * v, v - h * (k * x)
        x, v = X0, (X1 - lam if X1 > lam else X1 + lam if X1 < -lam else 0.0)
        stuck.append(abs(X1) <= lam)
        if stuck[p] != stuck[p - 1]:
            want.append(p)
    assert len(want) >= 4  # it slips, sticks, ... (x0 = 1 and k x0 > alpha)
    got, t, k_comm = [], 0.0, 0
    while k_comm < 400:
        end = (k_comm + 1) * 0.05
        _, _, early, last = fmu.doStep(currentCommunicationPoint=t, communicationStepSize=end - t)
        if early:
            got.append(round(last / h))
            assert abs(last - got[-1] * h) <= 1e-9 * h and last < end
            t = last
        else:
            t, k_comm = end, k_comm + 1
    assert got == [p for p in want if p % 5 != 0]
    fmu.terminate()
    fmu.freeInstance()
