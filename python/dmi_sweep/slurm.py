# Sweeps on SLURM (dmi-sweep run --slurm): the job settings (from the command line, the spec's
# [slurm] section and Dask's jobqueue.slurm configuration, in that order), checked before anything
# runs; dask-jobqueue's SLURMCluster built from them, its job script tried with `sbatch --test-only`
# (SLURM's own message if it refuses it); and which of the cluster's jobs SLURM still has.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import re
import shutil
import subprocess
from typing import Any

# The settings, named as in dask-jobqueue and SLURM (partition is SLURMCluster's queue).
KEYS = ("partition", "account", "cores", "memory", "walltime", "jobs")
# What each one becomes: a keyword of SLURMCluster (jobs is cluster.scale(jobs=...)).
JOBQUEUE = {"partition": "queue", "account": "account", "cores": "cores", "memory": "memory",
            "walltime": "walltime"}
# SLURM's time formats: minutes, minutes:seconds, hours:minutes:seconds, days-hours,
# days-hours:minutes, days-hours:minutes:seconds
WALLTIME = re.compile(r"\d+(:\d+){0,2}|\d+-\d+(:\d+){0,2}")


class SlurmSettingError(ValueError):
    """A bad SLURM setting: the message says which and why (a ``ValueError``)."""


def check(settings: dict[str, Any], where: str) -> dict[str, Any]:
    """The SLURM settings checked and normalised.

    Parameters
    ----------
    settings : dict
        Some of :data:`KEYS` (``partition``, ``account``, ``cores``, ``memory``, ``walltime``,
        ``jobs``); None values are dropped.
    where : str
        The prefix of the names in the messages: ``"slurm."`` for the spec's section, ``"--"`` for
        the command line.

    Returns
    -------
    dict
        The settings without the None values.

    Raises
    ------
    SlurmSettingError
        For an unknown key, ``cores`` or ``jobs`` not an integer >= 1, a text that is empty or has
        spaces, a ``memory`` that is not an amount (``"4GB"``), a ``walltime`` that is not a SLURM
        time limit.
    """
    from dask.utils import parse_bytes
    unknown = sorted(set(settings) - set(KEYS))
    if unknown:
        raise SlurmSettingError(f"unknown SLURM settings {', '.join(where + k for k in unknown)}; "
                                f"valid: {', '.join(where + k for k in KEYS)}")
    out: dict[str, Any] = {}
    for key, value in settings.items():
        if value is None:
            continue
        name = where + key
        if key in ("cores", "jobs"):
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise SlurmSettingError(f"{name} = {value!r} is not an integer >= 1")
        elif not isinstance(value, str) or not value.strip() or re.search(r"\s", value):
            raise SlurmSettingError(f"{name} = {value!r} is not a non-empty word without spaces")
        elif key == "memory":
            try:
                if parse_bytes(value) < 1:
                    raise ValueError
            except ValueError:
                raise SlurmSettingError(f"{name} = {value!r} is not an amount of memory per job, "
                                        "such as \"4GB\" or \"500MiB\"") from None
        elif key == "walltime" and not WALLTIME.fullmatch(value):
            raise SlurmSettingError(f"{name} = {value!r} is not a SLURM time limit (MM, HH:MM:SS, "
                                    "D-HH:MM:SS, ...)")
        out[key] = value
    return out


def resolve(command_line: dict[str, Any], section: dict[str, Any]) -> dict[str, Any]:
    """The settings of a run: the command line's over the spec's ``[slurm]`` section over Dask's
    configuration (``jobqueue.slurm.queue``, ``.account``, ``.cores``, ``.memory``, ``.walltime``).

    Parameters
    ----------
    command_line : dict
        The checked command-line settings (None: not given).
    section : dict
        The checked ``[slurm]`` section of the spec.

    Returns
    -------
    dict
        The merged settings; ``jobs`` defaults to 1.

    Raises
    ------
    SlurmSettingError
        If ``cores`` or ``memory`` comes from none of the three.
    """
    import dask
    config = {k: dask.config.get(f"jobqueue.slurm.{v}", None) for k, v in JOBQUEUE.items()}
    merged = {k: v for k, v in config.items() if v is not None}
    merged.update(section)
    merged.update({k: v for k, v in command_line.items() if v is not None})
    merged.setdefault("jobs", 1)
    missing = [k for k in ("cores", "memory") if k not in merged]
    if missing:
        raise SlurmSettingError(f"--slurm needs {' and '.join('--' + k for k in missing)} (or "
                                f"{', '.join('slurm.' + k for k in missing)} in the spec, or Dask's "
                                f"{', '.join('jobqueue.slurm.' + k for k in missing)})")
    return merged


