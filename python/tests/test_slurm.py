# dmi-sweep --slurm against a real one-node Slurm (Debian's slurmctld, slurmd and
# munge, 22.05) that the test starts on 127.0.0.1 from a temporary folder: its
# own munge key and socket, a minimal slurm.conf (proctrack/linuxproc,
# task/none, no accounting, select/cons_tres) on free ports; munged, slurmctld -D
# and slurmd -D stopped by their pids at the end, after every job is cancelled.
# Skipped, with the reason, only where those programs are not installed.
# Checks: a sweep over SLURM equals a local one bitwise; a job cancelled with
# scancel mid-sweep loses and doubles no point (exit 0), every job cancelled
# ends the run with exit 3 and the same command resumes; a partition SLURM does
# not know gives exit 2 with SLURM's message and nothing is written; bad
# settings are refused before anything runs (exit 2); over TLS (the --tls-* files)
# the sweep equals a local one and the jobs' workers start on tls://. And, without Slurm, the
# keywords of SLURMCluster built from the settings.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pandas as pd
import pytest

from conftest import (Processes, env_with_package, finish_group, free_port, grid_spec, kill_group, log_entries,
                      make_certs, run_sweep, start_group, sweep_cmd, write_spec)

PROGRAMS = ("munged", "slurmctld", "slurmd", "sbatch", "squeue", "scancel", "sinfo")


def spec_text(fmu: str, num: int, stop: float = 3.0, extra: str = "") -> str:
    return grid_spec(fmu, num, stop=stop, transient=2.0, extra=extra)


class Slurm:
    def __init__(self, root: Path, env: dict[str, str]):
        self.root, self.env = root, env

    def cmd(self, *args: str, check: bool = True) -> subprocess.CompletedProcess:
        return subprocess.run(list(args), capture_output=True, text=True, env=self.env, timeout=60,
                              check=check)

    def jobs(self) -> list[tuple[str, str]]:
        """(job id, state) of every job SLURM has."""
        out = self.cmd("squeue", "-h", "-o", "%i %T").stdout.split()
        return list(zip(out[::2], out[1::2]))

    def wait(self, what: str, ok, timeout: float = 90):
        deadline = time.monotonic() + timeout
        while not ok():
            assert time.monotonic() < deadline, f"Slurm: {what} did not happen in {timeout:g} s"
            time.sleep(0.3)


def _start(processes: Processes, root: Path) -> Slurm:
    for d in ("munge", "state", "spool", "log"):
        (root / d).mkdir()
    os.chmod(root / "munge", 0o700)
    key = root / "munge" / "munge.key"
    key.write_bytes(os.urandom(128))
    os.chmod(key, 0o600)
    sock = root / "munge" / "socket"
    processes.start(["munged", "--foreground", "--force", f"--socket={sock}", f"--key-file={key}",
                     f"--log-file={root / 'log' / 'munged.log'}", f"--pid-file={root / 'munge' / 'pid'}",
                     f"--seed-file={root / 'munge' / 'seed'}"],
                    stdout=subprocess.DEVNULL, stderr=processes.log(root / "log" / "munged.out"))
    host = socket.gethostname().split(".")[0]
    conf = root / "slurm.conf"
    conf.write_text(f"""ClusterName=dmitest
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
StateSaveLocation={root / 'state'}
SlurmdSpoolDir={root / 'spool'}
SlurmctldPidFile={root / 'slurmctld.pid'}
SlurmdPidFile={root / 'slurmd.pid'}
SlurmctldLogFile={root / 'log' / 'slurmctld.log'}
SlurmdLogFile={root / 'log' / 'slurmd.log'}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
NodeName=dmi1 NodeAddr=127.0.0.1 NodeHostname={host} CPUs=2 RealMemory=4000 State=UNKNOWN
PartitionName=debug Nodes=dmi1 Default=YES MaxTime=INFINITE State=UP
""")
    env = dict(os.environ, SLURM_CONF=str(conf))
    slurm = Slurm(root, env)
    slurm.wait("munged's socket", sock.exists, 20)
    quiet = dict(stdout=subprocess.DEVNULL, env=env)
    processes.start(["slurmctld", "-D", "-i"], stderr=processes.log(root / "log" / "slurmctld.out"), **quiet)
    processes.start(["slurmd", "-D", "-N", "dmi1"], stderr=processes.log(root / "log" / "slurmd.out"),
                    **quiet)
    slurm.wait("the node idle", lambda: slurm.cmd("sinfo", "-h", "-o", "%t", check=False).stdout.strip()
               == "idle", 60)
    # dask-jobqueue's configuration, as a user of a cluster writes it: the scheduler and the
    # workers on the loopback (interface: lo), the jobs' output in the Slurm folder
    slurm.env.update(DASK_JOBQUEUE__SLURM__INTERFACE="lo",
                     DASK_JOBQUEUE__SLURM__LOG_DIRECTORY=str(root / "log"))
    return slurm


