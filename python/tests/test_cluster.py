# dmi-sweep on a real Dask cluster on the loopback: a `dask scheduler` and two
# `dask worker` processes started by the test in another folder (no shared
# files, no dmi_sweep on their path); a worker killed with SIGKILL mid-sweep;
# the client killed mid-sweep and the command rerun; the only worker killed (the
# run stops after --no-worker-timeout); a timed-out sweep killed with its
# LocalCluster.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest

from conftest import (env_with_package, finish_group, grid_spec, group_members, kill_group, log_entries,
                      run_sweep, start_cluster, start_sweep, sweep_cmd, write_spec)


def worker_address(cluster, pid: int) -> str:
    from distributed import Client
    with Client(cluster.address, timeout=10) as c:
        pids = c.run(os.getpid)
    return next(a for a, p in pids.items() if p == pid)


def wait_for_parts(out: Path, n: int, proc: subprocess.Popen, timeout: float = 120):
    deadline = time.monotonic() + timeout
    while len(list(out.glob("part-*.parquet"))) < n:
        assert proc.poll() is None, "the sweep ended before it could be interrupted"
        assert time.monotonic() < deadline, "no progress"
        time.sleep(0.05)


def kill_worker_mid_sweep(processes, cluster, spec: Path, out: Path, parts: int, *args: str):
    """Starts a sweep of spec on the cluster (chunks of one point, args added), SIGKILLs the
    cluster's first worker by its pid once `parts` chunks are written, and returns the client
    process and the killed worker's address."""
    client = processes.start(sweep_cmd("run", spec, "--out", out, "--scheduler", cluster.address,
                                       "--chunk-size", "1", *args),
                             env=env_with_package(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    wait_for_parts(out, parts, client)
    victim = cluster.workers[0]
    address = worker_address(cluster, victim.pid)
    os.kill(victim.pid, signal.SIGKILL)
    victim.wait(timeout=10)
    return client, address


def check_complete(out: Path, total: int) -> pd.DataFrame:
    df = pd.read_parquet(out)
    assert sorted(df["point"]) == list(range(total))      # every point, each once
    assert df["error"].isna().all()
    return df


def test_two_clients_one_cluster(cluster, tmp_path, fmu_path):
    """Two clients sweep the same FMU on one external cluster at once: the first one ends (and
    removes its worker plugin) while the second one runs; the second still computes every point
    (each run has its own plugin: with one shared, the first end took the FMU from the other)."""
    first_spec = write_spec(tmp_path, grid_spec(fmu_path, 200), "first.toml")   # ~10 s
    second_spec = write_spec(tmp_path, grid_spec(fmu_path, 100), "second.toml")
    first = start_sweep("run", first_spec, "--out", tmp_path / "first", "--scheduler", cluster.address,
                        "--chunk-size", "1")
    second = None
    try:
        wait_for_parts(tmp_path / "first", 2, first)
        # the scheduler runs the first client's tasks first: the first run ends during the second
        second = start_sweep("run", second_spec, "--out", tmp_path / "second", "--scheduler",
                             cluster.address, "--chunk-size", "1")
        r = finish_group(first, 240)
        assert r.returncode == 0, r.stderr
        assert second.poll() is None, "the second sweep ended before the first one: no overlap"
        r = finish_group(second, 240)
        assert r.returncode == 0, r.stderr
    finally:
        for p in (first, second):
            if p is not None and p.poll() is None:      # an assertion failed: stop it by its group
                kill_group(p.pid)
                p.communicate()
    check_complete(tmp_path / "first", 200)
    check_complete(tmp_path / "second", 100)


def test_scheduler_and_workers_elsewhere(cluster, tmp_path, fmu_path):
    """The sweep through --scheduler equals the LocalCluster's; the FMU reached the workers through
    Dask only (their folder is another one, they have no path to the FMU)."""
    spec = write_spec(tmp_path, grid_spec(fmu_path, 6, stop=3.0, transient=2.0))
    r = run_sweep("run", spec, "--out", tmp_path / "remote", "--scheduler", cluster.address,
                  "--chunk-size", "1")
    assert r.returncode == 0, r.stderr
    r = run_sweep("run", spec, "--out", tmp_path / "local", "--workers", "1")
    assert r.returncode == 0, r.stderr
    remote = pd.read_parquet(tmp_path / "remote").sort_values("point").reset_index(drop=True)
    local = pd.read_parquet(tmp_path / "local").sort_values("point").reset_index(drop=True)
    pd.testing.assert_frame_equal(remote, local, check_exact=True)
    chunks = [e for e in log_entries(tmp_path / "remote") if "points" in e]
    assert len(chunks) == 6
    assert {p for e in chunks for p in e["workers"]} == {w.pid for w in cluster.workers}  # both worked
    assert {e["instantiations"] for e in chunks} == {1}        # one FMU instance per worker
    # the worker plugin is removed at the end: gone from the scheduler and the workers, and its
    # teardown removed the FMU unpacked in each worker's folder
    from distributed import Client
    with Client(cluster.address, timeout=10) as c:
        on_workers = c.run(lambda dask_worker: sorted(dask_worker.plugins))
        on_scheduler = c.run_on_scheduler(lambda dask_scheduler: sorted(dask_scheduler.worker_plugins))
    assert len(on_workers) == 2
    assert not [n for names in on_workers.values() for n in names if n.startswith("dmi-sweep")], on_workers
    assert not [n for n in on_scheduler if n.startswith("dmi-sweep")], on_scheduler
    assert not list(cluster.worker_dir.rglob("dmi-sweep-fmu-*")), "the unpacked FMU is left"


def test_worker_killed_mid_sweep(cluster, tmp_path, fmu_path, processes):
    total = 40
    spec = write_spec(tmp_path, grid_spec(fmu_path, total))
    out = tmp_path / "out"
    client, address = kill_worker_mid_sweep(processes, cluster, spec, out, 4, "--quiet")
    assert len(list(out.glob("part-*.parquet"))) < total       # killed mid-sweep
    stdout, stderr = client.communicate(timeout=180)
    assert client.returncode == 0, stderr
    check_complete(out, total)
    survivor = cluster.workers[1].pid
    entries = log_entries(out)
    after = [e for e in entries if "points" in e and e["workers"] == [survivor]]
    assert after, "the surviving worker computed nothing"
    # one line on stderr and one log entry name the lost worker and the chunks it was running,
    # which the survivor then computed
    lines = [x for x in stderr.splitlines() if "lost worker" in x]
    assert len(lines) == 1 and lines[0].startswith(f"dmi-sweep: lost worker {address}; "), stderr
    lost = [e for e in entries if "worker_lost" in e]
    assert [e["worker_lost"] for e in lost] == [address]
    again = lost[0]["chunks_again"]
    assert again, "the killed worker was running no chunk"
    assert lines[0].endswith(f"{len(again)} chunks (first points {', '.join(str(c[0]) for c in again)}) "
                             "run again on the other workers"), lines[0]
    i = entries.index(lost[0])
    rerun = {p for e in entries[i:] if "points" in e and e["workers"] == [survivor] for p in e["points"]}
    assert {p for c in again for p in c} <= rerun
    assert "Traceback" not in stderr


def test_client_killed_then_rerun(cluster, tmp_path, fmu_path, processes):
    """Only the points missing after the kill are computed by the rerun, each once."""
    total = 40
    spec = write_spec(tmp_path, grid_spec(fmu_path, total))
    out = tmp_path / "out"
    args = ("run", spec, "--out", out, "--scheduler", cluster.address, "--chunk-size", "1", "--quiet")
    client = processes.start(sweep_cmd(*args), env=env_with_package(), stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    wait_for_parts(out, 5, client)
    os.kill(client.pid, signal.SIGKILL)
    client.wait(timeout=10)
    # a reader never sees a partial chunk: every chunk file in the folder reads whole, a temporary
    # file the kill may have left is not read
    df = pd.read_parquet(out)
    done = set(df["point"])
    assert 5 <= len(done) < total
    assert len(df) == len(done) and df["error"].isna().all() and df["w_final"].notna().all()
    assert all(p.name.startswith(f".tmp-{client.pid}-") for p in out.glob(".*"))
    n_before = len(log_entries(out))
    r = run_sweep(*args)
    assert r.returncode == 0, r.stderr
    new = log_entries(out)[n_before:]
    assert new[0]["run"] and new[0]["done"] == len(done) and new[0]["todo"] == total - len(done)
    computed = [p for e in new[1:] for p in e["points"]]
    assert sorted(computed) == sorted(set(range(total)) - done)   # the missing ones, each once
    check_complete(out, total)
    assert not list(out.glob(".*")), "temporary files left"


def test_timed_out_sweep_leaves_no_process(tmp_path, fmu_path):
    """A sweep that exceeds its timeout in the tests is killed with its LocalCluster: its process
    group (client, nannies, workers) is empty afterwards."""
    spec = write_spec(tmp_path, grid_spec(fmu_path, 40))
    out = tmp_path / "out"
    p = start_sweep("run", spec, "--out", out, "--workers", "2", "--chunk-size", "1", "--quiet")
    try:
        wait_for_parts(out, 1, p)
        assert len(group_members(p.pid)) >= 3         # the client and its workers are running
    except BaseException:
        kill_group(p.pid)
        p.communicate()
        raise
    with pytest.raises(subprocess.TimeoutExpired):
        finish_group(p, timeout=0.1)
    deadline = time.monotonic() + 10
    while group_members(p.pid) and time.monotonic() < deadline:   # SIGKILL is delivered at once,
        time.sleep(0.05)                                           # the exit takes a moment
    assert group_members(p.pid) == []


def test_scheduler_killed_mid_sweep(cluster, tmp_path, fmu_path, processes):
    """The scheduler SIGKILLed by its pid mid-sweep: exit 3, a short message (points saved, the
    same command resumes), no traceback, Dask's log lines in _log.jsonl and not on the terminal; a
    rerun on a local cluster computes exactly the missing points."""
    total = 40
    spec = write_spec(tmp_path, grid_spec(fmu_path, total))
    out = tmp_path / "out"
    client = processes.start(sweep_cmd("run", spec, "--out", out, "--scheduler", cluster.address,
                                       "--chunk-size", "1"),
                             env=env_with_package(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    wait_for_parts(out, 3, client)
    os.kill(cluster.scheduler.pid, signal.SIGKILL)
    cluster.scheduler.wait(timeout=10)
    stdout, stderr = client.communicate(timeout=120)
    assert client.returncode == 3, stdout + stderr
    done = set(pd.read_parquet(out)["point"])
    assert 3 <= len(done) < total
    text = stdout + stderr
    assert "Traceback" not in text and " - ERROR - " not in text and "distributed." not in text, text
    assert f"lost the connection to the scheduler at {cluster.address}" in stderr
    assert f"{len(done)} of {total} points are saved in {out}; the same command resumes" in stderr
    messages = [x for x in stderr.splitlines() if not x.startswith("[")]
    assert len(messages) == 2, stderr                      # the reason, and what is saved
    entries = log_entries(out)
    assert [e for e in entries if "lost" in e], "no log entry of the loss"
    # Dask's ERROR lines (the client failing to reconnect) are in the log, not on the terminal
    assert [e for e in entries if e.get("level") == "ERROR" and e["log"].startswith("distributed.")], entries
    n_before = len(entries)
    r = run_sweep("run", spec, "--out", out, "--workers", "2", "--quiet")
    assert r.returncode == 0, r.stderr
    computed = [p for e in log_entries(out)[n_before:] if "points" in e for p in e["points"]]
    assert sorted(computed) == sorted(set(range(total)) - done)
    check_complete(out, total)


def test_every_worker_lost(processes, tmp_path_factory, tmp_path, fmu_path):
    """The only worker SIGKILLed by its pid mid-sweep, the scheduler still up: once the cluster has
    had no worker for --no-worker-timeout seconds (3 here), exit 3 with the short message, no
    traceback, the loss in _log.jsonl; a rerun on a local cluster computes exactly the missing
    points. (Before this timeout existed, the client waited forever: communicate() times out.)"""
    cluster = start_cluster(processes, tmp_path_factory, 1)
    total = 40
    spec = write_spec(tmp_path, grid_spec(fmu_path, total))
    out = tmp_path / "out"
    client, address = kill_worker_mid_sweep(processes, cluster, spec, out, 3, "--no-worker-timeout", "3")
    t = time.monotonic()
    stdout, stderr = client.communicate(timeout=60)
    waited = time.monotonic() - t
    assert client.returncode == 3, stdout + stderr
    assert cluster.scheduler.poll() is None, "the scheduler died: not the case under test"
    assert waited > 2.5, f"exit {waited:.1f} s after the last worker died, before the timeout of 3 s"
    done = set(pd.read_parquet(out)["point"])
    assert 3 <= len(done) < total
    text = stdout + stderr
    assert "Traceback" not in text and " - ERROR - " not in text and "distributed." not in text, text
    assert f"dmi-sweep: the scheduler at {cluster.address} has had no worker for 3 s.\n" in stderr, stderr
    assert (f"{len(done)} of {total} points are saved in {out}; the same command resumes the sweep "
            "(once the cluster has workers again)." in stderr), stderr
    messages = [x for x in stderr.splitlines() if not x.startswith("[")]
    assert len(messages) == 3 and messages[0].startswith(f"dmi-sweep: lost worker {address}; "), stderr
    assert messages[0].endswith(" wait for a worker (none is left now)"), stderr
    entries = log_entries(out)
    assert [e["worker_lost"] for e in entries if "worker_lost" in e] == [address]
    lost = [e for e in entries if "lost" in e]
    assert [(e["lost"], e["no_worker_timeout"]) for e in lost] == \
        [(f"the scheduler at {cluster.address} has had no worker for 3 s", 3.0)], lost
    n_before = len(entries)
    r = run_sweep("run", spec, "--out", out, "--workers", "2", "--quiet")
    assert r.returncode == 0, r.stderr
    computed = [p for e in log_entries(out)[n_before:] if "points" in e for p in e["points"]]
    assert sorted(computed) == sorted(set(range(total)) - done)
    check_complete(out, total)


def test_ctrl_c(tmp_path, fmu_path):
    """SIGINT to the whole process group, as Ctrl-C in a terminal sends it: exit 130, one message,
    no traceback and no leaked-semaphore warning; the rerun completes the sweep."""
    total = 40
    spec = write_spec(tmp_path, grid_spec(fmu_path, total))
    out = tmp_path / "out"
    p = start_sweep("run", spec, "--out", out, "--workers", "2", "--chunk-size", "1")
    try:
        wait_for_parts(out, 2, p)
        os.killpg(p.pid, signal.SIGINT)
        stdout, stderr = p.communicate(timeout=60)
        # what the workers print while they stop comes after the client's exit: wait for them
        deadline = time.monotonic() + 20
        while group_members(p.pid) and time.monotonic() < deadline:
            time.sleep(0.1)
    finally:
        kill_group(p.pid)
    assert p.returncode == 130, stdout + stderr
    assert "interrupted; the finished chunks are in" in stderr
    assert "Traceback" not in stderr and "leaked semaphore" not in stderr and "KeyboardInterrupt" not in stderr, stderr
    r = run_sweep("run", spec, "--out", out, "--workers", "2", "--quiet")
    assert r.returncode == 0, r.stderr
    check_complete(out, total)
