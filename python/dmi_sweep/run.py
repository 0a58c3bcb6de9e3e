# Runs a sweep on Dask: a LocalCluster of K single-threaded worker processes on
# 127.0.0.1 by default, an existing cluster (--scheduler, plain TCP or TLS), or
# workers in SLURM jobs (--slurm, see slurm.py).
# The FMU travels to each worker once, inside a worker plugin (removed at the
# end); chunks of points are tasks; each finished chunk is written to the result
# folder at once.  Dask's warnings and errors go to the folder's _log.jsonl, not
# to the terminal; a lost cluster (the scheduler gone, or no worker for a while)
# ends the run with ClusterLost.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import contextlib
import importlib.util
import logging
import math
import os
import pickle
import re
import signal
import ssl
import sys
import threading
import time
import uuid
from concurrent.futures import CancelledError
from dataclasses import dataclass
from typing import Any, Callable, Iterator, TextIO

import cloudpickle
import dask
from distributed import Client, KilledWorker, LocalCluster, as_completed
from distributed.comm.core import CommClosedError
from distributed.security import Security

from . import simulate
from . import slurm as slurm_jobs
from . import NO_WORKER_TIMEOUT
from .simulate import FMUPlugin, PluginClosed, check_start, has_worker_plugin, run_chunk
from .spec import Spec, SpecError
from .store import Store

# Neither the scheduler nor the workers need dmi_sweep installed: the worker code
# travels by value (cloudpickle), inside the plugin and inside each task.
cloudpickle.register_pickle_by_value(simulate)


class _Call:
    """Unpickling this calls fn(*args). A task is pickle.loads(cloudpickle.dumps(_Call(...))): the
    scheduler, which unpickles task graphs, sees only bytes; the worker runs fn, sent by value."""

    def __init__(self, fn, *args):
        self.fn, self.args = fn, args

    def __reduce__(self):
        return self.fn, self.args


def task(fn, *args) -> bytes:
    """The bytes of a task for ``pickle.loads``: the scheduler, which unpickles task graphs, sees
    only bytes; the worker runs `fn`, sent by value (see ``_Call``).

    Parameters
    ----------
    fn : callable
        The function the worker runs.
    *args
        Its arguments.

    Returns
    -------
    bytes
        ``cloudpickle.dumps`` of the call.
    """
    return cloudpickle.dumps(_Call(fn, *args))


class Progress:
    """A one-line progress bar on stderr: points done of total, rate, time left."""

    def __init__(self, total: int, done: int, stream: TextIO | None = sys.stderr, width: int = 30,
                 clock: Callable[[], float] = time.monotonic):
        """A bar at `done` of `total` points.

        Parameters
        ----------
        total : int
            The points of the sweep.
        done : int
            Those done before this run.
        stream : TextIO or None, optional
            Where the bar goes (None: nowhere). A line at most every 0.2 s on a terminal, every 5 s
            elsewhere (a log file), and at :meth:`close`.
        width : int, optional
            The bar's width in characters.
        clock : callable, optional
            The time in seconds (``time.monotonic``).
        """
        self.total, self.start_done, self.done = total, done, done
        self.stream, self.width, self.clock = stream, width, clock
        self.t0 = clock()
        self.last = -math.inf       # the first update shows at once
        self.shown = -1             # points done at the line last shown
        self.tty = stream is not None and stream.isatty()

    def update(self, n: int, force: bool = False) -> None:
        """Counts `n` more points done and shows the bar if it is time.

        Parameters
        ----------
        n : int
            Points done since the last call.
        force : bool, optional
            Show the line now.
        """
        self.done += n
        now = self.clock()
        if self.stream is None or (not force and now - self.last < (0.2 if self.tty else 5.0)):
            return
        self.last, self.shown = now, self.done
        elapsed = now - self.t0
        rate = (self.done - self.start_done) / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        filled = int(self.width * self.done / max(self.total, 1))
        bar = "#" * filled + "-" * (self.width - filled)
        if math.isfinite(left):
            s = round(left)
            eta = f"{s // 3600:02d}:{s // 60 % 60:02d}:{s % 60:02d}"   # hours beyond 99 as they are
        else:
            eta = "--:--:--"
        line = f"[{bar}] {self.done}/{self.total} points, {rate:.2f}/s, {eta} left"
        self.stream.write(("\r" + line) if self.tty else line + "\n")
        self.stream.flush()

    def note(self, stream: TextIO | None, text: str) -> None:
        """Writes a line of its own (a lost worker, say); on the bar's terminal, the bar is cleared
        first and shown again below at the next update.

        Parameters
        ----------
        stream : TextIO or None
            Where the line goes (None: nowhere).
        text : str
            The line.
        """
        if stream is None:
            return
        clear = stream is self.stream and self.tty and self.shown >= 0
        stream.write(("\r\033[K" if clear else "") + text + "\n")
        stream.flush()
        self.last = -math.inf
        if clear:
            self.shown = -1          # the bar's line is gone: close() shows it again

    def close(self) -> None:
        """Shows the last line, unless the line last shown has the same count."""
        if self.done != self.shown:
            self.update(0, force=True)
        if self.stream is not None and self.tty and self.shown >= 0:
            self.stream.write("\n")
            self.stream.flush()


