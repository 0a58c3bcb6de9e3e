# Fixtures of the dmi-sweep tests: the FMU (DMI_FMU, set by ctest), specs
# written to temporary folders, the command run as a subprocess in its own
# process group (the group killed when it ends), and a real Dask cluster (a
# `dask scheduler` and `dask worker` processes on 127.0.0.1, the workers in
# another temporary folder), every process stopped by its pid, then its group.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

PYTHON_DIR = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def fmu_path() -> str:
    path = os.environ.get("DMI_FMU")
    if not path:
        pytest.fail("environment variable DMI_FMU is not set (run the tests through ctest)")
    return path


# A grid of g_amp over the oscillator FMU: at stop = 30, transient = 20 about 0.1 s per point on
# this machine (long enough to kill something mid-sweep); stop = 3, transient = 2 for quick runs.
GRID_SPEC = """
fmu = "{fmu}"
stop_time = {stop}
output_interval = 0.01
transient = {transient}
outputs = ["w", "sticking"]
[start]
N = 9991
[grid]
g_amp = {{ start = 0.5, stop = 2.5, num = {num} }}
{extra}
"""


def grid_spec(fmu: str, num: int, stop: float = 30.0, transient: float = 20.0, extra: str = "") -> str:
    """GRID_SPEC of `num` points, with `extra` (such as a [slurm] section) at its end."""
    return GRID_SPEC.format(fmu=fmu, num=num, stop=stop, transient=transient, extra=extra)


def write_spec(directory: Path, text: str, name: str = "spec.toml") -> Path:
    p = directory / name
    p.write_text(text)
    return p


def env_with_package() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(PYTHON_DIR), env.get("PYTHONPATH")]))
    return env


def sweep_cmd(*args: str) -> list[str]:
    return [sys.executable, "-m", "dmi_sweep", *map(str, args)]


