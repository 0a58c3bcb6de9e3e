# The FMUs' Windows binaries (FMI 2.0: binaries/win64, FMI 3.0:
# binaries/x86_64-windows): imports (system DLLs only) and exports (the
# functions of fmu/fmi2/ or fmu/fmi3/, nothing else), read with mingw-w64's
# objdump; and the C master, built for Windows from tests/fmu/fmu_master.c,
# running under Wine with the DLL of each unpacked FMU: Example 4.3 at
# N = 9991 to T = 30 and rows of the bad-input table, its outputs equal to the
# Linux binary's (the same master on Linux) to 1e-12.  Without a working Wine
# the test fails.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re
import signal
import subprocess
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

NAME = "DelayFrictionOscillator"
# Rows of docs/bad-inputs.md that fmu_master's error paths go through (F: FMI 2.0, G: FMI 3.0).
ROWS = {"2": ["F06", "F11", "F12", "F13", "F25", "F27", "F33", "F50", "F64", "F65", "F87"],
        "3": ["G06", "G11", "G12", "G13", "G25", "G27", "G33", "G50", "G65", "G87"]}
# DLLs every Windows has: the kernel and the C runtime (msvcrt, or the UCRT's API sets).
SYSTEM_DLL = re.compile(r"(kernel32|msvcrt|api-ms-win-crt-[a-z0-9-]+)\.dll", re.I)


def _env(name):
    value = os.environ.get(name)
    if not value:
        pytest.fail(f"environment variable {name} is not set (run the tests through ctest)")
    return value


# FMI version: the FMU's variable, its Windows and Linux platform folders.
FMUS = {"2": ("DMI_FMU", "win64", "linux64"), "3": ("DMI_FMU3", "x86_64-windows", "x86_64-linux")}


def unpack(version, folder):
    with zipfile.ZipFile(_env(FMUS[version][0])) as z:
        z.extractall(folder)
    path = folder / "binaries" / FMUS[version][1] / f"{NAME}.dll"
    assert path.is_file(), f"the FMU has no binaries/{FMUS[version][1]}"
    return path


def objdump(path):
    return subprocess.run([_env("DMI_OBJDUMP"), "-p", str(path)], capture_output=True, text=True,
                          check=True).stdout


def exported_names(dump):
    """The names of objdump's export table ([Ordinal/Name Pointer] Table)."""
    table = dump.split("[Ordinal/Name Pointer] Table", 1)
    assert len(table) == 2, "the DLL has no export table"
    names = []
    for line in table[1].splitlines()[1:]:
        m = re.match(r"\s+\[\s*\d+\] (\S+)$", line)
        if not m:
            break
        names.append(m.group(1))
    return names


@pytest.mark.parametrize("version", ["2", "3"])
def test_imports_are_system_dlls(version, tmp_path):
    imports = re.findall(r"DLL Name: (\S+)", objdump(unpack(version, tmp_path)))
    assert imports, "no import table found"
    assert [d for d in imports if not SYSTEM_DLL.fullmatch(d)] == []


@pytest.mark.parametrize("version", ["2", "3"])
def test_exports_are_the_fmi_functions(version, tmp_path):
    v = version
    header = os.path.join(_env("DMI_SOURCE_DIR"), "fmu", f"fmi{v}", f"fmi{v}Functions.h")
    declared = re.findall(rf"^FMI{v}_Export fmi{v}\w+TYPE (fmi{v}\w+);", open(header).read(), re.M)
    assert len(declared) > 30
    assert sorted(exported_names(objdump(unpack(version, tmp_path)))) == sorted(declared)


def prefix_processes(prefix):
    """The pids of the running processes (not zombies) whose environment has
    WINEPREFIX=prefix (those of this user that /proc lets us read)."""
    mark = b"WINEPREFIX=" + os.fsencode(prefix) + b"\0"
    pids = []
    for entry in os.listdir("/proc"):
        if entry.isdigit() and int(entry) != os.getpid():
            try:
                if open(f"/proc/{entry}/stat").read().rsplit(")", 1)[1].split()[0] == "Z":
                    continue  # ended already, not yet reaped by its parent
                with open(f"/proc/{entry}/environ", "rb") as f:
                    if mark in f.read() + b"\0":
                        pids.append(int(entry))
            except OSError:  # another user's, or gone
                pass
    return pids


def stop(pids, sig):
    for pid in pids:
        try:
            os.kill(pid, sig)
        except ProcessLookupError:  # ended meanwhile
            pass


def program_name(pid):
    try:
        return os.path.basename(os.readlink(f"/proc/{pid}/exe"))
    except OSError:
        return ""


