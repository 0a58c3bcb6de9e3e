# Runs a sweep on Dask: a LocalCluster of K single-threaded worker processes by
# default, or an existing cluster (--scheduler).  The FMU travels to each worker
# once, inside a worker plugin; chunks of points are tasks; each finished chunk
# is written to the result folder at once.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import json
import logging
import math
import os
import pickle
import sys
import time
from dataclasses import dataclass
from typing import Callable, TextIO

import cloudpickle
import dask
from distributed import Client, KilledWorker, LocalCluster, as_completed

from . import simulate
from .simulate import FMUPlugin, run_chunk
from .spec import Spec
from .store import LOG, Store

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
    """The bytes of a task for pickle.loads (see _Call)."""
    return cloudpickle.dumps(_Call(fn, *args))


@dataclass
class Summary:
    total: int          # points of the sweep
    skipped: int        # already in the folder when this run started
    computed: int       # computed and written by this run
    failed: int         # of those, points whose row has an error
    seconds: float


class Progress:
    """A one-line progress bar on stderr: points done of total, rate, time left."""

    def __init__(self, total: int, done: int, stream: TextIO | None = sys.stderr, width: int = 30,
                 clock: Callable[[], float] = time.monotonic):
        """total points, of which `done` were done before; a line at most every 0.2 s on a terminal,
        every 5 s elsewhere (a log file), and at close()."""
        self.total, self.start_done, self.done = total, done, done
        self.stream, self.width, self.clock = stream, width, clock
        self.t0 = clock()
        self.last = -math.inf       # the first update shows at once
        self.tty = stream is not None and stream.isatty()

    def update(self, n: int, force: bool = False) -> None:
        """n more points done."""
        self.done += n
        now = self.clock()
        if self.stream is None or (not force and now - self.last < (0.2 if self.tty else 5.0)):
            return
        self.last = now
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

    def close(self) -> None:
        self.update(0, force=True)
        if self.stream is not None and self.tty:
            self.stream.write("\n")


def chunks(todo: list[int], n_workers: int, chunk_size: int | None) -> list[list[int]]:
    """Consecutive runs of the points to do, about 8 chunks per worker (at most 64 points each)
    unless chunk_size is given."""
    if chunk_size is None:
        chunk_size = max(1, min(64, len(todo) // (8 * max(n_workers, 1))))
    return [todo[i:i + chunk_size] for i in range(0, len(todo), chunk_size)]


def make_client(workers: int | None, scheduler: str | None) -> Client:
    """A client of the cluster at `scheduler`, or of a new LocalCluster of `workers` processes
    (default: one per core) with one thread each."""
    if scheduler:
        return Client(scheduler, timeout="30s")
    n = workers or os.cpu_count() or 1
    # No task waits on a busy worker: one that dies takes only its running chunk with it.
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
    return Client(cluster)


def run(spec: Spec, out: str | os.PathLike, workers: int | None = None, scheduler: str | None = None,
        restart: bool = False, chunk_size: int | None = None,
        progress: TextIO | None = sys.stderr) -> Summary:
    """Runs the sweep `spec` into the folder `out`, resuming what is there."""
    t0 = time.monotonic()
    store = Store.open(out, spec, restart=restart)
    done = store.done()
    todo = [i for i in range(spec.n_points) if i not in done]
    with open(store.dir / LOG, "a") as f:
        f.write(json.dumps({"time": time.time(), "client": os.getpid(), "run": True,
                            "done": len(done), "todo": len(todo)}) + "\n")
    if progress is not None and done:
        progress.write(f"dmi-sweep: {len(done)} of {spec.n_points} points already in {store.dir}, "
                       f"computing the {len(todo)} missing\n")
    if not todo:
        return Summary(spec.n_points, len(done), 0, 0, time.monotonic() - t0)

    client = make_client(workers, scheduler)
    cluster = client.cluster
    try:
        n_workers = len(client.scheduler_info().get("workers", {})) or (workers or 1)
        plugin = FMUPlugin(spec.fmu.read_bytes(), spec.sha256)
        client.register_plugin(plugin)
        job = spec.job()
        bar = Progress(spec.n_points, len(done), progress)

        def submit(points: list[int]):
            payload = task(run_chunk, plugin.name, job, [(i, spec.point(i)) for i in points])
            fut = client.submit(pickle.loads, payload, pure=False)
            pending[fut.key] = points
            return fut

        pending: dict[str, list[int]] = {}
        lost: dict[int, int] = {}    # point -> times its single-point task was lost with a worker
        stream = as_completed([submit(c) for c in chunks(todo, n_workers, chunk_size)])
        computed = failed = 0
        written: set[int] = set()
        for fut in stream:
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
            results = [r for r in results if r["point"] not in written]
            fut.release()
            if not results:
                continue
            written.update(r["point"] for r in results)
            store.write(results)
            computed += len(results)
            failed += sum(1 for r in results if r.get("error"))
            bar.update(len(results))
        bar.close()
    finally:
        client.close()
        if not scheduler and cluster is not None:
            cluster.close()
    return Summary(spec.n_points, len(done), computed, failed, time.monotonic() - t0)
