#!/usr/bin/env python3
# Simulates DelayFrictionOscillator.fmu with fmpy from its start values
# (Example 4.3), or with some of them changed by --start NAME=VALUE (repeatable,
# e.g. --start N=9991), and writes the CSV t,w,v,friction,delay_force,sticking.
# Usage: scripts/fmu_run.py [--fmu PATH] [--out CSV | CSV] [--stop-time T] [--interval DT]
#                           [--start NAME=VALUE ...]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import argparse
import os
import sys

from fmpy import read_model_description, simulate_fmu
from fmpy.fmi1 import FMICallException

OUTPUTS = ["w", "v", "friction", "delay_force", "sticking"]


def start_values(md, items):
    """{name: value} from NAME=VALUE strings, each a parameter of the FMU, the
    value converted to the variable's type."""
    params = {v.name: v.type for v in md.modelVariables if v.causality in ("parameter", "input")}
    values = {}
    for item in items:
        name, sep, text = item.partition("=")
        name = name.strip()
        if not sep or name not in params:
            sys.exit(f"fmu_run: --start {item}: expected NAME=VALUE with NAME one of "
                     + ", ".join(params))
        try:
            values[name] = int(text) if params[name] == "Integer" else float(text)
        except ValueError:
            sys.exit(f"fmu_run: --start {item}: {text!r} is not a valid {params[name]} value")
    return values


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--fmu", default=os.path.join(root, "build", "fmu", "DelayFrictionOscillator.fmu"))
    ap.add_argument("--out", default="fmu_ex43.csv")
    ap.add_argument("csv", nargs="?", help="the CSV to write (same as --out)")
    ap.add_argument("--stop-time", type=float, help="default: the FMU's DefaultExperiment")
    ap.add_argument("--interval", type=float, help="output interval; default: its stepSize")
    ap.add_argument("--start", action="append", default=[], metavar="NAME=VALUE",
                    help="start value of a parameter, e.g. N=9991 (repeatable)")
    a = ap.parse_args()
    if a.csv:
        a.out = a.csv
    if not os.path.isfile(a.fmu):
        sys.exit(f"fmu_run: {a.fmu} not found (build the project first)")
    md = read_model_description(a.fmu)
    start = start_values(md, a.start)
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
    print(f"fmu_run: {len(r)} rows, t = 0 .. {stop:g}{changed}, written to {a.out}")


if __name__ == "__main__":
    main()
