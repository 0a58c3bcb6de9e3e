# The command line of every program in bench/ and examples/:
# --help exits 0 with a usage that names each argument and says what the
# program prints; a bad argument exits 2 with a message that names it.  The
# programs are found in the build folders DMI_BENCH_DIR and DMI_EXAMPLES_DIR,
# so a new program is checked without a change here.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re
import subprocess
from pathlib import Path

import pytest


def programs():
    found = []
    for var in ("DMI_BENCH_DIR", "DMI_EXAMPLES_DIR"):
        folder = Path(os.environ[var])
        found += sorted(p for p in folder.iterdir() if p.is_file() and os.access(p, os.X_OK))
    return found


PROGRAMS = programs()
NAMES = {p.name: p for p in PROGRAMS}


def run(prog, *args):
    return subprocess.run([str(prog), *args], capture_output=True, text=True, timeout=120)


def test_all_programs_found():
    for name in ("bench_conv", "bench_fft", "ex41", "ex42", "ex43", "paper_summary",
                 "scheme44_as_printed"):
        assert name in NAMES, f"{name} not found among {sorted(NAMES)}"


def usage_arguments(text):
    """The argument names of the usage line 'usage: prog [--help] [A [B]]'."""
    line = text.splitlines()[0]
    return re.findall(r"\[([^\s\[\]]+)", line)[1:]  # without --help


@pytest.mark.parametrize("prog", PROGRAMS, ids=lambda p: p.name)
@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_help(prog, flag):
    r = run(prog, flag)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert r.stdout.startswith(f"usage: {prog.name} [--help]")
    assert "stdout:" in r.stdout, "the usage must say what the program prints"
    assert "exit status:" in r.stdout
    for name in usage_arguments(r.stdout):  # each argument: a line with its meaning and default
        assert re.search(rf"^  {re.escape(name)} +\S.*\(default", r.stdout, re.M), f"{name} not explained"


def test_ex43_help_warns_of_its_output():
    """With no arguments ex43 writes about 300,000 CSV lines (T*N + 2 = 299,732)."""
    text = " ".join(run(NAMES["ex43"], "--help").stdout.split())
    assert "with no arguments about 300,000 lines" in text


@pytest.mark.parametrize("prog", PROGRAMS, ids=lambda p: p.name)
def test_empty_argument_rejected(prog):
    """'' is a bad value for every kind of argument, and surplus where none is taken."""
    r = run(prog, "")
    assert r.returncode == 2, r.stderr
    assert r.stdout == ""
    assert re.match(rf"{prog.name}: (\S+ = ''|too many arguments: '')", r.stderr), r.stderr


@pytest.mark.parametrize("name, args, message", [
    # bench_conv 0 and abc used to die with SIGFPE, -1 said "out of memory"
    ("bench_conv", ["0"], "T = '0': must be > 0"),
    ("bench_conv", ["abc"], "T = 'abc': must be a number"),
    ("bench_conv", ["-1"], "T = '-1': must be > 0"),
    ("bench_conv", ["1e-9"], "T = '1e-9': gives no step"),
    ("bench_conv", ["1e300"], "T = '1e300': must be at most 100"),
    ("bench_conv", ["3", "4"], "too many arguments: '4'"),
    ("bench_fft", ["1"], "too many arguments: '1'"),
    ("ex41", ["0"], "N = '0': must be >= 1"),
    ("ex42", ["10", "nan"], "T = 'nan': must be a number"),
    ("ex43", ["-5"], "N = '-5': must be a whole number"),
    ("ex43", ["10", "1", "0"], "stride = '0': must be >= 1"),
    ("ex43", ["10", "inf"], "T = 'inf': must be finite"),
    ("ex43", ["10", "1", "1", "1"], "too many arguments: '1'"),
    ("ex43", ["--frobnicate"], "N = '--frobnicate'"),
    ("ex43", ["99999999999999999999999"], "N = '99999999999999999999999': is too large"),
    ("scheme44_as_printed", ["0"], "T = '0': must be > 0"),
    ("paper_summary", ["/nonexistent-dmi-dir/order.csv"],
     "order.csv = '/nonexistent-dmi-dir/order.csv': No such file"),
])
def test_bad_argument(name, args, message):
    r = run(NAMES[name], *args)
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert r.stdout == ""
    assert r.stderr.startswith(f"{name}: {message}"), r.stderr
    assert f"usage: {name}" in r.stderr


def test_good_arguments_unchanged():
    """exNN [N [T [stride]]] as scripts/main.sh uses it: rows t_p = 0, 0.1, ..., 1."""
    r = run(NAMES["ex43"], "100", "1", "10")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0] == "t,w,v"
    assert [float(x.split(",")[0]) for x in lines[1:]] == pytest.approx(
        [k / 10 for k in range(11)], abs=1e-12)
    assert "h = 1/100, 100 steps" in r.stderr