@pytest.fixture(scope="module")
def wine():
    """(wine, environment) with the prefix in the build tree.  Wine starts its
    wineserver and its own processes (services.exe, ...) on the first call;
    afterwards each process of the prefix (found by its environment) is
    stopped by its pid, the wineserver first (SIGTERM: it saves the prefix's
    registry), and the fixture fails if one is still there after SIGKILL."""
    wine, server = _env("DMI_WINE"), _env("DMI_WINESERVER")
    for program in (wine, server):
        if not os.access(program, os.X_OK):
            pytest.fail(f"{program}: Wine cannot run (scripts/deps.sh installs Debian's wine64)")
    prefix = os.path.abspath(_env("DMI_WINEPREFIX"))
    env = dict(os.environ, WINEPREFIX=prefix, WINEDEBUG="-all",
               WINEDLLOVERRIDES="mscoree,mshtml=;winemenubuilder.exe=d")
    env.pop("DISPLAY", None)
    left = prefix_processes(prefix)
    if left:
        pytest.fail(f"processes of {prefix} from an earlier run still run: {left}")
    try:
        yield wine, env
    finally:
        started = prefix_processes(prefix)
        servers = [p for p in started if program_name(p) == os.path.basename(server)]
        stop(servers + [p for p in started if p not in servers], signal.SIGTERM)
        deadline = time.monotonic() + 30
        while prefix_processes(prefix) and time.monotonic() < deadline:
            time.sleep(0.1)
        stop(prefix_processes(prefix), signal.SIGKILL)
        time.sleep(0.5)
        left = prefix_processes(prefix)
    assert not left, f"Wine processes still running after SIGKILL: {left}"


def test_prefix_processes_are_found_and_stopped(tmp_path):
    """The search of the wine fixture's teardown: a process with the prefix in
    its environment is found (and one without it is not), and stop() ends it."""
    prefix = str(tmp_path / "prefix")
    child = subprocess.Popen(["sleep", "60"], env=dict(os.environ, WINEPREFIX=prefix))
    other = subprocess.Popen(["sleep", "60"], env=dict(os.environ, WINEPREFIX=prefix + "x"))
    try:
        # until both have exec'd, /proc/<pid>/environ is still this process's environment
        for _ in range(100):
            if all(Path(f"/proc/{p.pid}/cmdline").read_bytes().startswith(b"sleep")
                   for p in (child, other)):
                break
            time.sleep(0.05)
        assert prefix_processes(prefix) == [child.pid]
        stop([child.pid], signal.SIGTERM)
        assert child.wait(timeout=10) == -signal.SIGTERM
        assert prefix_processes(prefix) == []
    finally:
        for p in (child, other):
            p.kill()
            p.wait()


def run_master(command, out, **kw):
    guid, ref = _env("DMI_FMU_GUID"), _env("DMI_REFERENCE")
    done = subprocess.run(command + [guid, ref, "30", str(out)], capture_output=True, text=True,
                          timeout=300, **kw)
    assert done.returncode == 0, done.stdout + done.stderr
    return done


def logged(stderr):
    """The messages fmu_master's logger printed ([instance status category] message)."""
    return [line for line in stderr.splitlines() if line.startswith("[")]


def table_messages():
    path = os.path.join(_env("DMI_SOURCE_DIR"), "docs", "bad-inputs.md")
    rows = {}
    for line in open(path):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if re.fullmatch(r"[FG]\d+", cells[0]):
            rows[cells[0]] = cells[-1]
    return rows


@pytest.mark.parametrize("version", ["2", "3"])
def test_master_under_wine(version, wine, tmp_path):
    program, env = wine
    dll = unpack(version, tmp_path)
    so = tmp_path / "binaries" / FMUS[version][2] / f"{NAME}.so"
    linux = run_master([_env("DMI_MASTER"), str(so)], tmp_path / "linux.csv")
    windows = run_master([program, _env("DMI_MASTER_EXE"), str(dll)], tmp_path / "windows.csv",
                         env=env)
    a = np.loadtxt(tmp_path / "linux.csv", delimiter=",")
    b = np.loadtxt(tmp_path / "windows.csv", delimiter=",")
    assert a.shape == b.shape and a.shape[0] > 2900  # t = 0, 100 h, ..., 30
    assert np.array_equal(a[:, 0], b[:, 0])
    assert np.max(np.abs(a[:, 1:] - b[:, 1:])) <= 1e-12
    # The same logged reasons, and those of the table's rows among them.
    assert logged(windows.stderr) == logged(linux.stderr)
    table = table_messages()
    for row in ROWS[version]:
        assert any(line.endswith("] " + table[row]) for line in logged(windows.stderr)), row
