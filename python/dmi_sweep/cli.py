# The command line: dmi-sweep run SPEC.toml --out DIR [--workers K] [--scheduler ADDRESS]
#                   dmi-sweep plot DIR --x PARAM [--y PARAM] [--metric COLUMN] -o FILE.png
# Exit status: 0 done, 1 a failure while running, 2 a bad spec or command line
# (nothing was run), 130 interrupted (what was written stays; rerun to resume).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import argparse
import sys

from . import __version__


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1 (the message names the bad text)."""
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer >= 1")
    return n


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="dmi-sweep", description="Parameter sweeps of a co-simulation "
                                 "FMU on Dask, and their plots.")
    ap.add_argument("--version", action="version", version=f"dmi-sweep {__version__}")
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run (or resume) a sweep")
    r.add_argument("spec", help="the sweep specification (TOML)")
    r.add_argument("--out", required=True, help="the result folder (a Parquet dataset)")
    r.add_argument("--workers", type=positive_int, help="worker processes of the local cluster "
                   "(default: one per core)")
    r.add_argument("--scheduler", help="address of an existing Dask scheduler, tcp://host:port")
    r.add_argument("--restart", action="store_true", help="delete the results of another sweep in --out")
    r.add_argument("--chunk-size", type=positive_int, help="points per task (default: about 8 tasks per "
                   "worker, at most 64 points each)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    p = sub.add_parser("plot", help="plot a sweep: bifurcation diagram (one parameter) or heatmap (two)")
    p.add_argument("dir", help="the result folder")
    p.add_argument("--x", required=True, help="the parameter on the x axis")
    p.add_argument("--y", help="a second parameter: a heatmap of the metric")
    p.add_argument("--metric", help="the column to show (default: the first *_poincare column with one "
                   "parameter, else the first *_mean column)")
    p.add_argument("-o", "--output", required=True, help="the PNG to write")
    return ap


def main(argv: list[str] | None = None) -> int:
    """Runs the command line; returns the exit status."""
    a = parser().parse_args(argv)
    if a.command == "run":
        from .run import run
        from .spec import SpecError, load
        from .store import StoreError
        if a.workers and a.scheduler:
            print("dmi-sweep: --workers is for the local cluster; with --scheduler the cluster's "
                  "workers are used", file=sys.stderr)
            return 2
        try:
            spec = load(a.spec)
        except SpecError as e:
            print(f"dmi-sweep: bad spec {a.spec}: {e}", file=sys.stderr)
            return 2
        try:
            s = run(spec, a.out, workers=a.workers, scheduler=a.scheduler, restart=a.restart,
                    chunk_size=a.chunk_size, progress=None if a.quiet else sys.stderr)
        except StoreError as e:
            print(f"dmi-sweep: {e}", file=sys.stderr)
            return 2
        except KeyboardInterrupt:
            print(f"\ndmi-sweep: interrupted; the finished chunks are in {a.out}: run the same "
                  "command to resume", file=sys.stderr)
            return 130
        print(f"dmi-sweep: {s.total} points in {a.out} ({s.skipped} already there, {s.computed} "
              f"computed in {s.seconds:.1f} s, {s.failed} failed)")
        return 0
    from .plot import PlotError, plot
    try:
        plot(a.dir, a.x, a.y, a.metric, a.output)
    except PlotError as e:
        print(f"dmi-sweep plot: {e}", file=sys.stderr)
        return 2
    print(f"dmi-sweep: wrote {a.output}")
    return 0
