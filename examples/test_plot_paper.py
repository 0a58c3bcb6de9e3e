# Tests of the main job's figure and comparison script examples/plot_paper.py
# on the CSV files of the example programs (as scripts/main.sh makes them).
# Run by ctest (examples/CMakeLists.txt) with DMI_EXAMPLES_DIR = the folder of
# the built example programs and DMI_REFERENCE_DIR = ../shared/reference.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import csv
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
PLOT = HERE / "plot_paper.py"
FIGURES = ["fig4_1.png", "fig4_2.png", "fig4_3.png", "fig4_4.png", "fig4_5.png", "scheme44.png"]


def programs():
    return Path(os.environ["DMI_EXAMPLES_DIR"])


def reference():
    return Path(os.environ["DMI_REFERENCE_DIR"])


@pytest.fixture(scope="module")
def csv_dir(tmp_path_factory):
    """The CSV files of main.sh (the (4.4) comparison on [-1, 3] to save time)."""
    out = tmp_path_factory.mktemp("out")
    bin_dir = programs()
    for e, N, T, name in (("41", "9991", "10", "ex41"), ("42", "9991", "10", "ex42"),
                          ("43", "9991", "30", "ex43"), ("43", "1000", "30", "ex43_fmu_native")):
        with open(out / f"{name}.csv", "w") as f:
            subprocess.run([bin_dir / f"ex{e}", N, T, "1"], stdout=f, check=True,
                           stderr=subprocess.DEVNULL)
    subprocess.run([bin_dir / "paper_summary", out / "order.csv"], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out / "scheme44.csv", "w") as f:
        subprocess.run([bin_dir / "scheme44_as_printed", "3", "10"], stdout=f, check=True,
                       stderr=subprocess.DEVNULL)
    return out


def run_plot(out, ref):
    return subprocess.run([sys.executable, PLOT, out, ref], capture_output=True, text=True,
                          env=dict(os.environ, MPLBACKEND="Agg"))


def table_row(stdout, start):
    """The cells of the comparison-table row that starts with start."""
    line = next(x for x in stdout.splitlines() if x.startswith(start))
    return re.split(r"\s{2,}", line.strip())


def copy_of(src, dst):
    shutil.copytree(src, dst)
    return dst


def test_figures_and_agreement_with_reference(csv_dir, tmp_path):
    out = copy_of(csv_dir, tmp_path / "out")
    r = run_plot(out, reference())
    assert r.returncode == 0, r.stdout + r.stderr
    for name in FIGURES:
        data = (out / name).read_bytes()
        assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10000, name
    assert not (out / "fmu_ex43.png").exists()
    assert "skipped the FMU figure" in r.stdout
    # The slope of Figure 4.3 as printed in the comparison table, against the paper's 0.993.
    row = table_row(r.stdout, "Figure 4.3 slope, Example 4.2, (w, w')")
    assert abs(float(row[1]) - 0.993) < 0.02 and row[2] == "0.993"


def test_disagreement_with_reference_fails(csv_dir, tmp_path):
    """A reference whose errors differ by 5 % must make the script fail."""
    out = copy_of(csv_dir, tmp_path / "out")
    ref = copy_of(reference(), tmp_path / "ref")
    path = ref / "errors_ex41_ex42.csv"
    rows = list(csv.reader(path.open()))
    for row in rows[1:]:
        if row[0] == "4.1":
            row[3] = repr(float(row[3]) * 1.05)
    with path.open("w", newline="") as f:
        csv.writer(f).writerows(rows)
    r = run_plot(out, ref)
    assert r.returncode == 1
    assert "Example 4.1 max error in (w, w')" in r.stdout.splitlines()[-1]


def test_fmu_overlay(csv_dir, tmp_path):
    """An FMU result = the native run + 1e-6 in w at every 10th step: difference 1e-6."""
    shift = 1e-6
    out = copy_of(csv_dir, tmp_path / "out")
    with open(out / "ex43_fmu_native.csv") as src, open(out / "fmu43.csv", "w") as dst:
        rows = list(csv.reader(src))[1::10]
        dst.write("t,w,v,sticking\n")
        for t, w, v in rows:
            dst.write(f"{t},{float(w) + shift!r},{v},0\n")
    r = run_plot(out, reference())
    assert r.returncode == 0, r.stdout + r.stderr
    assert (out / "fmu_ex43.png").read_bytes()[:4] == b"\x89PNG"
    row = table_row(r.stdout, "Example 4.3, max |FMU - native|")
    assert row[0].endswith(f"h = 1/1000, at {len(rows)} times")
    assert float(row[1]) == pytest.approx(shift, rel=1e-6, abs=1e-15)
