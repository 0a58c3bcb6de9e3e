# The binary wheel as a cluster user gets it: scripts/wheel.sh makes it (manylinux_2_17 =
# manylinux2014, libdmi and GSL compiled for glibc 2.17, GSL under dmi.libs/); every ELF file in it
# asks glibc for no symbol version above 2.17 (objdump -T, independent of auditwheel); installed with pip into a clean venv
# (binary packages only: no compiler, no GSL needed), it runs Example 4.3 of the paper equal to the
# reference (shared/reference/ex43_N9991.csv, an independent implementation) within 1e-11, and the
# libgsl the process maps is the wheel's copy, not /usr/lib's (/proc/self/maps, ldd, readelf).
# And the sdist builds, and pip turns it into a wheel that holds libdmi.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import json
import os
import re
import subprocess
import sys
import tarfile
import zipfile
from pathlib import Path

import pytest

SOURCE = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).parents[2]))
REFERENCE = Path(os.environ.get("DMI_REFERENCE_DIR", SOURCE.parent / "shared" / "reference"))
GLIBC_FLOOR = (2, 17)

# Example 4.3 (b = alpha = tau = 1, H(s) = cos 2 pi s + cos 10 pi s + cos 20 pi s, g = 1.3 cos 8t,
# z = 0) in first-order form u = (w, w'), written from the paper; N = 9991 to T = 30, every 100th step.
EX43 = r"""
import json, sys
import numpy as np
import dmi
pi = np.pi
s = dmi.Solver(2, 1.0, 9991)
s.set_rhs(lambda t, u: np.array([-u[1], u[0] + 1.3 * np.cos(8 * t)]))
s.set_kernel(lambda x: np.array([[0.0, 0.0], [np.cos(2 * pi * x) + np.cos(10 * pi * x) + np.cos(20 * pi * x), 0.0]]))
s.set_history(lambda t: np.zeros(2))
s.set_friction([0.0, 1.0])
s.init()
t, U = s.run(30 * 9991, stride=100)
ref = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1)
k = (ref[:, 0] // 100).astype(int)
maps = [line.split()[-1] for line in open("/proc/self/maps") if "libgsl" in line]
print(json.dumps({"t_equal": bool(np.array_equal(t[k], ref[:, 1])),
                  "dw": float(np.abs(U[k, 0] - ref[:, 2]).max()),
                  "dv": float(np.abs(U[k, 1] - ref[:, 3]).max()),
                  "static_same": bool(np.array_equal(U[k, 1] == 0, ref[:, 3] == 0)),
                  "static": int((ref[:, 3] == 0).sum()),
                  "gsl": sorted(set(maps)), "dmi": dmi.__file__}))
"""


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("dist")
    r = subprocess.run([str(SOURCE / "scripts" / "wheel.sh"), str(out)], capture_output=True, text=True,
                       timeout=2000)
    assert r.returncode == 0, r.stderr[-4000:]
    path = Path(r.stdout.strip().splitlines()[-1])
    assert path.parent == out and path.is_file()
    return path


def glibc_versions(path: Path) -> set[tuple[int, ...]]:
    """The GLIBC_x.y versions of the symbols path takes from glibc (objdump -T)."""
    text = subprocess.run(["objdump", "-T", str(path)], capture_output=True, text=True, check=True).stdout
    return {tuple(map(int, v.split("."))) for v in re.findall(r"\bGLIBC_([0-9.]+)\b", text)}


def test_wheel_tag_and_glibc_floor(wheel, tmp_path):
    assert re.fullmatch(r"dmi-[0-9.]+-py3-none-manylinux2014_x86_64\.manylinux_2_17_x86_64\.whl", wheel.name), wheel.name
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        z.extractall(tmp_path)
    libs = [n for n in names if re.search(r"\.so(\.[0-9]+)*$", n)]
    gsl = [n for n in libs if n.startswith("dmi.libs/libgsl-")]
    cblas = [n for n in libs if n.startswith("dmi.libs/libgslcblas-")]
    assert len(gsl) == len(cblas) == 1 and {"dmi/libdmi.so.1", "dmi/libdmipy.so"} <= set(libs), libs
    # libgsl names the libgslcblas beside it (its cblas_* symbols are found whoever loads it)
    dyn = subprocess.run(["readelf", "-d", str(tmp_path / gsl[0])], capture_output=True, text=True,
                         check=True).stdout
    assert f"[{Path(cblas[0]).name}]" in dyn, dyn
    versions = {name: glibc_versions(tmp_path / name) for name in libs}
    assert versions[gsl[0]] and versions["dmi/libdmi.so.1"]     # (libdmipy.so may call none)
    for name, v in versions.items():
        assert not v or max(v) <= GLIBC_FLOOR, (name, sorted(v)[-3:])


