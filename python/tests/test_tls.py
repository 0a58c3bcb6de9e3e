# dmi-sweep on a Dask cluster over TLS, all on 127.0.0.1: certificates made by
# the test with the openssl command (a CA for the cluster, another CA for a
# stranger), a TLS scheduler and two TLS workers started by the test and stopped
# by their pids.  A sweep over tls:// equals the local cluster's bit for bit;
# without certificates the client is refused before connecting (exit 2); a
# certificate of another CA, an unreadable file, a key that does not match:
# one paragraph, exit 2, no traceback.  What the scheduler and the local
# cluster listen on.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from conftest import (Processes, free_port, listening, make_certs, run_sweep, wait_for_cluster,
                      write_spec)

SPEC = """
fmu = "{fmu}"
stop_time = 2.0
output_interval = 0.01
transient = 1.0
outputs = ["w", "sticking"]
[start]
N = 400
[grid]
g_amp = {{ start = 0.5, stop = 2.5, num = 4 }}
"""


class TLSCluster:
    def __init__(self, address: str, certs: Path, scheduler: subprocess.Popen,
                 workers: list[subprocess.Popen]):
        self.address, self.certs, self.scheduler, self.workers = address, certs, scheduler, workers

    def options(self, cert: str = "client", ca: str = "ca") -> list[str]:
        return ["--tls-ca-file", self.certs / f"{ca}.pem", "--tls-cert", self.certs / f"{cert}.pem",
                "--tls-key", self.certs / f"{cert}.key"]


@pytest.fixture(scope="module")
def tls_cluster(tmp_path_factory):
    """A TLS scheduler on a free port of 127.0.0.1 (its HTTP server on 127.0.0.1 too) and two TLS
    workers, no nanny, one thread each, in another folder, without this package on their path."""
    from distributed.security import Security
    certs = tmp_path_factory.mktemp("certs")
    make_certs(certs)
    wdir = tmp_path_factory.mktemp("tlsworkers")
    dask = str(Path(sys.executable).parent / "dask")
    port = free_port()
    address = f"tls://127.0.0.1:{port}"
    node = ["--tls-ca-file", str(certs / "ca.pem"), "--tls-cert", str(certs / "node.pem"),
            "--tls-key", str(certs / "node.key")]
    procs = Processes()
    try:
        quiet = dict(stdout=subprocess.DEVNULL, stderr=procs.log(wdir / "cluster.log"))
        sched = procs.start([dask, "scheduler", "--protocol", "tls", "--host", "127.0.0.1", "--port",
                             str(port), "--dashboard-address", "127.0.0.1:0", *node], cwd=wdir, **quiet)
        env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
        workers = [procs.start([dask, "worker", address, "--nthreads", "1", "--no-nanny", "--host",
                                "127.0.0.1", "--dashboard-address", "127.0.0.1:0", "--local-directory",
                                str(wdir), *node], cwd=wdir, env=env, **quiet) for _ in range(2)]
        wait_for_cluster(address, sched, 2, Security(tls_ca_file=str(certs / "ca.pem"),
                                                     tls_client_cert=str(certs / "client.pem"),
                                                     tls_client_key=str(certs / "client.key"),
                                                     require_encryption=True))
        yield TLSCluster(address, certs, sched, workers)
    finally:
        procs.stop()


def test_tls_sweep_equals_local(tls_cluster, tmp_path, fmu_path):
    """Over tls:// with the three options, and again with the certificates in Dask's configuration
    (environment) only: both tables equal the local cluster's, bit for bit."""
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path))
    r = run_sweep("run", spec, "--out", tmp_path / "tls", "--scheduler", tls_cluster.address,
                  "--chunk-size", "1", *tls_cluster.options())
    assert r.returncode == 0, r.stderr
    env_vars = {"DASK_DISTRIBUTED__COMM__TLS__CA_FILE": str(tls_cluster.certs / "ca.pem"),
                "DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT": str(tls_cluster.certs / "client.pem"),
                "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY": str(tls_cluster.certs / "client.key")}
    old = {k: os.environ.get(k) for k in env_vars}
    os.environ.update(env_vars)
    try:
        r = run_sweep("run", spec, "--out", tmp_path / "config", "--scheduler", tls_cluster.address)
    finally:
        for k, v in old.items():
            if v is None:
                os.environ.pop(k)
            else:
                os.environ[k] = v
    assert r.returncode == 0, r.stderr
    r = run_sweep("run", spec, "--out", tmp_path / "local", "--workers", "1")
    assert r.returncode == 0, r.stderr
    local = pd.read_parquet(tmp_path / "local").sort_values("point").reset_index(drop=True)
    assert len(local) == 4 and local["error"].isna().all()
    for name in ("tls", "config"):
        df = pd.read_parquet(tmp_path / name).sort_values("point").reset_index(drop=True)
        pd.testing.assert_frame_equal(df, local, check_exact=True)


