# The distribution as pip builds it from this checkout (pyproject.toml at the
# top, scikit-build-core, no prior CMake build): the wheel holds the two
# packages, libdmi under its soname and libdmipy.so, the console script
# dmi-sweep, and nothing of libdmi's own install tree; installed into an empty
# folder it imports and runs without the build tree.  And `pip install <path>`
# into a clean venv (build isolation: pip fetches scikit-build-core, CMake's
# build runs from nothing) gives a working `import dmi`.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import re
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).parents[3]))
# the version, as CMakeLists.txt's project() states it
VERSION = re.search(r"project\(dmi VERSION ([0-9.]+)", (SOURCE / "CMakeLists.txt").read_text()).group(1)
# f = -u, no A, no kernel, z = 1: U^{p+1} = U^p - h f = (1 + h) U^p, h = 0.1
RUN = ("import dmi, numpy as np; s = dmi.Solver(1, 1.0, 10); s.set_rhs(lambda t, u: -u); "
       "s.set_history(lambda t: np.ones(1)); s.init(); t, U = s.run(10, 5); "
       "print(dmi.__file__, dmi.version(), U[:, 0].tolist())")


def check_run(python, env, cwd, package_dir):
    r = subprocess.run([str(python), "-c", RUN], capture_output=True, text=True, env=env, timeout=60,
                       cwd=cwd)
    assert r.returncode == 0, r.stderr
    where, version, states = r.stdout.split(" ", 2)
    assert where == str(package_dir / "dmi" / "__init__.py") and version == VERSION
    expected = [1.0, 1.1 ** 5, 1.1 ** 10]
    got = json.loads(states)
    assert len(got) == 3 and all(abs(a - b) <= 1e-14 * b for a, b in zip(got, expected)), got


def test_wheel_builds_installs_and_runs(tmp_path):
    pytest.importorskip("scikit_build_core")
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation",
                        "-w", str(tmp_path / "wheel"), str(SOURCE)],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    (wheel,) = (tmp_path / "wheel").glob("dmi-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    files = {n for n in names if ".dist-info/" not in n}
    assert {"dmi/__init__.py", "dmi/libdmi.so.1", "dmi/libdmipy.so", "dmi_sweep/cli.py"} <= files
    assert all(n.startswith(("dmi/", "dmi_sweep/")) for n in files), files
    entry = next(n for n in names if n.endswith("entry_points.txt"))
    assert "dmi-sweep = dmi_sweep.cli:main" in zipfile.ZipFile(wheel).read(entry).decode()

    target = tmp_path / "site"
    r = subprocess.run([sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target",
                        str(target), str(wheel)], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    check_run(sys.executable, dict(os.environ, PYTHONPATH=str(target)), tmp_path, target)


def test_pip_install_path_in_a_clean_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    r = subprocess.run([str(py), "-m", "pip", "install", "-q", str(SOURCE)], capture_output=True,
                       text=True, timeout=900, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    r = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                       capture_output=True, text=True, check=True, env=env)
    check_run(py, env, tmp_path, Path(r.stdout.strip()))