def test_clean_venv_runs_example_43_with_its_own_gsl(wheel, tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH")}
    # binary packages only: pip may not build anything (no compiler, no GSL needed)
    r = subprocess.run([str(py), "-m", "pip", "install", "-q", "--only-binary=:all:", str(wheel)],
                       capture_output=True, text=True, timeout=600, env=env, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    r = subprocess.run([str(py), "-c", EX43, str(REFERENCE / "ex43_N9991.csv")], capture_output=True,
                       text=True, timeout=600, env=env, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    got = json.loads(r.stdout)
    print(f"Example 4.3 from the wheel: max |dw| = {got['dw']:.3e}, |dv| = {got['dv']:.3e}")
    assert got["t_equal"] and got["dw"] <= 1e-11 and got["dv"] <= 1e-11
    assert got["static_same"] and got["static"] > 100
    package = Path(got["dmi"]).parent
    assert str(package).startswith(str(venv)), package
    # the process mapped one libgsl and one libgslcblas: the wheel's, under site-packages/dmi.libs
    assert sorted(Path(p).name.split("-")[0] for p in got["gsl"]) == ["libgsl", "libgslcblas"], got["gsl"]
    assert all(Path(p).parent == package.parent / "dmi.libs" for p in got["gsl"]), got["gsl"]
    # and the loader resolves libdmi's GSL there (ldd), through its RUNPATH (readelf)
    ldd = subprocess.run(["ldd", str(package / "libdmi.so.1")], capture_output=True, text=True, env=env,
                         check=True).stdout
    found = dict(re.findall(r"^\s*(libgsl\S*) => (\S+)", ldd, re.M))
    assert sorted(n.split("-")[0] for n in found) == ["libgsl", "libgslcblas"], ldd
    assert all(Path(p).resolve().parent == (package.parent / "dmi.libs").resolve() for p in found.values()), ldd
    dyn = subprocess.run(["readelf", "-d", str(package / "libdmi.so.1")], capture_output=True, text=True,
                         check=True).stdout
    assert re.search(r"\((RUNPATH|RPATH)\).*\$ORIGIN/\.\./dmi\.libs", dyn), dyn
    assert not re.search(r"NEEDED.*\[libgsl\.so", dyn), dyn


def tracked_copy(dest: Path) -> Path:
    """The files git tracks, as they are in the working tree, copied to dest: the source tree as a
    clone has it, without the checkout's .venv/ and build*/ (scikit-build-core walks every
    directory of the tree for ignore files before excluding them: 10 minutes over a CI clone's
    46000-file .venv and GSL build)."""
    import shutil
    names = subprocess.run(["git", "ls-files", "-z"], cwd=SOURCE, capture_output=True, check=True
                           ).stdout.decode().split("\0")
    for name in filter(None, names):
        if (SOURCE / name).is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(SOURCE / name, dest / name)
    return dest


def test_sdist_builds_and_makes_a_wheel(tmp_path):
    pytest.importorskip("scikit_build_core")
    src = tracked_copy(tmp_path / "src")
    r = subprocess.run([sys.executable, "-c", "import sys; from scikit_build_core.build import build_sdist; "
                        "print(build_sdist(sys.argv[1]))", str(tmp_path)], capture_output=True, text=True,
                       cwd=src, timeout=300)
    assert r.returncode == 0, r.stderr
    sdist = tmp_path / r.stdout.strip().splitlines()[-1]
    with tarfile.open(sdist) as t:
        names = {n.split("/", 1)[1] for n in t.getnames() if "/" in n}
    assert {"pyproject.toml", "CMakeLists.txt", "src/dmi.c", "python/dmi/__init__.py"} <= names
    r = subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps", "--no-build-isolation", "-w",
                        str(tmp_path / "w"), str(sdist)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    (whl,) = (tmp_path / "w").glob("dmi-*.whl")
    assert "dmi/libdmi.so.1" in zipfile.ZipFile(whl).namelist()
