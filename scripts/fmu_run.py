#!/usr/bin/env python3
# Simulates DelayFrictionOscillator.fmu with fmpy from its start values
# (Example 4.3) and writes the CSV t,w,v,friction,delay_force,sticking.
# Usage: scripts/fmu_run.py [--fmu PATH] [--out CSV | CSV] [--stop-time T] [--interval DT]
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import argparse
import os
import sys

from fmpy import read_model_description, simulate_fmu

OUTPUTS = ["w", "v", "friction", "delay_force", "sticking"]


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--fmu", default=os.path.join(root, "build", "fmu", "DelayFrictionOscillator.fmu"))
    ap.add_argument("--out", default="fmu_ex43.csv")
    ap.add_argument("csv", nargs="?", help="the CSV to write (same as --out)")
    ap.add_argument("--stop-time", type=float, help="default: the FMU's DefaultExperiment")
    ap.add_argument("--interval", type=float, help="output interval; default: its stepSize")
    a = ap.parse_args()
    if a.csv:
        a.out = a.csv
    if not os.path.isfile(a.fmu):
        sys.exit(f"fmu_run: {a.fmu} not found (build the project first)")
    de = read_model_description(a.fmu).defaultExperiment
    stop = a.stop_time if a.stop_time is not None else float(de.stopTime)
    interval = a.interval if a.interval is not None else float(de.stepSize)
    r = simulate_fmu(a.fmu, stop_time=stop, output_interval=interval, output=OUTPUTS)
    with open(a.out, "w") as f:
        f.write("t," + ",".join(OUTPUTS) + "\n")
        for row in r:
            f.write("%.17g,%.17g,%.17g,%.17g,%.17g,%d\n" % (row["time"], row["w"], row["v"],
                    row["friction"], row["delay_force"], int(row["sticking"])))
    print(f"fmu_run: {len(r)} rows, t = 0 .. {stop:g}, written to {a.out}")


if __name__ == "__main__":
    main()