def chunks(todo: list[int], n_workers: int, chunk_size: int | None) -> list[list[int]]:
    """Consecutive runs of the points to do.

    Parameters
    ----------
    todo : list of int
        The points to compute, in order.
    n_workers : int
        The workers they are for.
    chunk_size : int or None
        Points per chunk; None: about 8 chunks per worker, at most 64 points each.

    Returns
    -------
    list of list of int
        The chunks, in order.
    """
    if chunk_size is None:
        chunk_size = max(1, min(64, len(todo) // (8 * max(n_workers, 1))))
    return [todo[i:i + chunk_size] for i in range(0, len(todo), chunk_size)]


class ClusterLost(RuntimeError):
    """The scheduler (or the connection to it) is gone, or could not be reached, or it has had no
    worker for too long; the chunks written so far stay in the folder.
    """

    def __init__(self, reason: str, saved: int | None = None, total: int = 0,
                 resume: str = "once the scheduler is back"):
        """The loss and what is saved.

        Parameters
        ----------
        reason : str
            What happened (the exception's message).
        saved : int or None, optional
            The points in the folder (None: the folder was not opened).
        total : int, optional
            The points of the sweep.
        resume : str, optional
            When the same command can resume the sweep.
        """
        super().__init__(reason)
        self.reason, self.saved, self.total, self.resume = reason, saved, total, resume


class WorkerWatch:
    """Asks the scheduler how many workers it has, at most every `interval` seconds (1 s, or a
    quarter of the timeout if shorter); :meth:`check` raises ClusterLost once every answer for
    `timeout` seconds was none. :meth:`start` does this in a thread of its own: the client's waits (a
    result whose worker died before it was fetched is computed again, and waits for a worker) end
    there.
    """

    def __init__(self, client: Client, timeout: float, where: str = "",
                 clock: Callable[[], float] = time.monotonic,
                 waiting: Callable[[], bool] | None = None, waiting_gone: str = ""):
        """A watch of the client's cluster.

        Parameters
        ----------
        client : distributed.Client
            The client.
        timeout : float
            Seconds without a worker after which the cluster counts as lost.
        where : str, optional
            ``" at <address>"`` for the messages.
        clock : callable, optional
            The time in seconds (``time.monotonic``).
        waiting : callable, optional
            Asked when there is no worker: whether workers are still to come (SLURM jobs still queued or
            starting), which stops the count.
        waiting_gone : str, optional
            What the lost message adds when `waiting` said no (``"and ..."``).
        """
        self.client, self.timeout, self.where, self.clock = client, timeout, where, clock
        self.waiting, self.waiting_gone = waiting, waiting_gone
        self.interval = min(1.0, timeout / 4)
        self.asked = -math.inf       # when the scheduler was last asked
        self.none_since: float | None = None    # the first answer "no worker" of the current run of them
        self.lost: ClusterLost | None = None    # set by the thread before it calls on_lost
        self.stopped = threading.Event()

    def check(self) -> None:
        """Asks the scheduler (at most once per interval, while the client runs).

        Raises
        ------
        ClusterLost
            When every answer for `timeout` seconds was "no worker" (and `waiting` said none is to come).
        """
        now = self.clock()
        if now - self.asked < self.interval or self.client.status != "running":
            return
        self.asked = now
        if self.client.nthreads() or (self.waiting is not None and self.waiting()):
            self.none_since = None
        elif self.none_since is None:
            self.none_since = now
        elif now - self.none_since >= self.timeout:
            gone = f" and {self.waiting_gone}" if self.waiting_gone else ""
            raise ClusterLost(f"the scheduler{self.where} has had no worker for {self.timeout:g} s{gone}",
                              resume="once the cluster has workers again")

    def start(self, on_lost: Callable[[], object]) -> None:
        """Runs :meth:`check` every interval in a daemon thread until :meth:`stop`.

        Parameters
        ----------
        on_lost : callable
            Called (with no argument) when :meth:`check` raises; the ClusterLost is then in
            ``self.lost``. The run passes a function that cancels its futures.
        """
        def watch():
            while not self.stopped.wait(self.interval):
                try:
                    self.check()
                except ClusterLost as e:
                    self.lost = e
                    on_lost()
                    return
                except Exception:     # the connection to the scheduler: the futures report it
                    pass
        threading.Thread(target=watch, name="dmi-sweep-worker-watch", daemon=True).start()

    def stop(self) -> None:
        """Stops the thread of :meth:`start` (at its next interval)."""
        self.stopped.set()


class ConnectionSetupError(RuntimeError):
    """TLS options or configuration that cannot work (missing certificates, unreadable files,
    options without a tls:// address, a certificate the scheduler rejects): nothing was run.
    """


TLS_KEYS = ("distributed.comm.tls.ca-file", "distributed.comm.tls.client.cert",
            "distributed.comm.tls.client.key")


def security(scheduler: str | None, tls_ca_file: str | None = None, tls_cert: str | None = None,
             tls_key: str | None = None, slurm: bool = False) -> Security | None:
    """The Security of the connection to `scheduler`: the ``--tls-*`` options over Dask's
    configuration (``distributed.comm.tls.*``), checked before connecting.

    A ``tls://`` address needs a CA file and a client certificate, from either source; every file
    must be readable and make an SSL context. With `slurm` (the scheduler in this process, the
    workers in SLURM jobs) the options turn TLS on: the certificate and key serve the scheduler, the
    workers and this client, all signed by the CA file; the paths are made absolute (the jobs read
    them from the shared filesystem).

    Parameters
    ----------
    scheduler : str or None
        The scheduler's address (None: a local or SLURM cluster).
    tls_ca_file, tls_cert, tls_key : str, optional
        PEM files: the CA that signed the scheduler's certificate, this client's certificate, its key
        (unless the certificate file holds it).
    slurm : bool, optional
        The cluster is a SLURMCluster started here.

    Returns
    -------
    distributed.Security or None
        None for a plain address without TLS options (Dask's own defaults).

    Raises
    ------
    ConnectionSetupError
        TLS options without a tls:// address or ``--slurm``, a TLS address without certificates, an
        unreadable file, files that make no SSL context.
    """
    options = {"tls_ca_file": tls_ca_file, "tls_client_cert": tls_cert, "tls_client_key": tls_key}
    given = [f"--{k.replace('tls_client_', 'tls-').replace('_', '-')}" for k, v in options.items() if v]
    tls = bool(scheduler) and scheduler.startswith("tls://") or slurm and bool(given)
    if given and not tls:
        raise ConnectionSetupError(
            f"{', '.join(given)} given, but {'--scheduler ' + scheduler if scheduler else 'no --scheduler'}"
            " is not a tls:// address: the TLS options are for a scheduler started with "
            "--protocol tls, or for --slurm (the local cluster listens on 127.0.0.1 only and needs "
            "none)")
    if not tls:
        return None
    sec = Security(require_encryption=True, **{k: v for k, v in options.items() if v})
    if slurm and sec.tls_ca_file and sec.tls_client_cert:
        # the client's files (given or configured) serve the scheduler and the workers too, as
        # absolute paths (the job script names them); a certificate file that holds its key is
        # also the key file (a worker given "--tls-key None" would not start)
        paths = {k: os.path.abspath(v) if v and "\n" not in v else v for k, v in
                 (("ca", sec.tls_ca_file), ("cert", sec.tls_client_cert),
                  ("key", sec.tls_client_key or sec.tls_client_cert))}
        roles = {f"tls_{r}_{w}": paths[w] for r in ("client", "scheduler", "worker")
                 for w in ("cert", "key")}
        sec = Security(require_encryption=True, tls_ca_file=paths["ca"], **roles)
    if not sec.tls_ca_file or not sec.tls_client_cert:
        where = "--slurm with --tls-* options" if slurm else f"{scheduler} is a TLS address"
        raise ConnectionSetupError(
            f"{where}, but no certificates were given: pass --tls-ca-file (the CA "
            "that signed the scheduler's certificate), --tls-cert (this client's certificate) and "
            "--tls-key (its private key, unless the certificate file holds it), or set them in Dask's "
            f"configuration ({', '.join(TLS_KEYS)}; in the environment "
            "DASK_DISTRIBUTED__COMM__TLS__CA_FILE, DASK_DISTRIBUTED__COMM__TLS__CLIENT__CERT, "
            "DASK_DISTRIBUTED__COMM__TLS__CLIENT__KEY). Nothing was run")
    files = {"CA file": sec.tls_ca_file, "certificate": sec.tls_client_cert, "key": sec.tls_client_key}
    for what, path in files.items():
        if path and "\n" not in path:
            try:
                with open(path, "rb"):
                    pass
            except OSError as e:
                raise ConnectionSetupError(f"cannot read the TLS {what} {path}: {e.strerror}. "
                                           "Nothing was run") from None
    try:
        sec.get_connection_args("client")   # with --slurm every role has the client's files
    except (ssl.SSLError, ValueError, OSError) as e:
        raise ConnectionSetupError(
            f"the TLS files do not make a client context ({e}): --tls-cert must be a PEM "
            "certificate, --tls-key its PEM private key, --tls-ca-file PEM CA certificates "
            f"(given or configured: {', '.join(f'{w} {p}' for w, p in files.items() if p)}). "
            "Nothing was run") from None
    return sec


class _LogFileHandler(logging.Handler):
    """Log records as lines of the folder's _log.jsonl."""

    def __init__(self, store: Store):
        super().__init__(logging.WARNING)
        self.store = store

    def emit(self, record: logging.LogRecord) -> None:
        try:
            entry = {"log": record.name, "level": record.levelname, "message": record.getMessage()}
            if record.exc_info:
                entry["traceback"] = logging.Formatter().formatException(record.exc_info)
            self.store.log(entry)
        except Exception:
            self.handleError(record)


@contextlib.contextmanager
def logs_to(store: Store) -> Iterator[None]:
    """A context manager: while inside, the warnings and errors of Dask, Tornado and asyncio in this
    process, and Python warnings, go to the folder's ``_log.jsonl`` instead of the terminal.

    Parameters
    ----------
    store : Store
        The open store whose log receives them.

    Yields
    ------
    None
    """
    handler = _LogFileHandler(store)
    names = {"distributed", "tornado", "asyncio", "bokeh", "py.warnings"}
    names |= {n for n, lg in logging.root.manager.loggerDict.items()
              if isinstance(lg, logging.Logger) and lg.handlers and n.split(".")[0] in names}
    saved = {}
    for n in names:
        lg = logging.getLogger(n)
        saved[n] = (lg.handlers[:], lg.propagate)
        lg.handlers, lg.propagate = [handler], False
    logging.captureWarnings(True)
    try:
        yield
    finally:
        logging.captureWarnings(False)
        for n, (handlers, propagate) in saved.items():
            lg = logging.getLogger(n)
            lg.handlers, lg.propagate = handlers, propagate


@contextlib.contextmanager
def _sigint_ignored() -> Iterator[None]:
    """SIGINT ignored while the local cluster starts its processes: they inherit it, so a Ctrl-C
    reaches only this client, which closes them in order (no half-dead worker, no leaked
    semaphore)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


def make_client(workers: int | None, scheduler: str | None, sec: Security | None = None,
                dashboard: bool = False) -> Client:
    """A client of the cluster at `scheduler`, or of a new LocalCluster.

    Parameters
    ----------
    workers : int or None
        Processes of the new LocalCluster on 127.0.0.1, one thread each (default: one per core).
    scheduler : str or None
        The address of an existing scheduler; then `workers` is not used.
    sec : distributed.Security, optional
        The connection's security (:func:`security`).
    dashboard : bool, optional
        Start the local cluster's dashboard on a free port of 127.0.0.1.

    Returns
    -------
    distributed.Client
        The client; close it, and its ``cluster`` when it made one.

    Raises
    ------
    ClusterLost
        If the scheduler cannot be reached.
    ConnectionSetupError
        If the TLS handshake fails (the scheduler refuses this client's certificate, or the CA does
        not match).
    """
    if scheduler:
        try:
            return Client(scheduler, timeout="30s", security=sec)
        except (OSError, CommClosedError, ssl.SSLError) as e:
            text = _reasons(e)
            # the handshake failed: an SSLError among the causes, or in the message of Dask's
            # CommClosedError (which keeps only the text of tornado's SSLError), or a TLS connection
            # that the scheduler closed at once (under TLS 1.3 the client may see only that)
            if any(isinstance(c, ssl.SSLError) for c in _chain(e)) \
                    or re.search(r"SSL\w*Error|\[SSL|<TLS \(closed\)", text):
                raise ConnectionSetupError(
                    f"the TLS connection to {scheduler} failed: {text}. Check that --tls-ca-file is "
                    "the CA that signed the scheduler's certificate and that the scheduler trusts "
                    "the CA of --tls-cert. Nothing was run") from None
            raise ClusterLost(f"cannot reach the scheduler at {scheduler}: {text}") from None
    n = workers or os.cpu_count() or 1
    # No task waits on a busy worker: one that dies takes only its running chunk with it.
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}), _sigint_ignored():
        # The scheduler's HTTP server (the dashboard, if asked) on a free port of 127.0.0.1, not on
        # 8787, which another cluster of the machine may hold.
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address="127.0.0.1:0" if dashboard else None,
                               scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                               silence_logs=logging.CRITICAL)
    return Client(cluster)


def _chain(e: BaseException | None) -> Iterator[BaseException]:
    """An exception and its causes (at most 8)."""
    for _ in range(8):
        if e is None:
            return
        yield e
        e = e.__cause__ or e.__context__


def _reasons(e: BaseException) -> str:
    """The messages of an exception and its causes, in one line."""
    out: list[str] = []
    for c in _chain(e):
        text = f"{type(c).__name__}: {c}" if str(c) else type(c).__name__
        if text not in out:
            out.append(text)
    return "; ".join(out[:4])


STDERR: Any = object()   # run()'s default stream: sys.stderr when called (pytest, say, replaces it)


@dataclass
class Summary:
    """What a run did (:func:`run` returns it).

    Attributes
    ----------
    total : int
        The points of the sweep.
    skipped : int
        Those already in the folder when this run started.
    computed : int
        Those computed and written by this run.
    failed : int
        The points of the folder whose row has an error (this run's and earlier).
    seconds : float
        The run's wall time.
    repaired : int
        Duplicate rows of older runs dropped before computing.
    """
    total: int          # points of the sweep
    skipped: int        # already in the folder when this run started
    computed: int       # computed and written by this run
    failed: int         # points of the folder whose row has an error (this run's and earlier)
    seconds: float
    repaired: int = 0   # duplicate rows of older runs dropped before computing


def run(spec: Spec, out: str | os.PathLike, workers: int | None = None, scheduler: str | None = None,
        restart: bool = False, chunk_size: int | None = None,
        progress: TextIO | None = STDERR, tls_ca_file: str | None = None,
        tls_cert: str | None = None, tls_key: str | None = None, dashboard: bool = False,
        messages: TextIO | None = STDERR, no_worker_timeout: float = NO_WORKER_TIMEOUT,
        slurm: dict[str, Any] | None = None) -> Summary:
    """Runs the sweep `spec` into the folder `out`, resuming what is there.

    Before anything is written: the TLS options are checked and the FMU is instantiated here with
    the ``[start]`` values. Then the folder is locked and duplicates of older runs are repaired; the
    points missing from the folder are computed in chunks on the cluster, each chunk written as it
    arrives. The cluster started here (local or SLURM) is closed before the function returns.

    Parameters
    ----------
    spec : Spec
        The sweep (:func:`dmi_sweep.spec.load`).
    out : str or os.PathLike
        The result folder.
    workers : int, optional
        Processes of a new local cluster (default: one per core).
    scheduler : str, optional
        The address of a running scheduler to use instead (``tcp://``, ``tls://``).
    restart : bool, optional
        Delete the folder's results and start again.
    chunk_size : int, optional
        Points per task (default: about 8 tasks per worker, at most 64 points each).
    progress : TextIO or None, optional
        Where the progress bar goes (default: sys.stderr at the time of the call; None: nowhere).
    tls_ca_file, tls_cert, tls_key : str, optional
        TLS files (:func:`security`).
    dashboard : bool, optional
        Start the local cluster's dashboard and print its address.
    messages : TextIO or None, optional
        Where the lines about repairs, lost workers and the dashboard go (default: sys.stderr at the
        time of the call; None: nowhere).
    no_worker_timeout : float, optional
        Seconds without any worker after which the cluster counts as lost.
    slurm : dict, optional
        The job settings of :func:`dmi_sweep.slurm.resolve`: the workers run in SLURM jobs of a
        SLURMCluster started here; the no-worker count waits while SLURM still has one of its jobs.

    Returns
    -------
    Summary
        The counts of the run.

    Raises
    ------
    ValueError
        If `no_worker_timeout` is not > 0, or `slurm` is given with `scheduler` or `workers`.
    ConnectionSetupError
        For TLS options that cannot work (:func:`security`).
    SpecError
        If the FMU refuses the ``[start]`` values (its message).
    SlurmRefused
        If SLURM refuses the job script (before the folder is made).
    StoreError
        If the folder holds another sweep (without `restart`) or another client holds it.
    ClusterLost
        If the scheduler cannot be reached or is lost, or the cluster has had no worker for
        `no_worker_timeout` seconds; the chunks written stay, and the same call resumes.
    """
    if not no_worker_timeout > 0:
        raise ValueError(f"no_worker_timeout must be > 0 seconds, not {no_worker_timeout!r}")
    t0 = time.monotonic()
    progress = sys.stderr if progress is STDERR else progress
    messages = sys.stderr if messages is STDERR else messages
    sec = security(scheduler, tls_ca_file, tls_cert, tls_key, slurm is not None)
    refusal = check_start(spec.fmu.read_bytes(), spec.job())
    if refusal:
        raise SpecError(f"the FMU refuses the [start] values: {refusal}")
    # An external scheduler is reached (and its certificate checks passed), or SLURM accepts the
    # jobs, before the folder is made.
    client = None
    if slurm is not None:
        if scheduler or workers:
            raise ValueError("slurm excludes scheduler and workers")
        cluster = slurm_jobs.start(slurm, sec)
        try:
            client = Client(cluster)
        except BaseException:
            cluster.close()
            raise
        workers = slurm["cores"] * slurm["jobs"]
    elif scheduler:
        client = make_client(None, scheduler, sec)
    try:
        store = Store.open(out, spec, restart=restart)
    except BaseException:
        if client is not None:
            _close(client)
        raise
    try:
        with logs_to(store):
            return _run_locked(spec, store, t0, client, workers, chunk_size, progress, messages,
                               dashboard, no_worker_timeout, slurm is not None)
    finally:
        store.close()


def _close(client: Client) -> None:
    """Closes the client, and its cluster if it started one (a LocalCluster, a SLURMCluster: its
    jobs are cancelled)."""
    cluster = client.cluster
    with contextlib.suppress(Exception):
        client.close(timeout=5 if client.status == "running" else 1)
    if cluster is not None:
        cluster.close()


def _run_locked(spec: Spec, store: Store, t0: float, client: Client | None, workers: int | None,
                chunk_size: int | None, progress: TextIO | None, messages: TextIO | None,
                dashboard: bool, no_worker_timeout: float, on_slurm: bool = False) -> Summary:
    """The run once the folder is locked: with the client of the external or SLURM cluster, or None
    for a LocalCluster of `workers` processes (started only when points are missing)."""
    scheduler = client.scheduler.address if client is not None else None
    say = messages.write if messages is not None else (lambda text: None)
    repaired, rewritten, removed = store.repair()
    if repaired:
        say(f"dmi-sweep: {store.dir} held {repaired} extra copies of points from overlapping older runs: "
            f"dropped them, one row per point kept ({rewritten} chunk files rewritten, {removed} "
            "removed)\n")
    done = store.done()
    todo = [i for i in range(spec.n_points) if i not in done]
    failed_before = store.failed()
    store.log({"run": True, "done": len(done), "todo": len(todo), "repaired": repaired})
    if done:
        say(f"dmi-sweep: {len(done)} of {spec.n_points} points already in {store.dir}, "
            f"computing the {len(todo)} missing\n")
    if not todo:
        if client is not None:
            _close(client)
        return Summary(spec.n_points, len(done), 0, failed_before, time.monotonic() - t0, repaired)

    if client is None:
        client = make_client(workers, None, None, dashboard)
    cluster = client.cluster
    if dashboard:
        # the local scheduler serves the dashboard's pages only if bokeh is installed here
        if scheduler or importlib.util.find_spec("bokeh") is not None:
            say(f"dmi-sweep: the Dask dashboard is at {client.dashboard_link}\n")
        else:
            say("dmi-sweep: no dashboard: Dask's dashboard needs bokeh (pip install bokeh)\n")
    plugin = FMUPlugin(spec.fmu.read_bytes(), spec.sha256)      # a caller's, kept across runs
    bar = Progress(spec.n_points, len(done), progress)
    registered = False
    computed = failed = 0
    pending: dict[str, list[int]] = {}           # key of a task -> its points
    try:
        try:
            n_workers = len(client.scheduler_info(n_workers=-1).get("workers", {})) or (workers or 1)
            # A plugin of this FMU registered by the caller is used and kept; else this run registers
            # its own (a name no other client uses) and removes it at the end, so one client's end
            # never takes the FMU from another client's chunks.
            if not client.run_on_scheduler(has_worker_plugin, name=plugin.name):
                plugin = FMUPlugin(plugin.fmu_bytes, spec.sha256, uuid.uuid4().hex[:12])
                client.register_plugin(plugin)
                registered = True
            removals: list[dict[str, Any]] = []     # remove-worker events, from the client's thread

            def on_event(event):   # in the client's thread, when the scheduler sends the event
                msg = event[1]
                if isinstance(msg, dict) and msg.get("action") == "remove-worker":
                    keys = set(msg.get("processing-tasks", ())) | set(msg.get("lost-computed-tasks", ()))
                    again = [pending.get(k) for k in keys]
                    removals.append({**msg, "again": sorted(c for c in again if c)})

            client.subscribe_topic("all", on_event)
        except (OSError, CommClosedError, CancelledError) as e:
            raise ClusterLost(f"the connection to the scheduler broke: {_reasons(e)}") from None
        job = spec.job()

        where = f" at {scheduler}" if scheduler else ""
        watch = WorkerWatch(client, no_worker_timeout, where,
                            waiting=(lambda: slurm_jobs.jobs_alive(cluster)) if on_slurm else None,
                            waiting_gone="SLURM has none of its jobs left" if on_slurm else "")
        futures: dict[str, Any] = {}             # key of a task -> its future, while pending

        def submit(points: list[int]):
            payload = task(run_chunk, plugin.name, job, [(i, spec.point(i)) for i in points])
            fut = client.submit(pickle.loads, payload, pure=False)
            pending[fut.key], futures[fut.key] = points, fut
            if watch.lost:         # after the watch cancelled the others (it sets lost first)
                fut.cancel()
            return fut

        def cancel_all():          # in the watch's thread
            with contextlib.suppress(Exception):
                client.cancel(list(futures.values()))

        def report_removals():
            while removals:
                ev = removals.pop(0)
                store.log({"worker_lost": ev.get("worker"), "expected": ev.get("expected"),
                           "chunks_again": ev["again"]})
                if not ev.get("expected"):
                    firsts = ", ".join(str(c[0]) for c in ev["again"])
                    try:       # (asked now, when the line is written, not when the worker left)
                        others = bool(client.nthreads())
                    except Exception:   # (the connection to the scheduler: the futures report it)
                        others = True
                    where_again = ("run again on the other workers" if others
                                   else "wait for a worker (none is left now)")
                    bar.note(messages, f"dmi-sweep: lost worker {ev.get('worker')}; "
                             + (f"{len(ev['again'])} chunks (first points {firsts}) {where_again}"
                                if ev["again"] else "no chunk of this sweep was on it"))

        lost: dict[int, int] = {}    # point -> times its single-point task was lost with a worker
        closed: dict[int, int] = {}  # first point of a chunk -> times it found the plugin gone
        written: set[int] = set()
        try:
            stream = as_completed([submit(c) for c in chunks(todo, n_workers, chunk_size)])
            watch.start(cancel_all)
            for fut in stream:
                report_removals()
                points = pending.pop(fut.key)
                try:
                    results = fut.result()
                except KilledWorker as e:
                    # The chunk's workers died (the FMU crashed them?), or it was on a worker that
                    # another chunk killed. Each point alone, twice, finds the culprit.
                    if len(points) > 1 or lost.get(points[0], 0) < 1:
                        for i in points:
                            lost[i] = lost.get(i, -1) + 1
                            stream.add(submit([i]))
                        continue
                    results = [{"point": points[0], "error": f"{type(e).__name__}: {e}"}]
                except PluginClosed:
                    # the chunk reached a worker that was dropping the plugin: nothing computed
                    closed[points[0]] = closed.get(points[0], 0) + 1
                    if closed[points[0]] <= 3:
                        stream.add(submit(points))
                        continue
                    results = [{"point": i, "error": "the chunk found no worker with the FMU three "
                                "times (its plugin was removed)"} for i in points]
                except (OSError, CommClosedError, CancelledError) as e:
                    if watch.lost:                 # no worker left: the watch cancelled the futures
                        report_removals()
                        store.log({"lost": watch.lost.reason, "no_worker_timeout": no_worker_timeout})
                        raise watch.lost from None
                    store.log({"lost": _reasons(e)})          # the scheduler is gone
                    raise ClusterLost("lost the connection to the scheduler" + where) from None
                except Exception as e:     # the task itself failed (not the FMU: that is a row)
                    results = [{"point": i, "error": f"{type(e).__name__}: {e}"} for i in points]
                finally:
                    futures.pop(fut.key)       # after result(): the watch may cancel its wait
                results = [r for r in results if r["point"] not in written]
                fut.release()
                if not results:
                    continue
                written.update(r["point"] for r in results)
                store.write(results)
                computed += len(results)
                failed += sum(1 for r in results if r.get("error"))
                bar.update(len(results))
            report_removals()
        finally:
            watch.stop()
            bar.close()
    except ClusterLost as e:
        e.saved, e.total = len(done) + computed, spec.n_points
        raise
    finally:
        if client.status == "running":
            with contextlib.suppress(Exception):
                client.unsubscribe_topic("all")
            if scheduler and registered:
                with contextlib.suppress(Exception):
                    client.unregister_worker_plugin(plugin.name)
        _close(client)
    return Summary(spec.n_points, len(done), computed, failed_before + failed,
                   time.monotonic() - t0, repaired)