def kill_group(pgid: int) -> None:
    """SIGKILL to the process group pgid (a process started with start_new_session=True and its
    children, the workers of its LocalCluster); nothing if the group has no process left."""
    try:
        os.killpg(pgid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def start_group(args: list, env: dict[str, str]) -> subprocess.Popen:
    """A command started in its own process group (what it starts joins it); see finish_group."""
    return subprocess.Popen(list(map(str, args)), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env, start_new_session=True)


def finish_group(p: subprocess.Popen, timeout: float = 240) -> subprocess.CompletedProcess:
    """Waits for p (started by start_group); when it is done, times out (TimeoutExpired) or this
    fails, its process group is killed: no worker of a LocalCluster it started outlives it."""
    try:
        stdout, stderr = p.communicate(timeout=timeout)
    finally:
        kill_group(p.pid)
        p.communicate()
    return subprocess.CompletedProcess(p.args, p.returncode, stdout, stderr)


def start_sweep(*args: str) -> subprocess.Popen:
    return start_group(sweep_cmd(*args), env_with_package())


def run_sweep(*args: str, timeout: float = 240) -> subprocess.CompletedProcess:
    return finish_group(start_sweep(*args), timeout)


def group_members(pgid: int) -> list[int]:
    """The live (not zombie) processes of the process group pgid, from /proc."""
    members = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if fields[0] != "Z" and int(fields[2]) == pgid:
            members.append(int(stat.parent.name))
    return members


def log_entries(out: Path) -> list[dict]:
    """The lines of the result folder's _log.jsonl (a line cut by a kill is skipped)."""
    entries = []
    for line in (out / "_log.jsonl").read_text().splitlines():
        try:
            entries.append(json.loads(line))
        except json.JSONDecodeError:
            pass
    return entries


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _interrupted(signum: int, frame) -> None:
    raise KeyboardInterrupt(f"signal {signum}")


def pytest_configure(config):
    """A SIGTERM (ctest stopping the run, a cancelled CI job) ends the session as Ctrl-C does:
    pytest then tears the active fixtures down, so that ``processes`` stops what the tests
    started (the default action would end pytest at once and leave them running)."""
    signal.signal(signal.SIGTERM, _interrupted)


class Processes:
    """Processes started by a test, each in its own process group, and the log files they write;
    stop() ends each process by its pid (SIGTERM, then SIGKILL), then its group (what it started),
    and closes the files."""

    def __init__(self):
        self.procs: list[subprocess.Popen] = []
        self.files: list = []

    def start(self, args, **kw) -> subprocess.Popen:
        p = subprocess.Popen(args, start_new_session=True, **kw)
        self.procs.append(p)
        return p

    def log(self, path: Path):
        """path opened for writing, closed by stop()."""
        f = open(path, "w")
        self.files.append(f)
        return f

    def stop(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                os.kill(p.pid, signal.SIGTERM)
                try:
                    p.wait(timeout=15)
                except subprocess.TimeoutExpired:
                    os.kill(p.pid, signal.SIGKILL)
                    p.wait(timeout=15)
            kill_group(p.pid)
        for f in self.files:
            f.close()


@pytest.fixture
def processes():
    procs = Processes()
    yield procs
    procs.stop()


class Cluster:
    def __init__(self, address: str, scheduler: subprocess.Popen, workers: list[subprocess.Popen],
                 worker_dir: Path):
        self.address, self.scheduler, self.workers, self.worker_dir = address, scheduler, workers, worker_dir


@pytest.fixture
def cluster(processes, tmp_path_factory) -> Cluster:
    """A cluster of two workers (see start_cluster)."""
    return start_cluster(processes, tmp_path_factory, 2)


def start_cluster(processes: Processes, tmp_path_factory, n_workers: int) -> Cluster:
    """`dask scheduler` on a free port of 127.0.0.1 and n_workers `dask worker` processes (no nanny,
    one thread each) started in their own temporary folder, without this package on their path."""
    dask = str(Path(sys.executable).parent / "dask")
    sdir = tmp_path_factory.mktemp("scheduler")
    wdir = tmp_path_factory.mktemp("workers")
    address = f"tcp://127.0.0.1:{free_port()}"
    quiet = dict(stdout=subprocess.DEVNULL, stderr=processes.log(sdir / "cluster.log"))
    # --dashboard-address on 127.0.0.1: with --no-dashboard, Dask's HTTP server listens on 0.0.0.0
    sched = processes.start([dask, "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1],
                             "--dashboard-address", "127.0.0.1:0"], cwd=sdir, **quiet)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    workers = [processes.start([dask, "worker", address, "--nthreads", "1", "--nworkers", "1",
                                "--no-nanny", "--dashboard-address", "127.0.0.1:0", "--host", "127.0.0.1",
                                "--local-directory", str(wdir)], cwd=wdir, env=env, **quiet)
               for _ in range(n_workers)]
    wait_for_cluster(address, sched, n_workers)
    return Cluster(address, sched, workers, wdir)


def wait_for_cluster(address: str, scheduler: subprocess.Popen, n_workers: int, security=None) -> None:
    """Until the scheduler at `address` has n_workers workers (60 s at most)."""
    from distributed import Client
    deadline = time.monotonic() + 60
    while True:
        assert scheduler.poll() is None, "the dask scheduler exited"
        try:
            with Client(address, timeout=5, security=security) as c:
                c.wait_for_workers(n_workers, timeout=max(1, deadline - time.monotonic()))
            return
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.5)


def listening(pid: int) -> list[tuple[str, int]]:
    """The (address, port) pairs the process pid listens on (TCP)."""
    import psutil
    return sorted((c.laddr.ip, c.laddr.port) for c in psutil.Process(pid).net_connections(kind="inet")
                  if c.status == psutil.CONN_LISTEN)


def openssl(*args: str, cwd: Path) -> None:
    subprocess.run(["openssl", *args], cwd=cwd, check=True, capture_output=True, timeout=60)


def make_certs(d: Path) -> None:
    """ca.pem/key and other.pem/key (two self-signed CAs); node (scheduler and workers) and client
    signed by ca, stranger signed by other; each leaf valid for 127.0.0.1; node+key.pem: node's
    certificate and key in one file."""
    for ca in ("ca", "other"):
        openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", f"{ca}.key", "-out",
                f"{ca}.pem", "-days", "2", "-subj", f"/CN=dmi-sweep test {ca}", cwd=d)
    (d / "san.ext").write_text("subjectAltName=IP:127.0.0.1,DNS:localhost\n")
    for leaf, ca in (("node", "ca"), ("client", "ca"), ("stranger", "other")):
        openssl("req", "-newkey", "rsa:2048", "-nodes", "-keyout", f"{leaf}.key", "-out", f"{leaf}.csr",
                "-subj", f"/CN={leaf}", cwd=d)
        openssl("x509", "-req", "-in", f"{leaf}.csr", "-CA", f"{ca}.pem", "-CAkey", f"{ca}.key",
                "-CAcreateserial", "-out", f"{leaf}.pem", "-days", "2", "-extfile", "san.ext", cwd=d)
    (d / "node+key.pem").write_text((d / "node.pem").read_text() + (d / "node.key").read_text())
