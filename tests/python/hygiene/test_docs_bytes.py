# The manual's and the examples' text holds no control characters (a TeX command typed into a
# string where a backslash escape ate it: "\alpha" in a normal Python string is BEL + "lpha", "\v"
# a vertical tab, "\r" a carriage return): tabs and newlines only, and every file UTF-8.
# Copyright (C) 2026 the dmi authors.  SPDX-License-Identifier: GPL-3.0-or-later
from __future__ import annotations

import os
import re
from pathlib import Path

ROOT = Path(os.environ.get("DMI_SOURCE_DIR", Path(__file__).resolve().parents[3]))
TEXT = {".md", ".py", ".rst", ".txt", ".toml", ".c", ".h", ".f90", ".html", ".js", ".css", ".json",
        ".yaml", ".yml", ".sh", ".in", ".cfg"}
CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0d\x0e-\x1f\x7f]")


def offences(root: Path) -> list[str]:
    """"path:line: the control characters found" for every text file under root, and "path: not
    UTF-8" for a text file that does not decode."""
    found = []
    for dirpath, dirnames, filenames in os.walk(root):
        dirnames[:] = [d for d in dirnames if d not in {"__pycache__", "_build"}]
        for name in sorted(filenames):
            path = Path(dirpath, name)
            if path.suffix not in TEXT:
                continue
            try:
                text = path.read_bytes().decode("utf-8")
            except UnicodeDecodeError:
                found.append(f"{path.relative_to(root)}: not UTF-8")
                continue
            for i, line in enumerate(text.split("\n"), 1):
                bad = sorted({f"U+{ord(c):04X}" for c in CONTROL.findall(line)})
                if bad:
                    found.append(f"{path.relative_to(root)}:{i}: {', '.join(bad)}")
    return found


def test_the_scan_finds_control_characters(tmp_path):
    (tmp_path / "a.md").write_text("the reversal's \\rho and \x07lpha\n", encoding="utf-8")
    (tmp_path / "b.py").write_bytes(b"x = 1\r\n")
    (tmp_path / "c.md").write_bytes(b"caf\xe9\n")
    (tmp_path / "d.md").write_text("tabs\tare text\n", encoding="utf-8")
    (tmp_path / "e.png").write_bytes(b"\x89PNG\x00\x07")
    assert offences(tmp_path) == ["a.md:1: U+0007", "b.py:1: U+000D", "c.md: not UTF-8"]


def test_docs_and_examples_hold_no_control_characters():
    for folder in ("docs", "examples"):
        assert (ROOT / folder).is_dir(), ROOT / folder
        found = offences(ROOT / folder)
        assert not found, "\n".join(found[:20])
