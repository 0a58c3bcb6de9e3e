# docs/fmu-export.md, "Export your own model as an FMU": its model (the first
# C block, at most 80 lines) and its CMake lines (the first cmake block),
# built as written from an installed dmi; the FMUs run and agree with
# independent computations: without friction and memory the scheme is
# explicit Euler for x'' + k x = F_in (a recurrence computed here), with
# friction above the spring's force the block never moves.
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
    assert len(code) == 1 and len(code[0].splitlines()) <= 80
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
