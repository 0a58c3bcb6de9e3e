# The result folder: a Parquet dataset of chunk files part-<first point>.parquet
# (each written to a hidden temporary file, then renamed), the spec (_spec.toml),
# the metadata (_meta.json) and a log of the runs and chunks written (_log.jsonl:
# points, worker pids, FMU instantiations so far on the worker).
# Readers (pandas.read_parquet, pyarrow) skip names starting with "_" or ".".
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import json
import math
import os
import platform
import time
from importlib import metadata
from pathlib import Path
from typing import Any, BinaryIO, Callable

import pyarrow as pa
import pyarrow.parquet as pq

from .spec import Spec

META = "_meta.json"
SPEC = "_spec.toml"
LOG = "_log.jsonl"
TMP = ".tmp-"            # temporary files: .tmp-<pid of the writer>-<name>


class StoreError(RuntimeError):
    """The folder holds something else than this sweep (message says what to do)."""


def _running(pid: int) -> bool:
    """Whether the process `pid` exists (on this machine)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for dist in ("dmi", "fmpy", "dask", "distributed", "pyarrow", "numpy", "pandas"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def schema(spec: Spec) -> pa.Schema:
    """Columns: the swept parameters, point, per output y: y_final, y_min, y_max, y_mean
    (and y_poincare, a list), error (null when the point succeeded)."""
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
    """The result folder of one sweep."""

    def __init__(self, directory: Path, spec: Spec):
        self.dir = directory
        self.spec = spec
        self.schema = schema(spec)

    @classmethod
    def open(cls, directory: str | os.PathLike, spec: Spec, restart: bool = False) -> "Store":
        """Creates the folder, or reopens it to resume the same sweep. A folder of another sweep
        (spec or FMU changed) is an error unless restart, which deletes its results."""
        d = Path(directory)
        store = cls(d, spec)
        meta_path = d / META
        if d.exists() and not d.is_dir():
            raise StoreError(f"{d} exists and is not a folder")
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
                store._clear()
        elif d.exists() and any(p for p in d.iterdir()):
            raise StoreError(f"{d} is not empty and holds no dmi-sweep results ({META} missing); "
                             "give an empty or new folder")
        d.mkdir(parents=True, exist_ok=True)
        if not meta_path.exists():
            store._write_atomic(SPEC, lambda f: f.write(spec.text))
            meta = {"identity": identity, "fmu": str(spec.fmu), "fmu_sha256": spec.sha256,
                    "fmi_version": spec.model.fmiVersion, "model_name": spec.model.modelName,
                    "points": spec.n_points, "params": spec.params, "outputs": spec.outputs,
                    "mode": spec.mode, "versions": _versions(),
                    "created": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
            store._write_atomic(META, lambda f: f.write(json.dumps(meta, indent=1).encode()))
        store._remove_stale_temporaries()
        return store

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
        return sorted(self.dir.glob("part-*.parquet"))

    def done(self) -> set[int]:
        """The points already in the dataset."""
        done: set[int] = set()
        for p in self.parts():
            done.update(pq.read_table(p, columns=["point"]).column("point").to_pylist())
        return done

    def write(self, results: list[dict[str, Any]]) -> Path:
        """Writes one chunk of results (each with its "point") as part-<first point>.parquet:
        to a temporary file, then renamed, so a reader never sees half a chunk."""
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
        self._write_atomic(name, lambda f: pq.write_table(table, f))
        with open(self.dir / LOG, "a") as f:   # which points this run computed (pid of the worker)
            f.write(json.dumps({"time": time.time(), "client": os.getpid(), "file": name,
                                "points": [r["point"] for r in results],
                                "workers": sorted({r.get("pid") for r in results if r.get("pid")}),
                                "instantiations": max(r.get("instantiations", 0) for r in results)})
                    + "\n")
        return self.dir / name