def _stop(slurm: Slurm | None, processes: Processes) -> None:
    """Every job cancelled and gone, then munged, slurmctld and slurmd stopped by their pids."""
    try:
        if slurm is not None and processes.procs[-1].poll() is None:
            slurm.cmd("scancel", "--partition", "debug", check=False)
            slurm.wait("the cancelled jobs' end", lambda: not slurm.jobs(), 60)
    finally:
        processes.stop()


@pytest.fixture(scope="module")
def slurm(tmp_path_factory):
    missing = [p for p in PROGRAMS if shutil.which(p) is None]
    if missing:
        pytest.skip(f"Slurm is not installed here ({', '.join(missing)} missing): scripts/deps.sh "
                    "installs Debian's slurmctld, slurmd, slurm-client and munge")
    processes = Processes()
    cluster = None
    try:
        cluster = _start(processes, tmp_path_factory.mktemp("slurm"))
        yield cluster
    finally:
        _stop(cluster, processes)


def sweep(slurm: Slurm, *args) -> subprocess.Popen:
    """dmi-sweep run args, started with the package and the Slurm's environment."""
    env = env_with_package()
    env.update(slurm.env, PYTHONPATH=env["PYTHONPATH"])
    return start_group(sweep_cmd("run", *args), env)


def finish(p: subprocess.Popen, timeout: float = 300) -> subprocess.CompletedProcess:
    return finish_group(p, timeout)


def frame(out: Path) -> pd.DataFrame:
    return pd.read_parquet(out).sort_values("point").reset_index(drop=True)


def local_frame(spec: Path, out: Path, *args) -> pd.DataFrame:
    """The table of the same spec run on the local cluster into out (the reference)."""
    r = run_sweep("run", spec, "--out", out, *args)
    assert r.returncode == 0, r.stderr
    return frame(out)


def test_sweep_over_slurm_equals_local(slurm, tmp_path, fmu_path):
    spec = write_spec(tmp_path, spec_text(fmu_path, 8, extra="[slurm]\ncores = 1\nmemory = \"1GB\"\n"))
    r = finish(sweep(slurm, spec, "--out", tmp_path / "slurm", "--slurm", "--jobs", "2",
                     "--partition", "debug", "--walltime", "00:10:00", "--chunk-size", "1"))
    assert r.returncode == 0, r.stderr
    got, want = frame(tmp_path / "slurm"), local_frame(spec, tmp_path / "local", "--workers", "1")
    assert list(got["point"]) == list(range(8))
    pd.testing.assert_frame_equal(got, want, check_exact=True)
    # the workers ran in SLURM jobs: their output files are there (one per job, at least one)
    assert list(slurm.root.glob("log/*.out")) and not slurm.jobs()   # and the jobs ended with the run


def test_tls_sweep_over_slurm_equals_local(slurm, tmp_path, fmu_path):
    """--slurm with the --tls-* files (a CA of the test's and a certificate signed by it, made with
    openssl; the certificate file holds its key, no --tls-key: the workers must get that file as
    their key too): the same table as a local run, bit for bit, and the job's worker started on
    tls:// (its log in the Slurm folder)."""
    certs = tmp_path / "certs"
    certs.mkdir()
    make_certs(certs)
    spec = write_spec(tmp_path, spec_text(fmu_path, 4, extra="[slurm]\ncores = 1\nmemory = \"1GB\"\n"))
    before = set(slurm.root.glob("log/*"))
    r = finish(sweep(slurm, spec, "--out", tmp_path / "slurm", "--slurm", "--partition", "debug",
                     "--walltime", "00:10:00", "--chunk-size", "1", "--tls-ca-file", certs / "ca.pem",
                     "--tls-cert", certs / "node+key.pem"))
    assert r.returncode == 0, r.stderr
    pd.testing.assert_frame_equal(frame(tmp_path / "slurm"),
                                  local_frame(spec, tmp_path / "local", "--workers", "1"), check_exact=True)
    logs = [f.read_text(errors="replace") for f in set(slurm.root.glob("log/*")) - before]
    started = [line for text in logs for line in text.splitlines() if "Start worker at:" in line]
    assert started and all("tls://" in line for line in started), (started, logs)
    assert not slurm.jobs()


