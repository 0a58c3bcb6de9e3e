# scripts/fmu_run.py as a new user meets it: --help with a
# description and the defaults, a bad output folder refused before the
# simulation with exit 2, and the place of the CSV printed.  DMI_FMU = the
# packed FMU, DMI_SOURCE_DIR = the source tree.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(os.environ["DMI_SOURCE_DIR"]) / "scripts" / "fmu_run.py"
FMU = os.environ["DMI_FMU"]


def run(*args, cwd=None, timeout=60):
    return subprocess.run([sys.executable, str(SCRIPT), *args], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout)


def test_help_has_description_and_defaults():
    r = run("--help")
    assert r.returncode == 0, r.stderr
    text = " ".join(r.stdout.split())  # argparse wraps lines
    assert "Simulates DelayFrictionOscillator.fmu" in text
    assert "Exit status" in text
    # (argparse also breaks a path at its hyphens: compared without any white space)
    bare = "".join(text.split())
    for default in ("(default: " + str(SCRIPT.parent.parent / "build" / "fmu"),
                    "(default: fmu_ex43.csv in the current folder)", "stopTime, 30)",
                    "stepSize, 0.01)", "default: the FMU's start values"):
        assert "".join(default.split()) in bare, default


@pytest.mark.parametrize("out, message", [
    ("/nonexistent-dmi-dir/x.csv", "the folder /nonexistent-dmi-dir does not exist"),
    (".", "is a folder"),
])
def test_bad_output_refused_before_the_simulation(tmp_path, out, message):
    """A run of 10^9 steps (hours) would exceed the timeout: the check comes first."""
    r = run("--fmu", FMU, "--out", out, "--stop-time", "1e6", "--start", "N=1000", cwd=tmp_path,
            timeout=60)
    assert r.returncode == 2, r.stderr
    assert f"--out {out}: {message}" in r.stderr
    assert "Traceback" not in r.stderr


def test_bad_numbers_refused(tmp_path):
    for args in (["--stop-time", "0"], ["--interval", "-1"], ["--stop-time", "nan"]):
        r = run("--fmu", FMU, *args, cwd=tmp_path)
        assert r.returncode == 2 and "is not a number > 0" in r.stderr, (args, r.stderr)
    r = run("--fmu", str(tmp_path / "none.fmu"), cwd=tmp_path)
    assert r.returncode == 2 and "none.fmu: not found" in r.stderr, r.stderr
    assert not list(tmp_path.iterdir())


def test_says_where_it_wrote(tmp_path):
    r = run("--fmu", FMU, "--stop-time", "0.1", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "fmu_ex43.csv"
    assert f"written to {out}" in r.stdout
    lines = out.read_text().splitlines()
    assert lines[0] == "t,w,v,friction,delay_force,sticking" and len(lines) == 12
