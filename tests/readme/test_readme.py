# README.md as a newcomer reads it: at most 250 lines; the install command builds Release; every
# relative link and image resolves; the fmpy example runs and gives what it says (4001 rows 0.01
# apart, w(40) equal to the native Example 4.3 run of build/examples/ex43); the sweep example (its
# spec and its three commands) runs and writes one row per grid point and the plot.
# The C program is built and run by readme_snippet.sh.  Environment (set by ctest): DMI_FMU,
# DMI_EXAMPLES_DIR.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import io
import os
import re
import signal
import subprocess
import sys
from contextlib import redirect_stdout
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
README = (ROOT / "README.md").read_text()
FMU = os.environ.get("DMI_FMU", "")
EXAMPLES = Path(os.environ.get("DMI_EXAMPLES_DIR", ROOT / "build" / "examples"))
BIN = Path(sys.executable).parent


def blocks(lang: str) -> list[str]:
    return re.findall(rf"^```{lang}\n(.*?)^```$", README, re.M | re.S)


def run_group(cmd: str, cwd: Path, env: dict) -> subprocess.CompletedProcess:
    """A shell command in its own process group, the group killed by its id when it ends."""
    p = subprocess.Popen(cmd, shell=True, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, start_new_session=True)
    try:
        out, err = p.communicate(timeout=600)
    finally:
        try:
            os.killpg(p.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    return subprocess.CompletedProcess(cmd, p.returncode, out, err)


def test_short():
    n = len(README.splitlines())
    assert n <= 250, f"README.md has {n} lines"


def test_install_command_builds_release():
    sh = "\n".join(blocks("sh"))
    assert re.search(r"^cmake -S \. -B (\S+) -DCMAKE_BUILD_TYPE=Release$", sh, re.M), sh
    assert "cmake --install" in sh and "scripts/main.sh" in sh and "scripts/test.sh" in sh


def test_links_and_images_resolve():
    targets = re.findall(r"\]\(([^)\s]+)\)", README)
    local = [t for t in targets if not re.match(r"[a-z]+:", t)]
    assert len(local) >= 10
    for t in local:
        path = t.split("#")[0]
        assert (ROOT / path).exists(), f"README links to {t}, which does not exist"
    images = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", README)
    assert len(images) == 1, images


def test_fmpy_example():
    code = blocks("python")[0]
    assert "output_interval=0.01" in code and "simulate_fmu(" in code
    code = code.replace('"build/fmu/DelayFrictionOscillator.fmu"', repr(FMU))
    out = io.StringIO()
    scope: dict = {}
    with redirect_stdout(out):
        exec(compile(code, "README.md", "exec"), scope)
    rows, dt, w40 = out.getvalue().split()
    assert int(rows) == 4001 and float(dt) == 0.01
    r = scope["r"]
    assert np.allclose(np.diff(r["time"]), 0.01, rtol=0, atol=1e-12)
    native = subprocess.run([EXAMPLES / "ex43", "9991", "40", "399640"], capture_output=True, text=True,
                            check=True).stdout.strip().splitlines()[-1].split(",")
    assert abs(float(native[0]) - 40) < 1e-9
    assert abs(float(w40) - float(native[1])) <= 1e-10, (w40, native)


def test_sweep_example(tmp_path):
    spec = blocks("toml")[0].replace('"build/fmu/DelayFrictionOscillator.fmu"', repr(FMU))
    (tmp_path / "sweep.toml").write_text(spec)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
    commands = [ln for ln in blocks("sh")[-1].splitlines() if ln.startswith(".venv/bin/")]
    assert len(commands) == 3, commands
    for cmd in commands:
        cmd = re.sub(r"^\.venv/bin/dmi-sweep", f"{sys.executable} -m dmi_sweep", cmd)
        cmd = re.sub(r"^\.venv/bin/python", sys.executable, cmd)
        r = run_group(cmd, tmp_path, env)
        assert r.returncode == 0, r.stdout + r.stderr
    assert "tau" in r.stdout and "sticking_mean" in r.stdout
    import pandas
    table = pandas.read_parquet(tmp_path / "results")
    assert len(table) == 6 and table["error"].isna().all()
    assert sorted(table["tau"]) == list(np.linspace(2.0, 3.0, 6))
    assert (tmp_path / "bifurcation.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