def test_tls_without_certificates_refused(tls_cluster, tmp_path, fmu_path):
    """No certificate from the options nor the configuration: exit 2 before connecting, naming the
    three options and the configuration keys; no folder."""
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path))
    r = run_sweep("run", spec, "--out", tmp_path / "out", "--scheduler", tls_cluster.address)
    assert r.returncode == 2, r.stderr
    for name in ("--tls-ca-file", "--tls-cert", "--tls-key", "distributed.comm.tls.ca-file",
                 "distributed.comm.tls.client.cert", "distributed.comm.tls.client.key"):
        assert name in r.stderr, name
    assert "Traceback" not in r.stderr and not (tmp_path / "out").exists()


@pytest.mark.parametrize("case,message", [
    ("stranger", "the TLS connection to tls://127.0.0.1:"),
    ("missing", "cannot read the TLS certificate"),
    ("mismatch", "KEY_VALUES_MISMATCH"),
    ("tcp", "is not a tls:// address"),
])
def test_tls_bad_certificates(tls_cluster, tmp_path, fmu_path, case, message):
    """A certificate of another CA (the scheduler rejects it), a file that is not there, a key of
    another certificate, TLS options with a tcp:// address: one paragraph on stderr, exit 2, no
    traceback, no folder."""
    spec = write_spec(tmp_path, SPEC.format(fmu=fmu_path))
    c = tls_cluster.certs
    options = {"stranger": tls_cluster.options("stranger"),
               "missing": ["--tls-ca-file", c / "ca.pem", "--tls-cert", c / "nothere.pem"],
               "mismatch": ["--tls-ca-file", c / "ca.pem", "--tls-cert", c / "client.pem",
                            "--tls-key", c / "node.key"],
               "tcp": tls_cluster.options()}[case]
    address = tls_cluster.address.replace("tls://", "tcp://") if case == "tcp" else tls_cluster.address
    r = run_sweep("run", spec, "--out", tmp_path / "out", "--scheduler", address, *options, timeout=120)
    assert r.returncode == 2, r.stdout + r.stderr
    assert message in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Traceback" not in r.stderr and not (tmp_path / "out").exists()


def test_scheduler_listens_only_on_its_address(tls_cluster):
    """The scheduler started with --host 127.0.0.1 (and its HTTP server on 127.0.0.1) listens on
    127.0.0.1 only, on the port of its address among them; so do the workers."""
    port = int(tls_cluster.address.rsplit(":", 1)[1])
    sockets = listening(tls_cluster.scheduler.pid)
    assert (("127.0.0.1", port) in sockets) and {ip for ip, _ in sockets} == {"127.0.0.1"}, sockets
    for w in tls_cluster.workers:
        assert {ip for ip, _ in listening(w.pid)} == {"127.0.0.1"}


def test_local_cluster_listens_on_loopback_only():
    """The LocalCluster of dmi-sweep (scheduler and HTTP server in this process, workers in child
    processes) listens on 127.0.0.1 only, with or without the dashboard."""
    import psutil

    from dmi_sweep.run import make_client
    me = psutil.Process()
    for dashboard in (False, True):
        before = set(listening(me.pid))
        client = make_client(1, None, dashboard=dashboard)
        try:
            mine = [p.pid for p in me.children(recursive=True)]
            sockets = [s for pid in [me.pid, *mine] for s in listening(pid) if s not in before]
            assert len(sockets) >= 3, sockets          # scheduler, its HTTP server, the worker
            assert {ip for ip, _ in sockets} == {"127.0.0.1"}, sockets
        finally:
            client.close()
            client.cluster.close()