def test_tls_security_for_slurm(tmp_path, monkeypatch):
    """The Security of --slurm with TLS: the client's files serve the scheduler and the workers,
    as absolute paths (the job script names them); a certificate that holds its key is the key
    file of every role; the client certificate may come from Dask's configuration."""
    import dask
    from dmi_sweep.run import security
    make_certs(tmp_path)
    both = str(tmp_path / "node+key.pem")
    monkeypatch.chdir(tmp_path)
    roles = ("client", "scheduler", "worker")
    sec = security(None, "ca.pem", "node.pem", "node.key", slurm=True)
    for r in roles:
        assert (getattr(sec, f"tls_{r}_cert"), getattr(sec, f"tls_{r}_key")) == \
            (str(tmp_path / "node.pem"), str(tmp_path / "node.key"))
    assert sec.tls_ca_file == str(tmp_path / "ca.pem") and sec.require_encryption
    sec = security(None, "ca.pem", "node+key.pem", None, slurm=True)
    assert {getattr(sec, f"tls_{r}_{w}") for r in roles for w in ("cert", "key")} == {both}
    with dask.config.set({"distributed.comm.tls.client.cert": both}):
        sec = security(None, "ca.pem", None, None, slurm=True)
    assert sec.tls_worker_cert == sec.tls_worker_key == both
    assert security(None, slurm=True) is None


def wait_for_parts(out: Path, n: int, proc: subprocess.Popen, timeout: float = 180):
    deadline = time.monotonic() + timeout
    while len(list(out.glob("part-*.parquet"))) < n:
        assert proc.poll() is None, f"the sweep ended before it could be interrupted: {proc.communicate()}"
        assert time.monotonic() < deadline, "no progress"
        time.sleep(0.1)


def chunk_workers(out: Path) -> set[int]:
    """The pids of the workers that wrote chunks into out so far (its _log.jsonl)."""
    if not (out / "_log.jsonl").exists():
        return set()
    return {w for e in log_entries(out) if "points" in e for w in e["workers"]}


def running_jobs(slurm: Slurm) -> list[str]:
    return [i for i, state in slurm.jobs() if state == "RUNNING"]


def test_scancel_mid_sweep_loses_and_doubles_no_point(slurm, tmp_path, fmu_path):
    """One of two jobs cancelled mid-sweep: the other finishes, every point once (exit 0), equal to
    a local run; then every job cancelled: exit 3, the finished points kept, and the same command
    resumes to the same result."""
    num = 80     # about 0.1 s a point: long enough to cancel a job while both work
    spec = write_spec(tmp_path, spec_text(fmu_path, num, stop=30.0))
    args = [spec, "--out", tmp_path / "slurm", "--slurm", "--cores", "1", "--memory", "1GB", "--jobs", "2",
            "--chunk-size", "1", "--no-worker-timeout", "5", "--quiet"]
    p = sweep(slurm, *args)
    try:
        wait_for_parts(tmp_path / "slurm", 1, p)
        slurm.wait("both jobs' workers computing", lambda: len(chunk_workers(tmp_path / "slurm")) == 2, 120)
        assert p.poll() is None and len(list((tmp_path / "slurm").glob("part-*.parquet"))) < num
        slurm.cmd("scancel", running_jobs(slurm)[0])
        r = finish(p)
    finally:
        kill_group(p.pid)
    assert r.returncode == 0, r.stderr
    got = frame(tmp_path / "slurm")
    assert list(got["point"]) == list(range(num)) and got["error"].isna().all()
    lost = [e for e in log_entries(tmp_path / "slurm") if "worker_lost" in e]
    assert len(lost) == 1, lost             # the cancelled job's worker left mid-sweep

    # every job cancelled mid-sweep: exit 3 once --no-worker-timeout passed with no job left
    out2 = tmp_path / "again"
    p = sweep(slurm, *[out2 if a == tmp_path / "slurm" else a for a in args])
    try:
        wait_for_parts(out2, 3, p)
        slurm.cmd("scancel", "--partition", "debug")
        r = finish(p)
    finally:
        kill_group(p.pid)
    assert r.returncode == 3, (r.returncode, r.stderr)
    assert "SLURM has none of its jobs left" in r.stderr and "the same command resumes" in r.stderr
    saved = pd.read_parquet(out2)
    assert 3 <= len(saved) < num and saved["point"].is_unique
    r = finish(sweep(slurm, *[out2 if a == tmp_path / "slurm" else a for a in args]))
    assert r.returncode == 0, r.stderr
    assert f"{len(saved)} of {num} points already in" in r.stderr
    pd.testing.assert_frame_equal(frame(out2), got, check_exact=True)
    pd.testing.assert_frame_equal(got, local_frame(spec, tmp_path / "local"), check_exact=True)


