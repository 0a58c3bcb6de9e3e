# The result folder: a Parquet dataset of chunk files part-<first point>.parquet
# (each written to a hidden temporary file, then renamed), the spec (_spec.toml),
# the metadata (_meta.json), a log of the runs and chunks written (_log.jsonl:
# points, worker pids, FMU instantiations so far on the worker; lost workers,
# repairs, Dask's warnings and errors) and the lock file (_lock: the client that
# holds the folder).  Readers (pandas.read_parquet, pyarrow) skip names starting
# with "_" or ".".
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import contextlib
import errno
import json
import math
import os
import platform
import socket
import time
from importlib import metadata
from pathlib import Path
from typing import Any, BinaryIO, Callable

import psutil
import pyarrow as pa
import pyarrow.parquet as pq

from .spec import Spec

META = "_meta.json"
SPEC = "_spec.toml"
LOG = "_log.jsonl"
LOCK = "_lock"
TMP = ".tmp-"            # temporary files: .tmp-<pid of the writer>-<name>


class StoreError(RuntimeError):
    """The folder holds something else than this sweep, or another client uses it (the message says
    what to do).
    """


# The operating system's lock, the one place that depends on the platform. Both locks belong to the
# open file: closing it, or the end of the process however it ends, releases them.
try:
    import fcntl
except ImportError:          # Windows
    import msvcrt

    LOCK_KIND = "msvcrt.locking"
    # Windows locks byte ranges, and nobody else may read a locked byte: the lock is on one byte far
    # beyond the holder's description at the start of the file (a range past the end is allowed), so
    # that a refused client can still read who holds the folder.
    _LOCKED_BYTE = 1 << 30

    def _try_lock(fd: int) -> bool:
        """Locks the file fd without waiting: False if another open file holds the lock."""
        os.lseek(fd, _LOCKED_BYTE, os.SEEK_SET)
        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except OSError as e:
            if e.errno in (errno.EACCES, errno.EDEADLOCK):
                return False
            raise
        finally:
            os.lseek(fd, 0, os.SEEK_SET)
        return True

    def _unlock(fd: int) -> None:
        os.lseek(fd, _LOCKED_BYTE, os.SEEK_SET)
        msvcrt.locking(fd, msvcrt.LK_UNLCK, 1)
else:                        # POSIX
    LOCK_KIND = "flock"

    def _try_lock(fd: int) -> bool:
        """Locks the file fd without waiting: False if another open file holds the lock."""
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        return True

    def _unlock(fd: int) -> None:
        fcntl.flock(fd, fcntl.LOCK_UN)


