#!/usr/bin/env python3
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
"""Simulates DelayFrictionOscillator.fmu with fmpy from its start values (the
paper's Example 4.3), or with some of them changed by --start NAME=VALUE, and
writes the CSV t,w,v,friction,delay_force,sticking (one row per output
interval, from t = 0 to the stop time).  Prints where it wrote.

Exit status: 0; 1 if the FMU refuses a value or fails; 2 for a bad argument
(also an output folder that does not exist or cannot be written, checked
before the simulation).
"""
import argparse
import os
import sys

from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

OUTPUTS = ["w", "v", "friction", "delay_force", "sticking"]


def start_values(md, items: list, error) -> dict:
    """{name: value} from NAME=VALUE strings, each a parameter of the FMU, the
    value converted to the variable's type; error(message) for a bad one."""
    params = {v.name: v.type for v in md.modelVariables if v.causality in ("parameter", "input")}
    values = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or name not in params:
            error(f"--start {item}: expected NAME=VALUE with NAME one of " + ", ".join(params))
        try:
            values[name] = int(text) if params[name] == "Integer" else float(text)
        except ValueError:
            error(f"--start {item}: {text!r} is not a valid {params[name]} value")
    return values


def check_output(path: str, error) -> None:
    """error(message) unless path can be created or overwritten as a file."""
    if not path:
        error("--out '': no file name")
    folder = os.path.dirname(os.path.abspath(path))
    if os.path.isdir(path):
        error(f"--out {path}: is a folder, not a file name")
    if not os.path.isdir(folder):
        error(f"--out {path}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK) or (os.path.exists(path)
                                                     and not os.access(path, os.W_OK)):
        error(f"--out {path}: cannot write there (permission denied)")


def positive(text: str) -> float:
    """argparse type: a finite number > 0."""
    value = float(text)
    if not (0 < value < float("inf")):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number > 0")
    return value


def main() -> None:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(prog="fmu_run.py", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--fmu", default=os.path.join(root, "build", "fmu", "DelayFrictionOscillator.fmu"),
                    metavar="PATH",
                    help="the FMU to simulate (default: %(default)s)")
    ap.add_argument("--out", default="fmu_ex43.csv", metavar="CSV",
                    help="the CSV to write (default: %(default)s in the current folder)")
    ap.add_argument("csv", nargs="?", help="the CSV to write (same as --out)")
    ap.add_argument("--stop-time", type=positive, metavar="T",
                    help="end time in s (default: the FMU's DefaultExperiment stopTime, 30)")
    ap.add_argument("--interval", type=positive, metavar="DT",
                    help="output interval in s (default: its DefaultExperiment stepSize, 0.01)")
    ap.add_argument("--start", action="append", default=[], metavar="NAME=VALUE",
                    help="start value of a parameter or input, e.g. N=9991 (repeatable; "
                         "default: the FMU's start values)")
    a = ap.parse_args()
    if a.csv is not None:
        a.out = a.csv
    check_output(a.out, ap.error)
    if not os.path.isfile(a.fmu):
        ap.error(f"--fmu {a.fmu}: not found (build the project first)")
    md = read_model_description(a.fmu)
    start = start_values(md, a.start, ap.error)
    de = md.defaultExperiment
    stop = a.stop_time if a.stop_time is not None else float(de.stopTime)
    interval = a.interval if a.interval is not None else float(de.stepSize)
    try:
        r = simulate_fmu(a.fmu, stop_time=stop, output_interval=interval, output=OUTPUTS,
                         start_values=start)
    except FMICallException as e:  # the FMU's reason was logged above
        sys.exit(f"fmu_run: {e}")
    with open(a.out, "w") as f:
        f.write("t," + ",".join(OUTPUTS) + "\n")
        for row in r:
            f.write("%.17g,%.17g,%.17g,%.17g,%.17g,%d\n" % (row["time"], row["w"], row["v"],
                    row["friction"], row["delay_force"], int(row["sticking"])))
    changed = "".join(f", {k} = {v}" for k, v in start.items())
    print(f"fmu_run: {len(r)} rows, t = 0 .. {stop:g}{changed}, written to {os.path.abspath(a.out)}")


if __name__ == "__main__":
    main()
