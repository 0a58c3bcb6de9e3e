# A SIGTERM sent to a pytest run of these tests (ctest stopping it, a cancelled job) still stops
# the processes a test started through the ``processes`` fixture: the run is ended as Ctrl-C ends
# it, and the fixture's teardown runs.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    stat = Path(f"/proc/{pid}/stat")
    return not (stat.exists() and stat.read_text().split()[2] == "Z")


def test_sigterm_to_pytest_stops_the_processes_a_test_started(tmp_path):
    shutil.copy(HERE / "conftest.py", tmp_path / "conftest.py")
    pidfile = tmp_path / "pid"
    (tmp_path / "test_sleeper.py").write_text(
        "import time\n"
        "def test_sleeper(processes):\n"
        f"    p = processes.start(['sleep', '300'])\n"
        f"    open({str(pidfile)!r}, 'w').write(str(p.pid))\n"
        "    time.sleep(300)\n")
    run = subprocess.Popen([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                            str(tmp_path / "test_sleeper.py")], cwd=tmp_path,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    try:
        for _ in range(600):
            if pidfile.exists() and pidfile.read_text():
                break
            time.sleep(0.05)
        sleeper = int(pidfile.read_text())
        assert alive(sleeper)
        run.send_signal(signal.SIGTERM)
        run.wait(timeout=60)
        for _ in range(100):
            if not alive(sleeper):
                break
            time.sleep(0.1)
        assert not alive(sleeper), "the test's process outlived pytest's SIGTERM"
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
        if pidfile.exists() and pidfile.read_text() and alive(int(pidfile.read_text())):
            os.kill(int(pidfile.read_text()), signal.SIGKILL)
