# The progress bar (points done of total, rate, time left) on a fake clock; the
# watch of a cluster without workers, on a fake clock and client; the result
# folder's write-then-rename: no temporary file left, a temporary file of a
# killed writer never read and removed when the folder is reopened; the folder
# lock, with flock and with the Windows branch (msvcrt.locking, emulated here).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import io
import os
import subprocess
import sys

import pandas as pd
import pytest

from conftest import env_with_package, write_spec
from dmi_sweep.run import ClusterLost, Progress, WorkerWatch


class Clock:
    def __init__(self):
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_progress_lines_in_a_log():
    """Not a terminal: one line per update at most every 5 s, and one at close()."""
    clock, out = Clock(), io.StringIO()
    bar = Progress(100, 20, out, width=10, clock=clock)   # 20 points were there before this run
    clock.now += 2.0
    bar.update(5)                         # the first update shows at once: 5 points in 2 s
    clock.now += 3.0
    bar.update(5)                         # 3 s later: not shown
    clock.now += 5.0
    bar.update(10)                        # 40 of 100 after 10 s: 20 points in 10 s = 2/s, 60 left: 30 s
    clock.now += 1.0
    bar.update(1)                         # not shown, until close()
    bar.close()
    assert out.getvalue().splitlines() == [
        "[##--------] 25/100 points, 2.50/s, 00:00:30 left",      # 75 left at 2.5/s
        "[####------] 40/100 points, 2.00/s, 00:00:30 left",
        "[####------] 41/100 points, 1.91/s, 00:00:31 left",      # 21 in 11 s, 59 left: 30.9 s
    ]


def test_progress_on_a_terminal_and_long_times():
    """A terminal: the line is rewritten (carriage return) every 0.2 s at most; a newline at
    close(); times left of more than a day in hours; before any rate, no time left."""
    clock, out = Clock(), Terminal()
    bar = Progress(10_000, 0, out, width=4, clock=clock)
    bar.update(0)
    clock.now += 100.0
    bar.update(1)
    clock.now += 0.1
    bar.update(1)                         # 0.1 s later: not shown
    clock.now += 0.1
    bar.close()
    assert out.getvalue() == ("\r[----] 0/10000 points, 0.00/s, --:--:-- left"
                              "\r[----] 1/10000 points, 0.01/s, 277:45:00 left"   # 9999 * 100 s
                              "\r[----] 2/10000 points, 0.02/s, 139:08:20 left"   # 9998 * 50.1 s
                              "\n")


def test_progress_last_line_once():
    """close() after an update that showed the final count prints no second line."""
    clock, out = Clock(), io.StringIO()
    bar = Progress(10, 0, out, width=10, clock=clock)
    clock.now += 1.0
    bar.update(10)
    clock.now += 1.0
    bar.close()
    assert out.getvalue() == "[##########] 10/10 points, 10.00/s, 00:00:00 left\n"
    tty = Terminal()
    bar = Progress(10, 0, tty, width=10, clock=clock)
    clock.now += 1.0
    bar.update(10)
    bar.note(tty, "dmi-sweep: lost worker tcp://x")
    bar.close()
    assert tty.getvalue() == ("\r[##########] 10/10 points, 10.00/s, 00:00:00 left"
                              "\r\033[Kdmi-sweep: lost worker tcp://x\n"
                              "\r[##########] 10/10 points, 10.00/s, 00:00:00 left\n")


def test_progress_quiet():
    bar = Progress(10, 0, None, clock=Clock())
    bar.update(10)
    bar.close()
    assert bar.done == 10


def _dead_pid() -> int:
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait(timeout=30)
    return p.pid


