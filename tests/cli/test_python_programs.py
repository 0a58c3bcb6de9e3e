# The command line of every Python program in bench/ and scripts/, found in
# the source tree DMI_SOURCE_DIR, so that a new program is
# checked without a change here: --help exits 0 with a usage, a description
# that says what the program prints, and a help text for each option (with its
# default when it takes a value); an unknown option and an empty value for any
# option exit 2 with a message naming the option, without a traceback.
# PYTHONPATH holds python/ (bench_sweep.py imports dmi_sweep).
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

SOURCE = Path(os.environ["DMI_SOURCE_DIR"])
PROGRAMS = sorted(p for folder in ("bench", "scripts") for p in (SOURCE / folder).glob("*.py"))


def run(prog, *args, cwd=None):
    # an accepted bad value would start the program's real work: the timeout ends it, the test fails
    return subprocess.run([sys.executable, str(prog), *args], capture_output=True, text=True,
                          timeout=120, cwd=cwd)


def options(help_text: str) -> dict[str, tuple[bool, str]]:
    """The options of an argparse help text: name -> (takes a value, its help text)."""
    found: dict[str, tuple[bool, str]] = {}
    section = help_text.split("\noptions:\n", 1)[1]
    entry = None
    for line in section.splitlines():
        # names, each with its metavar words (one space apart: "--N N [N ...]", "--chart P Q"),
        # then the help text after two spaces or more
        m = re.match(r"  (-\S+(?: [^\s-]\S*)*(?:, -\S+(?: [^\s-]\S*)*)*)(?:  +(.*))?$", line)
        if m:
            names = [n.strip() for n in m.group(1).split(",")]
            entry = [n.split()[0] for n in names], any(" " in n for n in names), [m.group(2) or ""]
            for n in entry[0]:
                found[n] = entry
        elif entry and line.startswith("    "):
            entry[2].append(line.strip())
    return {n: (takes, " ".join(" ".join(text).split())) for n, (_, takes, text) in found.items()}


def test_programs_found():
    names = {p.name for p in PROGRAMS}
    assert {"bench_sweep.py", "bench_fmu.py", "fmu_run.py"} <= names, names


@pytest.mark.parametrize("prog", PROGRAMS, ids=lambda p: p.name)
def test_help(prog):
    r = run(prog, "--help")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(f"usage: {prog.name} "), r.stdout
    head = " ".join(r.stdout.split("\noptions:\n", 1)[0].split())
    assert re.search(r"\bprints?\b", head, re.I), "the description must say what the program prints"
    opts = options(r.stdout)
    assert "--help" in opts and len(opts) > 1, r.stdout
    for name, (takes_value, text) in opts.items():
        assert text, f"{name} has no help text"
        if takes_value:
            assert "default" in text, f"{name}: no default shown ({text})"


def test_option_parser_reads_argparse_help():
    """The parser of the help text on a known case (so that test_help cannot pass on nothing)."""
    text = ("usage: x\n\nPrints.\n\noptions:\n  -h, --help  show this help\n  --a A       first\n"
            "              (default: 1)\n  --bee BEE\n              second\n  --flag      a switch\n"
            "  --N N [N ...]\n              cells (default: [1000])\n  --chart P Q  a chart\n")
    assert options(text) == {"-h": (False, "show this help"), "--help": (False, "show this help"),
                             "--a": (True, "first (default: 1)"), "--bee": (True, "second"),
                             "--flag": (False, "a switch"), "--N": (True, "cells (default: [1000])"),
                             "--chart": (True, "a chart")}


@pytest.mark.parametrize("prog", PROGRAMS, ids=lambda p: p.name)
def test_unknown_option_rejected(prog, tmp_path):
    r = run(prog, "--no-such-option", cwd=tmp_path)
    assert r.returncode == 2, r.stderr
    assert "--no-such-option" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not list(tmp_path.iterdir())


def value_options():
    cases = []
    for prog in PROGRAMS:
        text = run(prog, "--help").stdout
        cases += [(prog, name) for name, (takes, _) in options(text).items() if takes]
    return cases


@pytest.mark.parametrize("prog, option", value_options(), ids=lambda x: getattr(x, "name", x))
def test_empty_value_rejected(prog, option, tmp_path):
    """'' is a bad value for every option that takes one: exit 2 before any work, a message
    naming the option, nothing written."""
    r = run(prog, option, "", cwd=tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert option in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize("args, message", [
    (["--points", "0"], "argument --points: '0' is not an integer >= 1"),
    (["--points", "2.5"], "argument --points: '2.5' is not an integer >= 1"),
    (["--stop-time", "-1"], "argument --stop-time: '-1' is not a finite number > 0"),
    (["--stop-time", "nan"], "argument --stop-time: 'nan' is not a finite number > 0"),
    (["--N", "abc"], "argument --N: 'abc' is not an integer >= 1"),
    (["--repeat", "0"], "argument --repeat: '0' is not an integer >= 1"),
    (["--fmu", "/nonexistent-dmi/x.fmu"], "--fmu '/nonexistent-dmi/x.fmu': no such file"),
])
def test_bench_sweep_bad_arguments(args, message):
    """bench_sweep.py --points 0 printed a SpecError traceback (exit 1)."""
    r = run(SOURCE / "bench" / "bench_sweep.py", *args)
    assert r.returncode == 2, r.stderr
    assert f"bench_sweep.py: error: {message}" in r.stderr and "Traceback" not in r.stderr, r.stderr


def test_bench_sweep_help_shows_defaults():
    text = " ".join(run(SOURCE / "bench" / "bench_sweep.py", "--help").stdout.split())
    for shown in ("points of the sweep (values of g_amp) (default: 48)", "(default: 60.0)",
                  "solver steps per unit time (default: 9991)", "Prints the points per second"):
        assert shown in text, shown
