# The progress bar (points done of total, rate, time left) on a fake clock, and
# the result folder's write-then-rename: no temporary file left, a temporary
# file of a killed writer never read and removed when the folder is reopened.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import io
import os
import subprocess
import sys

import pandas as pd
import pytest

from conftest import write_spec
from dmi_sweep.run import Progress


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
