# The command line: dmi-sweep run SPEC.toml --out DIR [options], dmi-sweep plot DIR --x PARAM [options]
# (`dmi-sweep run --help` and docs/sweep.md list them).  Exit statuses: see EXIT below.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import sys

from . import NO_WORKER_TIMEOUT, __version__


EXIT = """exit status:
  0    every point of the sweep succeeded (the folder holds all of them)
  1    every point was computed, but some failed: their rows hold the error (the count is printed)
  2    nothing was run: a bad spec or command line, [start] values the FMU refuses, a folder
       that holds another sweep or that another client is using, missing or bad TLS certificates,
       SLURM job settings that SLURM refuses
  3    the cluster was lost or could not be reached, or had no worker for --no-worker-timeout
       seconds (with --slurm: and SLURM had none of its jobs left): the finished points are
       saved, and the same command resumes
  130  interrupted (Ctrl-C): the finished points are saved, and the same command resumes"""


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1.

    Parameters
    ----------
    text : str
        The command-line text.

    Returns
    -------
    int
        Its value.

    Raises
    ------
    argparse.ArgumentTypeError
        If it is not an integer >= 1 (the message names the text).
    """
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer >= 1")
    return n


def positive_seconds(text: str) -> float:
    """argparse type: a finite number of seconds > 0.

    Parameters
    ----------
    text : str
        The command-line text.

    Returns
    -------
    float
        Its value.

    Raises
    ------
    argparse.ArgumentTypeError
        If it is not a finite number > 0 (the message names the text).
    """
    try:
        x = float(text)
    except ValueError:
        x = 0.0
    if not 0 < x < float("inf"):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds > 0")
    return x


def parser() -> argparse.ArgumentParser:
    """The command line of ``dmi-sweep``: the subcommands ``run`` and ``plot`` with their options.

    Returns
    -------
    argparse.ArgumentParser
        A new parser.
    """
    fmt = argparse.RawDescriptionHelpFormatter
    ap = argparse.ArgumentParser(prog="dmi-sweep", formatter_class=fmt, epilog=EXIT,
                                 description="Parameter sweeps of a co-simulation FMU on Dask, and "
                                 "their plots.")
    ap.add_argument("--version", action="version", version=f"dmi-sweep {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run (or resume) a sweep", formatter_class=fmt, epilog=EXIT,
                       description="Runs the sweep of SPEC into the folder --out, or resumes it: an "
                       "unchanged spec computes only the points missing from the folder. One client "
                       "per folder: a second one is refused (exit 2).")
    r.add_argument("spec", help="the sweep specification (TOML)")
    r.add_argument("--out", required=True, help="the result folder (a Parquet dataset)")
    r.add_argument("--workers", type=positive_int, help="worker processes of the local cluster "
                   "(default: one per core); the local cluster listens on 127.0.0.1 only")
    r.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler: "
                   "tls://host:port (with certificates), or tcp://host:port on a private network only")
    g = r.add_argument_group("SLURM", "run the workers as SLURM jobs (dask-jobqueue's SLURMCluster, "
                             "the scheduler in this process): these options, over the spec's [slurm] "
                             "section, over Dask's jobqueue.slurm configuration")
    g.add_argument("--slurm", action="store_true", help="submit the workers to SLURM (sbatch) instead "
                   "of a local cluster; the job script is tried first (sbatch --test-only): a job SLURM "
                   "refuses gives exit 2 with SLURM's message")
    g.add_argument("--partition", help="the partition (SLURMCluster's queue; sbatch -p)")
    g.add_argument("--account", help="the account charged (sbatch -A)")
    g.add_argument("--cores", type=positive_int, help="cores per job: one single-threaded worker "
                   "process on each (required, here or in the spec or configuration)")
    g.add_argument("--memory", help="memory per job, such as 64GB (required, here or in the spec or "
                   "configuration)")
    g.add_argument("--walltime", help="the time limit of each job, such as 04:00:00 (default: "
                   "Dask's jobqueue.slurm.walltime, 00:30:00)")
    g.add_argument("--jobs", type=positive_int, help="jobs to submit (default: 1)")
    r.add_argument("--no-worker-timeout", metavar="SECONDS", type=positive_seconds,
                   default=NO_WORKER_TIMEOUT, help="stop the run (exit 3, the finished points saved) "
                   "when the cluster has had no worker for this long, as when every worker of a "
                   f"--scheduler died (default: {NO_WORKER_TIMEOUT:g})")
    r.add_argument("--tls-ca-file", metavar="PEM", help="the CA certificate(s) that signed the "
                   "scheduler's certificate (default: Dask's distributed.comm.tls.ca-file); with "
                   "--slurm, the --tls-* files turn TLS on between the scheduler, the workers and "
                   "this client, each with --tls-cert and --tls-key (on the shared filesystem)")
    r.add_argument("--tls-cert", metavar="PEM", help="this client's certificate (default: Dask's "
                   "distributed.comm.tls.client.cert)")
    r.add_argument("--tls-key", metavar="PEM", help="this client's private key, unless --tls-cert "
                   "holds it (default: Dask's distributed.comm.tls.client.key)")
    r.add_argument("--restart", action="store_true", help="delete the folder's results, whatever "
                   "spec they came from, and start again (without it, an unchanged spec resumes and "
                   "a changed one is refused)")
    r.add_argument("--chunk-size", type=positive_int, help="points per task (default: about 8 tasks "
                   "per worker, at most 64 points each)")
    r.add_argument("--dashboard", action="store_true", help="start the local cluster's Dask dashboard "
                   "on a free port of 127.0.0.1 and print its address (with --scheduler: print the "
                   "scheduler's)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    p = sub.add_parser("plot", help="plot a sweep: bifurcation diagram (one parameter) or heatmap (two)",
                       description="Plots the sweep in DIR against the parameter --x: its Poincare "
                       "samples or a metric (a sweep of one parameter), one line per value of --hue, or "
                       "a heatmap over --x and --y. A sweep of two or more parameters needs --y or "
                       "--hue (and the others held at one value).")
    p.add_argument("dir", help="the result folder")
    p.add_argument("--x", required=True, help="the parameter on the x axis")
    p.add_argument("--y", help="a second parameter: a heatmap of the metric over --x and --y")
    p.add_argument("--hue", help="a second parameter: one line (or set of points) per value of it")
    p.add_argument("--metric", help="the column to show (default: the first *_poincare column, or "
                   "with --y the first *_mean column)")
    p.add_argument("-o", "--output", required=True, help="the PNG to write")
    return ap


def main(argv: list[str] | None = None) -> int:
    """Runs the command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the program name (default: ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit status: 0 every point succeeded, 1 some points failed, 2 nothing was run (bad
        input), 3 the cluster was lost (the finished points saved), 130 interrupted; :data:`EXIT`
        (the epilog of ``dmi-sweep run --help``) says each in full.

    Raises
    ------
    SystemExit
        From argparse, for bad options, ``--help`` and ``--version``.
    """
    a = parser().parse_args(argv)
    if a.command == "run":
        return _run(a)
    from .plot import PlotError, plot
    try:
        plot(a.dir, a.x, a.y, a.metric, a.output, hue=a.hue)
    except PlotError as e:
        print(f"dmi-sweep plot: {e}", file=sys.stderr)
        return 2
    print(f"dmi-sweep: wrote {a.output}")
    return 0


def _run(a: argparse.Namespace) -> int:
    from .run import ClusterLost, ConnectionSetupError, run
    from .slurm import KEYS, SlurmRefused, SlurmSettingError, check, resolve
    from .spec import SpecError, load
    from .store import StoreError
    if a.workers and a.scheduler:
        print("dmi-sweep: --workers is for the local cluster; with --scheduler the cluster's "
              "workers are used", file=sys.stderr)
        return 2
    given = [f"--{k}" for k in KEYS if getattr(a, k) is not None]
    if a.slurm and (a.workers or a.scheduler):
        print(f"dmi-sweep: --slurm runs its own cluster: not with {'--workers' if a.workers else '--scheduler'}",
              file=sys.stderr)
        return 2
    if given and not a.slurm:
        print(f"dmi-sweep: {', '.join(given)} given without --slurm", file=sys.stderr)
        return 2
    try:
        spec = load(a.spec)
        slurm = None
        if a.slurm:
            try:
                slurm = resolve(check({k: getattr(a, k) for k in KEYS}, "--"), spec.slurm)
            except SlurmSettingError as e:
                print(f"dmi-sweep: {e}", file=sys.stderr)
                return 2
        s = run(spec, a.out, workers=a.workers, scheduler=a.scheduler, restart=a.restart,
                chunk_size=a.chunk_size, progress=None if a.quiet else sys.stderr,
                tls_ca_file=a.tls_ca_file, tls_cert=a.tls_cert, tls_key=a.tls_key,
                dashboard=a.dashboard, no_worker_timeout=a.no_worker_timeout, slurm=slurm)
    except SpecError as e:
        print(f"dmi-sweep: bad spec {a.spec}: {e}", file=sys.stderr)
        return 2
    except (StoreError, ConnectionSetupError, SlurmRefused) as e:
        print(f"dmi-sweep: {e}", file=sys.stderr)
        return 2
    except ClusterLost as e:
        if e.saved is None:
            print(f"dmi-sweep: {e.reason}.\nNothing was run; the same command starts the sweep once "
                  "the scheduler is up.", file=sys.stderr)
        else:
            print(f"dmi-sweep: {e.reason}.\n{e.saved} of {e.total} points are saved in {a.out}; the "
                  f"same command resumes the sweep ({e.resume}).", file=sys.stderr)
        return 3
    except KeyboardInterrupt:
        print(f"dmi-sweep: interrupted; the finished chunks are in {a.out}: run the same "
              "command to resume", file=sys.stderr)
        return 130
    print(f"dmi-sweep: {s.total} points in {a.out} ({s.skipped} already there, {s.computed} "
          f"computed in {s.seconds:.1f} s, {s.failed} failed)")
    if s.failed:
        print(f"dmi-sweep: {s.failed} of {s.total} points failed: their rows hold the reason in the "
              "column error", file=sys.stderr)
        return 1
    return 0