def cluster_kwargs(settings: dict[str, Any]) -> dict[str, Any]:
    """The keywords of ``dask_jobqueue.SLURMCluster`` for the settings.

    One single-threaded worker process per core of a job (processes = cores), the scheduler's
    dashboard on a free port of 127.0.0.1 (reach it through an SSH tunnel) unless Dask's
    ``jobqueue.slurm.scheduler-options`` says otherwise. What is not given here (interface, python,
    job-extra-directives, log-directory, ...) comes from Dask's ``jobqueue.slurm`` configuration.

    Parameters
    ----------
    settings : dict
        Resolved settings (:func:`resolve`); ``cores`` is required.

    Returns
    -------
    dict
        The keywords.
    """
    import dask
    kw = {JOBQUEUE[k]: v for k, v in settings.items() if k in JOBQUEUE}
    kw["processes"] = settings["cores"]
    options = dict(dask.config.get("jobqueue.slurm.scheduler-options", None) or {})
    options.setdefault("dashboard_address", "127.0.0.1:0")
    kw["scheduler_options"] = options
    return kw


class SlurmRefused(RuntimeError):
    """SLURM refuses the job script (``sbatch --test-only``), or cannot be asked: nothing was run."""


def start(settings: dict[str, Any], security=None):
    """A SLURMCluster for the settings, its jobs submitted.

    Parameters
    ----------
    settings : dict
        Resolved settings (:func:`resolve`).
    security : distributed.Security, optional
        TLS files on the shared filesystem: the scheduler listens on ``tls://`` and the job script
        gives the workers ``--protocol tls://`` and the worker's files.

    Returns
    -------
    dask_jobqueue.SLURMCluster
        The cluster, whose job script SLURM accepted, with ``jobs`` jobs submitted.

    Raises
    ------
    SlurmRefused
        If ``sbatch`` is not on the PATH, dask-jobqueue is missing, or SLURM refuses the job script
        (its message; the cluster is closed).
    """
    sbatch = shutil.which("sbatch")
    if sbatch is None:
        raise SlurmRefused("--slurm: SLURM's sbatch is not on the PATH of this machine (run "
                           "dmi-sweep on a login node of the cluster). Nothing was run")
    try:
        from dask_jobqueue import SLURMCluster
    except ImportError:
        raise SlurmRefused("--slurm needs dask-jobqueue: pip install dask-jobqueue. "
                           "Nothing was run") from None
    import dask
    # One task per worker at a time: a job that ends takes only its running chunks with it.
    with dask.config.set({"distributed.scheduler.worker-saturation": 1.0}):
        cluster = SLURMCluster(**cluster_kwargs(settings), security=security)
    try:
        r = subprocess.run([sbatch, "--test-only"], input=cluster.job_script(), capture_output=True,
                           text=True, timeout=60)
        if r.returncode != 0:
            message = " ".join(line.strip() for line in r.stderr.splitlines() if line.strip())
            raise SlurmRefused(f"SLURM refuses the job ({', '.join(f'{k} {v}' for k, v in settings.items())}): "
                               f"{message or 'sbatch exited with ' + str(r.returncode)}. Nothing was run")
        cluster.scale(jobs=settings["jobs"])
    except BaseException:
        cluster.close()
        raise
    return cluster


def jobs_alive(cluster) -> bool:
    """Whether SLURM still has a job of the cluster (pending, configuring or running): its workers
    may yet come.

    Parameters
    ----------
    cluster : dask_jobqueue.SLURMCluster
        A cluster of :func:`start`.

    Returns
    -------
    bool
        True if ``squeue`` lists one of its jobs as PENDING, CONFIGURING or RUNNING; False when it
        has none, or when squeue cannot say (missing, failing, timing out).
    """
    ids = [str(job.job_id) for job in getattr(cluster, "workers", {}).values()
           if getattr(job, "job_id", None)]
    squeue = shutil.which("squeue")
    if not ids or squeue is None:
        return False
    try:
        r = subprocess.run([squeue, "-h", "-o", "%T", "-j", ",".join(ids)], capture_output=True,
                           text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return False
    return any(s in ("PENDING", "CONFIGURING", "RUNNING") for s in r.stdout.split())