def test_write_then_rename(tmp_path, fmu_path):
    """A chunk written leaves no temporary file; a half-written chunk of a killed writer (a
    temporary file of a process that no longer runs) is never read by pandas and is removed when
    the folder is reopened; a temporary file of a running writer is kept."""
    from dmi_sweep.spec import load
    from dmi_sweep.store import Store
    spec = load(write_spec(tmp_path, f'fmu = "{fmu_path}"\nstop_time = 1.0\noutput_interval = 0.1\n'
                                     'transient = 0.5\noutputs = ["w"]\n[grid]\ng_amp = [1.0, 2.0]\n'))
    out = tmp_path / "out"
    store = Store.open(out, spec)
    part = store.write([{"point": 1, "w_final": 0.5, "w_min": 0.0, "w_max": 1.0, "w_mean": 0.25}])
    assert sorted(p.name for p in out.iterdir()) == ["_lock", "_log.jsonl", "_meta.json", "_spec.toml",
                                                     part.name]
    half = part.read_bytes()[: part.stat().st_size // 2]
    dead = out / f".tmp-{_dead_pid()}-part-000000000.parquet"
    alive = out / f".tmp-{os.getpid()}-part-000000007.parquet"
    for p in (dead, alive):
        p.write_bytes(half)
    df = pd.read_parquet(out)                       # the reader skips the temporary files
    assert list(df["point"]) == [1] and list(df["w_final"]) == [0.5] and list(df["g_amp"]) == [2.0]
    store.close()
    assert Store.open(out, spec).done() == {1}
    assert not dead.exists() and alive.exists()


def test_failed_write_leaves_no_temporary_file(tmp_path, fmu_path):
    """A write that fails halfway (disk full, say) removes its temporary file and the file it
    would have replaced stays as it was."""
    from dmi_sweep.spec import load
    from dmi_sweep.store import Store
    spec = load(write_spec(tmp_path, f'fmu = "{fmu_path}"\nstop_time = 1.0\noutput_interval = 0.1\n'
                                     'transient = 0.5\noutputs = ["w"]\n[grid]\ng_amp = [1.0]\n'))
    store = Store.open(tmp_path / "out", spec)
    before = sorted((p.name, p.read_bytes()) for p in (tmp_path / "out").iterdir())

    def half_then_full(f):
        f.write(b"half a file")
        raise OSError(28, "No space left on device")

    with pytest.raises(OSError, match="No space left"):
        store._write_atomic("_meta.json", half_then_full)
    assert sorted((p.name, p.read_bytes()) for p in (tmp_path / "out").iterdir()) == before


def test_lock_held_until_close(tmp_path, fmu_path):
    """While a Store is open, opening the folder again (another open file, as another client's) is
    refused naming the holder; after close() it opens; an unrelated non-empty folder is refused
    without a lock file being left in it."""
    import json
    import socket
    from dmi_sweep.spec import load
    from dmi_sweep.store import Store, StoreError
    spec = load(write_spec(tmp_path, f'fmu = "{fmu_path}"\nstop_time = 1.0\noutput_interval = 0.1\n'
                                     'transient = 0.5\noutputs = ["w"]\n[grid]\ng_amp = [1.0]\n'))
    first = Store.open(tmp_path / "out", spec)
    holder = json.loads((tmp_path / "out" / "_lock").read_text())
    assert holder["pid"] == os.getpid() and holder["host"] == socket.gethostname()
    with pytest.raises(StoreError, match=f"in use by another dmi-sweep client \\(pid {os.getpid()} on "
                       f"{socket.gethostname()}, started {holder['started']}\\)"):
        Store.open(tmp_path / "out", spec)
    first.close()
    Store.open(tmp_path / "out", spec).close()
    other = tmp_path / "other"
    other.mkdir()
    (other / "notes.txt").write_text("mine")
    with pytest.raises(StoreError, match="holds no dmi-sweep results"):
        Store.open(other, spec)
    assert [p.name for p in other.iterdir()] == ["notes.txt"]


class Workers:
    """A client whose scheduler answers nthreads() with the given numbers of workers, in turn."""

    def __init__(self, answers: list[int]):
        self.answers, self.status, self.asked = list(answers), "running", 0

    def nthreads(self) -> dict[str, int]:
        self.asked += 1
        return {f"tcp://127.0.0.1:{40000 + i}": 1 for i in range(self.answers.pop(0))}


def test_worker_watch_times_out_after_a_run_of_answers_without_workers():
    """Timeout 4 s: the scheduler is asked at most every second; a worker seen resets the count;
    the 4th second of "no worker" in a row (asked at 3, 4, 5, 6, 7) raises ClusterLost."""
    clock, client = Clock(), Workers([0, 0, 1, 0, 0, 0, 0, 0])
    watch = WorkerWatch(client, 4.0, " at tcp://head:8786", clock=clock)
    start = clock.now
    for t in (0.0, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 6.9):
        clock.now = start + t
        watch.check()                     # 0.5 and 6.9: less than a second after the last question
    assert client.asked == 7
    client.status = "connecting"          # reconnecting to the scheduler: not asked
    clock.now = start + 8.0
    watch.check()
    assert client.asked == 7
    client.status = "running"
    with pytest.raises(ClusterLost) as e:
        watch.check()                     # 8 - 3 >= 4
    assert client.asked == 8
    assert e.value.reason == "the scheduler at tcp://head:8786 has had no worker for 4 s"
    assert e.value.resume == "once the cluster has workers again"


def test_worker_watch_short_timeout_and_workers_back():
    """A timeout under 4 s asks every quarter of it (0.125 s for 0.5 s); workers back before it
    ends: no error; then 0.5 s of "no worker" from the next answer on raises."""
    clock, client = Clock(), Workers([0, 0, 0, 2, 0, 0, 0, 0, 0])
    watch = WorkerWatch(client, 0.5, clock=clock)
    start = clock.now
    for k in range(8):                    # asked at 0, ..., 0.875 s: no worker since 0.5 s
        clock.now = start + 0.125 * k
        watch.check()
    assert client.asked == 8
    clock.now = start + 1.0
    with pytest.raises(ClusterLost, match="^the scheduler has had no worker for 0.5 s$"):
        watch.check()


# The Windows branch of the folder lock run on this machine: fcntl made unavailable and msvcrt
# replaced by an emulation with POSIX record locks (lockf on the byte range msvcrt.locking would
# lock: nbytes from the file's position; a refusal raises PermissionError(EACCES) as the C runtime's
# _locking does). What Windows alone would show (its locked bytes cannot be read by others) is not
# tested here.
WINDOWS = r"""
import errno, os, sys, time, types
from pathlib import Path
import fcntl as posix

msvcrt = types.ModuleType("msvcrt")
msvcrt.LK_UNLCK, msvcrt.LK_LOCK, msvcrt.LK_NBLCK, msvcrt.LK_RLCK, msvcrt.LK_NBRLCK = 0, 1, 2, 3, 4
calls = []

def locking(fd, mode, nbytes):
    pos = os.lseek(fd, 0, os.SEEK_CUR)
    calls.append((mode, pos, nbytes))
    if mode == msvcrt.LK_UNLCK:
        posix.lockf(fd, posix.LOCK_UN, nbytes, pos)
        return
    assert mode == msvcrt.LK_NBLCK, mode
    try:
        posix.lockf(fd, posix.LOCK_EX | posix.LOCK_NB, nbytes, pos)
    except OSError as e:
        if e.errno in (errno.EACCES, errno.EAGAIN):
            raise PermissionError(errno.EACCES, "Permission denied") from None
        raise

msvcrt.locking = locking
# the third-party packages first: their own choice of platform is not under test
import cloudpickle, dask, distributed, fmpy, pandas, psutil, pyarrow.parquet
sys.modules["fcntl"] = None                  # import fcntl raises ImportError
if sys.argv[1] != "no-msvcrt":
    sys.modules["msvcrt"] = msvcrt
import dmi_sweep, dmi_sweep.cli, dmi_sweep.plot, dmi_sweep.run, dmi_sweep.simulate, dmi_sweep.spec
from dmi_sweep import store
print("branch", store.LOCK_KIND, flush=True)
folder = Path(sys.argv[2])
if sys.argv[1] == "hold":
    store.FolderLock(folder)
    print("locked", flush=True)
    time.sleep(600)
elif sys.argv[1] == "try":
    try:
        lock = store.FolderLock(folder)
    except store.StoreError as e:
        print("refused", e, flush=True)
    else:
        print("locked", (folder / "_lock").read_text(), flush=True)
        lock.release()
        print("calls", calls, flush=True)
"""


def test_folder_lock_windows_branch(tmp_path, processes):
    """Without fcntl, dmi_sweep imports and takes the msvcrt branch (and without msvcrt either, the
    import names msvcrt); with msvcrt emulated, a second process is refused naming the holder, and
    after the holder is SIGKILLed the folder locks again, on one byte past the holder's description,
    and unlocks on release."""
    import json
    import signal
    import socket
    script = tmp_path / "windows.py"
    script.write_text(WINDOWS)
    folder = tmp_path / "out"
    folder.mkdir()

    def attempt(mode: str) -> subprocess.CompletedProcess:
        return subprocess.run([sys.executable, script, mode, folder], capture_output=True, text=True,
                              env=env_with_package(), timeout=120)

    r = attempt("no-msvcrt")
    assert r.returncode != 0 and "No module named 'msvcrt'" in r.stderr, r.stdout + r.stderr
    holder = processes.start([sys.executable, script, "hold", folder], stdout=subprocess.PIPE,
                             text=True, env=env_with_package())
    assert holder.stdout.readline() == "branch msvcrt.locking\n"
    assert holder.stdout.readline() == "locked\n"
    r = attempt("try")
    assert r.returncode == 0, r.stderr
    started = json.loads((folder / "_lock").read_text())["started"]
    assert r.stdout == ("branch msvcrt.locking\nrefused " f"{folder} is in use by another dmi-sweep "
                        f"client (pid {holder.pid} on {socket.gethostname()}, started {started}). One "
                        "client per folder: wait for it to end, or stop it (its finished points stay) "
                        "and run the same command again\n"), r.stdout
    os.kill(holder.pid, signal.SIGKILL)
    holder.wait(timeout=10)
    r = attempt("try")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "branch msvcrt.locking" and lines[1].startswith("locked "), r.stdout
    me = json.loads(lines[1][len("locked "):])
    assert me["pid"] != holder.pid and me["host"] == socket.gethostname()
    calls = eval(lines[2][len("calls "):])
    assert [mode for mode, _, _ in calls] == [2, 0]             # LK_NBLCK, then LK_UNLCK
    (_, at, n), (_, at_unlock, n_unlock) = calls
    assert (at, n) == (at_unlock, n_unlock) and n >= 1
    assert at >= 4096                    # beyond what a refused client reads of the description


def test_folder_lock_posix_is_flock(tmp_path, fmu_path):
    """On this machine (POSIX) the lock is flock: a flock taken on the _lock file by another open
    file refuses the folder; released, the folder opens."""
    import fcntl
    from dmi_sweep.spec import load
    from dmi_sweep.store import LOCK_KIND, Store, StoreError
    assert LOCK_KIND == "flock"
    spec = load(write_spec(tmp_path, f'fmu = "{fmu_path}"\nstop_time = 1.0\noutput_interval = 0.1\n'
                                     'transient = 0.5\noutputs = ["w"]\n[grid]\ng_amp = [1.0]\n'))
    out = tmp_path / "out"
    Store.open(out, spec).close()
    with open(out / "_lock", "r+") as f:
        fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(StoreError, match="in use by another dmi-sweep client"):
            Store.open(out, spec)
        fcntl.flock(f, fcntl.LOCK_UN)
    Store.open(out, spec).close()