class FolderLock:
    """The operating system's lock (flock on POSIX, msvcrt.locking on Windows) on the folder's
    ``_lock`` file, held by one client while it runs: it dies with its holder, also with a killed one.
    The file says who holds the lock (host, pid, start time); the file itself stays, empty of meaning
    once unlocked.

    Parameters
    ----------
    directory : Path
        The sweep's folder (it must exist).

    Raises
    ------
    StoreError
        If the filesystem cannot lock, or another client holds the lock (the message names it).
    """

    def __init__(self, directory: Path):
        self.path = directory / LOCK
        # not inherited by workers (PEP 446); binary: no newline translation on Windows
        fd = os.open(self.path, os.O_RDWR | os.O_CREAT | getattr(os, "O_BINARY", 0), 0o644)
        try:
            locked = _try_lock(fd)
        except OSError as e:
            os.close(fd)
            raise StoreError(f"cannot lock {self.path}: {e.strerror} (the filesystem must support "
                             f"{LOCK_KIND}; see the lock in the dmi-sweep documentation)") from None
        if not locked:
            holder = os.read(fd, 4096).decode(errors="replace")
            os.close(fd)
            try:
                h = json.loads(holder)
                who = f"pid {h['pid']} on {h['host']}, started {h['started']}"
            except (ValueError, KeyError, TypeError):
                who = "a client that has not yet said who it is"
            raise StoreError(f"{directory} is in use by another dmi-sweep client ({who}). One client "
                             "per folder: wait for it to end, or stop it (its finished points stay) "
                             "and run the same command again")
        self.fd: int | None = fd
        me = {"host": socket.gethostname(), "pid": os.getpid(),
              "started": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
        os.ftruncate(fd, 0)
        os.lseek(fd, 0, os.SEEK_SET)
        os.write(fd, json.dumps(me).encode())

    def release(self) -> None:
        """Unlocks and closes the file; again: nothing."""
        if self.fd is not None:
            with contextlib.suppress(OSError):
                _unlock(self.fd)
            os.close(self.fd)          # would release the lock anyway
            self.fd = None


def _running(pid: int) -> bool:
    """Whether the process `pid` exists (on this machine). Not os.kill(pid, 0), which on Windows
    ends the process."""
    return psutil.pid_exists(pid)


def _versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for dist in ("dmi", "fmpy", "dask", "distributed", "pyarrow", "numpy", "pandas"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def schema(spec: Spec) -> pa.Schema:
    """The Arrow schema of a sweep's rows.

    Parameters
    ----------
    spec : Spec
        The sweep.

    Returns
    -------
    pyarrow.Schema
        The swept parameters (their types), ``point``, per output ``y``: ``y_final``, ``y_min``,
        ``y_max``, ``y_mean`` (and ``y_poincare``, a list, with a Poincare period), ``error`` (null
        when the point succeeded).
    """
    kinds = {"float": pa.float64(), "int": pa.int64(), "bool": pa.bool_()}
    fields = [pa.field(p, kinds[spec.types[p]]) for p in spec.params]
    fields.append(pa.field("point", pa.int64()))
    for y in spec.outputs:
        fields += [pa.field(f"{y}_{s}", pa.float64()) for s in ("final", "min", "max", "mean")]
        if spec.poincare is not None:
            fields.append(pa.field(f"{y}_poincare", pa.list_(pa.float64())))
    fields.append(pa.field("error", pa.string()))
    return pa.schema(fields)


class Store:
    """The result folder of one sweep: Parquet chunk files ``part-<first point>.parquet``, the
    metadata ``_meta.json``, the log ``_log.jsonl`` and the lock. Made by :meth:`open`.

    Parameters
    ----------
    directory : Path
        The folder.
    spec : Spec
        The sweep.
    """

    def __init__(self, directory: Path, spec: Spec):
        self.dir = directory
        self.spec = spec
        self.schema = schema(spec)
        self.lock: FolderLock | None = None

    @classmethod
    def open(cls, directory: str | os.PathLike, spec: Spec, restart: bool = False) -> "Store":
        """Creates the folder, or reopens it to resume the same sweep, and locks it (:meth:`close`
        unlocks).

        Parameters
        ----------
        directory : str or os.PathLike
            The folder.
        spec : Spec
            The sweep.
        restart : bool, optional
            Delete the folder's results, whatever sweep they came from, and start again.

        Returns
        -------
        Store
            The open, locked store.

        Raises
        ------
        StoreError
            If the path is a file, a non-empty folder without dmi-sweep results, a folder of another
            sweep (spec or FMU changed) without `restart`, or a folder another client holds.
        """
        d = Path(directory)
        store = cls(d, spec)
        meta_path = d / META
        if d.exists() and not d.is_dir():
            raise StoreError(f"{d} exists and is not a folder")
        if d.exists() and not meta_path.exists() and not (d / LOCK).exists() and any(d.iterdir()):
            raise StoreError(f"{d} is not empty and holds no dmi-sweep results ({META} missing); "
                             "give an empty or new folder")
        d.mkdir(parents=True, exist_ok=True)
        store.lock = FolderLock(d)
        try:
            store._open_locked(restart)
        except BaseException:
            store.close()
            raise
        return store

    def _open_locked(self, restart: bool) -> None:
        d, spec, meta_path = self.dir, self.spec, self.dir / META
        identity = spec.identity()
        if meta_path.exists():
            meta = json.loads(meta_path.read_text())
            if meta.get("identity") != identity and not restart:
                what = ("the FMU changed (sha256 " + meta.get("identity", {}).get("fmu_sha256", "?")[:12]
                        + " -> " + spec.sha256[:12] + ")"
                        if meta.get("identity", {}).get("spec") == identity["spec"]
                        else f"the spec differs from {d / SPEC}")
                raise StoreError(f"{d} holds another sweep: {what}. Use another --out, or --restart "
                                 "to delete its results and start again")
            if restart:
                self._clear()
        if not meta_path.exists():
            self._write_atomic(SPEC, lambda f: f.write(spec.text))
            variables = {v.name: v for v in spec.model.modelVariables}
            meta = {"identity": identity, "fmu": str(spec.fmu), "fmu_sha256": spec.sha256,
                    "fmi_version": spec.model.fmiVersion, "model_name": spec.model.modelName,
                    "points": spec.n_points, "params": spec.params, "outputs": spec.outputs,
                    "output_types": {y: variables[y].type for y in spec.outputs},
                    "mode": spec.mode, "versions": _versions(),
                    "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
            self._write_atomic(META, lambda f: f.write(json.dumps(meta, indent=1).encode()))
        self._remove_stale_temporaries()

    def close(self) -> None:
        """Unlocks the folder; again: nothing."""
        if self.lock is not None:
            self.lock.release()
            self.lock = None

    def log(self, entry: dict[str, Any]) -> None:
        """Appends one line to ``_log.jsonl``: the entry with the time and the client's pid.

        Parameters
        ----------
        entry : dict
            What to log (JSON-serialisable, else written as text).
        """
        with open(self.dir / LOG, "a") as f:
            f.write(json.dumps({"time": time.time(), "client": os.getpid(), **entry}, default=str) + "\n")

    def repair(self) -> tuple[int, int, int]:
        """Drops the extra copies of points that several chunk files hold (overlapping chunks of
        older runs, before the lock existed).

        Keeps one row per point, a successful one if there is one, else the one in the first file. A
        file that loses rows is rewritten under its own name (write then rename: it holds either all its
        old rows or the kept ones), a file that keeps none is removed; the kept copy of a point is never
        touched, so a crash at any moment loses no point.

        Returns
        -------
        tuple of int
            (rows dropped, files rewritten, files removed).
        """
        parts = self.parts()
        keep: dict[int, tuple[int, int, bool]] = {}   # point -> (file, row, succeeded)
        tables = []
        for f, p in enumerate(parts):
            t = pq.read_table(p, columns=["point", "error"])
            tables.append(t)
            for row, (point, error) in enumerate(zip(t.column("point").to_pylist(),
                                                     t.column("error").to_pylist())):
                old = keep.get(point)
                if old is None or (error is None and not old[2]):
                    keep[point] = (f, row, error is None)
        kept_rows: dict[int, list[int]] = {}
        for f, row, _ in keep.values():
            kept_rows.setdefault(f, []).append(row)
        dropped = rewritten = removed = 0
        for f, (p, t) in enumerate(zip(parts, tables)):
            rows = sorted(kept_rows.get(f, []))
            if len(rows) == t.num_rows:
                continue
            dropped += t.num_rows - len(rows)
            if rows:
                table = pq.read_table(p).take(rows)
                self._write_atomic(p.name, lambda out: pq.write_table(table, out))
                rewritten += 1
            else:
                p.unlink()
                removed += 1
        if dropped:
            self.log({"repair": {"dropped": dropped, "rewritten": rewritten, "removed": removed}})
        return dropped, rewritten, removed

    def _clear(self):
        for p in self.dir.iterdir():
            if (p.name.startswith("part-") and p.suffix == ".parquet") or p.name in (META, SPEC, LOG) \
                    or p.name.startswith(TMP):
                p.unlink()

    def _write_atomic(self, name: str, write: Callable[[BinaryIO], object]) -> Path:
        """Writes the file `name` of the folder through write(file): into a hidden temporary file
        (.tmp-<pid>-<name>, skipped by readers), synced, then renamed, so a reader sees either no file
        or the whole file. A temporary file left by a killed process is removed by open()."""
        tmp = self.dir / f"{TMP}{os.getpid()}-{name}"
        try:
            with open(tmp, "wb") as f:
                write(f)
                f.flush()
                os.fsync(f.fileno())
            os.replace(tmp, self.dir / name)
        except BaseException:
            tmp.unlink(missing_ok=True)
            raise
        return self.dir / name

    def _remove_stale_temporaries(self):
        """Removes the temporary files of processes that no longer run (a killed client)."""
        for p in self.dir.glob(TMP + "*"):
            pid = p.name[len(TMP):].split("-", 1)[0]
            if not pid.isdigit() or not _running(int(pid)):
                p.unlink(missing_ok=True)

    def parts(self) -> list[Path]:
        """The chunk files.

        Returns
        -------
        list of Path
            ``part-*.parquet`` of the folder, sorted by name.
        """
        return sorted(self.dir.glob("part-*.parquet"))

    def done(self) -> set[int]:
        """The points already in the dataset.

        Returns
        -------
        set of int
            Their indices.
        """
        done: set[int] = set()
        for p in self.parts():
            done.update(pq.read_table(p, columns=["point"]).column("point").to_pylist())
        return done

    def failed(self) -> int:
        """The rows of the dataset whose point failed.

        Returns
        -------
        int
            The number of rows whose ``error`` is not null.
        """
        n = 0
        for p in self.parts():
            error = pq.read_table(p, columns=["error"]).column("error")
            n += len(error) - error.null_count
        return n

    def write(self, results: list[dict[str, Any]]) -> Path:
        """Writes one chunk of results as ``part-<first point>.parquet``: to a temporary file, then
        renamed, so a reader never sees half a chunk.

        Parameters
        ----------
        results : list of dict
            :func:`dmi_sweep.simulate.run_chunk`'s results, each with its ``point``; statistics it
            lacks are NaN (null for ``error`` and ``*_poincare``).

        Returns
        -------
        Path
            The file written.
        """
        results = sorted(results, key=lambda r: r["point"])
        cols: dict[str, list] = {f.name: [] for f in self.schema}
        for r in results:
            values = self.spec.point(r["point"])
            for f in self.schema:
                if f.name in values:
                    cols[f.name].append(values[f.name])
                elif f.name in ("point", "error") or f.name.endswith("_poincare"):   # null if absent
                    cols[f.name].append(r.get(f.name))
                else:
                    cols[f.name].append(r.get(f.name, math.nan))
        table = pa.Table.from_pydict(cols, schema=self.schema)
        name = f"part-{results[0]['point']:09d}.parquet"
        k = 1
        while (self.dir / name).exists():      # never replace a chunk (a repaired file keeps its name)
            name = f"part-{results[0]['point']:09d}-{k}.parquet"
            k += 1
        self._write_atomic(name, lambda f: pq.write_table(table, f))
        self.log({"file": name, "points": [r["point"] for r in results],   # the worker's pid
                  "workers": sorted({r.get("pid") for r in results if r.get("pid")}),
                  "instantiations": max(r.get("instantiations", 0) for r in results)})
        return self.dir / name
