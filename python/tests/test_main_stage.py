# The main job's sweep stage, scripts/sweep_ex43.sh: it fails with a message
# when the FMU or dmi-sweep is missing (it skipped the diagram silently),
# prints the number of points of the spec it ran (it printed a fixed 60), and
# plots over the spec's swept parameter (the main job's spec sweeps g_omega).
# dmi-sweep is this checkout's (python -m dmi_sweep through a wrapper); the
# script runs in its own process group, killed when it ends.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import sys
from pathlib import Path

import pytest

from conftest import PYTHON_DIR, env_with_package, finish_group, start_group

SCRIPT = PYTHON_DIR.parent / "scripts" / "sweep_ex43.sh"

SMALL = """stop_time = 2.0
output_interval = 0.01
transient = 1.0
outputs = ["w", "sticking"]
[start]
N = 200
[grid]
g_amp = { start = 0.5, stop = 4.0, num = 3 }
[poincare]
period = "g_omega"
"""


@pytest.fixture
def build(fmu_path) -> Path:
    return Path(fmu_path).resolve().parents[1]       # <build>/fmu/DelayFrictionOscillator.fmu


@pytest.fixture
def sweep_command(tmp_path) -> Path:
    wrapper = tmp_path / "dmi-sweep"
    wrapper.write_text(f"#!/bin/sh\nexec {sys.executable} -m dmi_sweep \"$@\"\n")
    wrapper.chmod(0o755)
    return wrapper


def run(out, *args, **env):
    return finish_group(start_group(["bash", SCRIPT, out, *args], {**env_with_package(), **env}), 300)


def test_prints_the_points_of_the_spec(tmp_path, build, sweep_command):
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL)
    r = run(tmp_path / "out", spec, DMI_BUILD_DIR=str(build), DMI_SWEEP=str(sweep_command))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "bifurcation diagram: 3 points of g_amp (N = 200, T = 2) in " in r.stdout, r.stdout
    for png in ("bifurcation_ex43.png", "stick_fraction_ex43.png"):
        assert (tmp_path / "out" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_plots_over_the_swept_parameter(tmp_path, build, sweep_command):
    spec = tmp_path / "small.toml"
    spec.write_text(SMALL.replace("g_amp = { start = 0.5, stop = 4.0, num = 3 }",
                                  "g_omega = { start = 6.0, stop = 8.0, num = 2 }"))
    r = run(tmp_path / "out", spec, DMI_BUILD_DIR=str(build), DMI_SWEEP=str(sweep_command))
    assert r.returncode == 0, r.stdout + r.stderr
    assert "bifurcation diagram: 2 points of g_omega (N = 200, T = 2) in " in r.stdout, r.stdout
    assert (tmp_path / "out" / "bifurcation_ex43.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_main_spec_is_valid():
    """The main job's default spec loads (every key and parameter known to dmi-sweep)."""
    from dmi_sweep.spec import load
    spec = load(PYTHON_DIR.parent / "examples" / "python" / "oscillator_tau.toml")
    assert spec.n_points >= 50


def test_missing_fmu_fails(tmp_path, sweep_command):
    r = run(tmp_path / "out", DMI_BUILD_DIR=str(tmp_path / "nobuild"), DMI_SWEEP=str(sweep_command))
    assert r.returncode == 1
    assert f"sweep_ex43: the FMU {tmp_path}/nobuild/fmu/DelayFrictionOscillator.fmu does not exist" in r.stderr
    assert not (tmp_path / "out").exists()


def test_missing_dmi_sweep_fails(tmp_path, build):
    r = run(tmp_path / "out", DMI_BUILD_DIR=str(build), DMI_SWEEP=str(tmp_path / "none"))
    assert r.returncode == 1
    assert f"sweep_ex43: dmi-sweep ({tmp_path}/none) is not installed" in r.stderr
    assert not (tmp_path / "out").exists()


def test_failing_sweep_fails(tmp_path, build, sweep_command):
    spec = tmp_path / "bad.toml"
    spec.write_text(SMALL.replace("g_amp", "g_ampp"))
    r = run(tmp_path / "out", spec, DMI_BUILD_DIR=str(build), DMI_SWEEP=str(sweep_command))
    assert r.returncode == 1
    assert "'g_ampp' is not a variable" in r.stderr and "sweep_ex43: the sweep failed" in r.stderr