def test_bad_partition_exit_2_with_slurms_message(slurm, tmp_path, fmu_path):
    spec = write_spec(tmp_path, spec_text(fmu_path, 2, extra="[slurm]\npartition = \"nope\"\n"))
    r = finish(sweep(slurm, spec, "--out", tmp_path / "out", "--slurm", "--cores", "1",
                     "--memory", "1GB"))
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "SLURM refuses the job (partition nope" in r.stderr
    assert "Invalid partition name specified" in r.stderr and "Nothing was run" in r.stderr
    assert not (tmp_path / "out").exists() and not slurm.jobs()
    # the command line wins over the spec: the same spec with --partition debug runs
    r = finish(sweep(slurm, spec, "--out", tmp_path / "out", "--slurm", "--cores", "1",
                     "--memory", "1GB", "--partition", "debug"))
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("args, extra, message", [
    (["--slurm", "--memory", "1GB"], "", "--slurm needs --cores"),
    (["--slurm", "--cores", "1", "--memory", "lots"], "", "--memory = 'lots' is not an amount of memory"),
    (["--slurm", "--cores", "1", "--memory", "1GB", "--walltime", "1h"], "",
     "--walltime = '1h' is not a SLURM time limit"),
    (["--slurm", "--cores", "1", "--memory", "1GB", "--partition", "a b"], "", "is not a non-empty word"),
    (["--slurm"], "[slurm]\ncores = 0\nmemory = \"1GB\"\n", "slurm.cores = 0 is not an integer >= 1"),
    (["--slurm"], "[slurm]\ncores = 1\nqueue = \"x\"\n", "unknown SLURM settings slurm.queue"),
    (["--partition", "debug"], "", "--partition given without --slurm"),
    (["--slurm", "--workers", "2"], "", "--slurm runs its own cluster: not with --workers"),
    (["--slurm", "--cores", "1", "--memory", "1GB", "--tls-cert", "client.pem"], "",
     "--slurm with --tls-* options, but no certificates were given: pass --tls-ca-file"),
    (["--slurm", "--cores", "1", "--memory", "1GB", "--tls-ca-file", "ca.pem", "--tls-cert", "c.pem"], "",
     "cannot read the TLS CA file /"),
])
def test_bad_settings_refused_before_running(tmp_path, fmu_path, args, extra, message):
    spec = write_spec(tmp_path, spec_text(fmu_path, 2, extra=extra))
    env = env_with_package()
    env.pop("SLURM_CONF", None)
    r = subprocess.run(sweep_cmd("run", spec, "--out", tmp_path / "out", *args), capture_output=True,
                       text=True, env=env, timeout=120)
    assert r.returncode == 2 and message in r.stderr, (r.returncode, r.stderr)
    assert not (tmp_path / "out").exists()


def test_cluster_keywords():
    """The settings become SLURMCluster's keywords as dask-jobqueue names them: one single-threaded
    worker per core; jobs is not a keyword (it is scale(jobs=...)); a value given on the command
    line wins over the spec's, which wins over Dask's configuration."""
    import dask
    from dmi_sweep.slurm import cluster_kwargs, resolve
    with dask.config.set({"jobqueue.slurm.walltime": "01:00:00", "jobqueue.slurm.cores": 4,
                          "jobqueue.slurm.account": "conf"}):
        s = resolve({"cores": 8, "partition": None}, {"cores": 2, "memory": "4GB", "partition": "p"})
    assert s == {"cores": 8, "memory": "4GB", "partition": "p", "walltime": "01:00:00",
                 "account": "conf", "jobs": 1}
    kw = cluster_kwargs(s)
    assert kw == {"cores": 8, "processes": 8, "memory": "4GB", "queue": "p", "walltime": "01:00:00",
                  "account": "conf", "scheduler_options": {"dashboard_address": "127.0.0.1:0"}}
    dask_jobqueue = pytest.importorskip("dask_jobqueue")
    with dask.config.set({"jobqueue.slurm.interface": "lo"}), dask_jobqueue.SLURMCluster(**kw) as c:
        header = c.job_header       # the #SBATCH lines of every job
    for line in ("#SBATCH -p p", "#SBATCH -A conf", "#SBATCH -n 1", "#SBATCH --cpus-per-task=8",
                 "#SBATCH --mem=4G", "#SBATCH -t 01:00:00"):
        assert line in header, header
